"""Compiled kernels, built when the package is installed (``setup.py``) and loaded with ctypes
(:mod:`.loader`); a run needs no compiler. Each has a numpy form the tests compare it with.

``delaunay_cgal``: the 3D Delaunay triangulation by CGAL (Debian's header-only
``libcgal-dev``, exact predicates): the cells and their circumcentres. Measured on the lattice
rod of ``bench/bench_scale.py`` at 1,000,188 points: 8.3 s including the file exchange,
against about 70 s for scipy's qhull, with the same 6,976,387 cells.

``YADE_ELECTRO_DELAUNAY``: ``auto`` (default: CGAL from 120,000 points on when the helper was
built at install, else qhull), ``cgal`` (an error when it was not built) or ``qhull``. Below 120,000
points qhull stays the default: there CGAL saves only 10-20 % of the bounded cells (the
clipping at curved walls dominates), and on a lattice (cospherical points) the cell
volumes from CGAL's triangulation are exact only to 3.4e-12, against 5e-15 from qhull's
(``cases/slab_transient.py``'s finite-volume check; the cause is not found yet).

``graph_hops``: hop distances on a bond graph for the crack rules of the ``voronoi`` law
(:func:`hops_linked`), a shared library loaded with ctypes. At 1M elements it answers the
3-hop test of every Voronoi face in 0.24 s, where sparse-matrix powers (the numpy form)
took about 10 s and 1 GB.

``laplacian_fill``: the values of a condensed Laplacian's unknown block from new edge values
(:func:`laplacian_fill`, used by :class:`yade_electro.network.condensation.ReducedSystem`), numpy's
operations in one pass, the same values to the last bit; measured on the rod problems in
one process, 0.17 against 0.36-0.38 ms at 5,000 elements and 0.47-0.62 against 1.39-1.44 ms
at 20,000.

``wall_contacts``: sphere-triangle distances and the candidate (sphere, triangle) pairs of
the granular mode's facet walls (:func:`triangle_distance`, :func:`triangle_candidates`), the
numpy form's closest-point regions in one compiled pass; and the facets' world vertices from
their poses (:func:`facet_vertices`).

``contact_radii``: the contact radius of each sphere pair of the granular mode's Verlet list
(:func:`contact_radii`, used by :func:`yade_electro.laws.factors.contact_radius`) and the
centre distances of node pairs (:func:`pair_lengths`, used by
:func:`yade_electro.laws.factors.edge_lengths`), numpy's operations in one pass.

``continuum_factors``: the geometric factors of the ``continuum`` law on every bond
(:func:`continuum_factors`, used by :class:`yade_electro.laws.factors.ContinuumLaw`): the
neighbours' barycentres, the eccentricity factors and sqrt(S_i S_j) / l_ij in three passes.

``csr_pattern``: a CSR sparsity pattern from (row, col) pairs with each pair's slot in the
data (:func:`csr_pattern`, used by :class:`yade_electro.network.condensation.ReducedSystem` for the
Laplacian's pattern and the incidence matrix): scipy's COO -> CSR conversion and index sort
in one call, the same pattern.

``soft_spheres``: the sphere-sphere forces of the jamming's overlap energy
(:func:`soft_sphere_forces`), the same operations in the same order as the numpy form in
:mod:`yade_electro.packing.jamming`, built without floating-point contraction, so that the
packings are the same to the last bit (a test compares them).
"""
from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path
from typing import Optional

import numpy as np

from .loader import HERE, NativeError, helper_path, shared_function as _shared_function  # noqa: F401

__all__ = ["delaunay_backend", "cgal_delaunay", "cgal_executable", "hops_linked", "soft_sphere_forces",
           "FireSteps", "DeflatedCG", "NativeError",
           "laplacian_fill", "triangle_distance", "triangle_candidates", "facet_vertices", "contact_radii",
           "pair_lengths",
           "continuum_factors", "csr_pattern"]

