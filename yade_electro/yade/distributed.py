"""An engine's calls when the run is distributed over MPI ranks (``solver='petsc'`` under
``mpiexec -n P`` with P > 1).

Two ways to run, one user script:

* **YADE's MPI mode** (``yade.mpy``, ``mp.mpirun(...)``): YADE's ownership is kept. Worker r owns
  the bodies with ``b.subdomain == r`` and sees the bodies of other subdomains it mirrors
  (``O.subD.mirrorIntersections``); the master (rank 0) owns no sphere and takes part in the
  solves with an empty share. Electrodes and fixed temperatures chosen when the engine is
  built work wherever their elements end up.
* **Plain mpiexec** (every rank runs the whole scene, as YADE does without ``mpy``): each rank
  owns a slab of the packing along its longest axis (equal counts, fixed by body id at the
  first call; bodies added later go by position). The mechanics are YADE's, replicated; the
  network is not: each rank builds, holds and solves only its share.

Each call: read the scene, carve this rank's share (:func:`~yade_electro.physics.distributed.carve_share`),
advance :class:`~yade_electro.physics.distributed.DistributedElectroThermal` (collective),
write potentials and temperatures back to the rank's own bodies, and append the totals as a
history row (the CSV is written by rank 0 only). What a distributed run does not do raises when
the engine is built (:func:`distributed_model`).
"""
from __future__ import annotations

import os
from typing import Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError
from ..core.materials import Material
from ..physics.distributed import DISTRIBUTED_LAWS, DistributedElectroThermal, Exchange, Held, carve_share
from .runtime import in_mpy_subdomain, mpy_subdomain
from .scene import ensure_thermal_state, write_body_attribute

__all__ = ["world_size", "world_rank", "distributed_requested", "distributed_model", "DistributedCalls",
           "PETSC_SOLVERS"]

#: the solver names of a distributed run, and the preconditioner each takes
PETSC_SOLVERS = {"petsc": "deflation", "petsc-hypre": "hypre", "petsc-gamg": "gamg"}


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


def distributed_model(*, solver: str, resistivity, materials, law: str, law_params: Optional[dict],
                      electrodes: Sequence = (), electrode_ids: Optional[dict] = None, heat: Optional[dict] = None,
                      conditions: Sequence = (), condition_ids: Optional[dict] = None,
                      walls: Sequence = ()) -> DistributedElectroThermal:
    """The distributed model of an engine's settings, or BoundaryConditionError naming what a
    distributed run does not do. ``electrodes`` are the engine's electrode specs (name,
    select, surface, wall, potential, current); ``electrode_ids`` and ``condition_ids`` the
    body ids their selections chose when the engine was built; ``heat`` the thermal settings
    (density, specific_heat, conductivity, temperature, beta, reference_temperature, eta,
    theta, volume_fraction), None for conduction only; ``conditions`` the heat boundary
    conditions."""
    if materials is not None:
        _refuse("per-material tables (Materials): give one Material")
    if law not in DISTRIBUTED_LAWS:
        _refuse(f"the {law!r} law (it does {', '.join(DISTRIBUTED_LAWS)})")
    if walls:
        _refuse("walls (Wall, Electrode(wall=...))")
    held = []
    for e in electrodes:
        if e.surface is not None or e.wall:
            _refuse(f"surface or wall electrodes (electrode {e.name!r}): select elements with select=")
        if e.potential is None:
            _refuse(f"current-driven electrodes (electrode {e.name!r} has current=): hold it at a potential")
        held.append(Held(e.name, (electrode_ids or {}).get(e.name, e.select), float(e.potential)))
    fixed, convection = [], []
    for bc in conditions:
        kind = type(bc).__name__
        if getattr(bc, "surface", None) is not None:
            _refuse(f"conditions at a surface ({kind} {bc.name!r}): select elements with nodes=")
        select = (condition_ids or {}).get(bc.name, bc.nodes)
        if bc.ROLE == "fixed":
            fixed.append(Held(bc.name, select, float(bc.field("value"))))
        elif bc.ROLE == "robin":
            area = getattr(bc, "area", None)
            if area is not None and np.ndim(area) != 0:
                _refuse(f"per-element areas ({kind} {bc.name!r}): give a scalar area or none")
            convection.append(Exchange(bc.name, select, float(bc.field("coefficient")), float(bc.field("ambient")),
                                       None if area is None else float(area)))
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
                                     temperature=h.get("temperature") if heat else None,
                                     theta=h.get("theta", "backward-euler"), eta=h.get("eta", 1.0),
                                     volume_fraction=h.get("volume_fraction"), safety=h.get("safety", 0.9),
                                     max_substeps=h.get("max_substeps", 100000), preconditioner=PETSC_SOLVERS[solver])


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
    """

    def __init__(self, O, reader, model: DistributedElectroThermal, write_back: Optional[str] = None,
                 temperatures: bool = False, thermal_dt: Optional[float] = None, time_scale: float = 1.0):
        self.O, self.reader, self.model = O, reader, model
        self.write_back, self.temperatures = write_back, temperatures
        self.thermal_dt, self.time_scale = thermal_dt, float(time_scale)
        self.rank = model.comm.Get_rank()
        self.size = model.comm.Get_size()
        self._slab_axis, self._bounds, self._owner_by_id = None, None, np.zeros(0, np.int64)
        self._last_time = float(O.time)
        self.share = None

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
        if self._bounds is None:                           # equal slabs along the longest axis
            self._slab_axis = int(np.argmax(np.ptp(graph.pos, axis=0)))
            x = np.sort(graph.pos[:, self._slab_axis])
            self._bounds = x[(np.arange(1, self.size) * x.shape[0]) // self.size]
        known = self._owner_by_id                         # owner by body id, -1: not seen yet
        if known.shape[0] <= int(graph.ids.max()):
            known = self._owner_by_id = np.concatenate([known, np.full(int(graph.ids.max()) + 1 - known.shape[0], -1)])
        owner = known[graph.ids]
        new = owner < 0
        owner[new] = np.searchsorted(self._bounds, graph.pos[new, self._slab_axis], side="right")
        known[graph.ids[new]] = owner[new]
        return owner

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
        graph = None if master else self.reader.read()
        share = carve_share(graph, self._owner(graph) if graph is not None else None, self.rank)
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
