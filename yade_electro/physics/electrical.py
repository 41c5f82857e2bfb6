"""The electrical model of a packing, independent of YADE: electrodes chosen once by selector
and kept by element id, a conductance law, a kept Kirchhoff problem, results.

``ElectricalModel.solve(graph)`` is the one call an engine makes each period. It compares the
graph with the previous one and does the least work (see :meth:`ElectricalModel.update`):

* same graph object, same resistivity: nothing (the last solution is returned);
* moved elements (same bonds): new geometric factors, conductances updated in place, the
  solver setup kept, a warm re-solve;
* new resistivity (rho_e(T)): conductances updated in place, warm re-solve;
* broken bonds: the law's new network; when it is a subset of the kept one (the usual case)
  the structure stays and the lost edges get conductance 0, the connected parts are checked
  again; otherwise the structure is rebuilt;
* another element set (bodies added or erased): everything is rebuilt, electrode membership
  carried over by id.

The model owns the electrode values (:meth:`set_electrode`); changing one never re-solves.

Units: SI (ohm m, V, A, ohm, W, s).
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from typing import Dict, List, Mapping, Optional, Sequence

import numpy as np

from ..laws.factors import ConductanceLaw
from ..laws.factor_network import FactorNetwork
from ..laws.law import Law
from ..core.errors import BoundaryConditionError
from ..core.graph import ContactGraph
from ..core.materials import Material, electrical_conductance, in_series, positive_property
from ..network.conduction import ConductionProblem
from ..network.records import PotentialSolution
from ..network.kirchhoff import Electrode, PotentialOrCurrent, electrode_value
from ..core.selection import Membership, Selector, select_nodes
from ..solvers.registry import check_solver_name

from .walls import WallContacts

from ..network.boundary import check_place

__all__ = ["ElectrodeSpec", "ElectricalModel", "electrode_specs"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ElectrodeSpec(PotentialOrCurrent):
    """An electrode to be resolved on a graph: where it is, and a fixed potential [V] or an
    imposed current [A] (exactly one), checked at construction.

    ``select``: the element layer the electrode is (paper 000's convention: a perfect conductor
    through the selected elements' centres). ``surface``: a surface of the container (e.g.
    ``container.face('top')``, see :mod:`yade_electro.geometry.boundary`): the electrode is that surface,
    each element with boundary faces on it connected through its half cell. ``wall=True``: a
    wall of a granular bed (a plate), each particle touching it connected through its contact
    (the contact law's sphere-wall factor, :meth:`ElectricalModel.set_wall_contacts` gives the
    contacts). Give one of them.
    """

    name: str
    select: Selector = None
    potential: Optional[float] = None
    current: Optional[float] = None
    surface: object = None
    wall: bool = False

    def __post_init__(self):
        if not isinstance(self.wall, bool):
            raise BoundaryConditionError(f"electrode {self.name!r}: wall= must be True or False")
        check_place("electrode", self.name, elements=self.select, surface=self.surface, wall=self.wall,
                    elements_key="select", allow_wall=True)
        self.check_value()

    def resolve(self, graph: ContactGraph) -> Electrode:
        if self.surface is not None or self.wall:
            raise BoundaryConditionError(f"electrode {self.name!r} is a surface: resolve it through ElectricalModel")
        return Electrode(self.name, select_nodes(graph, self.select, self.name, "electrode"), self.potential,
                         self.current)


def electrode_specs(electrodes) -> List[ElectrodeSpec]:
    """ElectrodeSpecs from a mapping name -> dict(select=..., potential=|current=) or specs."""
    if isinstance(electrodes, Mapping):
        out = []
        for name, spec in electrodes.items():
            if isinstance(spec, ElectrodeSpec):
                out.append(spec)
            elif isinstance(spec, Mapping):
                unknown = set(spec) - {"select", "surface", "potential", "current", "wall"}
                if unknown:
                    raise BoundaryConditionError(f"electrode {name!r}: unknown key(s) {sorted(unknown)}; give "
                                                 "select= or surface=, and potential= (V) or current= (A)")
                out.append(ElectrodeSpec(name, **spec))
            else:
                raise BoundaryConditionError(f"electrode {name!r}: give a dict(select=..., potential=...|current=...)")
        return out
    if electrodes is None:
        return []
    out = list(electrodes)
    for s in out:
        if not isinstance(s, ElectrodeSpec):
            raise BoundaryConditionError(f"electrodes must be a dict name -> dict(select=..., potential=...) or "
                                         f"ElectrodeSpecs, got {s!r}")
    return out


class ElectricalModel:
    """Electrical conduction of a packing, solved on demand on the current graph.

    Parameters
    ----------
    material : Material, or float or (n,) array
        ``Material(resistivity=...)``, or the electrical resistivity rho_e [ohm m] itself, > 0
        (304L steel: 0.73e-6). The model holds it (rho_0 of rho_e(T) in a coupled model).
    electrodes : sequence of ElectrodeSpec, or mapping name -> dict(select=..., potential=V | current=A)
    law : Law, str or ConductanceLaw
        The conductance law (default ``'continuum'``): ``Law('voronoi', container=shape)``,
        ``Law('continuum', threshold=0.4)``, a name of
        ``yade_electro.laws.factors.conductance_laws()``, or a law object. The Law's
        ``container`` is the solid, for surface electrodes (default: the 'voronoi' law's).
    solver : str or solver object
        'auto' (by size), 'cg', 'cg-deflated', 'cg-amg', 'direct' or an object with
        ``solve(A, b, x0=None) -> (x, info)`` (see :mod:`yade_electro.solvers.registry`).
    measure : (str, str), optional
        Electrodes between which R_eq is reported; default the first two.
    reselect : bool
        Re-evaluate the electrode selectors on every new structure instead of keeping the
        elements chosen the first time (by id).
    """

    def __init__(self, material, electrodes, *, law=None, solver="auto", measure: Optional[Sequence[str]] = None,
                 reselect: bool = False):
        self.material = material if isinstance(material, Material) else Material(resistivity=material)
        self.material.require_electrical()
        self.specs = electrode_specs(electrodes)
        if not self.specs:
            raise BoundaryConditionError("give at least one electrode")
        names = [s.name for s in self.specs]
        if len(set(names)) != len(names):
            raise BoundaryConditionError(f"electrode names must be unique, got {names}")
        check_solver_name(solver)
        container = None
        if isinstance(law, ConductanceLaw):
            self.law: ConductanceLaw = law
        else:
            law = Law.of(law)
            self.law, container = law.make(), law.container
        self.solver = solver
        if measure is None:
            measure = names[:2] if len(names) >= 2 else None
        else:
            measure = tuple(measure)
            if len(measure) != 2 or any(m not in names for m in measure) or measure[0] == measure[1]:
                raise BoundaryConditionError(f"measure={measure} must name two different electrodes of {names}")
        self.measure = tuple(measure) if measure else None
        self.memberships: Dict[str, Membership] = {s.name: Membership(s.name, s.select, reselect)
                                                   for s in self.specs if s.surface is None and not s.wall}
        self.walls = [s.name for s in self.specs if s.wall]
        if self.walls:
            try:
                self.law.wall_factor(np.ones(1), np.zeros(1))
            except ValueError as exc:
                raise BoundaryConditionError(f"wall electrodes {self.walls} with law {self.law.name!r}: {exc}") from None
        self._wall_contacts = WallContacts(self.walls, what="wall electrode")
        self._wall_nodes = {}                 # name -> the nodes of its edges in the kept problem
        self._walls_stale = False
        self.container = container if container is not None else getattr(self.law, "container", None)
        from ..geometry.boundary import BoundaryOfGraph, SurfaceMembership
        self.surfaces: Dict[str, SurfaceMembership] = {s.name: SurfaceMembership(s.name, s.surface)
                                                       for s in self.specs if s.surface is not None}
        self._boundary = None
        if any(not m.resolved for m in self.surfaces.values()):
            self._boundary = BoundaryOfGraph(self.container, self.law)
        self.values: Dict[str, float] = {s.name: s.value for s in self.specs}
        self.resistivity = self.material.resistivity
        self.network = FactorNetwork(self.law)
        self.problem: Optional[ConductionProblem] = None
        self.solution: Optional[PotentialSolution] = None
        self.conductance: Optional[np.ndarray] = None   # c on network.edges [S]
        self.rebuilds = 0
        self.updates = {"structure": 0, "topology": 0, "geometry": 0, "resistivity": 0}
        self._rho_stale = False
        self._graph_view = None
        self._surface_edges = np.zeros((0, 2), dtype=np.int64)
        self._surface_factor = np.zeros(0)
        self._surface_series = np.zeros(0)      # a contact film's resistance [ohm] in series (walls)
        self.n_elements = None

    # -- values (owned here) -----------------------------------------------------------------
    @property
    def law_name(self) -> str:
        return self.law.name

    def set_electrode(self, name: str, value: float):
        """Change an electrode's potential [V] or current [A] (no re-solve needed)."""
        if name not in self.values:
            raise BoundaryConditionError(f"no electrode named {name!r}; have {sorted(self.values)}")
        self.values[name] = electrode_value(name, value)

    def set_resistivity(self, resistivity):
        """The resistivity in use, rho_e [ohm m] (scalar or per node), e.g. rho_e(T) of a
        coupled model; a value update at the next solve. The material's rho_0 stays."""
        self.resistivity = positive_property("resistivity", resistivity, None, " (ohm m)")
        self._rho_stale = True

    def set_material(self, resistivity):
        """A new rho_0 [ohm m] (scalar or per node): the material's, held here only (a coupled
        model reads it from here), and the resistivity in use."""
        self.material = dataclasses.replace(self.material, resistivity=resistivity)
        self.set_resistivity(self.material.resistivity)

    def reset(self):
        """Forget everything derived from earlier graphs (network, solver setup); the electrode
        membership is kept."""
        self.network = FactorNetwork(self.law)
        self.problem = None
        self.solution = None

    # -- structure / values ------------------------------------------------------------------
    @property
    def bond_graph(self) -> Optional[ContactGraph]:
        """The graph of the last update (bonds read from the scene)."""
        return self.network.graph

    @property
    def factor(self) -> Optional[np.ndarray]:
        """Geometric factor g [m] on ``network_edges``."""
        return self.network.factor

    @property
    def network_edges(self) -> np.ndarray:
        """Edges of the kept network (node pairs); broken ones have conductance 0."""
        return self.network.edges

    @property
    def graph(self) -> Optional[ContactGraph]:
        """The network the current flows in: the bond graph's elements and the edges that
        conduct (``network_edges`` with a non-zero conductance). The solution's arrays
        (``branch_current``) follow ``network_edges``."""
        if self.problem is None:
            return None
        g = self.bond_graph
        conducting = self.network.factor > 0
        if self.network.edges is g.edges and np.all(conducting):
            return g
        key = (id(g), id(self.network.edges), id(self.network.factor))
        if self._graph_view is None or self._graph_view[0] != key:
            self._graph_view = (key, ContactGraph(g.pos, g.radius, self.network.edges[conducting], g.ids,
                                                  g.revision))
        return self._graph_view[1]

    def _full_conductance(self, n):
        """Conductances [S] of the problem's edges: the law's network (g / rho_edge), then the
        surface electrodes' half cells (g / rho of the element)."""
        film = getattr(self.law, "film", 0.0)     # a contact film in series (granular laws)
        c = electrical_conductance(self.network.factor, self._resistivity_of(n), self.network.edges,
                                   series=film and self.law.film_resistance(self.network.graph, self.network.edges))
        if self._surface_edges.size:
            rho = np.asarray(self.resistivity, float)
            rho_i = rho if rho.ndim == 0 else rho[self._surface_edges[:, 0]]
            c = np.concatenate([c, in_series(self._surface_factor / rho_i, self._surface_series if film else None)])
        return c

    @property
    def edges(self) -> np.ndarray:
        """Every edge of the problem: ``network_edges``, then the surface electrodes' half
        cells (element, electrode node); the solution's ``branch_current`` follows them."""
        return self.problem.edges

    def element_joule_power(self, eta: float = 1.0, sharing: str = "edges", volume=None) -> np.ndarray:
        """Joule heat [W] per element: each network edge's eta w^2 / c shared half and half by
        its ends, a surface half cell's given to its element (``sharing='edges'``); or, with
        ``sharing='cells'`` and the elements' ``volume`` [m^3], that total given by the field
        over each cell (:func:`~yade_electro.physics.thermal.cell_joule_sources`; an
        electrode's own elements and their neighbours keep their edge share)."""
        from ..network.kirchhoff import edge_power
        n, m = self.n_elements, self.network.edges.shape[0]
        p = eta * edge_power(self.solution.branch_current, self.conductance)
        e = self.network.edges
        out = 0.5 * (np.bincount(e[:, 0], p[:m], n) + np.bincount(e[:, 1], p[:m], n))
        if self._surface_edges.size:
            out += np.bincount(self._surface_edges[:, 0], p[m:], n)
        if sharing == "cells":
            from .thermal import cell_joule_sources
            held = np.zeros(n, bool)
            for el in self.problem.electrodes:          # an electrode's own elements (not surface/wall nodes)
                nodes = np.asarray(el.nodes, dtype=np.int64)
                held[nodes[nodes < n]] = True
            out = cell_joule_sources(self.bond_graph.pos, e[self.conductance[:m] > 0], self.solution.potential,
                                     volume, self._resistivity_of(n), out, held=held)
        return out

    def _resistivity_of(self, n):
        """The resistivity [ohm m], checked against the ``n`` elements when it is per element."""
        rho = self.resistivity
        if np.ndim(rho) == 1 and np.shape(rho)[0] != n:
            raise BoundaryConditionError(f"resistivity has {np.shape(rho)[0]} values but the packing has {n} elements")
        return rho

    def set_wall_contacts(self, name: str, nodes, overlap):
        """The particles touching wall electrode ``name`` (node indices of the next graph) and
        their overlaps [m] (> 0). Particles that touched it before keep their edge with a zero
        conductance (the structure is kept); a particle touching it for the first time makes a
        new structure."""
        if self._wall_contacts.set(name, nodes, overlap):
            self._walls_stale = True

    def _wall_factor(self, name, graph, nodes):
        """(factors g [m], film resistances [ohm]) of the kept edges ``nodes`` of wall ``name``
        for its current contacts."""
        nd, dl = self._wall_contacts.contacts(name)
        over = np.zeros(nodes.size)
        if nd.size:
            pos = np.searchsorted(nodes, nd)
            over[pos] = dl
        r = graph.radius[nodes]
        film = self.law.wall_film_resistance(r, over) if getattr(self.law, "film", 0.0) else np.zeros(nodes.size)
        return self.law.wall_factor(r, over), film

    def _walls_fit(self) -> bool:
        """True when every particle touching a wall electrode has an edge to it."""
        for name in self._wall_contacts.names:
            nd, _ = self._wall_contacts.contacts(name)
            kept = self._wall_nodes.get(name)
            if kept is None or (nd.size and not np.all(np.isin(nd, kept))):
                return False
        return True

    def _surface_contact(self, spec, graph):
        """The elements a surface electrode touches (made once, kept by element id)."""
        return self.surfaces[spec.name].contact(graph, self._boundary)

    def _build(self, graph: ContactGraph):
        n = graph.n_nodes
        electrodes, surf_edges, surf_g, surf_film, surf_nodes = [], [], [], [], []
        for s in self.specs:
            if s.wall:
                nd, _ = self._wall_contacts.contacts(s.name)
                if nd.size == 0:
                    raise BoundaryConditionError(
                        f"wall electrode {s.name!r} touches no particle: no current can enter there (is the bed "
                        "pressed against it? a wall conducts through overlapping contacts)")
                nodes = np.unique(nd)
                if nodes.max() >= n:
                    raise BoundaryConditionError(f"wall electrode {s.name!r}: contact node beyond the {n} elements")
                self._wall_nodes[s.name] = nodes
                k = n + len(surf_nodes)
                surf_nodes.append(k)
                surf_edges.append(np.column_stack([nodes, np.full(nodes.size, k)]))
                g_w, film_w = self._wall_factor(s.name, graph, nodes)
                surf_g.append(g_w)
                surf_film.append(film_w)
                electrodes.append(Electrode(s.name, [k], potential=s.potential, current=s.current))
            elif s.surface is not None:
                contact = self._surface_contact(s, graph)
                k = n + len(surf_nodes)
                surf_nodes.append(k)
                surf_edges.append(np.column_stack([contact.nodes, np.full(contact.nodes.size, k)]))
                surf_g.append(contact.factor)
                surf_film.append(np.zeros(contact.factor.size))
                electrodes.append(Electrode(s.name, [k], potential=s.potential, current=s.current))
            else:
                nodes = self.memberships[s.name].nodes(graph)
                electrodes.append(Electrode(s.name, nodes, potential=s.potential, current=s.current))
        self._check_apart(electrodes, graph)
        self._surface_edges = np.concatenate(surf_edges) if surf_edges else np.zeros((0, 2), dtype=np.int64)
        self._surface_factor = np.concatenate(surf_g) if surf_g else np.zeros(0)
        self._surface_series = np.concatenate(surf_film) if surf_film else np.zeros(0)
        offsets = np.cumsum([0] + [len(g) for g in surf_g])
        self._wall_slices = {}
        names = [sp.name for sp in self.specs if sp.surface is not None or sp.wall]
        for k, name in enumerate(names):
            if name in self._wall_nodes:
                self._wall_slices[name] = slice(int(offsets[k]), int(offsets[k + 1]))
        self._walls_stale = False
        self.n_elements = n
        edges = np.concatenate([self.network.edges, self._surface_edges])
        c = self._full_conductance(n)
        coords = graph.pos
        if surf_nodes:
            # a surface electrode's node sits at the mean centre of its elements (only the
            # deflated solver's clusters look at it, and it is not an unknown)
            coords = np.concatenate([graph.pos] + [graph.pos[e[:, 0]].mean(axis=0)[None, :] for e in surf_edges])
        solver = self.solver
        if self.problem is not None and not isinstance(self.solver, str):
            solver = self.problem.solver
        self.problem = ConductionProblem(n + len(surf_nodes), edges, c, electrodes, solver=solver, coords=coords)
        self.conductance = c
        self.rebuilds += 1
        self.updates["structure"] += 1

    def _check_apart(self, electrodes, graph) -> None:
        """BoundaryConditionError when two surface electrodes hold the same boundary faces, or an
        electrode's elements are also linked to a surface electrode: either shorts the two
        (overlapping element selections are refused by the conduction problem)."""
        from ..geometry.boundary import shared_faces
        n = graph.n_nodes
        contacts = {s.name: self._surface_contact(s, graph) for s in self.specs if s.surface is not None and not s.wall}
        names = list(contacts)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                k = shared_faces(contacts[a], contacts[b])
                if k:
                    raise BoundaryConditionError(
                        f"electrodes {a!r} and {b!r} hold the same {k} boundary face(s) (the same surface given twice, "
                        "or overlapping surfaces): they would short each other; give each face to one electrode")
        for e in electrodes:
            held = np.asarray(e.nodes)
            held = held[held < n]
            for name, c in contacts.items():
                both = np.intersect1d(held, c.nodes)
                if name != e.name and both.size:
                    raise BoundaryConditionError(
                        f"{both.size} element(s) of electrode {e.name!r} are also on surface electrode {name!r} "
                        "(e.g. a layer of elements and the face they touch): the two would short each other through "
                        "them; keep the selection off the surface's elements, or give one electrode")

    def update(self, graph: ContactGraph) -> Optional[str]:
        """Bring the kept problem to ``graph``; returns what changed: None, 'resistivity',
        'geometry', 'topology' or 'structure' (see the module doc and
        :class:`~yade_electro.laws.factors.FactorNetwork`)."""
        if not isinstance(graph, ContactGraph):
            raise TypeError(f"expected a ContactGraph, got {type(graph).__name__}")
        kind = self.network.update(graph)
        reselect = any(m.reselect for m in self.memberships.values())
        if (self.problem is None or kind == "structure" or (kind == "topology" and reselect)
                or (self.walls and not self._walls_fit())):
            self._rho_stale = False
            self._build(graph)
            return "structure"
        if self.walls and self._walls_stale:
            for name, sl in self._wall_slices.items():
                self._surface_factor[sl], self._surface_series[sl] = self._wall_factor(name, graph,
                                                                                         self._wall_nodes[name])
            self._walls_stale = False
            if kind is None:
                kind = "geometry"
        if kind is None:
            if not self._rho_stale:
                return None
            kind = "resistivity"
        self._rho_stale = False
        c = self._full_conductance(graph.n_nodes)
        if np.array_equal(c, self.conductance):
            return None
        self.conductance = c
        if self.problem.update_conductance(c) == "structure":
            self.updates["structure"] += 1
        self.updates[kind] += 1
        return kind

    def solve(self, graph: Optional[ContactGraph] = None,
              values: Optional[Mapping[str, float]] = None) -> PotentialSolution:
        """Potentials, currents and electrode figures on ``graph`` (default: the last one);
        ``values`` sets electrode values (kept, as :meth:`set_electrode`)."""
        if values:
            for k, v in values.items():
                self.set_electrode(k, v)
        if graph is not None:
            self.update(graph)
        elif self.problem is None:
            raise RuntimeError("no graph yet: call solve(graph) first")
        elif self._rho_stale:
            self.update(self.bond_graph)
        prev = self.solution
        self.solution = self.problem.solve(self.values)
        # the work of this call (a solution kept from an earlier call cost nothing)
        self.last_iterations = 0 if self.solution is prev else int(self.solution.info.get("iterations", 0))
        self.last_solve_time = 0.0 if self.solution is prev else float(self.solution.info.get("basis_time", 0.0))
        return self.solution

    def prepare(self, graph: ContactGraph) -> ConductionProblem:
        """Build (or bring up to date) the Kirchhoff problem of ``graph``."""
        self.update(graph)
        return self.problem

    # -- figures -----------------------------------------------------------------------------
    @property
    def equivalent_resistance(self) -> float:
        """R_eq [ohm] between the two ``measure`` electrodes of the last solution."""
        if self.solution is None or self.measure is None:
            raise RuntimeError("no solution yet, or fewer than two electrodes")
        return self.solution.equivalent_resistance(*self.measure)

    def joule_power(self) -> np.ndarray:
        """Power dissipated in each edge of ``network_edges`` by the last solution [W]."""
        return self.solution.joule_power(self.conductance)

    def summary(self) -> Dict[str, float]:
        """One history row of the last solution: R_eq, electrode potentials/currents, power,
        residual, solver figures, network size."""
        sol = self.solution
        if sol is None:
            raise RuntimeError("no solution yet")
        cached = getattr(self, "_summary_of", None)
        if cached is not None and cached[0] is sol:          # the figures of a kept solution
            row = dict(cached[1])
        else:
            row = {"R_eq": self.equivalent_resistance if self.measure else float("nan")}
            for name in sol.electrode_current:
                row[f"V_{name}"] = sol.electrode_potential[name]
                row[f"I_{name}"] = sol.electrode_current[name]
            row["joule_power"] = float(np.sum(self.joule_power()))
            row["n_nodes"] = int(self.bond_graph.n_nodes)
            row["n_edges"] = int(np.count_nonzero(self.conductance[:self.network.edges.shape[0]] > 0))
            row["n_floating"] = int(sol.floating[:self.n_elements].sum())
            row["residual"] = sol.residual
            row["current_imbalance"] = sol.current_imbalance
            self._summary_of = (sol, dict(row))
        row["iterations"] = self.last_iterations
        row["solve_time"] = self.last_solve_time
        return row
