"""Two discs pressed together, joined by a contact resistance: the finite-element reference
of paper 003's two-particle test (issue 35, ``cases/two_grains.py``).

Two thin cylinders of radius ``r`` and width ``w`` overlap by ``p`` (centres ``d = 2 r - p``
apart); each is cut at the overlap's chord (x = d / 2) and the two flat faces so made are the
contact, of area ``S_c = 2 h w`` (h the chord's half length). Everywhere else the discs are
insulated, and nothing varies across the width: the problem is the 2D one of two disc
segments, solved per unit width (linear triangles, scikit-fem; meshed by gmsh, the second
disc the mirror image of the first, so that the two chords carry the same nodes).

Across the contact the heat flux is ``q = (T_A - T_B) / R_c`` with ``R_c`` [m^2 K/W] the
specific contact resistance: the interface term ``(1/R_c) int (u_A - u_B)(v_A - v_B) ds`` on
the chord (paper 003 eq. 24-28, with the local temperatures). Time: the theta method.

Units: m, W/(m K), J/(m^3 K), m^2 K/W, K, s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .gmsh_session import GmshSession, MeshError

__all__ = ["TwoDiscs", "disc_segment_mesh", "two_discs_transient"]


@dataclass(frozen=True)
class TwoDiscs:
    """The geometry: radius ``r``, width ``w`` and overlap ``p`` [m]."""

    r: float
    w: float
    p: float

    def __post_init__(self):
        if not (0 < self.p < self.r and self.r > 0 and self.w > 0):
            raise MeshError(f"two discs need r > 0, w > 0 and 0 < p < r, got {self}")

    @property
    def d(self) -> float:
        """Centre distance [m]."""
        return 2.0 * self.r - self.p

    @property
    def half_chord(self) -> float:
        """h [m], half the contact's length in the plane."""
        return math.sqrt(self.r ** 2 - (0.5 * self.d) ** 2)

    @property
    def contact_area(self) -> float:
        """S_c = 2 h w [m^2]."""
        return 2.0 * self.half_chord * self.w

    @property
    def segment_area(self) -> float:
        """The area [m^2] of one disc less its cut (the 2D particle)."""
        c = 0.5 * self.d
        cap = self.r ** 2 * math.acos(c / self.r) - c * self.half_chord
        return math.pi * self.r ** 2 - cap


def disc_segment_mesh(g: TwoDiscs, h: float):
    """(points (2, n), triangles (3, m), chord nodes) of disc A: centred at the origin, cut at
    x = d / 2, mesh size ``h`` [m] (finer, h / 4, along the chord)."""
    with GmshSession() as gmsh:
        occ = gmsh.model.occ
        disc = occ.addDisk(0.0, 0.0, 0.0, g.r, g.r)
        cut = occ.addRectangle(-2.0 * g.r, -2.0 * g.r, 0.0, 2.0 * g.r + 0.5 * g.d, 4.0 * g.r)
        occ.intersect([(2, disc)], [(2, cut)])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        f = gmsh.model.mesh.field
        box = f.add("Box")
        for key, v in (("VIn", h / 4.0), ("VOut", h), ("XMin", 0.5 * g.d - 2 * h), ("XMax", g.d),
                       ("YMin", -2 * g.r), ("YMax", 2 * g.r), ("Thickness", 4 * h)):
            f.setNumber(box, key, v)
        f.setAsBackgroundMesh(box)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        coords = np.asarray(coords).reshape(-1, 3)[:, :2].T
        types, _, nodes = gmsh.model.mesh.getElements(2)
        if list(types) != [2]:
            raise MeshError(f"gmsh made surface elements of types {list(types)}, expected triangles (2)")
        index = np.full(int(np.max(tags)) + 1, -1, np.int64)
        index[np.asarray(tags, np.int64)] = np.arange(len(tags))
        t = index[np.asarray(nodes[0], np.int64).reshape(-1, 3).T]
    used, t = np.unique(t, return_inverse=True)
    p, t = coords[:, used], t.reshape(3, -1)
    a, b, c = (p[:, t[i]] for i in range(3))
    neg = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) < 0
    t[1, neg], t[2, neg] = t[2, neg].copy(), t[1, neg].copy()
    chord = np.flatnonzero(np.abs(p[0] - 0.5 * g.d) < 1e-9 * g.r)
    return p, t, chord


def two_discs_transient(g: TwoDiscs, conductivity: float, rho_c: float, contact_resistance: float,
                        T_A: float, T_B: float, times, h: float, dt: float, theta: float = 0.5) -> dict:
    """The two discs from uniform ``T_A`` and ``T_B`` [K]: the capacity-weighted mean
    temperature of each at ``times`` [s] (and the contact's mean temperature jump), by the
    theta method with steps of at most ``dt`` [s] on a mesh of size ``h`` [m]. Returns a dict
    of arrays: ``time``, ``mean_A``, ``mean_B``, ``jump`` [K], and ``nodes`` (of one disc)."""
    from skfem import Basis, ElementTriP1, FacetBasis, MeshTri
    from skfem.models.poisson import laplace, mass
    p, t, chord = disc_segment_mesh(g, h)
    mesh = MeshTri(np.ascontiguousarray(p), np.ascontiguousarray(t))
    basis = Basis(mesh, ElementTriP1())
    K1 = conductivity * laplace.assemble(basis)
    M1 = rho_c * mass.assemble(basis)
    on_chord = mesh.facets_satisfying(lambda x: np.abs(x[0] - 0.5 * g.d) < 1e-9 * g.r)
    Mc = mass.assemble(FacetBasis(mesh, ElementTriP1(), facets=on_chord)) / contact_resistance
    n = mesh.p.shape[1]
    # disc B is A mirrored about the chord: node i of B sits at (d - x_i, y_i); on the chord, on A's node i
    K = sp.bmat([[K1 + Mc, -Mc], [-Mc, K1 + Mc]], format="csc")
    M = sp.block_diag([M1, M1], format="csc")
    w = np.asarray(M1.sum(axis=1)).ravel()          # lumped weights of the means
    on = np.zeros(n)
    on[chord] = 1.0
    wc = np.asarray(Mc.sum(axis=1)).ravel()
    T = np.concatenate([np.full(n, float(T_A)), np.full(n, float(T_B))])
    times = np.asarray(times, float)
    out = {"time": times, "mean_A": [], "mean_B": [], "jump": [], "nodes": n}
    lu, step, now = None, None, 0.0
    for t_next in times:
        while now < t_next - 1e-12 * max(t_next, 1.0):
            h_t = min(dt, t_next - now)
            if lu is None or step != h_t:
                lu, step = splu((M + theta * h_t * K).tocsc()), h_t
            T = T + lu.solve(-h_t * (K @ T))
            now += h_t
        out["mean_A"].append(float(w @ T[:n] / w.sum()))
        out["mean_B"].append(float(w @ T[n:] / w.sum()))
        out["jump"].append(float(wc @ (T[:n] - T[n:]) / wc.sum()))
    for k in ("mean_A", "mean_B", "jump"):
        out[k] = np.array(out[k])
    return out