def cgal_executable() -> Path:
    """The ``delaunay_cgal`` helper built at install (NativeError when it was not: CGAL's
    headers were missing then)."""
    return helper_path("delaunay_cgal")


#: ``auto`` uses CGAL from this many points on, qhull below (see module doc)
CGAL_FROM = 120_000


def delaunay_backend(n_points: Optional[int] = None) -> str:
    """'cgal' or 'qhull', from ``YADE_ELECTRO_DELAUNAY`` (see module doc); ``auto`` picks
    CGAL from :data:`CGAL_FROM` points on (or when ``n_points`` is not given)."""
    want = os.environ.get("YADE_ELECTRO_DELAUNAY", "auto").strip().lower()
    if want not in ("auto", "cgal", "qhull"):
        raise ValueError(f"YADE_ELECTRO_DELAUNAY must be 'auto', 'cgal' or 'qhull', got {want!r}")
    if want == "qhull" or (want == "auto" and n_points is not None and n_points < CGAL_FROM):
        return "qhull"
    try:
        cgal_executable()
        return "cgal"
    except NativeError:
        if want == "cgal":
            raise
        return "qhull"


def cgal_delaunay(points, n_real: int, tmpdir: Optional[str] = None):
    """The Delaunay triangulation of ``points`` (N, 3) by CGAL, with its Voronoi faces:
    (cells (T, 4) int64, circumcentres (T, 3), pairs (m, 2) of the Delaunay edges with a
    point < ``n_real`` (i < j), counts (m,), the cells around each edge in cyclic order
    (flat)). Raises :class:`NativeError` if the helper fails or points coincide."""
    exe = cgal_executable()
    P = np.ascontiguousarray(points, dtype=np.float64)
    with tempfile.TemporaryDirectory(dir=tmpdir, prefix="yade-electro-dt-") as d:
        fin, fout = os.path.join(d, "in.bin"), os.path.join(d, "out.bin")
        with open(fin, "wb") as fh:
            np.array([P.shape[0]], np.int64).tofile(fh)
            P.tofile(fh)
        from ..core.progress import Progress
        progress = Progress("voronoi", f"{P.shape[0]:,} points triangulated by CGAL")
        try:
            proc = subprocess.Popen([str(exe), fin, fout, str(int(n_real))], stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)
        except OSError as exc:           # not executable, not a program: the caller falls back to qhull
            progress.done()
            raise NativeError(f"delaunay_cgal cannot run ({exc})") from None
        while True:                      # a long triangulation (about 20 s at 1M) shows progress
            progress.waiting("the helper process runs")
            try:
                _, err = proc.communicate(timeout=0.5)
                break
            except subprocess.TimeoutExpired:
                pass
        progress.done()
        if proc.returncode == 3:
            raise NativeError("delaunay_cgal: some points coincide (CGAL keeps one of each)")
        if proc.returncode != 0:
            raise NativeError(f"delaunay_cgal failed (exit {proc.returncode}): {err.strip()[-500:]}")
        try:
            with open(fout, "rb") as fh:
                nv, nc, ne, ni = (int(v) for v in np.fromfile(fh, np.int64, 4))
                cells = np.fromfile(fh, np.int64, 4 * nc).reshape(nc, 4)
                cc = np.fromfile(fh, np.float64, 3 * nc).reshape(nc, 3)
                pairs = np.fromfile(fh, np.int64, 2 * ne).reshape(ne, 2)
                counts = np.fromfile(fh, np.int64, ne)
                around = np.fromfile(fh, np.int64, ni)
        except (OSError, ValueError) as exc:         # no output, or cut short: not a triangulation
            raise NativeError(f"delaunay_cgal: unreadable output ({exc})") from None
    if around.size != ni or counts.sum() != ni or (cells.size and (cells.min() < 0 or cells.max() >= P.shape[0])):
        raise NativeError("delaunay_cgal: short or inconsistent output")
    return cells, cc, pairs, counts, around


