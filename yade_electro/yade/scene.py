"""Contact graphs read from a running YADE scene, with cheap change detection (the results go
back to the bodies through :mod:`yade_electro.yade.writeback`).

What is read
------------
* nodes: bodies whose shape is a ``Sphere``; clumps and clump members, facets, walls, boxes
  and every other shape are left out (counted in ``SceneReader.ignored``; clumps left out
  are said in a log warning). An optional ``mask`` keeps only bodies with ``b.mask & mask``.
  A periodic scene (``O.periodic``) is refused here (lengths are taken from the positions,
  without the cell's images); the granular reader takes it for heat conduction.
* edges (``bonds='cohesive'``, the continuum mode): real sphere-sphere interactions that
  are cohesive bonds: ``CohFrictPhys`` with ``cohesionBroken == False``, ``JCFpmPhys`` with
  ``isCohesive == True``. With ``bonds='contacts'`` (granular mode) every real
  sphere-sphere interaction is an edge.

Change detection, and what it costs (measured on the bonded 5,000-element rod, 16,851 bonds)
--------------------------------------------------------------------------------------------
A full read iterates the bodies and interactions in Python (about 35 ms at 5,000 spheres).
Every other call compares a *stamp* of YADE's own C++ counters, about 0.6 ms in all:

* ``utils.getSpheresVolume()`` (0.1 ms): any sphere added or erased, any radius changed
  (also to a negative value);
* ``O.interactions.countReal()`` (0.5 ms): contacts made or lost, bonds broken in tension
  (YADE erases a cohesive interaction that breaks with its spheres apart); with the bond
  sweep (below) it is counted once per sweep cycle;
* the crack counters ``nbTensCracks + nbShearCracks`` of the JCFpm law, when the scene
  uses it (O(1)): every JCFpm bond that breaks;
* one body compared with the one kept (``O.bodies[i] == b``, a pointer comparison): the
  scene was replaced (``O.load``, ``O.reset``);
* ``O.periodic`` (O(1)): the cell made periodic (or not), which the next full read refuses.

A CohFrictMat bond that breaks in shear while its spheres stay pressed together changes no
counter. ``bond_check`` says how such breaks are found, with a cost of about 0.19 us per
bond per read of its flag:

* ``'auto'`` (default): ``'counters'`` when the scene has a JCFpm law; else ``'flags'`` up to
  :data:`FLAG_BUDGET` bonds (2,500: about 0.5 ms a call), so that a break is seen at the next
  call, and beyond that ``'sweep'`` over the fewest calls that read at most that many flags a
  call, ``sweep_calls`` (8) at most (7 calls for the 5,000-element rod's 16,851 bonds). How
  many calls a break may take to be seen is :attr:`SceneReader.bond_check_calls`, in each
  history row as ``bond_check_calls`` (1: at the next call);
* ``'sweep'``: each call reads the flags of 1/``sweep_calls`` of the bonds, in turn: every
  bond is checked every ``sweep_calls`` calls (default 8: 0.4 ms a call at 5,000
  elements), so such a break is seen within ``sweep_calls`` calls; real interactions are
  then counted once per cycle too, so an interaction erased by the script is also seen
  within the cycle (a bond YADE breaks has its flag set, and is seen by the sweep);
* ``'flags'``: every bond every call (3.2 ms at 5,000 elements, 13 ms at 20,000);
* ``'counters'``: the stamp only (exact for JCFpm, which counts every break);
* ``'count'``: the stamp only, whatever the law.

Positions are read every ``geometry_every`` calls (default 10) with YADE's C++
``utils.coordsAndDisplacements`` (three lists of floats: 1.2 ms for 5,000 bodies, against
3.6 ms for the Python loop over ``b.state.pos`` and 206 ms for ``numpy.array`` of the
Vector3 list), and make a new graph (new values, never a new structure) only when an element
moved by more than ``move_tolerance`` times its radius since the last graph.
"""
from __future__ import annotations

import array
import logging
import operator
from collections import Counter
from typing import List, NamedTuple, Optional

import numpy as np

