"""The electrical engine for ``O.engines``: a ``PyRunner`` that reads the graph (only what
changed), solves the potentials, writes them back to the bodies and appends a history row.

Example (in a YADE script)::

    from yade import pack
    from yade_electro.yade import ElectricalEngine
    electro = ElectricalEngine(
        resistivity=0.73e-6,
        electrodes={"top": dict(select=pack.inAlignedBox((-1, -1, 4.9e-3), (1, 1, 1)), potential=1.0),
                    "bottom": dict(select=pack.inAlignedBox((-1, -1, -1), (1, 1, 0.1e-3)), potential=0.0)},
        iterPeriod=100, history="electro.csv")
    O.engines = O.engines + [electro.runner]
    O.run(1000, True)
    print(electro.equivalent_resistance, electro.potential_by_id[0])
    df = electro.history.to_dataframe()

Electrode selectors: YADE predicates (selection by element centre), lists of body ids,
boolean masks, or callables ``f(pos, radius) -> mask``; ``dict(mask=m)`` selects the
bodies with ``b.mask & m``.
"""
from __future__ import annotations

import dataclasses
import logging
from typing import Dict, Optional

import numpy as np

from ..engine import ElectricalModel, ElectrodeSpec, History
from .runtime import import_yade
from .scene import SceneReader, predicate_selector, write_body_attribute

__all__ = ["ElectricalEngine", "ElectroThermalEngine", "ensure_thermal_state", "ENGINES", "get_engine"]

log = logging.getLogger(__name__)

#: Engines by label, so that the PyRunner command (a string YADE evaluates) can reach them.
ENGINES: Dict[str, "ElectricalEngine"] = {}


def get_engine(label: str) -> "ElectricalEngine":
    """The ElectricalEngine registered under ``label``."""
    try:
        return ENGINES[label]
    except KeyError:
        raise KeyError(f"no yade-electro engine labelled {label!r}; have {sorted(ENGINES)}") from None


def _is_predicate(obj) -> bool:
    return callable(obj) and hasattr(obj, "aabb") and hasattr(obj, "dim")


def _normalise_selector(sel, reader: SceneReader):
    if _is_predicate(sel):
        return predicate_selector(sel)
    if isinstance(sel, dict) and set(sel) == {"mask"}:
        m = int(sel["mask"])

        def by_mask(pos, radius):
            return np.array([bool(b.mask & m) for b in reader.bodies])
        return by_mask
    return sel