def _hops_library():
    """The built ``graph_hops`` library's search (raises :class:`NativeError` when it cannot be
    built)."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    return _shared_function("graph_hops", "graph_hops_linked", [i64, ptr, ptr, i64, ptr, ptr, i64, ptr], ctypes.c_int)


def hops_linked(indptr, indices, pairs, hops: int) -> np.ndarray:
    """For each node pair (row of ``pairs``), is it linked by a path of at most ``hops`` edges of
    the symmetric CSR adjacency ``indptr``, ``indices``? (bool array). The compiled
    ``graph_hops`` helper: breadth-first balls of radius ceil(hops/2) around the first nodes
    and hops - that around the second; pairs sorted by their first node share the first
    ball. Raises :class:`NativeError` when it cannot be built (see
    :meth:`yade_electro.geometry.voronoi.VoronoiFaces.linked` for the sparse-matrix fallback)."""
    f = _hops_library()
    ip = np.ascontiguousarray(indptr, dtype=np.int64)
    ix = np.ascontiguousarray(indices, dtype=np.int64)
    pr = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    pi, pj = np.ascontiguousarray(pr[:, 0]), np.ascontiguousarray(pr[:, 1])
    n = ip.size - 1
    out = np.zeros(pr.shape[0], dtype=np.uint8)
    rc = f(n, ip.ctypes.data, ix.ctypes.data, pr.shape[0], pi.ctypes.data, pj.ctypes.data, int(hops), out.ctypes.data)
    if rc != 0:
        raise NativeError(f"graph_hops failed (code {rc}: {'a node index out of range' if rc == 2 else 'bad sizes'})")
    return out.astype(bool)


def _soft_library():
    """The ``soft_sphere_forces`` function of the compiled ``soft_spheres`` helper, built
    without floating-point contraction (raises :class:`NativeError` when it cannot be built)."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    return _shared_function("soft_spheres", "soft_sphere_forces", [i64, ptr, ptr, ctypes.c_double, i64, ptr, ptr, ptr, ptr],
                            i64)


def soft_sphere_forces(x, rho, s: float, pairs):
    """Sphere-sphere forces (n, 3) of the overlap energy 1/2 sum max(0, s (rho_i + rho_j) -
    d_ij)^2 over the candidate ``pairs`` (p, 2), the overlaps of the overlapping pairs in
    pair order, and the largest (0 if none). Raises :class:`NativeError` when the helper
    cannot be built (the caller then uses numpy)."""
    import ctypes
    f = _soft_library()
    x = np.ascontiguousarray(x, dtype=np.float64)
    rho = np.ascontiguousarray(rho, dtype=np.float64)
    pr = np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2)
    n = x.shape[0]
    F = np.empty((n, 3))
    ov = np.empty(pr.shape[0])
    mx = ctypes.c_double(0.0)
    m = f(n, x.ctypes.data, rho.ctypes.data, float(s), pr.shape[0], pr.ctypes.data, F.ctypes.data, ov.ctypes.data,
          ctypes.byref(mx))
    return F, ov[:m], float(mx.value)


def default_threads() -> int:
    """Threads of the compiled helpers that use more than one (1 or 2): ``YADE_ELECTRO_THREADS``
    when set; in a yade-batch job (``YADE_BATCH`` in the environment) the job's threads
    (``OMP_NUM_THREADS``, which yade-batch sets per job), so that parallel jobs do not
    oversubscribe the cores; otherwise the machine's cores. At most 2. (Plain ``yade`` sets
    OMP_NUM_THREADS = 1 for its own loops by default: that is not read as a limit here.)"""
    def count(name):
        v = os.environ.get(name, "").strip()
        return int(v) if v.isdigit() and int(v) >= 1 else None
    n = os.cpu_count() or 1
    if count("YADE_ELECTRO_THREADS") is not None:
        n = count("YADE_ELECTRO_THREADS")
    elif "YADE_BATCH" in os.environ:
        n = min(n, count("OMP_NUM_THREADS") or 1)
    return max(1, min(2, n))


