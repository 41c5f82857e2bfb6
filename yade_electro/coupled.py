"""Electro-thermal coupling: potential solve -> Joule sources -> heat step, one call per period.

:class:`ElectroThermalModel` wraps an :class:`~yade_electro.engine.ElectricalModel` and a
:class:`~yade_electro.thermal.HeatSolver` and keeps their state between calls of
``step(graph, dt)``:

* the potential is solved again only when something it depends on changed: the graph
  (object or revision), the resistivity (with ``beta != 0`` it follows the temperatures,
  ``rho_e(T) = rho_0 (1 + beta (T - T_0))`` per node), or the electrode values. With a
  constant resistivity, one potential solve serves any number of thermal steps;
* the heat solver (capacities, conductances, factorisation) is rebuilt only when the graph
  changes; temperatures are carried over by node id (new elements start at ``T_0``).
  Capacities depend on the bonds through the volume fractions, so ``heat_content`` can jump
  when bonds break.

Coupling in time: by default the sources of a step are computed with the resistivity at the
start of the step (lagged, first order). ``coupling_iterations = k > 0`` re-solves the
potential up to k times with the resistivity at the mid-step temperature ``(T^n +
T^{n+1})/2`` (fixed-point iterations, second order in dt), stopping when the sources change
by less than ``coupling_tol`` (relative).

Units: SI; temperatures in K (or degC if T_0 and every temperature are in degC).
"""
from __future__ import annotations

import logging
from typing import Mapping, Optional, Sequence

import numpy as np

from .engine import ElectricalModel, History
from .errors import MaterialError
from .graph import ContactGraph
from .thermal import (Convection, FixedTemperature, HeatFlux, HeatSolver, diffusion_time_step, heat_capacity,
                      joule_sources, thermal_conductance)

__all__ = ["ElectroThermalModel"]

log = logging.getLogger(__name__)


