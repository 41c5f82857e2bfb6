"""The electrical engine for ``O.engines``: a ``PyRunner`` that reads the graph (only what
changed), brings the kept model up to date, writes results back to the bodies and appends a
history row (:class:`ElectricalEngine`; the heat engines build on it).

Example (in a YADE script)::

    from yade import pack
    from yade_electro.yade import ElectricalEngine, Electrode, Material, Output
    electro = ElectricalEngine(
        material=Material(resistivity=0.73e-6),
        boundaries=[Electrode("top", select=pack.inAlignedBox((-1, -1, 4.9e-3), (1, 1, 1)), potential=1.0),
                    Electrode("bottom", select=pack.inAlignedBox((-1, -1, -1), (1, 1, 0.1e-3)), potential=0.0)],
        output=Output(history="electro.csv"), iterPeriod=100)
    O.engines = O.engines + [electro.runner]
    O.run(1000, True)
    print(electro.equivalent_resistance, electro.potential_by_id[0])

Electrode selectors: YADE predicates (selection by element centre), lists of body ids,
boolean masks, or callables ``f(pos, radius) -> mask``; ``dict(mask=m)`` selects the bodies
with ``b.mask & m``. The elements are selected once, when the engine is built, and kept by
body id (``Reader(reselect=True)`` selects again on each new structure).

Everything is checked when the engine is built, in the user's script, with the real
exception type (YADE reports errors inside ``O.run`` only as ``PyRunner error``).

Save and load: the engine keeps its configuration and state in ``O.tags``
(:mod:`.persistence`); after ``O.load`` it continues by itself (the saved PyRunner re-attaches
it), and ``engine = yade_electro.yade.attach(label)`` gives back a handle.
"""
from __future__ import annotations

import logging
from typing import Dict, Optional

import numpy as np

from ..laws.law import Law
from ..physics.electrical import ElectricalModel, ElectrodeSpec
from ..core.errors import BoundaryConditionError
from ..geometry.shapes import Shape, as_shape
from . import persistence
from . import registry
from .granular import check_wall_bodies
from .writeback import write_body_attribute

from .distributed import DistributedCalls, chosen_ids, distributed_model
from .engine_base import EngineBase, electrode_walls, keyword_only, material_table
from .options import Electrode, Output, Reader, electrical_settings
__all__ = ["ElectricalEngine"]

log = logging.getLogger(__name__)


def check_law_clumps(law, clumps):
    """ValueError when the law (a name, or None) reads clumps in a mode the reader is not given
    (the 'grains' law: every element of a grain, ``clumps='resolved'``)."""
    if law is None or not isinstance(law, str) or law == "auto":
        return
    from ..laws.factors import law_attribute
    needed = law_attribute(law, "clumps")
    if needed is not None and clumps != needed:
        raise ValueError(f"law {law!r} reads each grain's elements: give Reader(bonds='contacts', clumps={needed!r}) "
                         f"(got clumps={clumps!r})")