class FireSteps:
    """The compiled vector work of one FIRE step of the jamming (``fire_steps.cpp``), for large
    packings in spatial order (:data:`yade_electro.packing.jamming.SPATIAL_ORDER_FROM`): one
    pass over the arrays per operation instead of numpy's temporaries. Not the same bits as
    the numpy form. Raises :class:`NativeError` when the helper cannot be built.

    Arrays: ``x``, ``v``, ``F`` (n, 3) float64 C-contiguous (``F`` and ``v`` are written in
    place), ``rho`` (n,), ``pairs`` (p, 2) int64. ``threads`` (1 or 2, default
    :func:`default_threads`: 2 on two cores, a yade-batch job's own threads): the pair forces
    from 100,000 pairs on are split in two halves, one per thread."""

    def __init__(self, threads: Optional[int] = None):
        import ctypes
        i64, ptr, dbl = ctypes.c_int64, ctypes.c_void_p, ctypes.c_double

        def load(symbol, argtypes, restype):
            return _shared_function("fire_steps", symbol, argtypes, restype)
        self._forces = load("fire_pair_forces", [i64, ptr, ptr, dbl, i64, ptr, ptr, ptr, i64], i64)
        self._power = load("fire_power", [i64, ptr, ptr, ptr], None)
        self._move = load("fire_move", [i64, ptr, ptr, ptr, dbl, dbl, dbl], None)
        self._max_move2 = load("fire_max_move2", [i64, ptr, ptr], dbl)
        self._pairs_within = load("fire_pairs_within", [i64, ptr, dbl, i64, ptr], i64)
        # the pair forces on two threads (the pairs in two halves) where there are two cores and
        # the process may use them (see default_threads)
        self.threads = default_threads() if threads is None else max(1, min(2, int(threads)))
        self._out = np.zeros(4)
        self._room = 0

    @staticmethod
    def _check(*arrays):
        for a in arrays:
            if not (a.dtype == np.float64 and a.flags.c_contiguous):
                raise ValueError("FireSteps needs C-contiguous float64 arrays")

    def pair_forces(self, x, rho, s: float, pairs, F):
        """Forces into ``F`` (n, 3); returns (energy, largest overlap, overlapping pairs)."""
        self._check(x, rho, F)
        pr = np.ascontiguousarray(pairs, dtype=np.int64)
        m = self._forces(x.shape[0], x.ctypes.data, rho.ctypes.data, float(s), pr.shape[0], pr.ctypes.data,
                         F.ctypes.data, self._out.ctypes.data, self.threads)
        return float(self._out[0]), float(self._out[1]), int(m)

    def power(self, F, v):
        """(max_i ``|F_i|``, F.v, ``|v|``, ``|F|``)."""
        self._check(F, v)
        self._power(F.shape[0], F.ctypes.data, v.ctypes.data, self._out.ctypes.data)
        o = self._out
        return float(np.sqrt(o[0])), float(o[1]), float(np.sqrt(o[2])), float(np.sqrt(o[3]))

    def move(self, x, v, F, a: float, b: float, dt: float):
        """v = a v + b F + dt F, then x += dt v (both in place)."""
        self._check(x, v, F)
        self._move(x.shape[0], x.ctypes.data, v.ctypes.data, F.ctypes.data, float(a), float(b), float(dt))

    def max_move(self, x, ref) -> float:
        """max_i ``|x_i - ref_i|``."""
        self._check(x, ref)
        return float(np.sqrt(self._max_move2(x.shape[0], x.ctypes.data, ref.ctypes.data)))

    def pairs_within(self, x, cut: float) -> np.ndarray:
        """Every pair (i, j), i < j, closer than ``cut``, sorted by i (a grid of cells of side
        >= cut): the Verlet list, as ``cKDTree.query_pairs`` gives it but in this order."""
        self._check(x)
        n = x.shape[0]
        room = max(self._room, 8 * n, 16)
        while True:
            out = np.empty((room, 2), dtype=np.int64)
            m = self._pairs_within(n, x.ctypes.data, float(cut), room, out.ctypes.data)
            if m < 0:
                raise NativeError("fire_pairs_within: the cell grid would be too large (cut too small for the box)")
            if m <= room:
                self._room = int(1.25 * m)
                return out[:m]
            room = int(1.25 * m)