from ..core.errors import GraphError
from ..core.graph import ContactGraph
from ..network.lumping import MemberLabels, member_bonds
from ..packing.statistics import DEFAULT_DETECTION_FACTOR
from .runtime import import_yade

__all__ = ["SceneReader", "predicate_selector", "BOND_CHECKS", "FLAG_BUDGET", "SphereBodies", "read_spheres",
           "bulk_coordinates", "probe_replaced", "warn_left_out", "PERIODIC_REFUSAL"]

log = logging.getLogger(__name__)

BOND_CHECKS = ("auto", "sweep", "flags", "counters", "count")
#: 'auto' reads at most this many bond flags a call (0.19 us a flag): all of them up to this
#: many bonds, else a sweep over the calls that needs
FLAG_BUDGET = 2_500


def _bond_flag(phys):
    """A function phys -> bool telling whether the interaction is (still) a cohesive bond,
    or None if this phys type has no notion of bond."""
    if hasattr(phys, "cohesionBroken"):           # CohFrictPhys and derived
        return lambda p: not p.cohesionBroken
    if hasattr(phys, "isCohesive"):               # JCFpmPhys
        return lambda p: p.isCohesive and not getattr(p, "isBroken", False)
    log.debug("phys %s has no bond flag", type(phys).__name__)
    return None


class SphereBodies(NamedTuple):
    """The spherical bodies of a scene, read by :func:`read_spheres` (node order = body order)."""

    ids: np.ndarray            # (n,) body ids
    pos: np.ndarray            # (n, 3) centres [m]
    radius: np.ndarray         # (n,) radii [m], finite and > 0
    bodies: List               # the YADE bodies
    slot_of: "SlotMap"         # body id -> row of every existing body in YADE's bulk readers
    node_slot: np.ndarray      # (n,) row of each sphere in the bulk readers
    ignored: Counter           # what was left out, by reason
    clump: Optional[np.ndarray] = None   # (n,) the clump body id of each sphere (-1: none); None: clumps left out


#: why a periodic scene is refused (by the bonded reader, and for electrodes)
PERIODIC_REFUSAL = (
    "the scene has a periodic cell (O.periodic is True), which yade-electro supports only for heat conduction in "
    "a granular bed (HeatEngine, or ElectroThermalEngine without electrodes, with Reader(bonds='contacts')): the "
    "bonded reader takes bond lengths from the bodies' positions without the cell's periodic images, so the bonds across "
    "the cell's faces would get the wrong length, and electrodes are not defined across the images. Run this "
    "packing in a box without periodicity, or cut a piece out of the periodic packing")


class SlotMap:
    """Body id -> row of YADE's bulk readers, for every existing body (a sorted id array
    searched, not a dict: a few bytes per body)."""

    def __init__(self, existing):
        ids = np.asarray(existing, dtype=np.int64)          # YADE's order: by id, so sorted
        self._order = None if np.all(np.diff(ids) > 0) else np.argsort(ids, kind="stable")
        self.ids = ids if self._order is None else ids[self._order]

    def __len__(self) -> int:
        return int(self.ids.shape[0])

    def __getitem__(self, bid) -> int:
        k = int(np.searchsorted(self.ids, int(bid)))
        if k >= self.ids.shape[0] or self.ids[k] != int(bid):
            raise KeyError(bid)
        return k if self._order is None else int(self._order[k])

    def rows(self, ids) -> np.ndarray:
        """The rows of ``ids`` (all existing)."""
        k = np.searchsorted(self.ids, np.asarray(ids, dtype=np.int64))
        return k if self._order is None else self._order[k]