@registry.engine_type
class ElectricalEngine(EngineBase):
    """Electrical conduction solved every ``iterPeriod`` steps of a YADE simulation.

    Parameters
    ----------
    material : Material or Materials
        ``Material(resistivity=...)`` [ohm m]; spheres of several YADE materials:
        ``Materials(default=Material(...), by_yade_material={label: Material(resistivity=...)})``
        (an edge takes the mean of its two ends' resistivities).
    boundaries : list of Electrode
        The electrodes: ``Electrode(name, surface=... | select=... | wall=..., potential=V |
        current=A)`` (see :class:`~yade_electro.yade.options.Electrode`).
    law : str or Law
        The conductance law (default ``'auto'``: ``'voronoi'`` when the container is known,
        else ``'continuum'``; ``'contact'`` in a granular bed), with its parameters and
        container: ``Law('voronoi', container=rod, crack='facets')``.
    reader : Reader
        How the scene is read and what counts as a change; ``Reader(bonds='contacts')`` for a
        granular bed.
    output : Output
        History CSV, the body attribute written back, ``yade.plot``, the electrodes of R_eq.
    solver : str
        Linear solver (default ``'auto'``; ``'cg'``, ``'cg-deflated'``, ``'cg-amg'``, ``'petsc'``,
        ``'direct'``; see :mod:`yade_electro.solvers`).
    iterPeriod : int >= 1
        Steps between two calls (the PyRunner's period).
    label : str, optional
        Label of the PyRunner and key in the registry (default ``'electro'``, numbered if
        taken).

    Raises
    ------
    TypeError
        A positional argument, or a keyword of the engines before the option objects (the
        message names its new place).
    MaterialError, BoundaryConditionError, GraphError, ValueError
        Anything wrong in the set-up, found when the engine is built.
    """

    DEFAULT_LABEL = "electro"

    @keyword_only
    def __init__(self, *, material, boundaries, law="auto", reader: Reader = Reader(), output: Output = Output(),
                 solver="auto", iterPeriod: int = 1, label: Optional[str] = None):
        self._setup(**electrical_settings(material, boundaries, law, reader, output), solver=solver,
                    iterPeriod=iterPeriod, label=label)

    def _setup(self, resistivity=None, electrodes=None, law=None, law_params=None, solver="auto",
                 measure=None, iterPeriod: int = 1, history: Optional[str] = None, history_mode: str = "w",
                 bonds="cohesive", mask=None, geometry_every: int = 10, move_tolerance: float = 1e-4,
                 full_read_every: int = 0, bond_check: str = "auto", sweep_calls: int = 8,
                 write_back: Optional[str] = "potential", plot: bool = False, label: Optional[str] = None,
                 reselect: bool = False, container=None, skin="auto", materials=None, clumps=None, isolated="keep",
                 O=None, _resume=None):
        check_law_clumps(law, clumps)
        reader_options = dict(bonds=bonds, mask=mask, geometry_every=geometry_every, move_tolerance=move_tolerance,
                              full_read_every=full_read_every, bond_check=bond_check, sweep_calls=sweep_calls,
                              skin=skin, walls=electrode_walls(electrodes) or None, clumps=clumps, isolated=isolated)
        self._options_bonds = bonds
        self._electrode_walls = electrode_walls(electrodes)
        self._declared_walls = list(self._electrode_walls)
        self._start(O, label, _resume, iterPeriod, reader_options, history, history_mode, write_back, plot)
        self._materials = material_table(self.O, materials, ("resistivity",))
        self._materials_config = materials
        law, law_params = self._law_and_container(law, law_params, container)
        self._options = dict(law=law, solver=solver, measure=measure, reselect=reselect, **reader_options)
        self.model = self._make_electrical(resistivity, electrodes, law, law_params, solver, measure, reselect)
        self._finish(history_mode)

    def _law_and_container(self, law, law_params, container):
        """The container (given, the law's, or the scene's packing's) and the law (default
        'voronoi' with a container, else 'continuum')."""
        law_params = dict(law_params or {})
        if container is None:
            container = law_params.get("container")
        if container is None:
            container = persistence.scene_container(self.O)
        if container is not None and not isinstance(container, Shape):
            container = as_shape(container)
        self.container = container
        granular = self._options_bonds == "contacts"
        if law is None:
            law = "contact" if granular else ("voronoi" if container is not None else "continuum")
        from ..laws.factors import is_contact_law as _is_contact_law
        is_contact_law = _is_contact_law(law)
        if granular and not is_contact_law:
            raise ValueError(f"law {law!r} is a law of bonded solids, but Reader(bonds='contacts') (a granular bed): "
                             "use law='contact' or 'liggghts' (conduction through the contact areas)")
        if not granular and is_contact_law:
            raise ValueError(f"law {law!r} conducts through contact overlaps, but Reader(bonds='cohesive') (a bonded "
                             "solid whose bonds do not overlap): use Reader(bonds='contacts') for a granular bed, or a "
                             "solid's law "
                             "('voronoi', 'continuum')")
        if is_contact_law and law in ("contact", "liggghts", "pipe"):
            log.info("engine: law %r with the %s contact radius (radius='geometric': the lens where the two "
                     "spheres' surfaces cross, sqrt(2) times Hertz's for equal spheres; radius='hertz': Hertz's)",
                     law, law_params.get("radius", "geometric"))
        if law == "voronoi" and container is not None:
            law_params["container"] = law_params.get("container") or container
        if law_params.get("container") is not None and not isinstance(law_params["container"], Shape):
            law_params["container"] = as_shape(law_params["container"])
        return law, law_params

    def _make_electrical(self, resistivity, electrodes, law, law_params, solver, measure, reselect):
        if resistivity is None:
            raise ValueError("give resistivity= (ohm m)")
        if not electrodes or not all(isinstance(e, Electrode) for e in electrodes):
            raise BoundaryConditionError("give boundaries=[Electrode(...), Electrode(...)] (at least one)")
        self._law_params = law_params
        specs = []
        for e in electrodes:
            if e.wall is not None:           # granular mode only: checked in _start
                check_wall_bodies(self.O, e.name, list(e.wall))
            specs.append(ElectrodeSpec(e.name, select=None if e.select is None else self._normalise_selector(e.select),
                                       surface=e.surface, wall=e.wall is not None, potential=e.potential,
                                       current=e.current))
        self._resistivity = resistivity
        return ElectricalModel(resistivity, specs, law=self._law_option(law, law_params), solver=solver,
                               measure=measure, reselect=reselect)

    def _law_option(self, law: str, law_params, volume_fraction=None) -> Law:
        """The engine's law name and parameters as a :class:`Law`, bounded by the parameters'
        container or else the engine's."""
        params = dict(law_params or {})
        container = params.pop("container", None)
        return Law(law, container=self.container if container is None else container,
                   volume_fraction=volume_fraction, **params)

    # -- persistence ---------------------------------------------------------------------------
    def _electrode_config(self) -> list:
        """The electrodes as saved with the scene: Electrode objects, element layers by body id."""
        out = []
        for s in self.model.specs:
            if s.wall:
                place = dict(wall=list(self._electrode_walls[s.name]))
            elif s.surface is not None:        # as chosen (a distributed run's ranks chose apart: as given)
                m = self.model.surfaces[s.name]
                place = dict(surface=m.saved if m.resolved else s.surface)
            else:
                place = dict(select=np.asarray(self.model.memberships[s.name].ids, dtype=np.int64))
            out.append(Electrode(s.name, potential=s.potential, current=s.current, **place))
        return out

    def _law_config(self):
        params = dict(self._law_params)
        ref = getattr(self.model.law, "reference", None)
        if ref is not None:
            params["reference"] = ref
        return params

    def _config_kwargs(self):
        o = self._options
        return dict(resistivity=self._resistivity, electrodes=self._electrode_config(), law=o["law"],
                    law_params=self._law_config(), solver=o["solver"] if isinstance(o["solver"], str) else "auto",
                    measure=o["measure"], iterPeriod=self.iterPeriod, history=self.history_path,
                    bonds=o["bonds"], mask=o["mask"], geometry_every=o["geometry_every"],
                    move_tolerance=o["move_tolerance"], full_read_every=o["full_read_every"],
                    bond_check=o["bond_check"], sweep_calls=o["sweep_calls"], write_back=self.write_back,
                    plot=self.plot, reselect=o["reselect"], container=self.container, skin=o["skin"], clumps=o["clumps"],
                    isolated=o["isolated"], materials=self._materials_config)

    def _save_state(self):
        persistence.save_state(self.O, self.label, {
            "iter": int(self.O.iter), "time": float(self.O.time), "values": dict(self.model.values),
            "rows": len(self.history)})

    def _prepare(self, graph):
        if self._resume is not None:
            for k, v in (self._resume_state.get("values") or {}).items():
                self.model.set_electrode(k, v)
        self._feed_electrode_walls()
        self._apply_materials()
        self.model.update(graph)

    def _electrode_ids(self, graph) -> dict:
        """Body ids each selected electrode chose in the scene, every rank having read its part
        ``graph`` (collective; surface and wall electrodes have none)."""
        if self.model is None:
            return {}
        chosen = {s.name for s in self.model.specs if s.surface is None and not s.wall}
        return chosen_ids(graph, {name: m for name, m in self.model.memberships.items() if name in chosen})

    def _distributed_calls(self, graph):
        ids = self._electrode_ids(graph)
        model = distributed_model(solver=self._distributed_solver(), resistivity=self._resistivity,
                                  materials=self._materials_config, law=self._options["law"],
                                  law_params=self._law_params, electrodes=self.model.specs, electrode_ids=ids,
                                  walls=getattr(self, "_walls", None))
        return DistributedCalls(self.O, self.reader, model, write_back=self.write_back, slabs=self._slabs,
                                graph=graph, container=self.container)

    def _surface_names(self) -> dict:
        return {s.name: s.surface for s in self.model.specs if s.surface is not None}

    def _material_base(self):
        return {"resistivity": self._resistivity}

    def _set_properties(self, props):
        self.model.set_material(resistivity=props["resistivity"])

    def _feed_electrode_walls(self):
        if self.model is None:
            return
        for name in self.model.walls:
            self.model.set_wall_contacts(name, *self.reader.wall_contacts(name))

    # -- stepping ------------------------------------------------------------------------
    def set_electrode(self, name: str, value: float):
        """Change an electrode's potential [V] or current [A] from the next call on (distributed:
        call it on every rank with the same value, as a script does)."""
        self.model.set_electrode(name, value)          # checks the name and the value
        if self._distributed is not None:
            self._distributed.model.set_electrode(name, self.model.values[name])

    def _step(self):
        graph = self.reader.read()
        self._feed_electrode_walls()
        self._apply_materials()
        sol = self.model.solve(graph)
        if self.write_back and sol is not self._written:
            write_body_attribute(self.reader.bodies, self.write_back, sol.potential)
            self._written = sol
        row = {"iter": int(self.O.iter), "time": float(self.O.time)}
        row.update(self.model.summary())
        row["graph_revision"] = int(graph.revision)
        self._write_row(row)
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
        """The last PotentialSolution of the network: its nodes are the elements (in
        ``body_ids`` order), then one node per surface electrode (use :attr:`potential`
        for the elements' values)."""
        return self.model.solution

    @property
    def equivalent_resistance(self) -> float:
        """R_eq [ohm] between the ``measure`` electrodes at the last solve (network property;
        distributed: between the first two electrodes, the same on every rank)."""
        if self._distributed is not None:
            return float(self.history.rows[-1].get("R_eq", float("nan"))) if len(self.history) else float("nan")
        return self.model.equivalent_resistance

    @property
    def body_ids(self) -> np.ndarray:
        """Ids of the elements (distributed: this rank's own)."""
        if self._distributed is not None:
            share = self._distributed.model.share
            return share.owned_ids if share is not None else np.zeros(0, np.int64)
        return self.model.bond_graph.ids

    @property
    def potential(self) -> np.ndarray:
        """Potential [V] of each element, in ``body_ids`` order."""
        if self._distributed is not None:
            return self._distributed.model.potential
        return self.solution.potential[:self.model.n_elements]

    @property
    def potential_by_id(self) -> Dict[int, float]:
        return dict(zip(self.body_ids.tolist(), self.potential.tolist()))

    @property
    def branch_currents(self):
        """(id pairs (m, 2), current (m,) [A] flowing from the first body to the second), over
        the edges that conduct."""
        m = self.model.network_edges.shape[0]
        keep = self.model.conductance[:m] > 0
        return self.body_ids[self.model.network_edges[keep]], self.solution.branch_current[:m][keep]

    @property
    def electrode_currents(self) -> Dict[str, float]:
        """Current [A] fed into the network by each electrode (distributed: summed over the ranks)."""
        if self._distributed is not None:
            row = self.history.rows[-1] if len(self.history) else {}
            return {s.name: float(row.get(f"I_{s.name}", float("nan"))) for s in self.model.specs}
        return dict(self.solution.electrode_current)


# =========================================================================================