def laplacian_fill(data, c, e_uu, o1, o2, diag, incidence, extra=None) -> None:
    """``data`` (K_uu's CSR values) from the edge values ``c``, as
    :meth:`yade_electro.network.condensation.ReducedSystem.assemble` fills them with numpy: -c at each
    unknown-unknown pair's off-diagonal entries ``o1``, ``o2`` (pair t is edge ``e_uu[t]``, or t
    when ``e_uu`` is None), the incidence matrix (CSR, unknowns x edges, ones) times c on the
    diagonal entries ``diag`` (int64), plus ``extra``. ``laplacian_fill.cpp``, one pass; raises
    :class:`NativeError` when it cannot be built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    width = {np.dtype(np.int32): "32", np.dtype(np.int64): "64"}
    wi = "i32" if o1.dtype == np.int32 else "i64"
    if e_uu is not None and e_uu.dtype != o1.dtype:
        e_uu = e_uu.astype(o1.dtype)
    symbol = f"laplacian_fill_{wi}_p{width[incidence.indptr.dtype]}_j{width[incidence.indices.dtype]}"
    if symbol.endswith("p32_j64"):               # (scipy never makes this one)
        symbol = symbol.replace("p32", "p64")
        incidence = (incidence.indptr.astype(np.int64), incidence.indices)
    else:
        incidence = (incidence.indptr, incidence.indices)
    f = _shared_function("laplacian_fill", symbol, [i64, ptr, ptr, i64, ptr, ptr, ptr, i64, ptr, ptr, ptr, ptr], None)
    for a, dt in ((data, np.float64), (c, np.float64), (o1, None), (o2, None), (diag, np.int64)):
        if not a.flags.c_contiguous or (dt is not None and a.dtype != dt):
            raise ValueError("laplacian_fill: arrays must be C-contiguous (data, c float64; diag int64)")
    if extra is not None:
        extra = np.ascontiguousarray(extra, dtype=np.float64)
    f(data.size, data.ctypes.data, c.ctypes.data, o1.size, None if e_uu is None else e_uu.ctypes.data,
      o1.ctypes.data, o2.ctypes.data, diag.size, diag.ctypes.data, incidence[0].ctypes.data,
      incidence[1].ctypes.data, None if extra is None else extra.ctypes.data)


def _wall_function(symbol, argtypes, restype):
    return _shared_function("wall_contacts", symbol, argtypes, restype)


def triangle_distance(points, triangles) -> np.ndarray:
    """Distance [m] from each point (k, 3) to the triangle (k, 3, 3) of its row, as
    :func:`yade_electro.geometry.contacts.triangle_distance` computes it with numpy (the same regions
    and precedence); ``wall_contacts.cpp``. Raises :class:`NativeError` when it cannot be
    built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    f = _wall_function("wall_triangle_distance", [i64, ptr, ptr, ptr], None)
    p = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    t = np.ascontiguousarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    if p.shape[0] != t.shape[0]:
        raise ValueError(f"triangle_distance: {p.shape[0]} points for {t.shape[0]} triangles")
    out = np.empty(p.shape[0])
    f(p.shape[0], p.ctypes.data, t.ctypes.data, out.ctypes.data)
    return out