class ElectricalEngine:
    """Electrical conduction solved every ``iterPeriod`` steps of a YADE simulation.

    Parameters
    ----------
    resistivity : float
        rho_e [ohm m].
    electrodes : dict name -> dict(select=..., potential=V | current=A)
    law, law_params, solver, measure : see ``yade_electro.engine.ElectricalModel``
    iterPeriod : int
        Steps between two solves (the PyRunner's period).
    history : str, optional
        CSV path written row by row (iter, time, R_eq, V_/I_ per electrode, power, ...).
    bonds, mask, geometry_every, move_tolerance, full_read_every, bond_check : see ``SceneReader``
    write_back : str or None
        Body attribute that receives each element's potential [V] (default 'potential');
        None to skip.
    plot : bool
        Also feed ``yade.plot.addData`` with the history row.
    label : str
        Label of the PyRunner and key in ``ENGINES``.
    """

    def __init__(self, resistivity, electrodes, law="continuum", law_params=None, solver="cg",
                 measure=None, iterPeriod: int = 1, history: Optional[str] = None, bonds="cohesive",
                 mask=None, geometry_every: int = 1, move_tolerance: float = 1e-4, full_read_every: int = 0,
                 bond_check: str = "flags", write_back: Optional[str] = "potential", plot: bool = False, label: str = "electro",
                 O=None):
        yade = import_yade()
        self.O = O if O is not None else yade.Omega()
        self.reader = SceneReader(self.O, bonds=bonds, mask=mask, geometry_every=geometry_every,
                                  move_tolerance=move_tolerance, full_read_every=full_read_every,
                                  bond_check=bond_check)
        law_params = dict(law_params or {})
        if _is_predicate(law_params.get("container")):
            # the voronoi law needs a signed distance: convert YADE's predicate
            from .packing import as_shape
            law_params["container"] = as_shape(law_params["container"])
        specs = []
        for name, spec in dict(electrodes).items():
            spec = dict(spec)
            spec["select"] = _normalise_selector(spec.get("select"), self.reader)
            specs.append(ElectrodeSpec(name, **spec))
        self.model = ElectricalModel(resistivity, specs, law=law, law_params=law_params, solver=solver,
                                     measure=measure)
        self.history = History(history)
        self.write_back = write_back
        self.plot = plot
        self.label = label
        self.values: Dict[str, float] = {}
        ENGINES[label] = self
        # fail in the user's script, with the real exception type, rather than later inside
        # O.run() where YADE reports every PyRunner failure as "RuntimeError: PyRunner error."
        if any(b is not None and isinstance(b.shape, yade.Sphere) for b in self.O.bodies):
            self.model.prepare(self.reader.read())
        self.runner = yade.PyRunner(
            command=f"__import__('yade_electro.yade.engines', fromlist=['get_engine']).get_engine({label!r}).step()",
            iterPeriod=int(iterPeriod), label=label)

    # -- stepping ------------------------------------------------------------------------
    def set_electrode(self, name: str, value: float):
        """Change an electrode's potential [V] or current [A] from the next solve on."""
        if name not in [s.name for s in self.model.specs]:
            raise KeyError(f"no electrode {name!r}")
        self.values[name] = float(value)

    def step(self):
        """One solve on the current scene (what the PyRunner calls)."""
        graph = self.reader.read()
        sol = self.model.solve(graph, self.values or None)
        if self.write_back:
            write_body_attribute(self.reader.bodies, self.write_back, sol.potential)
        row = {"iter": int(self.O.iter), "time": float(self.O.time)}
        row.update(self.model.summary())
        row["graph_revision"] = int(graph.revision)
        self.history.append(row)
        if self.plot:
            from yade import plot
            plot.addData(**{f"electro_{k}" if k not in ("iter", "time") else k: v for k, v in row.items()})
        return sol

    # -- results -------------------------------------------------------------------------
    @property
    def graph(self):
        """The network the current flows in (the bond graph, or wider for the 'voronoi' law)."""
        return self.model.graph

    @property
    def bond_graph(self):
        """The bonded contact graph read from the scene."""
        return self.model.bond_graph

    @property
    def solution(self):
        return self.model.solution

    @property
    def equivalent_resistance(self) -> float:
        """R_eq [ohm] between the ``measure`` electrodes at the last solve."""
        return self.model.equivalent_resistance

    @property
    def body_ids(self) -> np.ndarray:
        return self.graph.ids

    @property
    def potential(self) -> np.ndarray:
        """Potential [V] of each element, in ``body_ids`` order."""
        return self.solution.potential

    @property
    def potential_by_id(self) -> Dict[int, float]:
        return dict(zip(self.graph.ids.tolist(), self.solution.potential.tolist()))

    @property
    def branch_currents(self):
        """(id pairs (m, 2), current (m,) [A] flowing from the first body to the second)."""
        return self.graph.ids[self.graph.edges], self.solution.branch_current

    @property
    def electrode_currents(self) -> Dict[str, float]:
        return dict(self.solution.electrode_current)

    def remove(self):
        """Take the engine out of ``O.engines`` and the registry."""
        self.O.engines = [e for e in self.O.engines if e is not self.runner]
        ENGINES.pop(self.label, None)


def ensure_thermal_state(bodies) -> int:
    """Give every body a ``ThermalState`` (YADE's state with ``temp``), carrying over all the
    attributes of its current state (position, velocity, mass, blocked DOFs...). Returns how
    many states were replaced."""
    yade = import_yade()
    replaced = 0
    for b in bodies:
        if not isinstance(b.state, yade.ThermalState):
            ts = yade.ThermalState()
            ts.updateAttrs(b.state.dict())
            b.state = ts
            replaced += 1
    return replaced


