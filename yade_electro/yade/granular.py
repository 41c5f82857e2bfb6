"""The contact graph of a granular bed in YADE (``bonds='contacts'``), kept cheap while the
contacts change every step, and the bed's walls.

Reading YADE's interactions from Python costs microseconds per contact: too much for a bed
whose contacts change at every step. :class:`GranularReader` reads instead the positions
with YADE's C++ bulk reader (``utils.coordsAndDisplacements``, about 1 ms for 5,000
bodies) at every call, and finds the contacts itself: the edges are a Verlet list of the
pairs closer than ``r_i + r_j + skin`` (:func:`yade_electro.geometry.contacts.candidate_pairs`), kept
until some sphere (or wall) has moved by more than half the skin, and a pair conducts only
while its spheres overlap (the contact laws give g = 0 otherwise). These are the contacts
YADE's ``Ig2_Sphere_Sphere_ScGeom`` makes real (overlap > 0, detection factor 1); a larger
``interactionDetectionFactor`` makes YADE interactions at a distance, which conduct nothing
here either. Between two lists the engine sees a change of values on a kept structure.

Walls: ``Wall(name, bodies=ids, ...)`` names YADE bodies whose shape is ``Wall``,
``Box`` or ``Facet`` (a facet mesh such as ``geom.facetCylinder`` given as one wall). Their
geometry is read at every call (a few Python reads per body) and the spheres touching them
are found with the same skin (:mod:`yade_electro.geometry.contacts`).

Periodic cells (``O.periodic``, sheared or not, and deforming through ``O.cell.velGrad``):
the Verlet list is made with the cell's images
(:func:`yade_electro.geometry.contacts.periodic_candidate_pairs`); the graph's positions are the
centres wrapped into the cell (what the selections, the outputs and VTK see) and each edge
carries the shift of its image (``ContactGraph.shift``), recomputed at every call from the
cell and the spheres' own periods, so a sphere leaving the cell through a face keeps its
contacts. The list is made again when the spheres' moves in the cell's frame and the cell's
deformation since the list could have closed a gap of a skin. Walls and electrodes are
refused in a periodic cell.

Full reads (a Python loop over the bodies) happen when the body count or the total sphere
volume changes (spheres added, erased, or a radius changed), the cell becomes periodic or
not, or the scene was replaced.
Units: SI.
"""
from __future__ import annotations

import logging
from collections import Counter
from operator import attrgetter
from typing import Dict, List, NamedTuple, Optional

import numpy as np

from ..geometry.contacts import (WallGeometry, candidate_pairs, facet_vertices, max_displacement, periodic_candidate_pairs,
                        quaternion_matrices, wall_candidates, wall_overlaps)
from ..core.errors import BoundaryConditionError, GraphError
from ..core.graph import ContactGraph
from ..network.lumping import MemberLabels
from .runtime import import_yade
from .scene import bulk_coordinates, probe_replaced, read_spheres, warn_left_out

__all__ = ["Capture", "GranularReader", "WALL_SHAPES", "check_wall_bodies"]

log = logging.getLogger(__name__)

#: YADE shapes that can be walls
WALL_SHAPES = ("Wall", "Box", "Facet")


def check_wall_bodies(O, name, ids):
    """The bodies of wall ``name``, checked: they exist and are all walls of one kind."""
    if isinstance(ids, (int, np.integer)) and not isinstance(ids, bool):
        ids = [ids]
    try:
        ids = [int(i) for i in ids]
    except (TypeError, ValueError):
        raise BoundaryConditionError(f"wall {name!r}: bodies= must be a body id or a list of body ids, got "
                                     f"{ids!r}") from None
    if not ids:
        raise BoundaryConditionError(f"wall {name!r}: bodies= is empty")
    kinds = set()
    for i in ids:
        b = O.bodies[i] if 0 <= i < len(O.bodies) else None
        if b is None:
            raise BoundaryConditionError(f"wall {name!r}: there is no body {i} in the scene")
        kind = type(b.shape).__name__
        if kind not in WALL_SHAPES:
            raise BoundaryConditionError(f"wall {name!r}: body {i} is a {kind}, not a wall; a wall is a body of "
                                         f"shape {', '.join(WALL_SHAPES)} (spheres are the particles)")
        kinds.add(kind)
    if len(kinds) > 1:
        raise BoundaryConditionError(f"wall {name!r}: its bodies mix shapes {sorted(kinds)}; give one wall per shape")
    kind = kinds.pop()
    if kind != "Facet" and len(ids) > 1:
        raise BoundaryConditionError(f"wall {name!r}: give one {kind} body per wall (only facets form a mesh)")
    return kind, ids