def triangle_candidates(pos, radius, skin: float, triangles, centre, reach):
    """The (sphere, triangle) pairs closer than ``radius[i] + skin`` [m] among the spheres
    within ``reach[t]`` of the triangles' ball centres ``centre`` (k, 3): (spheres, pieces)
    int64 arrays sorted by sphere, then triangle, as
    :func:`yade_electro.geometry.contacts.wall_candidates` finds them with a KD-tree;
    ``wall_contacts.cpp``, a pass over every sphere and triangle. Raises :class:`NativeError`
    when it cannot be built."""
    import ctypes
    i64, ptr, dbl = ctypes.c_int64, ctypes.c_void_p, ctypes.c_double
    f = _wall_function("wall_triangle_candidates", [i64, ptr, ptr, dbl, i64, ptr, ptr, ptr, i64, ptr, ptr], i64)
    x = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
    r = np.ascontiguousarray(radius, dtype=np.float64)
    t = np.ascontiguousarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    c = np.ascontiguousarray(centre, dtype=np.float64).reshape(-1, 3)
    reach = np.ascontiguousarray(reach, dtype=np.float64)
    room = max(64, 4 * x.shape[0])
    while True:
        spheres, pieces = np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64)
        m = f(x.shape[0], x.ctypes.data, r.ctypes.data, float(skin), t.shape[0], t.ctypes.data, c.ctypes.data,
              reach.ctypes.data, room, spheres.ctypes.data, pieces.ctypes.data)
        if m <= room:
            return spheres[:m].copy(), pieces[:m].copy()
        room = m


def facet_vertices(pos, quat, local) -> np.ndarray:
    """World vertices (k, 3, 3) [m] of k rigid triangles from their positions (k, 3), unit
    quaternions (k, 4) stored (x, y, z, w) and vertices in the body frame (k, 3, 3), as
    :func:`yade_electro.geometry.contacts.facet_vertices` computes them with numpy;
    ``wall_contacts.cpp``. Raises :class:`NativeError` when it cannot be built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    f = _wall_function("wall_facet_vertices", [i64, ptr, ptr, ptr, ptr], None)
    p = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
    q = np.ascontiguousarray(quat, dtype=np.float64).reshape(-1, 4)
    loc = np.ascontiguousarray(local, dtype=np.float64).reshape(-1, 3, 3)
    if not (p.shape[0] == q.shape[0] == loc.shape[0]):
        raise ValueError(f"facet_vertices: {p.shape[0]} positions, {q.shape[0]} quaternions, {loc.shape[0]} "
                         "triangles")
    out = np.empty_like(loc)
    f(p.shape[0], p.ctypes.data, q.ctypes.data, loc.ctypes.data, out.ctypes.data)
    return out


def contact_radii(pos, radius, edges, shift=None, model: str = "geometric"):
    """Contact radius a [m] of each sphere pair ``edges`` (m, 2) (0 where the spheres do not
    overlap), as :func:`yade_electro.laws.factors.contact_radius` computes it with numpy
    (``model`` 'geometric' or 'hertz'; ``shift`` (m, 3): the periodic image of the second
    sphere), and the number of pairs with coincident centres (their radii are not
    meaningful); ``contact_radii.cpp``, one pass. Raises :class:`NativeError` when it cannot
    be built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    f = _shared_function("contact_radii", "contact_radii", [i64, ptr, ptr, ptr, ptr, ctypes.c_int, ptr], i64)
    x = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
    r = np.ascontiguousarray(radius, dtype=np.float64)
    e = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
    s = None if shift is None else np.ascontiguousarray(shift, dtype=np.float64).reshape(-1, 3)
    if r.shape[0] != x.shape[0] or (s is not None and s.shape[0] != e.shape[0]):
        raise ValueError("contact_radii: sizes do not match")
    if e.size and (e.min() < 0 or e.max() >= x.shape[0]):
        raise ValueError("contact_radii: a node index is out of range")
    out = np.empty(e.shape[0])
    bad = f(e.shape[0], x.ctypes.data, r.ctypes.data, e.ctypes.data, None if s is None else s.ctypes.data,
            1 if model == "hertz" else 0, out.ctypes.data)
    return out, int(bad)


