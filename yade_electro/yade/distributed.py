"""An engine's calls when the run is distributed over MPI ranks (``solver='petsc'`` under
``mpiexec -n P`` with P > 1).

Two ways to run, one user script:

* **YADE's MPI mode** (``yade.mpy``, ``mp.mpirun(...)``): YADE's ownership is kept. Worker r owns
  the bodies with ``b.subdomain == r`` and sees the bodies of other subdomains it mirrors
  (``O.subD.mirrorIntersections``); the master (rank 0) owns no sphere and takes part in the
  solves with an empty share. Electrodes and fixed temperatures chosen when the engine is
  built work wherever their elements end up; walls are the master's bodies, which every
  worker sees: each joins its own spheres on them.
* **Plain mpiexec** (every rank runs the whole scene, as YADE does without ``mpy``): each rank
  owns a slab of the packing along its longest axis (equal counts, fixed by body id at the
  first read; bodies added later go by position) and reads only its *region*, the slab and a
  halo around it (:class:`Slabs`), from the engine's first read on. The mechanics are YADE's,
  replicated; the network is not: each rank reads, builds, holds and solves only its share.
  The 'voronoi' law and surface conditions run here only: each rank tessellates its region
  (:meth:`DistributedCalls.choose_surfaces`).

Each call: read the scene, carve this rank's share (:func:`~yade_electro.physics.shares.carve_share`),
advance :class:`~yade_electro.physics.distributed.DistributedElectroThermal` (collective),
write potentials and temperatures back to the rank's own bodies, and append the totals as a
history row (the CSV is written by rank 0 only). What a distributed run does not do raises when
the engine is built (:func:`distributed_model`).
"""
from __future__ import annotations

import os
import sys
from typing import Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError
from ..core.materials import Material
from ..core.selection import check_selector
from ..physics.distributed import (DISTRIBUTED_LAWS, REGION_LAWS, DistributedElectroThermal, Exchange, Feed, Held,
                                   IsothermalWall)
from ..physics.shares import carve_region_share, carve_share
from ..solvers.partitioned import mpi_comm
from .runtime import in_mpy_subdomain, mpy_subdomain
from .writeback import ensure_thermal_state, write_body_attribute

__all__ = ["world_size", "world_rank", "distributed_requested", "distributed_model", "DistributedCalls", "refuse_clumps",
           "PETSC_SOLVERS", "Slabs", "slab_region", "chosen_ids"]

#: the solver names of a distributed run, and the preconditioner each takes ('petsc-auto': the
#: first solves measure our deflation and GAMG, and the faster is kept)
PETSC_SOLVERS = {"petsc": "deflation", "petsc-hypre": "hypre", "petsc-gamg": "gamg", "petsc-auto": "auto"}


def world_size() -> int:
    """Ranks of the ``mpiexec`` this process runs in (1 outside one), read from the launcher's
    environment: no MPI call, so it is safe when an engine is built."""
    for key in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"):
        if os.environ.get(key, "").isdigit():
            return int(os.environ[key])
    return 1


def world_rank() -> int:
    """This process's rank in ``mpiexec`` (0 outside one)."""
    for key in ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"):
        if os.environ.get(key, "").isdigit():
            return int(os.environ[key])
    return 0


def distributed_requested(solver) -> bool:
    """True when an engine with ``solver`` runs distributed: a PETSc solver name and more than
    one rank."""
    return isinstance(solver, str) and solver in PETSC_SOLVERS and world_size() > 1


def _refuse(what: str):
    raise BoundaryConditionError(f"a distributed run (solver='petsc' under mpiexec) does not do {what} yet; run it "
                                 "serially, or leave it out")


def refuse_clumps(reader) -> None:
    """BoundaryConditionError on every rank when some rank's reader found clump members (a
    clump's members may sit on two ranks, and its heat is one): collective."""
    if mpi_comm().allreduce(int(getattr(reader, "has_clumps", False))):
        _refuse("clumps (their members may sit on two ranks, and a lumped clump's heat is one): run the bed "
                "serially, or of spheres")


