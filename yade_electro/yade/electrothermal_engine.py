"""The electro-thermal engine: Joule heating and heat conduction every ``iterPeriod`` steps of a
YADE simulation (see :class:`ElectroThermalEngine`)."""

from __future__ import annotations

import dataclasses
import logging
import warnings
from typing import Dict, Optional

import numpy as np

from ..physics.coupled import ElectroThermalModel
from ..core.errors import BoundaryConditionError, ThermalError
from ..core.materials import Material, real_number
from ..laws.factors import law_attribute
from ..laws.law import Law
from ..network.heat_conditions import ThermalWall
from . import persistence
from . import registry
from .runtime import import_yade
from .clumps import ClumpTemperatures, clump_volume_fraction
from .granular import check_wall_bodies
from .writeback import TemperatureWriter, write_body_attribute

from .distributed import DistributedCalls, chosen_ids, distributed_model, refuse_clumps
from .electrical_engine import ElectricalEngine, check_law_clumps
from .engine_base import electrode_walls, keyword_only, material_table, synced_property
from .options import Output, Reader, absolute_temperature, thermal_settings
from ..physics.integrator import MODEL_OPTIONS, Integrator
from .overlap import OverlappedCalls, OverlapWork, available_cores, overlap_competes
__all__ = ["ElectroThermalEngine"]

log = logging.getLogger(__name__)