def read_spheres(O, mask: Optional[int] = None, periodic: bool = False, keep=None,
                 clumps: bool = False) -> SphereBodies:
    """Every body whose shape is a ``Sphere`` (not a clump or clump member unless ``clumps``,
    and with ``b.mask & mask`` when a mask is given), by a Python loop over ``O.bodies``.
    GraphError when there is none, a radius is not finite and > 0, or the scene is periodic
    and the caller does not take ``periodic`` cells (:data:`PERIODIC_REFUSAL`).

    ``clumps``: clump members are spheres like the others, each with its clump's body id
    (``SphereBodies.clump``); GraphError naming the clump when a member is not a sphere or
    has no mass. The clump bodies themselves are not elements.

    ``keep``: a region, ``keep(ids, pos, radius) -> mask`` over every sphere; only the spheres
    it keeps are read (their YADE bodies fetched by id), so what is held grows with the
    region, not the scene (a distributed run's rank reads its slab and a halo)."""
    if O.periodic and not periodic:
        raise GraphError(PERIODIC_REFUSAL)
    Sphere = import_yade().Sphere
    ids, xyz, rad, bodies, existing = array.array("q"), array.array("d"), array.array("d"), [], array.array("q")
    clump_of = array.array("q")
    ignored = Counter()
    for b in O.bodies:
        if b is None:
            continue
        existing.append(b.id)
        if mask is not None and not (b.mask & mask):
            ignored["masked out"] += 1
            continue
        if b.isClump or (b.isClumpMember and not clumps):
            ignored["clump" if not clumps else "clump body"] += 1
            continue
        if not isinstance(b.shape, Sphere):
            if b.isClumpMember:
                raise GraphError(f"clump {b.clumpId}: its member {b.id} is a {type(b.shape).__name__}, not a sphere; "
                                 "clumps conduct when they are made of spheres (O.bodies.appendClumped([sphere(...), "
                                 "...])): build it of spheres, or leave it out with a mask")
            ignored[type(b.shape).__name__] += 1
            continue
        if clumps:
            if b.isClumpMember and not b.state.mass > 0:
                raise GraphError(f"clump {b.clumpId}: its member {b.id} has no mass ({b.state.mass}); give its "
                                 "material a density > 0")
            clump_of.append(int(b.clumpId) if b.isClumpMember else -1)
        p = b.state.pos
        ids.append(b.id)
        xyz.extend((p[0], p[1], p[2]))
        rad.append(b.shape.radius)
        if keep is None:
            bodies.append(b)
    if not ids:
        raise GraphError("the simulation has no spherical bodies to conduct through "
                         f"(bodies: {len(O.bodies)}, left out: {dict(ignored) or 'none'}); "
                         "add spheres, or check the mask")
    ids = np.frombuffer(ids, dtype=np.int64).copy()
    pos = np.frombuffer(xyz, dtype=float).reshape(-1, 3).copy()
    rad = np.frombuffer(rad, dtype=float).copy()
    bad = ~(np.isfinite(rad) & (rad > 0))
    if np.any(bad):
        raise GraphError(f"sphere radius must be finite and > 0; bodies {ids[bad][:10].tolist()} have "
                         f"{rad[bad][:5].tolist()}")
    clump = np.frombuffer(clump_of, dtype=np.int64).copy() if clumps else None
    if keep is not None:
        chosen = np.asarray(keep(ids, pos, rad), dtype=bool)
        ids, pos, rad = ids[chosen], pos[chosen], rad[chosen]
        clump = None if clump is None else clump[chosen]
        bodies = [O.bodies[i] for i in ids.tolist()]
    slot = SlotMap(np.frombuffer(existing, dtype=np.int64))
    return SphereBodies(ids, pos, rad, bodies, slot, slot.rows(ids), ignored, clump)


def warn_left_out(ignored: Counter, before: Counter) -> None:
    """Say (a log warning) when a full read leaves out more clumps than the one before: a
    clump's members do not conduct, nor do the contacts they make (only plain spheres are
    elements), which a bed of clumps would otherwise get silently."""
    n = ignored.get("clump", 0)
    if n > before.get("clump", 0):
        log.warning("%d clump(s) and clump member(s) are left out: this reader takes plain spheres only, so they "
                    "carry no heat or current and their contacts do not conduct. Read them with "
                    "Reader(clumps='lumped') (one temperature per clump) or Reader(clumps='resolved') (one per "
                    "member), or leave the clumps out of the mask on purpose", n)