def _rotation(q):
    """Rotation matrix of a YADE Quaternion."""
    return quaternion_matrices(np.array([[q[0], q[1], q[2], q[3]]]))[0]


class _WallReader:
    """Reads one wall's world geometry from its YADE bodies."""

    def __init__(self, O, name, ids):
        self.name = name
        self.kind, self.ids = check_wall_bodies(O, name, ids)
        self.O = O
        if self.kind == "Facet":
            self._local = np.array([[[v[0], v[1], v[2]] for v in O.bodies[i].shape.vertices] for i in self.ids])

    def geometry(self, coords=None, slot=None) -> WallGeometry:
        """The wall now; ``coords`` (bodies, 3) [m] from YADE's bulk reader and ``slot`` (the
        row of each existing body id) give the facets' positions without a read per body."""
        bodies = list(map(self.O.bodies.__getitem__, self.ids))
        if self.kind == "Wall":
            b = bodies[0]
            axis, sense = int(b.shape.axis), int(b.shape.sense)
            normal = np.zeros(3)
            normal[axis] = 1.0 if sense >= 0 else -1.0
            p = b.state.pos
            return WallGeometry("plane", point=(p[0], p[1], p[2]), normal=normal, two_sided=sense == 0)
        if self.kind == "Box":
            b = bodies[0]
            p, e = b.state.pos, b.shape.extents
            return WallGeometry("box", center=(p[0], p[1], p[2]), axes=_rotation(b.state.ori).T,
                                extents=(e[0], e[1], e[2]))
        states = list(map(attrgetter("state"), bodies))
        if coords is not None:
            pos = coords[[slot[i] for i in self.ids]]
        else:
            pos = np.array([tuple(st.pos) for st in states], dtype=float)
        quat = np.array([(q[0], q[1], q[2], q[3]) for q in map(attrgetter("ori"), states)], dtype=float)
        return WallGeometry("triangles", vertices=facet_vertices(pos, quat, self._local))


class Capture(NamedTuple):
    """What :meth:`GranularReader.capture` read from YADE at one call (plain data: it pickles).

    ``reason``: why the call made a full read (None: it did not); ``ids``: the graph's body
    ids; ``pos`` (n, 3) [m]: their centres (not wrapped into a periodic cell); ``walls``: name
    -> WallGeometry; ``cell`` (3, 3) [m]: a periodic cell's base vectors (columns), else None."""

    reason: Optional[str]
    ids: np.ndarray
    pos: np.ndarray
    walls: Dict[str, WallGeometry]
    cell: Optional[np.ndarray]


