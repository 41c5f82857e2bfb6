"""Electro-thermal coupling: potential -> Joule sources -> heat step, one call per period.

:class:`ElectroThermalModel` joins an :class:`~yade_electro.physics.electrical.ElectricalModel` (or no
electrical model: heat conduction only) and a :class:`~yade_electro.network.transient.HeatSolver` and
keeps both across calls of ``step(graph, dt)``. One geometric factor g per edge serves the
electrical conductance (g / rho_e), the thermal conductance (lambda g), the Joule heat and the
history. What a call costs depends on what changed:

* nothing: the potential of the previous call is reused (constant rho_e), the heat step is
  one warm-started solve with the kept matrix;
* rho_e(T) (``beta != 0``): conductances updated in place, potential re-solved warm with the
  kept solver setup (re-solved only when some element's resistivity moved by more than
  ``resistivity_tol``, relative, default 0: whenever it changed);
* moved elements: new g, electrical and thermal values updated in place;
* broken bonds: the lost edges get g = 0 (same structure); the capacities follow the new
  bond counts (paper model) or stay (Voronoi cells);
* another element set: new structures; temperatures carried over by element id, new
  elements start at ``temperature``; time and energy ledger continue.

One owner each: the thermal clock and the energy ledger are the heat solver's (``time``,
``energy``), the electrode values the electrical model's (``set_electrode``).

Coupling in time: the sources of a step are computed with the resistivity at the start of
the step (lagged, first order); ``Integrator(coupling_iterations=k)``, k > 0, re-solves the
potential up to k times with the resistivity at the mid-step temperature ``(T^n + T^{n+1})/2``
(fixed-point iterations, second order in dt), stopping when the sources change by less than
``coupling_tol`` (relative).

Units: SI; temperatures in K (or degC if T_0 and every temperature are in degC).
"""
from __future__ import annotations

import dataclasses
import functools
import logging
from typing import Mapping, Optional, Sequence

import numpy as np

from ..laws.factor_network import FactorNetwork
from ..laws.law import Law
from .electrical import ElectricalModel
from ..core.errors import BoundaryConditionError, MaterialError
from ..core.graph import ContactGraph
from ..core.history import History
from ..core.materials import Material, in_series, real_number, thermal_conductance_of
from ..core.selection import Membership
from ..geometry.boundary import BoundaryOfGraph, SurfaceMembership
from ..network.boundary import FixedValue
from ..network.lumping import LumpedHeatSolver, Lumping
from ..network.transient import HeatSolver
from .thermal import (diffusion_time_step, heat_capacity, heat_material, source_power, split_heat_boundaries,
                      surface_conditions)
from .walls import WallContacts
from .integrator import Integrator

__all__ = ["ElectroThermalModel"]

log = logging.getLogger(__name__)