class ElectroThermalEngine(ElectricalEngine):
    """Joule heating and heat conduction every ``iterPeriod`` steps of a YADE simulation.

    Each call reads the graph (only what changed), solves the potential (again only when the
    graph, rho_e(T) or an electrode value changed), computes the Joule heat, advances the
    temperatures by the thermal time step and writes them to ``b.state.temp`` (a
    ``ThermalState`` is given to bodies that do not have one), and the potential to
    ``b.potential``. One history row per call is written to the CSV as the run goes.

    Thermal time: by default each call advances by the simulated time elapsed since the
    previous call (``O.time`` difference) times ``time_scale``; give ``thermal_dt`` to
    advance by a fixed thermal step per call instead (the heat and mechanics then run on
    separate clocks). Either way the integrator sub-cycles (explicit) or takes the step in
    one implicit solve (theta method), so it is never bound to ``O.dt``.

    Parameters
    ----------
    resistivity, electrodes, law, law_params, solver, measure, iterPeriod, history, bonds,
    mask, geometry_every, move_tolerance, full_read_every, plot, label : see ElectricalEngine
    density [kg/m^3], specific_heat [J/(kg K)], conductivity [W/(m K)] : thermal material
    temperature : initial temperature [K]
    beta : rho_e(T) = rho_0 (1 + beta (T - T_0)) [1/K]; 0 for a constant resistivity
    theta : 'explicit', 'crank-nicolson', 'backward-euler' or a number in [0, 1]
    fixed, flux, convection : lists of ``yade_electro.thermal`` FixedTemperature, HeatFlux,
        Convection; their ``nodes`` may be YADE predicates, body id lists or masks
    thermal_dt : float, optional; time_scale : float
    coupled_options : dict, extra keyword arguments of ``ElectroThermalModel``
    """

    def __init__(self, resistivity, electrodes, density, specific_heat, conductivity, temperature,
                 beta=0.0, eta=1.0, theta="backward-euler", fixed=(), flux=(), convection=(),
                 thermal_dt=None, time_scale=1.0, coupled_options=None, label="electrothermal", **kw):
        from ..coupled import ElectroThermalModel
        self._thermal_setup = None
        super().__init__(resistivity, electrodes, label=label, **kw)
        bcs = []
        for group in (fixed, flux, convection):
            out = []
            for bc in group:
                out.append(dataclasses.replace(bc, nodes=_normalise_selector(bc.nodes, self.reader)))
            bcs.append(out)
        if thermal_dt is not None and not (thermal_dt > 0):
            raise ValueError(f"thermal_dt must be > 0 (s), got {thermal_dt}")
        if not (time_scale > 0):
            raise ValueError(f"time_scale must be > 0, got {time_scale}")
        self.thermal_dt, self.time_scale = thermal_dt, float(time_scale)
        self.coupled = ElectroThermalModel(self.model, density, specific_heat, conductivity, temperature,
                                           beta=beta, eta=eta, theta=theta, fixed=bcs[0], flux=bcs[1],
                                           convection=bcs[2], **(coupled_options or {}))
        self._last_time = float(self.O.time)
        self._states_checked = -1

    def step(self):
        """One coupled step on the current scene (what the PyRunner calls)."""
        graph = self.reader.read()
        if self.thermal_dt is not None:
            dt = self.thermal_dt
        else:
            dt = (float(self.O.time) - self._last_time) * self.time_scale
        if dt <= 0:             # first call at the start of a run: nothing to integrate yet
            dt = None
        if dt is None:
            self.coupled._prepare(graph)
            self.coupled._solve_potential(graph)
            row = self.coupled.summary()
        else:
            row = self.coupled.step(graph, dt, self.values or None)
        self._last_time = float(self.O.time)
        bodies = self.reader.bodies
        if self._states_checked != self.reader.full_reads:    # the body set changes only there
            ensure_thermal_state(bodies)
            self._states_checked = self.reader.full_reads
        for b, t in zip(bodies, self.coupled.temperature.tolist()):
            b.state.temp = t
        if self.write_back:
            write_body_attribute(bodies, self.write_back, self.model.solution.potential)
        out = {"iter": int(self.O.iter), "mech_time": float(self.O.time)}
        out.update(row)
        out["graph_revision"] = int(graph.revision)
        self.history.append(out)
        if self.plot:
            from yade import plot
            plot.addData(**{f"electro_{k}": v for k, v in out.items()})
        return out

    @property
    def temperature(self) -> np.ndarray:
        """Temperature [K] of each element, in ``body_ids`` order."""
        return self.coupled.temperature