class GranularReader:
    """Contact graph of a granular bed, read from YADE's ``O`` at every call.

    Parameters
    ----------
    O : yade.Omega, optional
    mask : int, optional
        Keep only spheres with ``b.mask & mask``.
    skin : float or 'auto'
        Verlet skin, in units of the smallest sphere radius. ``'auto'`` (default) starts at 0.2
        and adapts it to how the bed moves between calls: a list that lasted fewer than 6
        calls makes the next skin 1.5 times larger (up to 1.0), one that lasted 30 calls or
        more 1.25 times smaller (down to 0.05). A new list costs several plain calls (the
        pair search, the walls' candidates, the heat solver's new pattern: about 7 ms
        against 3 ms on the 2,000-particle drum), so a list should last several calls (on
        the drum every 10 steps, fixed skins of 0.45, 0.7 and 1.0 gave calls of 3.9-4.1 ms,
        0.2 gave 4.7 ms). A number keeps that skin. A larger skin keeps a list longer at the
        price of more candidate pairs.
    walls : dict name -> body id or list of ids, optional
        The walls whose contacts are wanted (see module doc).
    periodic : bool
        Take periodic cells (default False: a periodic scene raises GraphError). The heat-only
        engines take them; the engines with electrodes do not (an electrode selected by
        position, or a wall, is not defined across the cell's images here).
    clumps : bool
        Read clump members as spheres, each with its clump (:meth:`clump_labels`); False:
        clumps are left out, with a warning.

    Attributes
    ----------
    graph : the last ContactGraph (edges: the candidate pairs; in a periodic cell, positions
        wrapped into the cell and each edge's image shift)
    periodic : True when the scene's cell is periodic (at the last full read)
    list_builds : how many Verlet lists were made
    full_reads, calls, ignored, last_change : as :class:`~yade_electro.yade.scene.SceneReader`
    """

    bonds = "contacts"

    #: the adaptive skin's start, bounds and thresholds (see ``skin``)
    SKIN_START, SKIN_MIN, SKIN_MAX = 0.2, 0.05, 1.0
    #: a list that lasted fewer calls than this grows the skin, one that lasted at least
    #: ``SHRINK_FROM`` calls shrinks it
    GROW_BELOW, SHRINK_FROM = 6, 30

    def __init__(self, O=None, mask: Optional[int] = None, skin="auto", walls: Optional[Dict] = None,
                 periodic: bool = False, clumps: bool = False):
        self.adaptive = isinstance(skin, str) and skin == "auto"
        if self.adaptive:
            skin = self.SKIN_START
        try:
            skin = float(skin)
        except (TypeError, ValueError):
            raise ValueError(f"skin must be 'auto' or a number > 0 (in smallest radii), got {skin!r}") from None
        if not (np.isfinite(skin) and skin > 0):
            raise ValueError(f"skin must be finite and > 0 (in smallest radii), got {skin!r}")
        if mask is not None and (isinstance(mask, bool) or int(mask) != mask):
            raise ValueError(f"mask must be an integer (YADE group mask), got {mask!r}")
        if O is None:
            O = import_yade().Omega()
        self.O, self.mask, self.skin = O, mask, skin
        self.walls = {name: _WallReader(O, name, ids) for name, ids in (walls or {}).items()}
        self.graph: Optional[ContactGraph] = None
        self.ignored: Counter = Counter()
        self.full_reads = self.list_builds = self.calls = 0
        self.geometry_reads = 0
        self.last_change: Optional[str] = None
        self._revision = -1
        self._bodies: List = []
        self._stamp = None
        self._probe = None
        self._wall_geom: Dict[str, WallGeometry] = {}
        self._wall_contacts: Dict[str, tuple] = {}
        self.periodic = False
        self.accepts_periodic = bool(periodic)
        self.clumps = bool(clumps)
        self._clumps = MemberLabels()
        #: ``keep(ids, pos, radius) -> mask``: read only the spheres of a region (see
        #: :func:`~yade_electro.yade.scene.read_spheres`); None: all
        self.region = None
        #: the centres [m] of every existing body at the last capture (YADE's bulk reader)
        self.last_coordinates = None

    # -- public --------------------------------------------------------------------------
    def read(self) -> ContactGraph:
        """The current graph (a new revision whenever the spheres moved)."""
        return self.advance(self.capture())

    def capture(self) -> "Capture":
        """What :meth:`read` takes from YADE (a full read when the scene changed, the centres,
        the walls' poses, the periodic cell), and nothing else: :meth:`advance` then makes the
        graph from it without touching YADE, so it may run while YADE steps on."""
        self.calls += 1
        self.last_change = None
        reason = "first read" if self.graph is None else self._changed()
        if reason:
            self._full_read()
        coords = bulk_coordinates(self._n_existing)
        self.last_coordinates = coords
        pos = coords[self._node_slot]
        if not np.all(np.isfinite(pos)):
            bad = self.graph.ids[~np.all(np.isfinite(pos), axis=1)]
            raise GraphError(f"spheres {bad[:10].tolist()} have non-finite positions (the mechanics blew up?)")
        if self.periodic:
            return Capture(reason, self.graph.ids, pos, {}, self._cell())
        geoms = {name: w.geometry(coords, self._slot_of) for name, w in self.walls.items()}
        return Capture(reason, self.graph.ids, pos, geoms, None)

    def advance(self, cap: "Capture") -> ContactGraph:
        """The graph of a :meth:`capture` (the last one, or a saved one of the same spheres):
        the Verlet lists, the new positions and the walls' overlaps (numpy only)."""
        if not np.array_equal(cap.ids, self.graph.ids):
            raise GraphError("this capture holds other spheres than the reader's graph (a full read came between)")
        self.last_change = cap.reason
        pos, geoms = cap.pos, cap.walls
        self.geometry_reads += 1
        if self.periodic:
            self._read_periodic(pos, bool(cap.reason), cap.cell)
            return self.graph
        rebuild = bool(cap.reason)
        if not rebuild:
            moved = max_displacement(pos, self._list_pos)
            walls_moved = max([geoms[k].moved(self._list_walls[k]) for k in geoms], default=0.0)
            rebuild = 2.0 * moved > self._skin_m or moved + walls_moved > self._skin_m
        if rebuild:
            self._make_lists(pos, geoms)
            if not cap.reason:
                self.last_change = "new Verlet list"
        elif not np.array_equal(pos, self.graph.pos):
            self._revision += 1
            self.graph = self.graph.with_positions(pos, self._revision)
            self.last_change = self.last_change or "geometry"
        self._wall_geom = geoms
        r = self.graph.radius
        self._wall_contacts = {name: wall_overlaps(geoms[name], self.graph.pos, r, *self._wall_cand[name])
                               for name in self.walls}
        return self.graph

    @property
    def has_clumps(self) -> bool:
        """True when the last full read found clump members."""
        return self._clumps.any

    def clump_labels(self, ids) -> np.ndarray:
        """The clump body id of each sphere of body ids ``ids`` (-1: not in a clump), as at the
        last full read (the element set changes only there)."""
        return self._clumps.of(ids)

    def wall_contacts(self, name: str):
        """(nodes, overlaps [m]) of the spheres touching wall ``name`` at the last read."""
        return self._wall_contacts[name]

    def wall_geometry(self, name: str) -> WallGeometry:
        return self._wall_geom[name]

    def invalidate(self):
        self.graph = None

    @property
    def bodies(self) -> list:
        return self._bodies

    @property
    def scene_replaced(self) -> bool:
        return probe_replaced(self.O, self._probe)

    def positions(self) -> np.ndarray:
        """Current centres (n, 3) [m] of the graph's spheres (YADE's C++ bulk reader)."""
        return bulk_coordinates(self._n_existing)[self._node_slot]

    # -- internals -----------------------------------------------------------------------
    def _stamp_now(self):
        U = import_yade().utils
        return (len(self.O.bodies), float(U.getSpheresVolume()), bool(self.O.periodic))

    def _changed(self) -> Optional[str]:
        if self.scene_replaced:
            return "scene replaced"
        stamp = self._stamp_now()
        if stamp != self._stamp:
            names = ("body count", "sphere volume", "periodic cell")
            return "changed " + ", ".join(n for n, a, b in zip(names, stamp, self._stamp) if a != b)
        return None

    def _full_read(self):
        spheres = read_spheres(self.O, self.mask, periodic=self.accepts_periodic, keep=self.region,
                               clumps=self.clumps)
        if spheres.clump is not None:
            self._clumps.update(spheres.ids, spheres.clump)
        self.periodic = bool(self.O.periodic)
        if self.periodic and self.walls:
            raise GraphError(f"walls ({sorted(self.walls)}) in a periodic cell are not supported: a sphere meets a "
                             "wall only in the cell's own image here. Leave the walls out, or make the cell not "
                             "periodic (O.periodic = False)")
        ids, rad, bodies = spheres.ids, spheres.radius, spheres.bodies
        self._slot_of = spheres.slot_of
        self._node_slot = spheres.node_slot
        self._n_existing = len(spheres.slot_of)
        self._bodies = bodies
        self._probe = (int(ids[0]), bodies[0])
        self._stamp = self._stamp_now()
        warn_left_out(spheres.ignored, self.ignored)
        self.ignored = spheres.ignored
        self.full_reads += 1
        self._skin_m = self.skin * float(rad.min())
        self._revision += 1
        self.graph = ContactGraph(spheres.pos, rad, np.zeros((0, 2), dtype=np.int64), ids, self._revision)

    def _adapt_skin(self):
        g = self.graph
        if self.adaptive and self.list_builds:
            lasted = self.calls - self._built_at
            if lasted < self.GROW_BELOW:
                self.skin = min(1.5 * self.skin, self.SKIN_MAX)
            elif lasted >= self.SHRINK_FROM:
                self.skin = max(self.skin / 1.25, self.SKIN_MIN)
            self._skin_m = self.skin * float(g.radius.min())
        self._built_at = self.calls

    def _cell(self) -> np.ndarray:
        """The periodic cell's base vectors [m] as columns (YADE's ``O.cell.hSize``)."""
        h = self.O.cell.hSize
        return np.array([[h[i, j] for j in range(3)] for i in range(3)], dtype=float)

    def _read_periodic(self, raw, rebuild, H):
        """The graph of a periodic bed from the centres ``raw`` [m] (YADE's, not wrapped) and
        the cell's base vectors ``H`` [m] (columns)."""
        if not (np.all(np.isfinite(H)) and abs(np.linalg.det(H)) > 0):
            raise GraphError(f"the periodic cell is degenerate (O.cell.hSize = {H.tolist()})")
        H_inv = np.linalg.inv(H)
        s = raw @ H_inv.T                                   # the centres in cell periods
        g = self.graph
        if not rebuild:
            # a pair's gap changes by at most |H_list| (|ds_i| + |ds_j|) + |H - H_list| |u|, u its
            # separation in periods now, |u| <= |H^-1| 2 r_max for a pair that touches now
            ds = s - self._list_s
            moved = float(np.sqrt(np.max(np.einsum("ij,ij->i", ds, ds), initial=0.0)))
            strain = np.linalg.norm(H - self._list_cell, 2) * np.linalg.norm(H_inv, 2) * 2.0 * float(g.radius.max())
            rebuild = 2.0 * np.linalg.norm(self._list_cell, 2) * moved + strain > self._skin_m
        periods = np.floor(s)
        wrapped = (s - periods) @ H.T
        if rebuild:
            self._adapt_skin()
            edges, self._images = periodic_candidate_pairs(raw, g.radius, self._skin_m, H)
            self._list_s, self._list_cell = s, H
        else:
            edges = g.edges
        # the images relative to the wrapped centres: the list's, plus each end's own periods
        shift = (self._images + periods[edges[:, 1]] - periods[edges[:, 0]]) @ H.T
        if rebuild:
            self.list_builds += 1
            self._revision += 1
            self.graph = ContactGraph(wrapped, g.radius, edges, g.ids, self._revision, shift=shift)
            self.last_change = self.last_change or "new Verlet list"
        elif not (np.array_equal(wrapped, g.pos) and np.array_equal(shift, g.shift)):
            self._revision += 1
            self.graph = g.with_positions(wrapped, self._revision, shift=shift)
            self.last_change = self.last_change or "geometry"
        self._wall_geom, self._wall_contacts = {}, {}

    def _make_lists(self, pos, geoms):
        g = self.graph
        self._adapt_skin()
        edges = candidate_pairs(pos, g.radius, self._skin_m)
        self._revision += 1
        self.graph = ContactGraph(pos, g.radius, edges, g.ids, self._revision)
        self._list_pos = self.graph.pos
        self._list_walls = dict(geoms)
        self._wall_cand = {name: wall_candidates(geoms[name], pos, g.radius, self._skin_m) for name in self.walls}
        self.list_builds += 1