def distributed_model(*, solver: str, resistivity, materials, law: str, law_params: Optional[dict],
                      electrodes: Sequence = (), electrode_ids: Optional[dict] = None, heat: Optional[dict] = None,
                      conditions: Sequence = (), condition_ids: Optional[dict] = None,
                      walls: Optional[dict] = None) -> DistributedElectroThermal:
    """The distributed model of an engine's settings, or BoundaryConditionError naming what a
    distributed run does not do. ``electrodes`` are the engine's electrode specs (name,
    select, surface, wall, potential, current); ``electrode_ids`` and ``condition_ids`` the
    body ids their selections chose when the engine was built; ``heat`` the thermal settings
    (density, specific_heat, conductivity, temperature, beta, reference_temperature, eta,
    theta, joule_sharing, volume_fraction), None for conduction only; ``conditions`` the heat boundary
    conditions; ``walls`` the thermal walls, name -> dict(bodies=, temperature= K or None
    (adiabatic: conducts nothing), conductivity=)."""
    if materials is not None:
        _refuse("per-material tables (Materials): give one Material")
    if float((law_params or {}).get("film", 0.0) or 0.0):
        _refuse("contact films (Law(..., film=...)): leave the film out")
    comm = mpi_comm()
    if law not in DISTRIBUTED_LAWS:
        _refuse(f"the {law!r} law (it does {', '.join(DISTRIBUTED_LAWS)})")
    if law in REGION_LAWS and "yade.mpy" in sys.modules:
        raise BoundaryConditionError(
            f"the {law!r} law runs distributed under plain mpiexec only (its tessellation needs a halo wider than "
            "yade.mpy's mirrors), and this script imports yade.mpy: run it without yade.mpy (plain mpiexec, "
            "solver='petsc'), or take law='continuum' under mp.mpirun")
    surfaces = [e.name for e in electrodes if e.surface is not None] + [
        bc.name for bc in conditions if getattr(bc, "surface", None) is not None]
    if surfaces and "yade.mpy" in sys.modules:
        raise BoundaryConditionError(
            f"electrodes and conditions on a surface ({surfaces}) run distributed under plain mpiexec only (their "
            "half cells need a halo wider than yade.mpy's mirrors), and this script imports yade.mpy: run it "
            "without yade.mpy (plain mpiexec, solver='petsc'), or select the elements with select= / nodes=")
    held = []
    for e in electrodes:
        fed = e.potential is None
        linked = e.wall or e.surface is not None
        held.append(Held(e.name, None if linked else (electrode_ids or {}).get(e.name, e.select),
                         float(e.current if fed else e.potential), wall=bool(e.wall), fed=fed, surface=e.surface))
    if held and all(h.fed for h in held):
        raise BoundaryConditionError(f"every electrode ({[h.name for h in held]}) has an imposed current: hold one at "
                                     "a potential (potential=0, the ground) to give the current a return path")
    isothermal = [IsothermalWall(name, float(w["temperature"]), w.get("conductivity"))
                  for name, w in (walls or {}).items() if w.get("temperature") is not None]
    fixed, convection, feeds = [], [], []
    for bc in conditions:
        kind = type(bc).__name__
        surface = getattr(bc, "surface", None)
        select = None if surface is not None else (condition_ids or {}).get(bc.name, bc.nodes)
        if bc.ROLE == "fixed":
            fixed.append(Held(bc.name, select, float(bc.field("value")), surface=surface))
        elif bc.ROLE == "robin":
            area = getattr(bc, "area", None)
            if area is not None and np.ndim(area) != 0:
                _refuse(f"per-element areas ({kind} {bc.name!r}): give a scalar area or none")
            convection.append(Exchange(bc.name, select, float(bc.field("coefficient")), float(bc.field("ambient")),
                                       None if area is None or surface is not None else float(area), surface=surface))
        elif bc.ROLE in ("injection", "source"):
            area = getattr(bc, "area", None)
            if area is not None and np.ndim(area) != 0:
                _refuse(f"per-element areas ({kind} {bc.name!r}): give a scalar area or none")
            rate, density = bc.field("rate"), bc.field("density")
            feeds.append(Feed(bc.name, select, "flux" if bc.ROLE == "injection" else "source",
                              None if rate is None else float(rate), None if density is None else float(density),
                              None if area is None or surface is not None else float(area), surface=surface))
        else:
            _refuse(f"{kind} conditions ({bc.name!r})")
    rho = resistivity if electrodes else None
    if rho is not None and np.ndim(rho) != 0:
        _refuse("per-element resistivities: give a scalar")
    h = dict(heat or {})
    material = Material(resistivity=rho, density=h.get("density"), specific_heat=h.get("specific_heat"),
                        conductivity=h.get("conductivity"), beta=h.get("beta", 0.0) or 0.0,
                        reference_temperature=h.get("reference_temperature"))
    return DistributedElectroThermal(material, law, law_params, electrodes=held, fixed=fixed, convection=convection,
                                     walls=isothermal, feeds=feeds,
                                     temperature=h.get("temperature") if heat else None,
                                     theta=h.get("theta", "backward-euler"), eta=h.get("eta", 1.0),
                                     joule_sharing=h.get("joule_sharing", "auto"),
                                     volume_fraction=h.get("volume_fraction"), safety=h.get("safety", 0.9),
                                     max_substeps=h.get("max_substeps", 100000), preconditioner=PETSC_SOLVERS[solver],
                                     comm=comm)