def pair_lengths(pos, edges, shift=None):
    """Centre distances ``|x_j - x_i (+ shift)|`` [m] of the node pairs ``edges`` (m, 2), and how
    many are zero; ``contact_radii.cpp``. Raises :class:`NativeError` when it cannot be built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    f = _shared_function("contact_radii", "pair_lengths", [i64, ptr, ptr, ptr, ptr], i64)
    x = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
    e = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
    s = None if shift is None else np.ascontiguousarray(shift, dtype=np.float64).reshape(-1, 3)
    if s is not None and s.shape[0] != e.shape[0]:
        raise ValueError("pair_lengths: one shift per pair")
    if e.size and (e.min() < 0 or e.max() >= x.shape[0]):
        raise ValueError("pair_lengths: a node index is out of range")
    out = np.empty(e.shape[0])
    zero = f(e.shape[0], x.ctypes.data, e.ctypes.data, None if s is None else s.ctypes.data, out.ctypes.data)
    return out, int(zero)


def continuum_factors(pos, radius, alpha_r2, edges, threshold: float, factor: float):
    """g = sqrt(S_i S_j) / l_ij [m] of every bond ``edges`` (m, 2) of the ``continuum`` law,
    S_i = ``alpha_r2``[i] / f_i with the eccentricity factor f_i of the bonds' neighbour
    barycentres (as :func:`yade_electro.laws.transmission.edge_transmission_surface` over
    :func:`yade_electro.laws.factors.edge_lengths` computes them with numpy), and the number
    of bonds with coincident centres (their g is not meaningful); ``continuum_factors.cpp``.
    Raises :class:`NativeError` when it cannot be built."""
    import ctypes
    i64, ptr, dbl = ctypes.c_int64, ctypes.c_void_p, ctypes.c_double
    f = _shared_function("continuum_factors", "continuum_factors",
                         [i64, ptr, ptr, ptr, i64, ptr, dbl, dbl, ptr, ptr, ptr, ptr], i64)
    x = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
    n = x.shape[0]
    r = np.ascontiguousarray(radius, dtype=np.float64)
    a = np.ascontiguousarray(alpha_r2, dtype=np.float64)
    e = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
    if r.shape != (n,) or a.shape != (n,):
        raise ValueError("continuum_factors: sizes do not match")
    if e.size and (e.min() < 0 or e.max() >= n):
        raise ValueError("continuum_factors: a node index is out of range")
    work, count, surface = np.empty((n, 3)), np.empty(n, dtype=np.int64), np.empty(n)
    out = np.empty(e.shape[0])
    bad = f(n, x.ctypes.data, r.ctypes.data, a.ctypes.data, e.shape[0], e.ctypes.data, float(threshold),
            float(factor), work.ctypes.data, count.ctypes.data, surface.ctypes.data, out.ctypes.data)
    return out, int(bad)


def csr_pattern(rows, cols, shape):
    """(indptr, indices) int32 of the CSR pattern of the (row, col) pairs, columns sorted in
    each row, and ``slot`` (N,) int64: the position of each pair in the data; None when a
    pair repeats or the sizes need 64-bit indices (the caller then uses scipy);
    ``csr_pattern.cpp``. Raises :class:`NativeError` when it cannot be built."""
    import ctypes
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    f = _shared_function("csr_pattern", "csr_pattern", [i64, i64, ptr, ptr, ptr, ptr, ptr], i64)
    r = np.ascontiguousarray(rows, dtype=np.int64)
    c = np.ascontiguousarray(cols, dtype=np.int64)
    nr, nc = (int(v) for v in shape)
    N = r.size
    if c.size != N or N >= 2 ** 31 - 1 or nc >= 2 ** 31 - 1:
        return None
    if N and (r.min() < 0 or r.max() >= nr or c.min() < 0 or c.max() >= nc):
        raise ValueError("csr_pattern: a row or column index is out of range")
    indptr, indices, slot = np.empty(nr + 1, np.int32), np.empty(N, np.int32), np.empty(N, np.int64)
    m = f(nr, N, r.ctypes.data, c.ctypes.data, indptr.ctypes.data, indices.ctypes.data, slot.ctypes.data)
    return None if m < 0 else (indptr, indices, slot)


EIGEN_INCLUDE = "/usr/include/eigen3"


class DeflatedCG:
    """The iterations of :class:`yade_electro.solvers.registry.DeflatedCGSolver` compiled
    (``deflated_cg.cpp``: the same deflated CG, coarse matrix factorised by Eigen's
    SimplicialLLT), for ``n`` unknowns and ``k`` clusters. Raises :class:`NativeError` when the
    kernel was not built at install."""

    def __init__(self, n: int, k: int):
        import ctypes
        import weakref
        i64, ptr, dbl = ctypes.c_int64, ctypes.c_void_p, ctypes.c_double

        def load(symbol, argtypes, restype):
            return _shared_function("deflated_cg", symbol, argtypes, restype)
        create = load("dcg_create", [i64, i64], ptr)
        destroy = load("dcg_destroy", [ptr], None)
        self._pattern = load("dcg_coarse_pattern", [ptr, i64, ptr], None)
        self._wta_pattern = load("dcg_wta_pattern", [i64, i64, ptr, ptr, ptr, ptr, ptr, ptr], i64)
        self._refill = load("dcg_refill", [ptr, i64, ptr, ptr, ptr, ptr, i64, ptr, ptr], ctypes.c_int)
        self._solve = load("dcg_solve", [ptr] + [ptr] * 10 + [dbl, dbl, i64, ptr], None)
        self.n, self.k = int(n), int(k)
        self._h = create(self.n, self.k)
        self._finalizer = weakref.finalize(self, destroy, self._h)
        self._out = np.zeros(3)

    def wta_pattern(self, A, lab):
        """The structural pattern of W^T A (``indptr``, ``indices`` int32; columns unsorted
        within a row) and ``slot`` (int64): the entry of W^T A each non-zero of ``A`` (CSR,
        int32) adds to, for the clusters ``lab`` (int64) of the rows."""
        lab = np.ascontiguousarray(lab, dtype=np.int64)
        indptr = np.empty(self.k + 1, dtype=np.int32)
        indices = np.empty(A.nnz, dtype=np.int32)
        slot = np.empty(A.nnz, dtype=np.int64)
        m = self._wta_pattern(self.n, self.k, A.indptr.ctypes.data, A.indices.ctypes.data, lab.ctypes.data,
                              indptr.ctypes.data, indices.ctypes.data, slot.ctypes.data)
        return indptr, indices[:m].copy(), slot

    def coarse_pattern(self, key):
        """The pattern of the coarse matrix: ``key`` = row * k + col (int64) of its entries."""
        key = np.ascontiguousarray(key, dtype=np.int64)
        self._pattern(self._h, key.size, key.ctypes.data)

    def refill(self, A, diag_pos, inv_diag, wta_slot, WtA, e_slot) -> int:
        """New values of ``A`` (same pattern): ``inv_diag`` (1 / its diagonal, at ``diag_pos``
        in ``A.data``), ``WtA.data`` (non-zero t of A adds to ``wta_slot[t]``), the coarse
        values (to ``e_slot[t]``) and their factor, in one compiled pass. Returns 0, 1 (the
        coarse matrix is not positive definite) or 2 (a diagonal entry <= 0)."""
        return self._refill(self._h, A.nnz, A.data.ctypes.data, diag_pos.ctypes.data, inv_diag.ctypes.data,
                            wta_slot.ctypes.data, WtA.nnz, WtA.data.ctypes.data, e_slot.ctypes.data)

    def solve(self, A, inv_diag, lab, WtA, b, x, rtol: float, atol: float, maxiter: int):
        """Deflated CG on ``A`` (CSR, int32 indices) from ``x`` (float64, in place). Returns
        (iterations, relative residual, status: 0 done, 2 breakdown: p.Ap <= 0, given in place
        of the residual)."""
        arrays = (A.indptr, A.indices, A.data, inv_diag, lab, WtA.indptr, WtA.indices, WtA.data, b, x)
        self._solve(self._h, *(a.ctypes.data for a in arrays), float(rtol), float(atol), int(maxiter),
                    self._out.ctypes.data)
        return int(self._out[0]), float(self._out[1]), int(self._out[2])