class ElectroThermalModel:
    """Joule heating and heat conduction of a packing, advanced one period at a time.

    Parameters
    ----------
    electrical : ElectricalModel
        Electrodes (voltage- or current-driven), conductance law, solver; its resistivity is
        rho_0, the value at ``reference_temperature``.
    density : float or (n,) [kg/m^3]
    specific_heat : float or (n,) [J/(kg K)]
    conductivity : float or (n,) thermal conductivity lambda [W/(m K)]
    temperature : float
        Initial temperature of every element [K].
    reference_temperature : float, optional
        T_0 of rho_e(T) and of ``heat_content``; default ``temperature``.
    beta : float
        Temperature coefficient of the resistivity [1/K] (0: constant resistivity).
    eta : float in [0, 1]
        Share of the electrical power released as heat (paper 000 eq. 11).
    theta : float or name
        Heat integrator: 'explicit' (sub-cycled to the stable step), 'crank-nicolson',
        'backward-euler' (default) or a number in [0, 1].
    subcycle, safety, max_substeps, thermal_solver :
        Passed to :class:`HeatSolver` (``thermal_solver`` is its ``solver``).
    fixed, flux, convection : sequences of FixedTemperature, HeatFlux, Convection
        Their ``nodes`` are selectors as for electrodes (callable, mask, graph ids).
    area : callable(graph) -> (n,) exposed areas [m^2], optional
        Default area of convection/flux conditions (else ``thermal.exposed_area``).
    volume_fraction, cell_volume : optional, see :func:`~yade_electro.thermal.heat_capacity`
        Scalars or callables ``f(graph) -> (n,)`` (per-node arrays only fit a fixed graph).
        Default: paper 000's fv(n) capacities, except with the 'voronoi' law, where the
        bounded Voronoi cell volumes are used (``voronoi.cell_volume_of(container)``).
    coupling_iterations, coupling_tol : see the module notes.
    resistivity_tol : float
        With beta != 0, re-solve the potential only when some node's resistivity moved by
        more than this (relative) since the last solve (default 0: whenever it changed).
    history : History or path, optional
        Every row returned by ``step`` is appended to it.
    """

    def __init__(self, electrical: ElectricalModel, density, specific_heat, conductivity, temperature: float,
                 *, reference_temperature: Optional[float] = None, beta: float = 0.0, eta: float = 1.0,
                 theta="backward-euler", subcycle: bool = True, safety: float = 0.9, max_substeps: int = 100000,
                 thermal_solver="direct", fixed: Sequence[FixedTemperature] = (), flux: Sequence[HeatFlux] = (),
                 convection: Sequence[Convection] = (), area=None, volume_fraction=None, cell_volume=None,
                 coupling_iterations: int = 0, coupling_tol: float = 1e-10, resistivity_tol: float = 0.0,
                 history=None):
        if not isinstance(electrical, ElectricalModel):
            raise TypeError("electrical must be an ElectricalModel (yade_electro.engine)")
        self.electrical = electrical
        self.rho0 = electrical.resistivity
        self.density, self.specific_heat, self.conductivity = density, specific_heat, conductivity
        if not np.isfinite(temperature):
            raise ValueError(f"temperature must be finite, got {temperature}")
        self.initial_temperature = float(temperature)
        self.T0 = float(temperature if reference_temperature is None else reference_temperature)
        if not np.isfinite(beta):
            raise MaterialError(f"beta must be finite (1/K), got {beta}")
        self.beta = float(beta)
        if not (0.0 <= eta <= 1.0):
            raise ValueError(f"eta must be in [0, 1], got {eta}")
        self.eta = float(eta)
        self.heat_options = dict(theta=theta, subcycle=subcycle, safety=safety, max_substeps=max_substeps,
                                 solver=thermal_solver)
        self.fixed, self.flux, self.convection = list(fixed), list(flux), list(convection)
        if (cell_volume is None and volume_fraction is None and electrical.law == "voronoi"
                and electrical.law_params.get("container") is not None):
            # the capacities that go with Voronoi conductances: the cells fill the solid,
            # from the tessellation the electrical law already made for this element set
            cell_volume = self._voronoi_cells
        self.area, self.volume_fraction, self.cell_volume = area, volume_fraction, cell_volume
        if int(coupling_iterations) < 0:
            raise ValueError("coupling_iterations must be >= 0")
        self.coupling_iterations, self.coupling_tol = int(coupling_iterations), float(coupling_tol)
        self.resistivity_tol = float(resistivity_tol)
        self.history = History(history) if isinstance(history, str) else history

        self.heat: Optional[HeatSolver] = None
        self.graph: Optional[ContactGraph] = None
        self._graph_key = None
        self.time = 0.0
        self.joule_energy = 0.0
        self.n_potential_solves = 0
        self.n_rebuilds = 0
        self._sol_key = None
        self._rho_solved = None     # per-node resistivity of the last potential solve
        self._rho_version = 0
        self._values: dict = {}
        self.solution = None
        self.sources = None

    def _voronoi_cells(self, graph: ContactGraph) -> np.ndarray:
        """Bounded Voronoi cell volumes of ``graph``'s elements, from the electrical law's
        cached tessellation (prepared for this graph just before)."""
        faces = self.electrical._law_cache.get("faces")
        if faces is None or faces.n != graph.n_nodes:
            from .voronoi import voronoi_cell_volumes
            return voronoi_cell_volumes(graph.pos, graph.radius, self.electrical.law_params["container"])
        return faces.cell_volumes()

    # -- structure ---------------------------------------------------------------------------
    @staticmethod
    def _key(graph):
        return (id(graph), graph.revision, graph.n_nodes, graph.n_edges)

    def _prepare(self, graph: ContactGraph):
        key = self._key(graph)
        if key == self._graph_key and self.heat is not None:
            return
        T = np.full(graph.n_nodes, self.initial_temperature)
        if self.heat is not None:               # carry the temperatures over by id
            old_ids, old_T = self.graph.ids, self.heat.temperature
            order = np.argsort(old_ids)
            pos = np.clip(np.searchsorted(old_ids[order], graph.ids), 0, old_ids.size - 1)
            found = old_ids[order][pos] == graph.ids
            T[found] = old_T[order][pos[found]]
        self._set_resistivity(T, force=True)
        el = self.electrical
        el.prepare(graph)
        net = el.graph
        params = dict(el.law_params)
        cache = getattr(el, "_law_cache", None)
        if el.law == "voronoi" and cache is not None:
            params["cache"] = cache
        G = thermal_conductance(net, self.conductivity, el.law, **params)
        vf = self.volume_fraction(graph) if callable(self.volume_fraction) else self.volume_fraction
        cv = self.cell_volume(graph) if callable(self.cell_volume) else self.cell_volume
        C = heat_capacity(graph, self.density, self.specific_heat, volume_fraction=vf, cell_volume=cv)
        area = self.area(graph) if callable(self.area) else self.area
        self.heat = HeatSolver(C, net.edges, G, T, fixed=self.fixed, flux=self.flux, convection=self.convection,
                               time=self.time, graph=graph, area=area, **self.heat_options)
        self.graph, self._graph_key = graph, key
        self._sol_key = None
        self.n_rebuilds += 1
        log.debug("electro-thermal model rebuilt on a graph of %d nodes, %d edges (dt_crit %.3g s)",
                  graph.n_nodes, net.n_edges, self.heat.critical_time_step)

    def _rho_of(self, T):
        return np.asarray(self.rho0, dtype=float) * (1.0 + self.beta * (np.asarray(T) - self.T0))

    def _set_resistivity(self, T, force=False):
        """Give the electrical model rho_e(T); True if it changed (a new solve is needed)."""
        if self.beta == 0.0:
            return False
        rho = self._rho_of(T)
        if not np.all(rho > 0):
            bad = np.flatnonzero(~(rho > 0))
            raise MaterialError(f"rho_e(T) = rho_0 (1 + beta (T - T_0)) is <= 0 at {bad.size} node(s) "
                                f"(e.g. node {bad[0]}, T = {np.atleast_1d(T)[bad[0]]:.6g}); beta={self.beta:g} "
                                "does not fit this temperature range")
        if not force and self._rho_solved is not None:
            change = np.max(np.abs(rho / self._rho_solved - 1.0))
            if change <= self.resistivity_tol and (self.resistivity_tol > 0 or change == 0):
                return False
        self.electrical.set_resistivity(rho)
        self._rho_solved = rho
        self._rho_version += 1
        return True

    def _solve_potential(self, graph):
        key = (self._graph_key, self._rho_version, tuple(sorted(self._values.items())))
        if key != self._sol_key or self.solution is None:
            self.solution = self.electrical.solve(graph, self._values or None)
            self._sol_key = key
            self.n_potential_solves += 1
            el = self.electrical
            self.sources = joule_sources(el.graph.edges, self.solution.branch_current, el.conductance,
                                         el.graph.n_nodes, self.eta)
        return self.sources

    # -- stepping ----------------------------------------------------------------------------
    def step(self, graph: ContactGraph, dt: float, values: Optional[Mapping[str, float]] = None) -> dict:
        """Advance by ``dt`` [s] on ``graph``; ``values`` changes electrode potentials [V] /
        currents [A] (kept for later steps). Returns the history row (and appends it to
        ``history``). A ThermalError leaves temperatures, time and energies as they were."""
        if values:
            self._values.update({k: float(v) for k, v in values.items()})
        self._prepare(graph)
        heat = self.heat
        self._set_resistivity(heat.temperature)
        src = self._solve_potential(graph)
        if self.beta != 0.0 and self.coupling_iterations > 0:
            T_old = heat.temperature
            for _ in range(self.coupling_iterations):
                T_new, _ = heat.trial(dt, src)
                self._set_resistivity(0.5 * (T_old + T_new))
                new = self._solve_potential(graph)
                change = np.max(np.abs(new - src)) / max(np.max(np.abs(new)), 1e-300)
                src = new
                if change <= self.coupling_tol:
                    break
        step = heat.advance(dt, src)
        self.time = heat.time
        power = float(np.sum(src))
        self.joule_energy += power * dt
        row = self.summary(step, power)
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

    def time_steps(self) -> dict:
        """Thermal step figures of the current graph [s]: ``critical`` = min C_i / sum_j G_ij
        (the bound the explicit integrator uses), ``allowed`` = the (sub-)step it takes, and
        ``paper`` = l_min^2 / (2 alpha) (paper 000 eq. 14, for comparison)."""
        if self.heat is None:
            raise RuntimeError("no step yet")
        return {"critical": self.heat.critical_time_step, "allowed": self.heat.allowed_time_step(),
                "paper": diffusion_time_step(self.graph, self.conductivity, self.density, self.specific_heat)}

    def heat_content(self) -> float:
        """``sum_i C_i (T_i - T_0)`` [J]."""
        return self.heat.heat_content(self.T0)

    def summary(self, step=None, power=None) -> dict:
        """History row: time, dt, current, voltage, R_eq, joule_power [W] (of the last step),
        joule_energy [J] (cumulative), heat_content [J], and, cumulative [J]: absorbed_heat
        (Joule heat generated on fixed-temperature elements, taken by their thermostat),
        boundary_heat, convection_heat, flux_heat (heat *received* by the solid from the
        fixed-temperature elements, the ambient and imposed fluxes: negative when it leaves);
        then T_mean (capacity-weighted), T_max, T_min, n_substeps, n_potential_solves.
        Balance: heat_content change = joule_energy - absorbed_heat + boundary_heat +
        convection_heat + flux_heat."""
        sol, el, heat = self.solution, self.electrical, self.heat
        names = list(sol.electrode_current)
        a, b = el.measure if el.measure else (names[0], None)
        T, C = heat.temperature, heat.capacity
        return {
            "time": self.time,
            "dt": step.dt if step is not None else 0.0,
            "current": sol.electrode_current[a],
            "voltage": sol.electrode_potential[a] - (sol.electrode_potential[b] if b else 0.0),
            "R_eq": sol.equivalent_resistance(a, b) if b else float("nan"),
            "joule_power": float(np.sum(self.sources)) if power is None else power,
            "joule_energy": self.joule_energy,
            "heat_content": float(np.sum(C * (T - self.T0))),
            "absorbed_heat": heat.energy["absorbed"],
            "boundary_heat": heat.energy["boundary"],
            "convection_heat": heat.energy["convection"],
            "flux_heat": heat.energy["flux"],
            "T_mean": float(np.sum(C * T) / np.sum(C)),
            "T_max": float(np.max(T)),
            "T_min": float(np.min(T)),
            "n_substeps": step.n_substeps if step is not None else 0,
            "n_potential_solves": self.n_potential_solves,
        }