class Slabs:
    """Plain mpiexec: this rank's slab and the region it reads.

    Ownership: equal counts of spheres in slabs along the packing's longest axis, fixed by
    body id when a sphere is first seen (every rank sees every sphere's position then: the
    region is chosen from all of them; spheres added later go by position).

    Region (:meth:`region`, the readers' ``keep`` hook): the spheres this rank owns and every
    sphere within ``halo`` [m] of one of them, so a rank holds its slab and a layer around it,
    not the scene. The halo is the reach of an element's share (its contacts and bonds: two
    largest diameters; with the 'voronoi' law, whose cells and crack rule look farther,
    ``hops + 2`` of them) plus a margin of one largest diameter. The region is kept by id until
    some body has moved by half the margin since it was made (a granular reader's contacts;
    not with the 'voronoi' law, whose faces are those of the first configuration), or spheres
    appear. A bond or interaction that leaves the region from an owned element means the halo
    was too thin: :meth:`read` doubles it and reads again (three times at most, then an error).

    Parameters
    ----------
    rank, size : this rank and the number of ranks
    hops : None, or the 'voronoi' law's hops (its wider reach, and no move check)
    cells : the owned elements' bounded cells are made on the region (surface electrodes and
        conditions: their half cells): the 'voronoi' law's reach with 3 hops, 5 diameters
    """

    def __init__(self, rank: int, size: int, hops: Optional[int] = None, cells: bool = False):
        self.rank, self.size, self.hops, self.cells = int(rank), int(size), hops, bool(cells)
        self.axis, self._bounds, self._owner_by_id = None, None, np.zeros(0, np.int64)
        #: the halo [m], how often the region was made, the whole packing's (r_min, r_max)
        #: and (lo, hi) of its centres [m]
        self.halo, self.builds, self.radius_range, self.bounds = None, 0, None, None
        self._ids, self._seen, self._coords, self._margin, self._scale = None, None, None, 0.0, 1.0
        self._fresh = False

    def owner(self, ids, pos) -> np.ndarray:
        """The owner of each sphere (see the class doc)."""
        if self._bounds is None:
            self.axis = int(np.argmax(np.ptp(pos, axis=0)))
            x = np.sort(pos[:, self.axis])
            self._bounds = x[(np.arange(1, self.size) * x.shape[0]) // self.size]
        known = self._owner_by_id                         # owner by body id, -1: not seen yet
        if known.shape[0] <= int(ids.max()):
            known = self._owner_by_id = np.concatenate([known, np.full(int(ids.max()) + 1 - known.shape[0], -1)])
        owner = known[ids]
        new = owner < 0
        owner[new] = np.searchsorted(self._bounds, pos[new, self.axis], side="right")
        known[ids[new]] = owner[new]
        return owner

    def region(self, ids, pos, radius) -> np.ndarray:
        """Which of the spheres (all of the scene's) this rank reads (see the class doc)."""
        from scipy.spatial import cKDTree
        owner = self.owner(ids, pos)
        if self._ids is not None and np.all(np.isin(ids, self._seen)):
            return np.isin(ids, self._ids)
        own = owner == self.rank
        d = 2.0 * float(np.max(radius))
        hops = self.hops if self.hops is not None else (3 if self.cells else None)
        reach = 2.0 * d if hops is None else max(2.0 * d, (int(hops) + 2) * d)
        self._margin = d
        self.halo = self._scale * (reach + self._margin)
        keep = own.copy()
        if own.any() and (~own).any():
            dist, _ = cKDTree(pos[own]).query(pos[~own], distance_upper_bound=self.halo)
            keep[~own] = np.isfinite(dist)
        self._ids, self._seen = ids[keep], ids.copy()
        self.radius_range = (float(np.min(radius)), float(np.max(radius)))
        self.bounds = (pos.min(axis=0), pos.max(axis=0))
        self._coords, self._fresh = None, True           # the positions then: the reader's, after it
        self.builds += 1
        return keep

    def forget(self):
        """Make the region again at the next full read."""
        self._ids = None

    def _moved(self, coords) -> bool:
        """Has some body moved by more than half the margin since the region was made (two
        bodies could then have closed the margin between them)?"""
        if self._coords is None or coords is None:
            return False
        return coords.shape != self._coords.shape or bool(np.max(
            np.abs(coords - self._coords).sum(axis=1), initial=0.0) > 0.5 * self._margin)

    def read(self, reader):
        """The region's graph from ``reader`` (see the class doc). A granular reader's
        contacts come from the positions: when a body has moved too far since the region was
        made (checked on the positions of every body the reader reads anyway), the region is
        made again and read again. A bonded reader's edges are YADE's interactions: a new one
        makes it read again, and one that leaves the region from an owned element means the
        halo was too thin."""
        for _ in range(4):
            graph = reader.read()
            coords = getattr(reader, "last_coordinates", None)
            if self._fresh:
                self._coords, self._fresh = coords, False
            elif self.hops is None and self._moved(coords):
                self.forget()
                reader.invalidate()
                graph = reader.read()
                self._coords, self._fresh = getattr(reader, "last_coordinates", None), False
            cut = getattr(reader, "cut_nodes", np.zeros(0, np.int64))
            if not cut.size or not np.any(self.owner(graph.ids[cut], graph.pos[cut]) == self.rank):
                return graph
            self._scale *= 2.0
            self.forget()
            reader.invalidate()
        raise BoundaryConditionError(f"rank {self.rank}: owned elements keep interactions with elements beyond a halo "
                                     f"of {self.halo:.3g} m; their bonds reach farther than the packing's diameters")


def slab_region(law: str, law_params: Optional[dict], cells: bool = False) -> Optional[Slabs]:
    """The :class:`Slabs` of a distributed engine under plain mpiexec (None under yade.mpy),
    made before its first read so that no rank reads the whole scene; ``cells``: the engine
    has surface electrodes or conditions (see :class:`Slabs`)."""
    if in_mpy_subdomain():
        return None
    hops = int((law_params or {}).get("hops") or 3) if law in REGION_LAWS else None
    return Slabs(world_rank(), world_size(), hops, cells=cells)


def chosen_ids(graph, memberships: dict, what: str = "electrode", comm=None) -> dict:
    """Body ids each membership (name -> :class:`~yade_electro.core.selection.Membership`,
    selecting by ids or a predicate ``f(pos, radius) -> mask``) chose in the whole scene, when
    each rank read only a part of it (``graph``): each rank selects on its part, the ranks join
    their choices (collective, so every rank raises the same error) and each membership is kept
    by those ids, as a serial engine keeps it. Ids that are no sphere of the scene, or a
    selection that chose nothing, raise BoundaryConditionError."""
    comm = mpi_comm(comm)
    out = {}
    for name in sorted(memberships):
        sel, label = memberships[name].select, f"{what} {name!r}"
        check_selector(sel, label)
        asked = None
        if callable(sel):
            mask = np.asarray(sel(graph.pos, graph.radius), dtype=bool)
            if mask.shape != (graph.n_nodes,):
                raise BoundaryConditionError(f"{label}: the selector returned shape {mask.shape}, expected a mask of "
                                             f"({graph.n_nodes},)")
            mine = graph.ids[mask]
        else:
            asked = np.atleast_1d(np.asarray(sel))
            if asked.dtype == bool:
                raise BoundaryConditionError(f"{label}: a boolean mask cannot select in a distributed run (each rank "
                                             "reads a part of the scene); give body ids or a predicate f(pos, radius)")
            asked = asked.astype(np.int64)
            mine = asked[np.isin(asked, graph.ids)]
        ids = np.unique(np.concatenate(comm.allgather(np.asarray(mine, np.int64))))
        if asked is not None and ids.size < np.unique(asked).size:
            missing = np.setdiff1d(asked, ids)
            raise BoundaryConditionError(f"{label}: ids not in the packing: {missing[:10].tolist()} (ids must be "
                                         "spherical bodies of the packing)")
        if ids.size == 0:
            raise BoundaryConditionError(f"{label} selects no element: check its region/ids against the packing "
                                         "(selection is by element centre)")
        out[name] = ids
        memberships[name].restore(ids)
    return out


class DistributedCalls:
    """The calls of a distributed engine (see the module doc).

    Parameters
    ----------
    O : YADE's Omega
    reader : the engine's scene reader
    model : DistributedElectroThermal
    write_back : body attribute of the potential (None: not written)
    temperatures : write the temperatures to ``b.state.temp``
    thermal_dt, time_scale : the thermal step of a call (fixed, or the elapsed O.time scaled)
    slabs : the Slabs the reader's first read used (plain mpiexec), or None
    graph : that first read's graph: the 'voronoi' law's faces are made on it, as a serial
        engine makes them when it is built (the reference configuration), and the elements of
        the surface conditions are chosen on it (:meth:`choose_surfaces`)
    container : the solid's Shape (surface conditions)
    """

    def __init__(self, O, reader, model: DistributedElectroThermal, write_back: Optional[str] = None,
                 temperatures: bool = False, thermal_dt: Optional[float] = None, time_scale: float = 1.0,
                 slabs: Optional[Slabs] = None, graph=None, container=None):
        self.O, self.reader, self.model = O, reader, model
        self.write_back, self.temperatures = write_back, temperatures
        self.thermal_dt, self.time_scale = thermal_dt, float(time_scale)
        self.rank = model.comm.Get_rank()
        self.size = model.comm.Get_size()
        self.slabs = slabs
        self._last_time = float(O.time)
        self.share = None
        if slabs is not None and graph is not None and model.law_name in REGION_LAWS:
            model.law.radius_range, model.law.bounds = slabs.radius_range, slabs.bounds
            model.law.faces(graph)
        if model.surface_names:
            self.choose_surfaces(graph, container)

    def choose_surfaces(self, graph, container):
        """The elements of each surface condition and their half cells (collective): each
        rank makes the bounded cells of its region (its slab and a halo of 5 diameters, wide
        enough for its own elements' cells) and keeps the faces on each surface, as a serial
        engine does on the whole packing; a surface no rank's region touches is an error."""
        from ..geometry.boundary import BoundaryOfGraph, surface_contact
        m = self.model
        lam = m.material.conductivity
        found, first_error = {}, None
        if graph is not None:
            law = m.law if getattr(m.law, "container", None) is container else None
            cells, pos = BoundaryOfGraph(container, law).cells(graph)
        for name, surface in sorted(m.surface_names.items()):
            ids, values = np.zeros(0, np.int64), np.zeros(0)
            if graph is not None:
                try:
                    c = surface_contact(cells, pos, surface, name, container=container)
                except BoundaryConditionError as exc:     # not on this rank's region
                    first_error = first_error or str(exc)
                else:
                    ids = graph.ids[c.nodes]
                    conv = next((x for x in m.convection if x.name == name), None)
                    fed = any(x.name == name for x in m.feeds)
                    values = c.area if fed else (c.factor if conv is None else c.convection_area(conv.h, lam))
            found[name] = int(m.comm.allreduce(int(ids.size)))
            m.set_surface(name, ids, values)
        empty = [k for k, v in found.items() if v == 0]
        if empty:
            raise BoundaryConditionError(f"surface condition(s) {empty} hold no element on any rank"
                                         + (f": {first_error}" if first_error else ""))

    @property
    def mode(self) -> str:
        """'mpy' (YADE's subdomains) or 'slabs' (plain mpiexec)."""
        return "mpy" if in_mpy_subdomain() else "slabs"

    def _owner(self, graph) -> np.ndarray:
        if self.mode == "mpy":
            subD = mpy_subdomain()
            owner = np.full(graph.n_nodes, -1, np.int64)
            owner[np.isin(graph.ids, np.asarray(list(subD.ids), np.int64))] = self.rank
            for k, mirrored in enumerate(subD.mirrorIntersections):
                if k != self.rank and len(mirrored):
                    owner[np.isin(graph.ids, np.asarray(list(mirrored), np.int64))] = k
            for i in np.flatnonzero(owner < 0):          # seen but in no list: ask the body
                owner[i] = int(self.O.bodies[int(graph.ids[i])].subdomain)
            return owner
        return self.slabs.owner(graph.ids, graph.pos)

    def abort(self, exc: BaseException):
        """End every rank after this one failed (the others would wait for it forever): the
        error is printed, then MPI_Abort."""
        import sys
        import traceback
        sys.stderr.write(f"yade-electro: rank {self.rank} of {self.size} failed; ending all ranks (MPI_Abort)\n")
        traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
        sys.stderr.flush()
        self.model.comm.Abort(1)

    def call(self) -> dict:
        """One call (collective): read, carve, advance, write back; returns the history row."""
        master = self.mode == "mpy" and self.rank == 0
        if not master and (self.mode == "mpy" or self.reader.scene_replaced):
            # yade.mpy erases and re-inserts mirrored bodies when it collides: what the reader
            # counts to detect a change does not see that, so a full read each call
            self.reader.invalidate()
            if self.slabs is not None:
                self.slabs.forget()
        region_law = self.model.law_name in REGION_LAWS
        if self.mode == "mpy":
            if region_law:
                raise BoundaryConditionError(f"the {self.model.law_name!r} law runs distributed under plain mpiexec "
                                             "only (its tessellation needs a halo wider than yade.mpy's mirrors)")
            self.reader.region = None                  # the workers read what YADE gave them
            graph = None if master else self.reader.read()
        else:
            if self.slabs is None:                     # built where the first read was not a region's
                self.slabs = Slabs(self.rank, self.size, getattr(self.model.law, "hops", None) if region_law else None)
            if self.reader.region is None:
                self.reader.region = self.slabs.region
                self.reader.invalidate()
            graph = self.slabs.read(self.reader)
            if region_law:                             # the whole packing's band and tolerances
                self.model.law.radius_range, self.model.law.bounds = self.slabs.radius_range, self.slabs.bounds
        owner = self._owner(graph) if graph is not None else None
        share = (carve_region_share(graph, owner, self.rank, self.model.law) if region_law
                 else carve_share(graph, owner, self.rank))
        for name in self.model.wall_names:           # each rank's spheres on the walls it sees
            nodes, overlap = self.reader.wall_contacts(name) if graph is not None else (np.zeros(0, np.int64), ())
            self.model.set_wall_contacts(name, graph.ids[nodes] if graph is not None else nodes, overlap)
        self.share = share
        now = float(self.O.time)
        dt = self.thermal_dt if self.thermal_dt is not None else (now - self._last_time) * self.time_scale
        row = self.model.step(share, dt)
        self._last_time = now
        if graph is not None and share.n_owned:
            bodies = self.reader.bodies
            own = [bodies[i] for i in graph.index_of(share.owned_ids).tolist()]
            if self.write_back and self.model.conduction is not None:
                write_body_attribute(own, self.write_back, self.model.potential)
            if self.temperatures and self.model.heat is not None:
                ensure_thermal_state(own)
                write_body_attribute(own, "state.temp", self.model.T)
        out = {"iter": int(self.O.iter), "time": now, "ranks": self.size}
        out.update(row)
        return out