class ElectroThermalModel:
    """Joule heating and heat conduction of a packing, advanced one period at a time.

    Parameters
    ----------
    electrical : ElectricalModel or None
        Electrodes (voltage- or current-driven), conductance law, solver; it holds the
        resistivity rho_0, the value at the material's ``reference_temperature``. None: heat
        conduction only (then give ``law``).
    material : Material
        ``density`` [kg/m^3], ``specific_heat`` [J/(kg K)] and ``conductivity`` lambda
        [W/(m K)] (scalars or one per element), ``beta`` [1/K] (rho_e(T), 0: constant) and
        ``reference_temperature`` (T_0 of rho_e(T), needed with ``beta``, and of
        ``heat_content``; default ``temperature``). The resistivity is the electrical model's:
        leave it out here, or give the same value.
    temperature : float
        Initial temperature of every element [K].
    integrator : Integrator
        The theta method, sub-cycling, safety, the heat step's linear solver, ``eta`` (the share
        of the electrical power released as heat, paper 000 eq. 11) and the coupling to rho_e(T)
        (:class:`~yade_electro.physics.integrator.Integrator`; its ``dt``, ``time_scale`` and
        ``steady`` are the engines' per-call settings).
    boundaries : sequence of boundary conditions
        ``FixedTemperature``, ``HeatFlux``, ``Convection``, ``HeatSource`` and ``ThermalWall``
        (or the generic ``FixedValue``, ``Injection``, ``Robin``, ``Source`` of
        :mod:`yade_electro.network.boundary`), in one list. Their ``nodes`` are selectors as
        for electrodes (callable, mask, graph ids), resolved on the first graph and then kept
        by element id; or ``surface=`` a surface of the ``container`` (see
        :mod:`yade_electro.geometry.boundary`): a fixed temperature then acts through the
        touching elements' half cells, a flux on their boundary faces' areas, convection on
        those areas in series with the half cells. Heat sources act inside the solid [W or
        W/m^3], shared by element volume. Walls of a granular bed are isothermal or adiabatic;
        their contacts are given before each step by :meth:`set_wall_contacts` (the YADE
        engine does it from the scene); they need a contact law ('contact', 'liggghts').
    law : Law or str, optional
        The conductance law of a heat-only model (default ``'continuum'``); with an electrical
        model its law is used, and ``law`` may only add ``volume_fraction`` and ``container``.
        ``Law(volume_fraction=...)``: a scalar or ``f(graph) -> (n,)``; default paper 000's
        fv(n) capacities, except with the 'voronoi' law, whose bounded Voronoi cell volumes
        are used. ``Law(container=...)``: the solid, for surface conditions (default the
        electrical model's, or the law's).
    area : callable(graph) -> (n,) exposed areas [m^2], optional
        Default area of convection/flux conditions (else ``thermal.exposed_area``).
    cell_volume : scalar or callable(graph) -> (n,), optional
        The volume each element stands for [m^3] (see
        :func:`~yade_electro.physics.thermal.heat_capacity`).
    lumps : callable(graph) -> (n,) clump label per element (-1: none), optional
        One temperature per clump (:class:`~yade_electro.network.lumping.LumpedHeatSolver`).
    history : History or path, optional
        Every row returned by ``step`` is appended to it.
    """

    def __init__(self, electrical: Optional[ElectricalModel], material: Material, temperature: float, *,
                 integrator: Integrator = Integrator(), boundaries: Sequence = (), law=None, area=None,
                 cell_volume=None, lumps=None, history=None):
        if electrical is not None and not isinstance(electrical, ElectricalModel):
            raise TypeError("electrical must be an ElectricalModel (yade_electro.physics.electrical) or None")
        if not isinstance(material, Material):
            raise TypeError(f"material must be a Material(density=..., specific_heat=..., conductivity=...) "
                            f"(yade_electro.core.materials), got {material!r}")
        self.electrical = electrical
        self.initial_temperature = real_number("temperature (K)", temperature)
        self._heat_material = heat_material(material, electrical.material if electrical is not None else None,
                                            self.initial_temperature)
        self._material = None
        self.T0 = float(self.material.reference_temperature)
        self.beta = self.material.beta
        law = Law.of(law)
        if electrical is not None and (law.name != "auto" or law.params):
            raise ValueError(f"the conductance law is the electrical model's ({electrical.law.name!r}); give law= "
                             "to the ElectricalModel (Law(volume_fraction=..., container=...) may still come here)")
        volume_fraction, container = law.volume_fraction, law.container
        if not isinstance(integrator, Integrator):
            raise TypeError(f"integrator must be an Integrator(...) (yade_electro.physics.integrator), got "
                            f"{integrator!r}")
        self.integrator = integrator
        self.eta = float(integrator.eta)
        self.heat_options = dict(theta=integrator.theta, subcycle=integrator.subcycle, safety=integrator.safety,
                                 max_substeps=integrator.max_substeps, solver=integrator.solver)
        self.conditions, self.heat_sources, self.walls = split_heat_boundaries(boundaries)
        everything = self.conditions
        self.bc_memberships = {b.name: Membership(b.name, b.nodes, what=b.KIND)
                               for b in everything if b.surface is None}
        self.bc_memberships.update({src.name: Membership(src.name, src.nodes, what=src.KIND)
                                    for src in self.heat_sources if src.nodes is not None})
        self.bc_surfaces = {b.name: SurfaceMembership(b.name, b.surface, what=b.KIND)
                            for b in everything if b.surface is not None}
        self.network = electrical.network if electrical is not None else FactorNetwork(law.make())
        if self.walls:
            law_ = self.network.law
            try:
                law_.wall_factor(np.ones(1), np.zeros(1))
            except ValueError as exc:
                raise BoundaryConditionError(f"walls (ThermalWall) given with law {law_.name!r}: {exc}") from None
        self._wall_contacts = WallContacts([w.name for w in self.walls], what="wall")
        self._walls_applied = None
        if container is None and electrical is not None:
            container = electrical.container
        if container is None:
            container = getattr(self.network.law, "container", None)
        self.container = container
        self._boundary = None
        if any(not m.resolved for m in self.bc_surfaces.values()):
            self._boundary = BoundaryOfGraph(container, self.network.law)
        if cell_volume is None and volume_fraction is None and hasattr(self.network.law, "cell_volumes"):
            # the capacities that go with Voronoi conductances: the cells fill the solid
            cell_volume = self.network.law.cell_volumes
        self.area, self.volume_fraction, self.cell_volume, self.lumps = area, volume_fraction, cell_volume, lumps
        self.coupling_iterations = int(integrator.coupling_iterations)
        self.coupling_tol = float(integrator.coupling_tol)
        self.resistivity_tol = real_number("resistivity_tol", integrator.resistivity_tol)
        self.history = History(history) if isinstance(history, str) else history

        self.heat: Optional[HeatSolver] = None
        self.alone_remedy = "leave them out of the model"   # the floating messages' advice for lone elements
        self.n_potential_solves = 0
        self.n_rebuilds = 0
        self._rho_solved = None     # per-node resistivity of the last potential solve
        self._sol_id = None
        self.solution = None
        self.sources = None         # per-element Joule sources of the last potential [W]
        self._time0, self._energy0 = 0.0, None

    # -- one owner: time and energy are the heat solver's ------------------------------------
    @property
    def time(self) -> float:
        """Thermal clock [s]."""
        return self.heat.time if self.heat is not None else self._time0

    @property
    def joule_energy(self) -> float:
        """Joule heat released since the start [J] (on free and on fixed-temperature nodes)."""
        if self.heat is None:
            return 0.0 if self._energy0 is None else self._energy0.get("source", 0.0) + self._energy0.get("absorbed", 0.0)
        return self.heat.energy["source"] + self.heat.energy["absorbed"]

    @property
    def energy_ledger(self) -> dict:
        """The heat solver's energy ledger [J] plus each wall's heat (``link:<name>``): what
        :meth:`restore` takes back."""
        if self.heat is None:
            return dict(self._energy0 or {})
        out = dict(self.heat.energy)
        out.update({f"link:{k}": v for k, v in self.heat.link_energy.items()})
        return out

    def restore(self, time: float, energy: Optional[dict] = None):
        """Continue a saved run: thermal clock [s] and energy ledger [J] (before the first step)."""
        if self.heat is not None:
            self.heat.time = float(time)
            if energy:
                self.heat.energy.update({k: float(v) for k, v in energy.items() if k in self.heat.energy})
                for k in self.heat.link_energy:
                    self.heat.link_energy[k] = float(energy.get(f"link:{k}", self.heat.link_energy[k]))
        else:
            self._time0, self._energy0 = float(time), dict(energy or {})

    # -- structure ---------------------------------------------------------------------------
    def _capacities(self, graph):
        vf = self.volume_fraction(graph) if callable(self.volume_fraction) else self.volume_fraction
        cv = self.cell_volume(graph) if callable(self.cell_volume) else self.cell_volume
        return heat_capacity(graph, self.material.density, self.material.specific_heat, volume_fraction=vf,
                             cell_volume=cv)

    def _thermal_conductance(self, graph):
        lam = self.material.conductivity
        G = thermal_conductance_of(self.network.factor, lam, self.network.edges)
        series = getattr(self.network.law, "thermal_series", None)     # a contact resistance [K/W] (grains)
        return G if series is None else in_series(G, series(graph, self.network.edges))

    def prepare(self, graph: ContactGraph):
        """Bring both models to ``graph`` (see the module doc). Heat that the change of the
        element set or of the capacities brings in or takes out (a particle erased while hot,
        one added, a radius changed) goes into the ledger's ``exchange`` (``particle_heat``
        of the history), so that the energy balance still closes."""
        # the same graph object again (a step on an unchanged scene) changes no element
        fresh = graph is not self._prepared or self._materials_changed
        before = self.heat_content() if self.heat is not None and fresh else None
        self._prepare_models(graph)
        self._materials_changed = False
        self._prepared = graph
        if before is not None:
            change = self.heat_content() - before
            if change != 0.0:
                self.heat.record_exchange(change)

    def _prepare_models(self, graph: ContactGraph):
        if self.electrical is not None:
            kind = self.electrical.update(graph)
        else:
            kind = self.network.update(graph)
        if self.heat is None or graph.n_nodes != self.heat.n or kind == "structure" and not np.array_equal(
                graph.ids, self._ids):
            self._new_heat_solver(graph)
            self._apply_walls(graph)
            self._radius = graph.radius
            return
        walls_changed = self._apply_walls(graph, assemble=False)
        refill = self._materials_changed        # new material data: conductances and capacities again
        if walls_changed and not refill and kind not in ("structure", "topology", "geometry"):
            self.heat.update_values()
        if kind == "structure":
            self.heat.update_edges(self.network.edges, self._thermal_conductance(graph), self._capacities(graph))
            self.n_rebuilds += 1
        elif kind == "topology":
            self.heat.update_edges(self.network.edges, self._thermal_conductance(graph),
                                   None if self.cell_volume is not None and not refill else self._capacities(graph))
        elif kind == "geometry":
            resized = refill or self.cell_volume is None and not np.array_equal(graph.radius, self._radius)
            self.heat.update_values(self._thermal_conductance(graph), self._capacities(graph) if resized else None)
        elif refill:
            self.heat.update_values(self._thermal_conductance(graph), self._capacities(graph))
        self._radius = graph.radius

    # -- walls -------------------------------------------------------------------------------
    def set_wall_contacts(self, name: str, nodes, overlap):
        """The spheres touching wall ``name`` now (node indices of the next step's graph) and
        their overlaps [m] (> 0); applied at the next step."""
        if self._wall_contacts.set(name, nodes, overlap):
            self._walls_applied = None

    def wall_conductances(self, graph: ContactGraph, names=None) -> dict:
        """name -> (nodes, G [W/K]) of each wall's contacts on ``graph`` (adiabatic walls too:
        what they would conduct), or of the walls ``names`` only."""
        lam = np.asarray(self.material.conductivity, dtype=float)
        out = {}
        for w in self.walls:
            if names is not None and w.name not in names:
                continue
            nd, g = self._wall_contacts.factors(w.name, self.network.law, graph.radius, graph.n_nodes)
            lam_p = lam if lam.ndim == 0 else lam[nd]
            lam_w = lam_p if w.conductivity is None else w.conductivity
            lam_e = 2.0 * lam_p * lam_w / (lam_p + lam_w)
            out[w.name] = (nd, lam_e * g)
        return out

    def _apply_walls(self, graph, assemble=True) -> bool:
        """Give the heat solver the walls' contacts; True if they were new."""
        if not self.walls or self._walls_applied is graph:
            return False
        # isothermal walls only (a linked fixed temperature); an adiabatic wall conducts nothing
        isothermal = [w.name for w in self.walls if w.name in self.heat.nodes_of]
        for name, (nd, G) in self.wall_conductances(graph, isothermal).items():
            self.heat.set_links(name, nd, G, assemble=assemble)
        self._walls_applied = graph
        return True

    def _new_heat_solver(self, graph):
        T = np.full(graph.n_nodes, self.initial_temperature)
        time, energy = self._time0, self._energy0
        if self.heat is not None:               # carry the temperatures over by id
            old_ids, old_T = self._ids, self.heat.temperature
            order = np.argsort(old_ids)
            pos = np.clip(np.searchsorted(old_ids[order], graph.ids), 0, old_ids.size - 1)
            found = old_ids[order][pos] == graph.ids
            T[found] = old_T[order][pos[found]]
            time, energy = self.heat.time, self.energy_ledger
        elif self._T_restore is not None:
            T = self._T_restore(graph)
        nodes_of = {name: m.nodes(graph) for name, m in self.bc_memberships.items()}
        surface_nodes, area_of, link_of = surface_conditions(
            self.conditions,
            {name: m.contact(graph, self._boundary) for name, m in self.bc_surfaces.items()},
            self.material.conductivity)
        nodes_of.update(surface_nodes)
        conditions = list(self.conditions)
        for w in self.walls:
            if w.isothermal:
                conditions.append(FixedValue(w.name, nodes=np.zeros(0, dtype=np.int64), value=w.temperature))
                nodes_of[w.name], link_of[w.name] = np.zeros(0, dtype=np.int64), np.zeros(0)
        capacity = self._capacities(graph)
        area = self.area(graph) if callable(self.area) else self.area
        self._walls_applied = None
        labels = self.lumps(graph) if self.lumps is not None else None
        solver = HeatSolver if labels is None or not np.any(np.asarray(labels) >= 0) else \
            functools.partial(LumpedHeatSolver, Lumping.of(labels))
        self.heat = solver(capacity, self.network.edges, self._thermal_conductance(graph), T, conditions=conditions,
                           time=time, energy=energy, graph=graph, area=area, nodes_of=nodes_of, area_of=area_of,
                           link_of=link_of, power=self._source_power(graph), coords=graph.pos, **self.heat_options)
        self._ids = graph.ids.copy()
        self.heat.alone_remedy = self.alone_remedy          # (on a lumped solver's wrapper: unused there)
        self._rho_solved = None
        self.n_rebuilds += 1
        log.debug("electro-thermal model rebuilt on a graph of %d nodes, %d edges (dt_crit %.3g s)",
                  graph.n_nodes, self.network.edges.shape[0], self.heat.critical_time_step)

    _T_restore = _prepared = None
    _materials_changed = False

    def _volumes(self, graph):
        """The volume each element stands for [m^3] (what its heat capacity is made of)."""
        return self._capacities(graph) / (np.asarray(self.material.density, float)
                                          * np.asarray(self.material.specific_heat, float))

    def _source_power(self, graph):
        if not self.heat_sources:
            return None
        nodes = {src.name: self.bc_memberships[src.name].nodes(graph) if src.nodes is not None
                 else np.arange(graph.n_nodes) for src in self.heat_sources}
        return source_power(self.heat_sources, nodes, self._volumes(graph))

    def set_material(self, **properties):
        """New material data from the next step on: ``density`` [kg/m^3], ``specific_heat``
        [J/(kg K)], ``conductivity`` [W/(m K)], ``resistivity`` (rho_0) [ohm m], each a scalar
        or one value per element of the next graph (e.g. elements of several materials, given
        again when the element set changes). Capacities and conductances follow at the next
        :meth:`prepare`; the heat a capacity change brings goes into ``particle_heat``."""
        unknown = set(properties) - {"density", "specific_heat", "conductivity", "resistivity"}
        if unknown:
            raise ValueError(f"set_material: unknown properties {sorted(unknown)}")
        if "resistivity" in properties and self.electrical is None:
            raise MaterialError("a heat-only model has no resistivity")
        rho0 = properties.pop("resistivity", None)
        if properties:
            self._heat_material = dataclasses.replace(self._heat_material, **properties)
        if rho0 is not None:
            self.electrical.set_material(resistivity=rho0)
            self._rho_solved = None
        self._material = None
        self._materials_changed = True

    @property
    def material(self) -> Material:
        """The material: density, specific heat, conductivity, beta and T_0 held here, rho_0
        the electrical model's (the one place it is kept)."""
        if self.electrical is None:
            return self._heat_material
        m = self._material
        if m is None or m[0] is not self.electrical.material:
            m = self._material = (self.electrical.material, dataclasses.replace(
                self._heat_material, resistivity=self.electrical.material.resistivity))
        return m[1]

    def set_temperatures(self, nodes, temperatures):
        """Set the temperatures [K] of ``nodes`` of the current graph now (e.g. particles just
        poured in hot); fixed-temperature nodes keep their imposed value. The heat this adds
        or takes goes into the ledger's ``exchange`` (``particle_heat``)."""
        if self.heat is None:
            raise RuntimeError("no graph yet: call prepare(graph) or step first")
        nodes = np.asarray(nodes, dtype=np.int64).reshape(-1)
        values = np.asarray(temperatures, dtype=float).reshape(-1)
        if values.shape != nodes.shape or (nodes.size and (nodes.min() < 0 or nodes.max() >= self.heat.n)):
            raise ValueError(f"set_temperatures: give one temperature per node of the {self.heat.n}-node graph")
        before = self.heat_content()
        T = np.array(self.heat.temperature)
        T[nodes] = values
        self.heat.set_temperature(T)
        self.heat.record_exchange(self.heat_content() - before)

    def restore_temperatures(self, fn):
        """Temperatures of the first graph from ``fn(graph) -> (n,)`` (a resumed run)."""
        self._T_restore = fn

    # -- potential ---------------------------------------------------------------------------
    def _set_resistivity(self, T, force=False) -> bool:
        """Give the electrical model rho_e(T); True if it changed."""
        if self.beta == 0.0 or self.electrical is None:
            return False
        rho = self.material.resistivity_at(T)
        if not force and self._rho_solved is not None:
            change = np.max(np.abs(rho / self._rho_solved - 1.0))
            if change <= self.resistivity_tol and (self.resistivity_tol > 0 or change == 0):
                return False
        self.electrical.set_resistivity(rho)
        self._rho_solved = rho
        return True

    def _solve_potential(self):
        n = self.heat.n
        if self.electrical is None:
            self.sources = np.zeros(n)
            return self.sources
        el = self.electrical
        sol = el.solve()
        if sol is not self._sol_id:
            self.solution = self._sol_id = sol
            self.n_potential_solves += 1
            sharing = self.integrator.joule_sharing_for(self.network.law.name)
            vol = self._volumes(self._prepared) if sharing == "cells" else None
            self.sources = el.element_joule_power(self.eta, sharing, vol)
        return self.sources

    # -- stepping ----------------------------------------------------------------------------
    def step(self, graph: ContactGraph, dt: float, values: Optional[Mapping[str, float]] = None) -> dict:
        """Advance by ``dt`` [s] on ``graph``; ``values`` changes electrode potentials [V] /
        currents [A] (kept for later steps). Returns the history row (and appends it to
        ``history``). A ThermalError leaves temperatures, time and energies as they were."""
        if values:
            if self.electrical is None:
                raise ValueError("a heat-only model has no electrode values")
            for k, v in values.items():
                self.electrical.set_electrode(k, v)
        self.prepare(graph)
        heat = self.heat
        self._set_resistivity(heat.temperature)
        src = self._solve_potential()
        if self.beta != 0.0 and self.coupling_iterations > 0:
            T_old = heat.temperature
            for _ in range(self.coupling_iterations):
                T_new, _ = heat.trial(dt, src)
                self._set_resistivity(0.5 * (T_old + T_new))
                new = self._solve_potential()
                change = np.max(np.abs(new - src)) / max(np.max(np.abs(new)), 1e-300)
                src = new
                if change <= self.coupling_tol:
                    break
        step = heat.advance(dt, src)
        row = self.summary(step, float(np.sum(src)))
        if self.history is not None:
            self.history.append(row)
        return row

    def refresh(self, graph: ContactGraph) -> dict:
        """Bring the models to ``graph`` and solve the potential without a heat step (an
        engine's first call); returns the history row of that state."""
        self.prepare(graph)
        self._set_resistivity(self.heat.temperature)
        self._solve_potential()
        return self.summary()

    def steady_state(self, graph: ContactGraph, max_iterations: int = 50) -> dict:
        """The steady temperatures on ``graph`` (they replace the current ones; the clock does
        not move): potential, Joule sources, then the steady heat balance with every boundary
        condition and heat source. With rho_e(T) (``beta != 0``) the potential and the
        temperatures are iterated (fixed point) until the sources change by less than
        ``coupling_tol`` (relative), at most ``max_iterations`` times (a warning if not: a
        thermal runaway has no steady state). Returns the history row, with
        ``steady_iterations`` and ``steady_balance_error`` (``|sum of powers|`` / max power)."""
        self.prepare(graph)
        heat = self.heat
        self._set_resistivity(heat.temperature)
        src = self._solve_potential()
        done = 0
        for done in range(1, int(max_iterations) + 1):
            st = heat.steady(src)
            if self.beta == 0.0 or self.electrical is None:
                break
            self._set_resistivity(heat.temperature)
            new = self._solve_potential()
            change = np.max(np.abs(new - src)) / max(np.max(np.abs(new)), 1e-300)
            src = new
            if change <= self.coupling_tol:
                st = heat.steady(src)
                break
        else:
            import warnings
            warnings.warn(f"the steady state with rho_e(T) did not converge in {max_iterations} iterations (the "
                          "sources still change by more than coupling_tol): the temperatures are the last iterate; "
                          "a thermal runaway has no steady state", stacklevel=2)
        row = self.summary(None, float(np.sum(src)))
        row.update({"steady_iterations": done, "steady_balance_error": st.balance_error})
        if self.history is not None:
            self.history.append(row)
        return row

    # -- figures ----------------------------------------------------------------------------
    @property
    def temperature(self) -> np.ndarray:
        """Temperatures of the nodes of the current graph [K] (read-only)."""
        if self.heat is None:
            raise RuntimeError("no step yet")
        return self.heat.temperature

    @property
    def graph(self) -> ContactGraph:
        """The graph of the last step (elements and bonds read from the scene)."""
        return self.network.graph

    @property
    def capacity(self) -> np.ndarray:
        """Heat capacities C_i of the current graph's elements [J/K]."""
        if self.heat is None:
            raise RuntimeError("no step yet")
        return self.heat.capacity

    def time_steps(self) -> dict:
        """Thermal step figures of the current graph [s]: ``critical`` = min C_i / sum_j G_ij
        (the bound the explicit integrator uses), ``allowed`` = the (sub-)step it takes, and
        ``paper`` = l_min^2 / (2 alpha) (paper 000 eq. 14, for comparison)."""
        if self.heat is None:
            raise RuntimeError("no step yet")
        m = self.material
        return {"critical": self.heat.critical_time_step, "allowed": self.heat.allowed_time_step(),
                "paper": diffusion_time_step(self.network.graph, m.conductivity, m.density, m.specific_heat)}

    def heat_content(self) -> float:
        """``sum_i C_i (T_i - T_0)`` [J]."""
        return self.heat.heat_content(self.T0)

    def summary(self, step=None, power=None) -> dict:
        """History row: time, dt, current, voltage, R_eq, joule_power [W] (of the last step),
        joule_energy [J] (cumulative), heat_content [J], and, cumulative [J]: absorbed_heat
        (Joule heat generated on fixed-temperature elements, taken by their thermostat),
        boundary_heat, convection_heat, flux_heat (heat *received* by the solid from the
        fixed-temperature elements, the ambient and imposed fluxes: negative when it leaves),
        particle_heat (brought by elements added, taken by elements erased or resized, or
        set by :meth:`set_temperatures`);
        then T_mean (capacity-weighted), T_max, T_min, n_substeps, n_potential_solves, and
        ``heat_flow:<name>`` [W] through each boundary at the row's temperatures.
        Balance: heat_content change = joule_energy - absorbed_heat + boundary_heat +
        convection_heat + flux_heat + particle_heat."""
        heat = self.heat
        row = {"time": self.time, "dt": step.dt if step is not None else 0.0}
        if self.electrical is not None:
            sol, el = self.solution, self.electrical
            names = list(sol.electrode_current)
            a, b = el.measure if el.measure else (names[0], None)
            row.update({
                "current": sol.electrode_current[a],
                "voltage": sol.electrode_potential[a] - (sol.electrode_potential[b] if b else 0.0),
                "R_eq": sol.equivalent_resistance(a, b) if b else float("nan"),
                "joule_power": float(np.sum(self.sources)) if power is None else power,
                "joule_energy": self.joule_energy,
            })
        T, C = heat.temperature, heat.capacity
        row.update({
            "heat_content": float(np.sum(C * (T - self.T0))),
            "absorbed_heat": heat.energy["absorbed"],
            "boundary_heat": heat.energy["boundary"],
            "convection_heat": heat.energy["convection"],
            "flux_heat": heat.energy["flux"],
            "particle_heat": heat.energy["exchange"],
            "T_mean": float(np.sum(C * T) / np.sum(C)),
            "T_max": float(np.max(T)),
            "T_min": float(np.min(T)),
            "n_substeps": step.n_substeps if step is not None else 0,
            "n_potential_solves": self.n_potential_solves,
        })
        flows = heat.boundary_flows()                   # (a wall's is its link's)
        row.update({f"heat_flow:{k}": v for k, v in flows.items()})
        if self.walls:
            for w in self.walls:
                if not w.isothermal:
                    continue                # adiabatic: nothing to report
                nd, _ = self._wall_contacts.contacts(w.name)
                row[f"wall_contacts:{w.name}"] = int(nd.size)
                row[f"wall_power:{w.name}"] = flows.get(w.name, 0.0)
                row[f"wall_heat:{w.name}"] = heat.link_energy.get(w.name, 0.0)
        return row