def bulk_coordinates(n_existing: Optional[int] = None) -> np.ndarray:
    """Centres (n_existing, 3) [m] of every existing body, by YADE's C++ bulk reader
    ``utils.coordsAndDisplacements`` (rows as ``SphereBodies.slot_of``); GraphError when the
    body count is no longer ``n_existing`` (None: not checked).

    The lists of Python floats go to numpy through ``array.array('d', ...)``, about 10 % of the
    read faster than ``numpy.fromiter`` (``bench/bench_live.py``'s ``live_positions_read``
    lines: 0.93 against 1.04 ms at 5,000 bodies, 4.41 against 4.73 ms at 20,000; YADE's three
    calls alone 0.62 and 3.0 ms)."""
    U = import_yade().utils
    cols = []
    for k in range(3):                      # one axis at a time: its Python floats go at once
        c = array.array("d", U.coordsAndDisplacements(k)[0])
        if n_existing is not None and len(c) != n_existing:
            raise GraphError("the number of bodies changed since the last full read (call invalidate())")
        cols.append(np.frombuffer(c))
    return np.column_stack(cols)


def probe_replaced(O, probe) -> bool:
    """True when ``O`` holds another scene than the one where ``probe`` = (id, body) was read
    (``O.load``, ``O.reset``). An erased probe (a particle that left) is not a new scene: the
    full read its body count or volume change causes takes another probe."""
    if probe is None:
        return False
    pid, body = probe
    try:
        if len(O.bodies) <= pid:
            return True
        now = O.bodies[pid]
        return now is not None and not (now == body)
    except Exception:
        return True


def _jcfpm_laws(O):
    """The JCFpm law functors of the scene's interaction loops (they count their cracks)."""
    out = []
    for e in O.engines:
        disp = getattr(e, "lawDispatcher", None)
        for f in (getattr(disp, "functors", None) or []):
            if type(f).__name__ == "Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM":
                out.append(f)
    return out


