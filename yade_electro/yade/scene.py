"""Contact graphs read from a running YADE scene, re-read only when something changed, and
results written back to the bodies.

What is read
------------
* nodes: bodies whose shape is a ``Sphere``; clumps and clump members, facets, walls, boxes
  and every other shape are left out (counted in ``SceneReader.ignored``). An optional
  ``mask`` keeps only bodies with ``b.mask & mask``.
* edges (``bonds='cohesive'``, the continuum mode): real sphere-sphere interactions that
  are cohesive bonds: ``CohFrictPhys`` with ``cohesionBroken == False``, ``JCFpmPhys`` with
  ``isCohesive == True``. With ``bonds='contacts'`` (granular mode) every real
  sphere-sphere interaction is an edge.

Change detection (cheap)
------------------------
A full read iterates the bodies and interactions (about 7 ms for 5,000 spheres and 28,000
interactions here). Afterwards, each ``read()`` only checks, on the interaction objects it
kept: the number of bodies, ``O.interactions.countReal()``, and the bond flag of each kept
edge (``cohesionBroken`` / ``isCohesive`` / ``isReal``: ~0.3 us each). Any difference
triggers a full read and a new graph revision. Positions are read every
``geometry_every`` calls (3.5 ms for 5,000 bodies) and make a new graph only when an
element moved by more than ``move_tolerance`` times its radius since the graph was made.
"""
from __future__ import annotations

import logging
from collections import Counter
from typing import List, Optional

import numpy as np

from ..graph import ContactGraph
from ..errors import GraphError
from .runtime import import_yade

__all__ = ["SceneReader", "write_body_attribute", "predicate_selector"]

log = logging.getLogger(__name__)