@registry.engine_type
class ElectroThermalEngine(OverlappedCalls, ElectricalEngine):
    """Joule heating and heat conduction every ``iterPeriod`` steps of a YADE simulation.

    Each call reads the graph (only what changed), brings the potential up to date (a solve
    only when the geometry, rho_e(T) or the structure changed), computes the Joule heat,
    advances the temperatures by the thermal step and writes them to ``b.state.temp`` (a
    ``ThermalState`` is given to bodies that do not have one) and the potential to
    ``b.potential``. One history row per call goes to the CSV as the run goes.

    Thermal time: by default each call advances by the simulated time elapsed since the
    previous call (``O.time`` difference) times ``Integrator(time_scale=...)``; give
    ``Integrator(dt=...)`` to advance by a fixed thermal step per call instead (the heat and mechanics then run on separate
    clocks). Either way the integrator sub-cycles (explicit) or takes the step in one implicit
    solve (theta method), so it is never bound to ``O.dt``.

    Parameters
    ----------
    material : Material or Materials
        ``Material(density=..., specific_heat=..., conductivity=...)`` [kg/m^3, J/(kg K),
        W/(m K)], with ``resistivity`` [ohm m] when there are electrodes, and ``beta`` [1/K]
        with ``reference_temperature`` [K] for rho_e(T) = rho_0 (1 + beta (T - T_0)).
    boundaries : list
        :class:`~yade_electro.yade.options.Electrode` (none: heat conduction only),
        ``FixedTemperature``, ``HeatFlux``, ``Convection`` (on elements ``nodes=`` or at a
        ``surface=`` of the container), ``HeatSource`` (W or W/m^3, shared by element volume),
        and in a granular bed :class:`~yade_electro.yade.options.Wall` (isothermal or
        adiabatic walls; their heat is in the history as ``wall_heat:<name>`` and in
        :meth:`wall_heat`).
    temperature : float or InitialTemperature
        Starting temperature [K] of every element and of elements added later;
        ``InitialTemperature(K, by_id={id: K})`` gives chosen elements their own.
    law : str or Law
        As for :class:`ElectricalEngine`; ``Law(..., volume_fraction=...)`` sets the heat
        capacities ``rho c V / fv``.
    integrator : Integrator
        Time integration (theta, step, steady states, sub-cycling, safety) and the coupling
        to rho_e(T); see :class:`~yade_electro.physics.integrator.Integrator`.
    reader : Reader
        As for :class:`ElectricalEngine`; ``Reader(overlap=True)`` runs a heat-only granular
        engine's numpy work on a worker thread (results one call later; see :meth:`sync`).
    output : Output
        As for :class:`ElectricalEngine`.
    solver : str
        Linear solver of the potential (the heat step's is ``Integrator(solver=...)``).
    iterPeriod : int >= 1
        Steps between two calls.
    label : str, optional
        Default ``'electrothermal'`` (``'heat'`` for :class:`HeatEngine`).

    Raises
    ------
    TypeError
        A positional argument, or an old keyword (the message names its new place).
    MaterialError, BoundaryConditionError, ThermalError, GraphError, ValueError
        Anything wrong in the set-up, found when the engine is built.
    """

    DEFAULT_LABEL = "electrothermal"


    @keyword_only
    def __init__(self, *, material, boundaries=(), temperature, law="auto", integrator: Integrator = Integrator(),
                 reader: Reader = Reader(), output: Output = Output(), solver="auto", iterPeriod: int = 1,
                 label: Optional[str] = None):
        self._setup(**thermal_settings(material, boundaries, temperature, law, integrator, reader, output,
                                       type(self).__name__), solver=solver, iterPeriod=iterPeriod, label=label)

    def _setup(self, resistivity=None, electrodes=None, density=None, specific_heat=None, conductivity=None,
                 temperature=None, initial_temperature=None, beta=0.0, eta=1.0, theta="backward-euler",
                 heat_conditions=(), thermal_dt=None, time_scale=1.0, steady=False, thermal_solver="cg",
                 coupled_options=None, law=None,
                 law_params=None, solver="auto", measure=None, iterPeriod: int = 1, history: Optional[str] = None,
                 history_mode: str = "w", bonds="cohesive", mask=None, geometry_every: int = 10,
                 move_tolerance: float = 1e-4, full_read_every: int = 0, bond_check: str = "auto",
                 sweep_calls: int = 8, write_back: Optional[str] = "potential", plot: bool = False,
                 label: Optional[str] = None, reselect: bool = False, container=None, walls=None, skin="auto",
                 materials=None, overlap=False, clumps=None, isolated="keep", O=None, _resume=None):
        if not isinstance(overlap, bool):
            raise ValueError(f"overlap must be True or False, got {overlap!r}")
        check_law_clumps(law, clumps)
        if overlap and (electrodes is not None or bonds != "contacts"):
            raise ValueError("overlap=True is for heat-only engines in the granular mode (no Electrode, "
                             "Reader(bonds='contacts')); leave it False here")
        self._drop_inflight()                  # a re-attach in place: the old scene's call is void
        self.overlap = overlap
        if overlap and _resume is None:
            said = overlap_competes(int((O if O is not None else import_yade().Omega()).numThreads), available_cores())
            if said:
                warnings.warn(said, stacklevel=4)
        self._resumed_work = None
        wall_specs = self._wall_specs(walls)
        reader_options = dict(bonds=bonds, mask=mask, geometry_every=geometry_every, move_tolerance=move_tolerance,
                              full_read_every=full_read_every, bond_check=bond_check, sweep_calls=sweep_calls,
                              skin=skin, walls={w.name: ids for w, ids in wall_specs if w.isothermal} or None,
                              clumps=clumps, isolated=isolated)
        self._electrode_walls = electrode_walls(electrodes)
        clash = set(self._electrode_walls) & {w.name for w, _ in wall_specs}
        if clash:
            raise BoundaryConditionError(f"{sorted(clash)} name both a thermal wall and an electrode; give them "
                                         "different names (they may be the same bodies)")
        if self._electrode_walls:
            reader_options["walls"] = {**(reader_options["walls"] or {}), **self._electrode_walls}
        self._options_bonds = bonds
        self._walls = {w.name: dict(bodies=list(ids), temperature=w.temperature, conductivity=w.conductivity)
                       for w, ids in wall_specs}
        self._declared_walls = list(self._electrode_walls) + list(self._walls)     # adiabatic ones too
        self._heat_only = electrodes is None
        self._start(O, label, _resume, iterPeriod, reader_options, history, history_mode,
                    write_back if electrodes is not None else None, plot)
        for w, ids in wall_specs:
            check_wall_bodies(self.O, w.name, ids)
        allowed = ("density", "specific_heat", "conductivity") + (("resistivity",) if electrodes is not None else ())
        self._materials = material_table(self.O, materials, allowed)
        self._materials_config = materials
        self._pending_temperatures: Dict[int, float] = {}
        law, law_params = self._law_and_container(law, law_params, container)
        self._options = dict(law=law, solver=solver, measure=measure, reselect=reselect, **reader_options)
        if temperature is None:
            raise ValueError("give the initial temperature= (K)")
        if electrodes is not None:
            self.model = self._make_electrical(resistivity, electrodes, law, law_params, solver, measure, reselect)
        else:
            self.model = None
            self._law_params = law_params
            self._resistivity = resistivity
        if thermal_dt is not None:
            thermal_dt = real_number("thermal_dt (s)", thermal_dt)
            if not thermal_dt > 0:
                raise ValueError(f"thermal_dt must be > 0 (s), got {thermal_dt}")
        time_scale = real_number("time_scale", time_scale)
        if not time_scale > 0:
            raise ValueError(f"time_scale must be > 0, got {time_scale}")
        self.thermal_dt, self.time_scale = thermal_dt, float(time_scale)
        # selectors made picklable; the model checks what each condition is (split_heat_boundaries)
        conditions = [bc if getattr(bc, "nodes", None) is None else dataclasses.replace(
            bc, nodes=self._normalise_selector(bc.nodes)) for bc in heat_conditions]
        self._heat_conditions = conditions
        self._initial_by_id = initial_temperature is not None
        if not isinstance(steady, bool):
            raise ValueError(f"steady must be True or False, got {steady!r}")
        self.steady = steady
        self._thermal = dict(density=density, specific_heat=specific_heat, conductivity=conductivity,
                             temperature=temperature, beta=beta, eta=eta, theta=theta, thermal_dt=thermal_dt,
                             time_scale=time_scale, thermal_solver=thermal_solver, steady=steady,
                             coupled_options=dict(coupled_options or {}), overlap=overlap)
        extra = dict(coupled_options or {})
        volume_fraction = extra.pop("volume_fraction", None)
        law_cells = law_attribute(law or "continuum", "cell_volumes") is not None    # the law makes the capacities
        if bonds == "contacts" and "cell_volume" not in extra and volume_fraction is None and not law_cells:
            volume_fraction = 1.0                        # a particle is its own volume
            if clumps is not None:                       # a clump's members: their shares of its volume
                volume_fraction = clump_volume_fraction(self.reader)
        if clumps == "lumped":
            extra.setdefault("lumps", lambda graph: self.reader.clump_labels(graph.ids))
        integrator = Integrator(theta=theta, eta=eta, solver=thermal_solver,
                                **{k: extra.pop(k) for k in MODEL_OPTIONS if k in extra})
        heat_material = Material(density=density, specific_heat=specific_heat, conductivity=conductivity,
                                 beta=beta, reference_temperature=extra.pop("reference_temperature", None))
        if self.model is None:        # the heat-only model's own law
            heat_law = self._law_option(law or "continuum", self._law_params, volume_fraction)
        else:
            heat_law = Law(container=self.container, volume_fraction=volume_fraction)
        self._coupled = ElectroThermalModel(self.model, heat_material, temperature, integrator=integrator,
                                           boundaries=conditions + [w for w, _ in wall_specs], law=heat_law,
                                           **extra)
        if bonds == "cohesive":
            self._coupled.alone_remedy = ("leave them out with Reader(isolated='leave out'), or erase them "
                                          "(O.bodies.erase(id))")
        self._last_time = float(self.O.time)
        self._temperature_writer = TemperatureWriter()
        self._clump_writer = ClumpTemperatures()
        if initial_temperature is not None and _resume is None:
            self.coupled.restore_temperatures(self._initial_temperatures(initial_temperature, temperature))
        if _resume is not None:
            st = self._resume_state
            self._last_time = float(st.get("mech_time", self._last_time))
            self.coupled.restore(st.get("thermal_time", 0.0), st.get("energy"))
            self.coupled.restore_temperatures(self._read_temperatures)
            self._pending_temperatures = {int(k): float(v) for k, v in (st.get("pending") or {}).items()}
            saved_call = persistence.load_call(self.O, self.label) if st.get("overlap_iter") is not None else None
            if saved_call is not None:
                self._resumed_work = OverlapWork.saved(saved_call)
        self._finish(history_mode)

    # -- the model, and the overlapped call -----------------------------------------------
    coupled = synced_property("_coupled", "The engine's ElectroThermalModel (up to date with the last call).")
    reader = synced_property("_reader", "The engine's scene reader (its graph is the last call's).")
    history = synced_property("_history", "The engine's History (with the last call's row).")

    @staticmethod
    def _wall_specs(walls):
        """[(ThermalWall, body ids)] from ``walls={name: dict(bodies=..., temperature=K | None,
        conductivity=W/(m K))}`` (checked here; the bodies' shapes by the reader)."""
        if walls is None:
            return []
        if not isinstance(walls, dict):
            raise BoundaryConditionError("walls= must be a dict name -> dict(bodies=ids, temperature=K or None "
                                         "(adiabatic), conductivity=W/(m K))")
        out = []
        for name, spec in walls.items():
            if not isinstance(spec, dict) or "bodies" not in spec:
                raise BoundaryConditionError(f"wall {name!r}: give dict(bodies=ids, temperature=K or None, "
                                             "conductivity=...)")
            unknown = set(spec) - {"bodies", "temperature", "conductivity"}
            if unknown:
                raise BoundaryConditionError(f"wall {name!r}: unknown key(s) {sorted(unknown)}; give bodies=, "
                                             "temperature=, conductivity=")
            ids = spec["bodies"]
            ids = [ids] if isinstance(ids, (int, np.integer)) else list(ids)
            out.append((ThermalWall(name, spec.get("temperature"), spec.get("conductivity")), ids))
        return out

    def _feed_walls(self):
        self._feed_electrode_walls()
        # adiabatic walls carry no heat: their contacts are not looked for (their bodies are
        # checked when the engine is built)
        for name in self._walls:
            if name not in self.reader.walls:
                continue
            self.coupled.set_wall_contacts(name, *self.reader.wall_contacts(name))

    def wall_heat(self) -> Dict[str, float]:
        """Heat [J] each isothermal wall gave the bed since the start (negative: taken)."""
        return dict(self.coupled.heat.link_energy)

    def contact_heat_flow(self):
        """Per contact: (body id pairs (m, 2), conductance G [W/K], heat flow [W] from the
        first body to the second) of the contacts that conduct now."""
        e, G, q = self._conducting_contacts()
        ids = self.body_ids
        return np.column_stack([ids[e[:, 0]], ids[e[:, 1]]]), G, q

    def _conducting_contacts(self):
        """(node pairs (m, 2), G [W/K], heat flow [W] from the first node to the second) of the
        edges that conduct now."""
        heat = self.coupled.heat
        on = heat.conductance > 0
        e, G, T = self.coupled.network.edges[on], heat.conductance[on], heat.temperature
        return e, G, G * (T[e[:, 0]] - T[e[:, 1]])

    def write_vtk(self, prefix: str) -> Dict[str, str]:
        """Write the last call's state for ParaView (meshio, ``.vtu``): ``<prefix>_particles.vtu``
        (points with ``radius`` [m], ``temperature`` [K], ``body_id``, and ``potential`` [V]
        with electrodes) and ``<prefix>_contacts.vtu`` (a line per conducting contact, cell
        data ``conductance_W_per_K``, ``heat_flow_W`` from the first body to the second, body
        ids ``id1``, ``id2``). In a periodic cell, a contact that crosses a face is drawn to
        the neighbour's image. Returns {'particles': path, 'contacts': path}."""
        from ..post.vtk import write_bonds, write_elements
        if self.coupled.heat is None:
            raise RuntimeError(f"engine {self.label!r} has not run yet: call O.run (or engine.step()) first")
        graph = self.coupled.network.graph
        fields = {"temperature": self.coupled.heat.temperature, "body_id": graph.ids.astype(float)}
        sol = self.coupled.solution
        if sol is not None:
            fields["potential"] = sol.potential[:graph.n_nodes]      # (surface electrodes' nodes follow)
        e, G, q = self._conducting_contacts()
        return {"particles": write_elements(f"{prefix}_particles.vtu", graph.pos, graph.radius, fields),
                "contacts": write_bonds(f"{prefix}_contacts.vtu", graph.pos, e,
                                        {"conductance_W_per_K": G, "heat_flow_W": q,
                                         "id1": graph.ids[e[:, 0]].astype(float),
                                         "id2": graph.ids[e[:, 1]].astype(float)},
                                        vectors=graph.edge_vectors(e) if graph.shift is not None else None)}

    def _initial_temperatures(self, table, default):
        """A function graph -> starting temperatures from ``{body id: K}`` (checked now)."""
        if not hasattr(table, "items"):
            raise ValueError(f"initial_temperature must be a dict body id -> temperature (K), got {type(table).__name__}")
        known = {b.id for b in self.O.bodies if b is not None}
        values = {}
        for k, v in table.items():
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or int(k) not in known:
                raise ValueError(f"initial_temperature: {k!r} is not the id of a body of this scene")
            values[int(k)] = real_number(f"initial_temperature[{k}] (K)", v)
        t0 = float(default)
        return lambda graph: np.array([values.get(int(i), t0) for i in graph.ids], dtype=float)

    def _read_temperatures(self, graph):
        yade = import_yade()
        bodies = self.reader.bodies
        if not all(isinstance(b.state, yade.ThermalState) for b in bodies):
            raise ThermalError(f"engine {self.label!r}: the loaded bodies have no ThermalState, so their temperatures "
                               "were not saved; cannot continue the thermal run")
        return np.array([b.state.temp for b in bodies], dtype=float)

    # -- persistence ---------------------------------------------------------------------------
    def _config_kwargs(self):
        if self.model is not None:
            kw = super()._config_kwargs()
        else:
            o = self._options
            kw = dict(resistivity=self._resistivity, electrodes=None, law=o["law"], law_params=self._law_params,
                      solver="auto", measure=None, iterPeriod=self.iterPeriod, history=self.history_path,
                      bonds=o["bonds"], mask=o["mask"], geometry_every=o["geometry_every"],
                      move_tolerance=o["move_tolerance"], full_read_every=o["full_read_every"],
                      bond_check=o["bond_check"], sweep_calls=o["sweep_calls"], write_back=None, plot=self.plot,
                      reselect=o["reselect"], container=self.container)
        t = dict(self._thermal)
        t["walls"] = dict(self._walls) or None
        t["skin"] = self._options["skin"]
        t["clumps"] = self._options["clumps"]
        t["isolated"] = self._options["isolated"]
        t["materials"] = self._materials_config
        saved = []
        for bc in self.coupled.conditions + self.coupled.heat_sources:
            if getattr(bc, "surface", None) is not None:      # as chosen (distributed: as given)
                m = self.coupled.bc_surfaces[bc.name]
                saved.append(dataclasses.replace(bc, surface=m.saved if m.resolved else bc.surface))
            elif bc.nodes is not None:
                ids = self.coupled.bc_memberships[bc.name].ids
                saved.append(dataclasses.replace(bc, nodes=np.asarray(ids, dtype=np.int64)))
            else:
                saved.append(bc)
        kw.update(t)
        kw["heat_conditions"] = saved
        return kw

    def _save_state(self):
        if self._inflight is not None:
            state = dict(self._inflight_state)      # the model is the worker's now
            state["pending"] = {str(k): v for k, v in self._pending_temperatures.items()}
        else:
            state = self._state_dict()
        persistence.save_state(self.O, self.label, state)

    def _state_dict(self) -> dict:
        heat = self._coupled.heat
        return {"iter": int(self.O.iter), "time": float(self.O.time), "mech_time": self._last_time,
                "values": dict(self.model.values) if self.model is not None else {},
                "thermal_time": self._coupled.time, "energy": self._coupled.energy_ledger,
                "fixed_values": heat.fixed_values if heat is not None else {},
                "pending": {str(k): v for k, v in self._pending_temperatures.items()},
                "rows": len(self.history)}

    def _distributed_calls(self, graph):
        t, c = self._thermal, self._coupled
        if self.steady or self.overlap or c.coupling_iterations or self._initial_by_id:
            raise BoundaryConditionError("a distributed run (solver='petsc' under mpiexec) does not do steady states, "
                                         "overlapped calls, coupling iterations or InitialTemperature(by_id=...) yet")
        refuse_clumps(self.reader)
        specs = self.model.specs if self.model is not None else ()
        ids = self._electrode_ids(graph)
        cond_ids = chosen_ids(graph, {
            name: m for name, m in c.bc_memberships.items()
            if any(b.name == name and getattr(b, "surface", None) is None for b in self._heat_conditions)},
            what="thermal boundary condition")
        vf = c.volume_fraction if not callable(c.volume_fraction) else getattr(c.volume_fraction, "without_clumps", None)
        heat = dict(density=t["density"], specific_heat=t["specific_heat"], conductivity=t["conductivity"],
                    temperature=t["temperature"], beta=t["beta"], eta=t["eta"], theta=t["theta"],
                    joule_sharing=c.integrator.joule_sharing,
                    reference_temperature=t["coupled_options"].get("reference_temperature"), volume_fraction=vf,
                    safety=c.heat_options["safety"], max_substeps=c.heat_options["max_substeps"])
        model = distributed_model(solver=self._distributed_solver(), resistivity=self._resistivity,
                                  materials=self._materials_config, law=self._options["law"] or "continuum",
                                  law_params=self._law_params, electrodes=specs, electrode_ids=ids, heat=heat,
                                  conditions=self._heat_conditions, condition_ids=cond_ids,
                                  walls=getattr(self, "_walls", None))
        return DistributedCalls(self.O, self.reader, model, write_back=self.write_back, temperatures=True,
                                thermal_dt=self.thermal_dt, time_scale=self.time_scale, slabs=self._slabs,
                                graph=graph, container=self.container)

    def _surface_names(self) -> dict:
        out = {s.name: s.surface for s in (self.model.specs if self.model is not None else ())
               if s.surface is not None}
        out.update({b.name: b.surface for b in self._heat_conditions if getattr(b, "surface", None) is not None})
        return out

    def _prepare(self, graph):
        if self._resume is not None and self.model is not None:
            for k, v in (self._resume_state.get("values") or {}).items():
                self.model.set_electrode(k, v)
        self._feed_walls()
        self._apply_materials()
        self.coupled.refresh(graph)
        if self._resume is not None:
            for k, v in (self._resume_state.get("fixed_values") or {}).items():
                self.coupled.heat.set_fixed_temperature(k, v)
        if self.steady:                         # a steady solve that cannot be: said now, in the script
            self.coupled.heat.check_steady(self.coupled.sources)      # (the Joule heat of the potential solved)

    def _material_base(self):
        t = self._thermal
        return {"density": t["density"], "specific_heat": t["specific_heat"], "conductivity": t["conductivity"],
                "resistivity": self._resistivity}

    def _set_properties(self, props):
        self.coupled.set_material(**props)

    def set_fixed_temperature(self, name: str, temperature: float):
        """Change a fixed-temperature boundary condition's value [K, > 0] from the next call on."""
        self.coupled.heat.set_fixed_temperature(name, absolute_temperature(f"set_fixed_temperature({name!r})",
                                                                           temperature))

    @property
    def written_attributes(self) -> tuple:
        return super().written_attributes + ("state.temp",)

    # -- stepping ------------------------------------------------------------------------
    def steady_state(self) -> dict:
        """Solve the steady temperatures now (from the script, e.g. before ``O.run``): reads the
        scene, writes the temperatures (and potentials) back; returns the history row. When it
        raises and the engine is not in ``O.engines`` (nothing of it runs), the engine is
        removed (its label, history file and saved configuration freed: make a new one)."""
        try:
            return self._guarded(lambda: self._step(steady=True))
        except Exception as exc:
            if not self.removed and self.runner not in list(self.O.engines):
                self.remove()
                exc.add_note(f"engine {self.label!r} is removed (it was not in O.engines): make a new one")
            raise

    def _step(self, steady=None):
        if self.overlap and steady is None:
            return self._step_overlapped()
        self.sync()
        graph = self.reader.read()
        self._apply_materials()
        pending, self._pending_temperatures = self._pending_temperatures, {}
        row = self._heat_step(graph, self._call_dt(), steady, pending)
        self._last_time = float(self.O.time)
        bodies = self.reader.bodies
        self._temperature_writer.write(bodies, self.coupled.temperature)
        if getattr(self.reader, "has_clumps", False):       # and on each clump body: its members' mean
            self._clump_writer.write(self.O, self.reader, graph.ids, self.coupled.temperature, self.coupled.capacity)
        sol = self.coupled.solution
        if self.write_back and sol is not None and sol is not self._written:
            write_body_attribute(bodies, self.write_back, sol.potential)
            self._written = sol
        out = self._row(int(self.O.iter), float(self.O.time), row, graph)
        self._write_row(out)
        return out

    def _call_dt(self) -> float:
        """The thermal step of a call now [s]."""
        if self.thermal_dt is not None:
            return self.thermal_dt
        return (float(self.O.time) - self._last_time) * self.time_scale

    def _heat_step(self, graph, dt, steady, pending) -> dict:
        """The model's part of a call (numpy only): walls, set temperatures, then a steady
        solve, a refresh (no time elapsed) or a step of ``dt`` [s]."""
        self._feed_walls()
        self._apply_pending_temperatures(graph, pending)
        if self.steady if steady is None else steady:
            return self.coupled.steady_state(graph)
        if dt <= 0:           # first call at the start of a run: nothing to integrate yet
            return self.coupled.refresh(graph)
        return self.coupled.step(graph, dt)

    @staticmethod
    def _row(iteration, mech_time, row, graph) -> dict:
        out = {"iter": int(iteration), "mech_time": float(mech_time)}
        out.update(row)
        out["graph_revision"] = int(graph.revision)
        return out

    @property
    def critical_time_step(self) -> float:
        """The explicit scheme's stability bound ``min_i C_i / (sum_j G_ij + h_i A_i)`` [s] on
        the current graph (inf when no free element exchanges heat). A forward-Euler step longer
        than ``Integrator.safety`` times it is split into equal sub-steps."""
        return float(self.coupled.heat.critical_time_step)

    @property
    def allowed_time_step(self) -> float:
        """The longest (sub-)step the integrator takes [s]: ``safety * critical_time_step /
        (1 - 2 theta)`` for theta < 1/2, inf otherwise."""
        return float(self.coupled.heat.allowed_time_step())

    @property
    def substeps(self) -> int:
        """The sub-steps the last call's heat step was split into (1 for an implicit step)."""
        rows = self.history.rows
        return int(rows[-1].get("n_substeps", 1)) if rows else 0

    @property
    def temperature(self) -> np.ndarray:
        """Temperature [K] of each element, in ``body_ids`` order (distributed: this rank's own)."""
        if self._distributed is not None:
            return self._distributed.model.T
        return self.coupled.temperature

    @property
    def body_ids(self) -> np.ndarray:
        if self._distributed is not None:
            return ElectricalEngine.body_ids.fget(self)
        return self.coupled.network.graph.ids

    @property
    def temperature_by_id(self) -> Dict[int, float]:
        return dict(zip(self.body_ids.tolist(), self.temperature.tolist()))

    def set_temperatures(self, temperatures: Dict[int, float]):
        """Give chosen spheres a temperature [K] at the next call, before its step:
        ``{body id: K}``, for spheres the engine has or spheres added since (particles
        poured in hot: they take it instead of ``temperature``); a clump's id stands for all its
        members when the reader reads clumps. The heat this adds or takes
        is in the history's ``particle_heat``, so the balance still closes. A scene saved
        before that call (``O.save``) keeps them for the run that loads it. Checked now: an
        id that is not a sphere of this scene (or is masked out), or a temperature that is not
        a finite number, raises ValueError."""
        if not hasattr(temperatures, "items"):
            raise ValueError(f"set_temperatures takes a dict body id -> temperature (K), got "
                             f"{type(temperatures).__name__}")
        Sphere = import_yade().Sphere
        mask = self.reader.mask
        checked = {}
        for k, v in temperatures.items():
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
                raise ValueError(f"set_temperatures: {k!r} is not a body id")
            b = self.O.bodies[int(k)] if 0 <= int(k) < len(self.O.bodies) else None
            clumps = bool(getattr(self.reader, "clumps", False))
            if b is not None and b.isClump and clumps:        # a clump read member by member: all its members
                members = sorted(int(m) for m in b.shape.members.keys())
                checked.update(dict.fromkeys(members, absolute_temperature(f"set_temperatures[{k}] (K)", v)))
                continue
            if b is None or not isinstance(b.shape, Sphere) or b.isClump or (b.isClumpMember and not clumps):
                raise ValueError(f"set_temperatures: body {k!r} is not a sphere of this scene (only spheres carry "
                                 "temperatures; clumps and their members do when the reader reads clumps, "
                                 "Reader(bonds='contacts', clumps=...))")
            if mask is not None and not (b.mask & mask):
                raise ValueError(f"set_temperatures: body {k} is masked out of this engine (mask={mask})")
            checked[int(k)] = absolute_temperature(f"set_temperatures[{k}] (K)", v)
        self._pending_temperatures.update(checked)
        self._save_state()                  # an O.save before the next call keeps them

    def _apply_pending_temperatures(self, graph, pending):
        if not pending:
            return
        ids = np.array(sorted(pending), dtype=np.int64)
        here = np.isin(ids, graph.ids)
        if not np.all(here):
            log.warning("engine %r: set_temperatures for bodies %s that left the scene before the call; dropped",
                        self.label, ids[~here][:10].tolist())
        self.coupled.prepare(graph)
        self.coupled.set_temperatures(graph.index_of(ids[here]), [pending[int(i)] for i in ids[here]])