class SceneReader:
    """Reads a :class:`ContactGraph` from YADE's ``O`` and keeps it while nothing changed.

    Parameters
    ----------
    O : yade.Omega, optional (the running one by default)
    bonds : {'cohesive', 'contacts'}
        Which interactions are edges (see module doc).
    mask : int, optional
        Keep only bodies with ``b.mask & mask`` (YADE group mask).
    geometry_every : int
        Re-read positions every so many calls (0 = never after a full read).
    move_tolerance : float
        Relative displacement (in radii) above which new positions make a new graph.
    full_read_every : int
        Also read everything every so many calls (0 = only when a change is seen). The cheap
        checks cannot see an interaction that *becomes* a bond while the number of real
        interactions stays the same (re-bonding by ``setCohesionNow`` during a run); set
        this when a simulation does that.
    bond_check : {'auto', 'sweep', 'flags', 'counters', 'count'}
        How bonds broken with no counter change are found (see module doc).
    sweep_calls : int
        Calls over which ``'sweep'`` reads every bond flag once.
    clumps : bool
        Read clump members as elements, members of one clump bonded where their spheres are
        closer than ``clump_bond_factor`` times their radii's sum (YADE makes no interaction
        inside a clump; those bonds never break); False: clumps are left out, with a warning.
    isolated : {'keep', 'leave out'}
        ``bonds='cohesive'``: spheres with no bond are elements (``'keep'``) or are left out,
        named in a log warning (``'leave out'``; their body ids in ``left_out``).
    """

    def __init__(self, O=None, bonds: str = "cohesive", mask: Optional[int] = None,
                 geometry_every: int = 10, move_tolerance: float = 1e-4, full_read_every: int = 0,
                 bond_check: str = "auto", sweep_calls: int = 8, clumps: bool = False,
                 clump_bond_factor: float = DEFAULT_DETECTION_FACTOR, isolated: str = "keep"):
        if bond_check not in BOND_CHECKS:
            raise ValueError(f"bond_check must be one of {', '.join(BOND_CHECKS)}, got {bond_check!r}")
        if bonds not in ("cohesive", "contacts"):
            raise ValueError(f"bonds must be 'cohesive' or 'contacts', got {bonds!r}")
        for name, v in (("geometry_every", geometry_every), ("full_read_every", full_read_every)):
            if isinstance(v, bool) or int(v) != v or v < 0:
                raise ValueError(f"{name} must be an integer >= 0 (calls), got {v!r}")
        if isinstance(sweep_calls, bool) or int(sweep_calls) != sweep_calls or sweep_calls < 1:
            raise ValueError(f"sweep_calls must be an integer >= 1, got {sweep_calls!r}")
        if not (np.isfinite(move_tolerance) and move_tolerance >= 0):
            raise ValueError(f"move_tolerance must be finite and >= 0 (radii), got {move_tolerance!r}")
        if mask is not None and (isinstance(mask, bool) or int(mask) != mask):
            raise ValueError(f"mask must be an integer (YADE group mask), got {mask!r}")
        if O is None:
            O = import_yade().Omega()
        self.O = O
        self.bonds = bonds
        self.mask = mask
        self.clumps, self.clump_bond_factor = bool(clumps), float(clump_bond_factor)
        if isolated not in ("keep", "leave out"):
            raise ValueError(f"isolated must be 'keep' or 'leave out', got {isolated!r}")
        self.isolated = isolated
        #: body ids of the spheres with no bond that the last full read left out (isolated='leave out')
        self.left_out = np.zeros(0, np.int64)
        self._clumps = MemberLabels()
        self.geometry_every = int(geometry_every)
        self.move_tolerance = float(move_tolerance)
        self.full_read_every = int(full_read_every)
        self.bond_check = bond_check
        self.sweep_calls = int(sweep_calls)
        self.graph: Optional[ContactGraph] = None
        self.ignored: Counter = Counter()
        self.full_reads = 0
        self.geometry_reads = 0
        self.calls = 0
        self.last_change: Optional[str] = None
        self._revision = -1
        self._bodies: List = []
        self._phys: List = []
        self._flags: List = []
        self._stamp = None
        self._uniform = None
        self._sweep_at = 0
        self._probe = None
        self._jcfpm = []
        self._node_slot = None
        #: ``keep(ids, pos, radius) -> mask``: read only the spheres of a region (see
        #: :func:`read_spheres`); None: all
        self.region = None
        #: after a full read with a region: the nodes with a real interaction to a sphere
        #: outside it (its halo was too thin if one of them needs all its neighbours)
        self.cut_nodes = np.zeros(0, np.int64)

    # -- the one public call -------------------------------------------------------------
    def read(self) -> ContactGraph:
        """The current graph: the kept one if nothing changed, else a new revision.
        ``last_change`` says why: None, 'geometry' or a reason for a full read."""
        self.calls += 1
        self.last_change = None
        periodic = self.full_read_every and self.calls % self.full_read_every == 0
        reason = "first read" if self.graph is None else ("periodic" if periodic else self._changed())
        if reason:
            self._full_read()
            self.last_change = reason
        elif self.geometry_every and self.calls % self.geometry_every == 0:
            if self._refresh_geometry():
                self.last_change = "geometry"
        return self.graph

    def invalidate(self):
        """Force a full read at the next call (after the user edited bodies by hand)."""
        self.graph = None

    @property
    def scene_replaced(self) -> bool:
        """True when ``O`` holds another scene than the one read (``O.load``, ``O.reset``)."""
        return probe_replaced(self.O, self._probe)

    @property
    def has_clumps(self) -> bool:
        """True when the last full read found clump members."""
        return self._clumps.any

    def clump_labels(self, ids) -> np.ndarray:
        """The clump body id of each sphere of body ids ``ids`` (-1: not in a clump)."""
        return self._clumps.of(ids)

    @property
    def bond_mode(self) -> str:
        """The bond check in use ('auto' resolved)."""
        if self.bond_check != "auto":
            return self.bond_check
        if self._jcfpm:
            return "counters"
        return "flags" if len(self._phys) <= FLAG_BUDGET else "sweep"

    @property
    def bond_check_calls(self) -> int:
        """The calls within which a broken bond is seen: 1 (every flag read at every call, or
        the crack counters), else the sweep's cycle."""
        if self.bond_mode != "sweep":
            return 1
        if self.bond_check == "auto":       # the budget's calls, never more than the sweep's
            return min(self.sweep_calls, -(-len(self._phys) // FLAG_BUDGET))
        return self.sweep_calls

    # -- internals -----------------------------------------------------------------------
    def _stamp_now(self, count_real=True):
        U = import_yade().utils
        cracks = sum(int(f.nbTensCracks) + int(f.nbShearCracks) for f in self._jcfpm)
        real = self.O.interactions.countReal() if count_real else self._stamp[1]
        return (len(self.O.bodies), real, float(U.getSpheresVolume()), cracks, bool(self.O.periodic))

    def _changed(self) -> Optional[str]:
        if self.scene_replaced:
            return "scene replaced"
        # with the bond sweep, real interactions are counted once per sweep cycle (0.5 ms at
        # 5,000 elements): a bond broken in tension is erased by YADE but its flag is read by
        # the sweep within the same cycle anyway
        sweeping = self.bond_mode == "sweep" and self.bonds == "cohesive" and self._phys
        stamp = self._stamp_now(count_real=not sweeping or self._sweep_at == 0)
        if stamp != self._stamp:
            names = ("body count", "real interactions", "sphere volume", "crack counters", "periodic cell")
            return "changed " + ", ".join(n for n, a, b in zip(names, stamp, self._stamp) if a != b)
        mode = self.bond_mode
        if mode in ("count", "counters") or not self._phys:
            return None
        m = len(self._phys)
        if mode == "flags":
            lo, hi = 0, m
        else:
            chunk = -(-m // self.bond_check_calls)
            lo = self._sweep_at
            hi = min(m, lo + chunk)
            self._sweep_at = 0 if hi >= m else hi
        if self._uniform is not None:             # one phys type: a C-level loop over the flags
            attr, broken_when = self._uniform
            if broken_when in map(operator.attrgetter(attr), self._phys[lo:hi]):
                return "a bond broke"
            return None
        for p, flag in zip(self._phys[lo:hi], self._flags[lo:hi]):
            if flag is not None and not flag(p):
                return "a bond broke"
        return None

    def _full_read(self):
        O = self.O
        spheres = read_spheres(O, self.mask, keep=self.region, clumps=self.clumps)
        ids, rad, bodies = spheres.ids, spheres.radius, spheres.bodies
        if spheres.clump is not None:
            self._clumps.update(ids, spheres.clump)
        index = {int(i): k for k, i in enumerate(ids)}
        edges, phys, flags, cut = [], [], [], []
        flag_of_type = {}
        for inter in O.interactions:
            if not inter.isReal:
                continue
            a, b = index.get(inter.id1), index.get(inter.id2)
            if a is None and b is None:
                continue
            ph = inter.phys
            t = type(ph)
            if t not in flag_of_type:
                flag_of_type[t] = _bond_flag(ph)
            flag = flag_of_type[t]
            if self.bonds == "cohesive":
                if flag is None or not flag(ph):
                    continue
            if a is None or b is None:                        # an edge leaving the region
                cut.append(a if a is not None else b)
                continue
            edges.append((a, b))
            phys.append(ph)
            flags.append(flag if self.bonds == "cohesive" else None)
        self._revision += 1
        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if spheres.clump is not None:             # the bonds inside clumps: of the members' geometry
            inside = member_bonds(spheres.pos, rad, spheres.clump, self.clump_bond_factor)
            n = len(ids)
            known = np.sort(edges, axis=1) @ np.array([n, 1]) if len(edges) else np.zeros(0, np.int64)
            edges = np.concatenate([edges, inside[~np.isin(inside @ np.array([n, 1]), known)]])
        if self.isolated == "leave out" and self.bonds == "cohesive" and len(ids):
            spheres, edges, cut = self._without_isolated(spheres, edges, cut)
            ids, rad, bodies = spheres.ids, spheres.radius, spheres.bodies
        self.graph = ContactGraph(spheres.pos, rad, edges, ids, self._revision)
        self.cut_nodes = np.unique(np.asarray(cut, dtype=np.int64))
        self._bodies, self._phys, self._flags = bodies, phys, flags
        # every bond of one phys type: read its flag attribute directly
        self._uniform = None
        if phys and len({type(p) for p in phys}) == 1:
            if hasattr(phys[0], "cohesionBroken"):
                self._uniform = ("cohesionBroken", True)
            elif hasattr(phys[0], "isCohesive") and not hasattr(phys[0], "isBroken"):
                self._uniform = ("isCohesive", False)
        self._sweep_at = 0
        self._node_slot = spheres.node_slot
        self._n_existing = len(spheres.slot_of)
        self._probe = (int(ids[0]), bodies[0])
        self._jcfpm = _jcfpm_laws(O)
        self._stamp = self._stamp_now()
        warn_left_out(spheres.ignored, self.ignored)
        self.ignored = spheres.ignored
        self.full_reads += 1
        if self.bonds == "cohesive" and not len(edges):
            log.warning("no cohesive bond between spheres: every element is isolated "
                        "(did the bonding step run? use Reader(bonds='contacts') for cohesionless packings)")

    def _without_isolated(self, spheres, edges, cut):
        """The spheres, edges (re-indexed) and cut nodes without the spheres that have no edge."""
        n = len(spheres.ids)
        linked = np.zeros(n, bool)
        linked[np.asarray(edges, np.int64).ravel()] = True
        if np.all(linked):
            self.left_out = np.zeros(0, np.int64)
            return spheres, edges, cut
        if not np.any(linked):
            raise GraphError(f"none of the {n} spheres has a bond: Reader(isolated='leave out') would leave every one "
                             "out (did the bonding step run? a cohesionless packing is Reader(bonds='contacts'))")
        new = np.cumsum(linked) - 1
        gone = spheres.ids[~linked]
        if not np.array_equal(gone, self.left_out):
            log.warning("%d sphere(s) with no bond left out (Reader(isolated='leave out')): bodies %s%s", gone.size,
                        gone[:20].tolist(), " ..." if gone.size > 20 else "")
        self.left_out = gone
        keep = np.flatnonzero(linked)
        spheres = spheres._replace(ids=spheres.ids[keep], pos=spheres.pos[keep], radius=spheres.radius[keep],
                                   bodies=[spheres.bodies[k] for k in keep], node_slot=spheres.node_slot[keep],
                                   clump=None if spheres.clump is None else spheres.clump[keep])
        cut = [int(new[c]) for c in cut if linked[c]]
        return spheres, new[np.asarray(edges, np.int64)].reshape(-1, 2), cut

    def positions(self) -> np.ndarray:
        """Current centres (n, 3) [m] of the graph's elements, by YADE's C++ bulk reader."""
        return bulk_coordinates(self._n_existing)[self._node_slot]

    def _refresh_geometry(self) -> bool:
        self.geometry_reads += 1
        pos = self.positions()
        g = self.graph
        moved = np.sqrt(((pos - g.pos) ** 2).sum(axis=1)) / g.radius
        if moved.max(initial=0.0) > self.move_tolerance:
            self._revision += 1
            self.graph = g.with_positions(pos, self._revision)
            return True
        return False

    @property
    def bodies(self) -> list:
        """The YADE bodies of the graph's nodes, in node order."""
        return self._bodies


def predicate_selector(predicate, whole: bool = False):
    """Turn a YADE predicate (``pack.inAlignedBox(...)``, ``pack.inCylinder(...)``, a
    combination) into a selector ``f(pos, radius) -> mask``: an element is selected when its
    centre is inside (``whole=True``: the whole sphere, ``predicate(c, r)``)."""
    def select(pos, radius):
        if whole:
            return np.array([bool(predicate(tuple(p), float(r))) for p, r in zip(pos, radius)])
        return np.array([bool(predicate(tuple(p), 0.0)) for p in pos])
    select.predicate = predicate
    return select