def _bond_flag(phys):
    """A function phys -> bool telling whether the interaction is (still) a cohesive bond,
    or None if this phys type has no notion of bond."""
    names = type(phys).__name__
    if hasattr(phys, "cohesionBroken"):           # CohFrictPhys and derived
        return lambda p: not p.cohesionBroken
    if hasattr(phys, "isCohesive"):               # JCFpmPhys
        return lambda p: p.isCohesive and not getattr(p, "isBroken", False)
    log.debug("phys %s has no bond flag", names)
    return None


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
        Re-read positions every so many calls (0 = never after the first read).
    move_tolerance : float
        Relative displacement (in radii) above which new positions make a new graph.
    full_read_every : int
        Also read everything every so many calls (0 = only when a change is seen). The cheap
        check cannot see an interaction that *becomes* a bond while the number of real
        interactions stays the same (re-bonding by ``setCohesionNow`` during a run); set
        this when a simulation does that.
    bond_check : {'flags', 'count'}
        'flags' (default): every call reads the bond flag of each kept edge (~0.4 us each:
        6 ms for 17,000 bonds), so a bond that breaks while its spheres stay in contact is
        seen at once. 'count': only the numbers of bodies and real interactions are
        compared (under 1 ms); a bond broken in shear or compression, whose contact
        survives, is then seen only at the next full read (``full_read_every``).
    """

    def __init__(self, O=None, bonds: str = "cohesive", mask: Optional[int] = None,
                 geometry_every: int = 1, move_tolerance: float = 1e-4, full_read_every: int = 0,
                 bond_check: str = "flags"):
        if bond_check not in ("flags", "count"):
            raise ValueError(f"bond_check must be 'flags' or 'count', got {bond_check!r}")
        self.bond_check = bond_check
        if bonds not in ("cohesive", "contacts"):
            raise ValueError(f"bonds must be 'cohesive' or 'contacts', got {bonds!r}")
        if O is None:
            O = import_yade().Omega()
        self.O = O
        self.bonds = bonds
        self.mask = mask
        self.geometry_every = int(geometry_every)
        self.move_tolerance = float(move_tolerance)
        self.full_read_every = int(full_read_every)
        self.graph: Optional[ContactGraph] = None
        self.ignored: Counter = Counter()
        self.full_reads = 0
        self.calls = 0
        self._revision = -1
        self._bodies: List = []
        self._kept: List = []
        self._flags: List = []
        self._stamp = None

    # -- the one public call -------------------------------------------------------------
    def read(self) -> ContactGraph:
        """The current graph: the kept one if nothing changed, else a new revision."""
        self.calls += 1
        periodic = self.full_read_every and self.calls % self.full_read_every == 0
        if self.graph is None or periodic or self._changed():
            self._full_read()
        elif self.geometry_every and self.calls % self.geometry_every == 0:
            self._refresh_geometry()
        return self.graph

    def invalidate(self):
        """Force a full read at the next call (after the user edited bodies by hand)."""
        self.graph = None

    # -- internals -----------------------------------------------------------------------
    def _stamp_now(self):
        O = self.O
        return (len(O.bodies), O.interactions.countReal())

    def _changed(self) -> bool:
        if self._stamp_now() != self._stamp:
            return True
        if self.bond_check == "count":
            return False
        for inter, flag in zip(self._kept, self._flags):
            if not inter.isReal or (flag is not None and not flag(inter.phys)):
                return True
        return False

    def _full_read(self):
        yade = import_yade()
        Sphere = yade.Sphere
        O = self.O
        ids, pos, rad, bodies = [], [], [], []
        ignored = Counter()
        for b in O.bodies:
            if b is None:
                continue
            if self.mask is not None and not (b.mask & self.mask):
                ignored["masked out"] += 1
                continue
            if b.isClump or b.isClumpMember:
                ignored["clump"] += 1
                continue
            if not isinstance(b.shape, Sphere):
                ignored[type(b.shape).__name__] += 1
                continue
            p = b.state.pos
            ids.append(b.id)
            pos.append((p[0], p[1], p[2]))
            rad.append(b.shape.radius)
            bodies.append(b)
        if not ids:
            raise GraphError("the simulation has no spherical bodies to conduct through "
                             f"(bodies: {len(O.bodies)}, left out: {dict(ignored) or 'none'}); "
                             "add spheres, or check the mask")
        ids = np.asarray(ids, dtype=np.int64)
        index = {int(i): k for k, i in enumerate(ids)}
        edges, kept, flags = [], [], []
        flag_of_type = {}
        for inter in O.interactions:
            if not inter.isReal:
                continue
            a, b = index.get(inter.id1), index.get(inter.id2)
            if a is None or b is None:
                continue
            t = type(inter.phys)
            if t not in flag_of_type:
                flag_of_type[t] = _bond_flag(inter.phys)
            flag = flag_of_type[t]
            if self.bonds == "cohesive":
                if flag is None or not flag(inter.phys):
                    continue
            edges.append((a, b))
            kept.append(inter)
            flags.append(flag if self.bonds == "cohesive" else None)
        self._revision += 1
        self.graph = ContactGraph(np.asarray(pos, dtype=float), np.asarray(rad, dtype=float),
                                  np.asarray(edges, dtype=np.int64).reshape(-1, 2), ids, self._revision)
        self._bodies, self._kept, self._flags = bodies, kept, flags
        self._stamp = self._stamp_now()
        self.ignored = ignored
        self.full_reads += 1
        if self.bonds == "cohesive" and not edges:
            log.warning("no cohesive bond between spheres: every element is isolated "
                        "(did the bonding step run? use bonds='contacts' for cohesionless packings)")

    def _refresh_geometry(self):
        pos = np.array([(p[0], p[1], p[2]) for p in (b.state.pos for b in self._bodies)], dtype=float)
        g = self.graph
        moved = np.sqrt(((pos - g.pos) ** 2).sum(axis=1)) / g.radius
        if moved.max(initial=0.0) > self.move_tolerance:
            self._revision += 1
            self.graph = ContactGraph(pos, g.radius, g.edges, g.ids, self._revision)

    @property
    def bodies(self) -> list:
        """The YADE bodies of the graph's nodes, in node order."""
        return self._bodies


def write_body_attribute(bodies, name: str, values) -> None:
    """Set ``b.<name> = value`` on each body (a Python attribute YADE keeps on the body, so
    ``yade.export.VTKExporter(...).exportSpheres(what=dict(potential='b.potential'))`` and
    scripts can read it)."""
    for b, v in zip(bodies, np.asarray(values, dtype=float).tolist()):
        setattr(b, name, v)


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
