"""The electrical model of a packing, independent of YADE: electrodes chosen by ids, masks
or geometric selectors, conductances, a kept Kirchhoff problem, results and a history.

``ElectricalModel.solve(graph)`` is the one call an engine makes each period. It re-uses
everything that does not depend on what changed:

* same graph object (or same ``graph.revision``) and same resistivity -> the conductances,
  the reduced matrix, the solver setup (factorisation / preconditioner) and the previous
  potentials as starting guess are kept; only the right-hand side is rebuilt;
* otherwise everything is rebuilt from the new graph.

Units: SI (ohm m, V, A, ohm, W, s).
"""
from __future__ import annotations

import csv
import inspect
import logging
import os
from dataclasses import dataclass
from typing import Callable, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from .conductance import _law, check_resistivity, conductance, network_graph
from .errors import BoundaryConditionError
from .graph import ContactGraph
from .network import ConductionProblem, Electrode, PotentialSolution, make_solver

__all__ = ["ElectrodeSpec", "ElectricalModel", "History", "select_nodes"]

log = logging.getLogger(__name__)

Selector = Union[Sequence[int], np.ndarray, Callable]


def select_nodes(graph: ContactGraph, select: Selector, name: str = "?") -> np.ndarray:
    """Node indices chosen by ``select``.

    ``select`` is one of: a callable ``f(pos (n,3), radius (n,)) -> bool mask`` (see
    ``yade_electro.yade.predicate_selector`` for YADE predicates); a boolean mask over the
    graph's nodes; a sequence of ids (YADE body ids) of nodes of the graph.
    """
    if callable(select):
        mask = np.asarray(select(graph.pos, graph.radius), dtype=bool)
        if mask.shape != (graph.n_nodes,):
            raise BoundaryConditionError(f"electrode {name!r}: the selector returned shape {mask.shape}, "
                                         f"expected a mask of ({graph.n_nodes},)")
        nodes = np.flatnonzero(mask)
    else:
        arr = np.asarray(select)
        if arr.dtype == bool:
            if arr.shape != (graph.n_nodes,):
                raise BoundaryConditionError(f"electrode {name!r}: mask has shape {arr.shape}, the graph "
                                             f"has {graph.n_nodes} elements")
            nodes = np.flatnonzero(arr)
        else:
            if arr.size == 0:
                nodes = np.zeros(0, dtype=np.int64)
            else:
                try:
                    nodes = graph.index_of(arr.astype(np.int64))
                except Exception as exc:
                    raise BoundaryConditionError(f"electrode {name!r}: {exc} (ids must be spherical "
                                                 "bodies of the packing)") from None
    if nodes.size == 0:
        raise BoundaryConditionError(f"electrode {name!r} selects no element: check its region/ids "
                                     "against the packing (selection is by element centre)")
    return nodes


@dataclass(frozen=True)
class ElectrodeSpec:
    """An electrode to be resolved on a graph: a selector plus a fixed potential [V] or an
    imposed current [A] (exactly one)."""

    name: str
    select: Selector
    potential: Optional[float] = None
    current: Optional[float] = None

    def resolve(self, graph: ContactGraph) -> Electrode:
        return Electrode(self.name, select_nodes(graph, self.select, self.name), self.potential, self.current)


def _as_specs(electrodes) -> List[ElectrodeSpec]:
    if isinstance(electrodes, Mapping):
        out = []
        for name, spec in electrodes.items():
            if isinstance(spec, ElectrodeSpec):
                out.append(spec)
            elif isinstance(spec, Mapping):
                out.append(ElectrodeSpec(name, **spec))
            else:
                raise TypeError(f"electrode {name!r}: give a dict(select=..., potential=...|current=...)")
        return out
    return list(electrodes)


class History:
    """Rows of figures, kept in memory and appended to a CSV file as they come (flushed at
    every row, so a crash loses nothing written so far).

    The columns are fixed by the first row; later rows with new keys raise.
    """

    def __init__(self, path: Optional[str] = None):
        self.path = path
        self.rows: List[dict] = []
        self._fields: Optional[List[str]] = None
        if path:
            d = os.path.dirname(os.path.abspath(path))
            os.makedirs(d, exist_ok=True)
            # start a fresh file: a rerun must not mix with an old history
            open(path, "w").close()

    def append(self, row: Mapping[str, float]):
        row = dict(row)
        if self._fields is None:
            self._fields = list(row)
            if self.path:
                with open(self.path, "a", newline="") as fh:
                    csv.writer(fh).writerow(self._fields)
        elif set(row) != set(self._fields):
            raise ValueError(f"history row keys {sorted(row)} differ from the columns {self._fields}")
        self.rows.append(row)
        if self.path:
            with open(self.path, "a", newline="") as fh:
                csv.writer(fh).writerow([_fmt(row[k]) for k in self._fields])

    def __len__(self):
        return len(self.rows)

    def column(self, name: str) -> np.ndarray:
        return np.array([r[name] for r in self.rows])

    def to_dataframe(self):
        """The history as a pandas DataFrame (pandas is imported only here)."""
        import pandas as pd
        return pd.DataFrame(self.rows, columns=self._fields)


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return v


class ElectricalModel:
    """Electrical conduction of a packing, solved on demand on the current graph.

    Parameters
    ----------
    resistivity : float or (n,) array
        Electrical resistivity rho_e [ohm m], > 0 (304L steel: 0.73e-6).
    electrodes : mapping name -> dict(select=..., potential=V | current=A), or ElectrodeSpecs
    law : str
        Conductance law name (``yade_electro.conductance_laws()``), default 'continuum'.
    law_params : dict, optional
        Parameters of the law (e.g. ``threshold``, ``factor`` of the continuum model).
    solver : str or solver object
        'cg' (Jacobi-preconditioned CG, the default), 'cg-amg', 'direct' or an object with
        ``solve(A, b, x0=None) -> (x, info)``.
    measure : (str, str), optional
        Pair of electrodes between which R_eq is reported; default the first two.
    """

    def __init__(self, resistivity, electrodes, law: str = "continuum", law_params: Optional[dict] = None,
                 solver="cg", measure: Optional[Sequence[str]] = None):
        check_resistivity(resistivity, np.size(resistivity) if np.ndim(resistivity) else 1)
        self.resistivity = resistivity
        self.specs = _as_specs(electrodes)
        if not self.specs:
            raise BoundaryConditionError("give at least one electrode")
        names = [s.name for s in self.specs]
        if len(set(names)) != len(names):
            raise BoundaryConditionError(f"electrode names must be unique, got {names}")
        _law(law)                      # unknown names fail here, not at the first solve
        if isinstance(solver, str):
            make_solver(solver)
        self.law = law
        self.law_params = dict(law_params or {})
        self.solver = solver
        if measure is None:
            measure = names[:2] if len(names) >= 2 else None
        elif any(m not in names for m in measure):
            raise BoundaryConditionError(f"measure={measure} names an unknown electrode; have {names}")
        self.measure = tuple(measure) if measure else None
        self._key = None
        self.problem: Optional[ConductionProblem] = None
        self.graph: Optional[ContactGraph] = None
        self.conductance: Optional[np.ndarray] = None
        self.solution: Optional[PotentialSolution] = None
        self.rebuilds = 0
        self.bond_graph: Optional[ContactGraph] = None
        self._law_cache: dict = {}

    def reset(self):
        """Forget everything derived from earlier graphs (conductances, tessellation, solver setup)."""
        self._key = None
        self.problem = None
        self._law_cache.clear()

    def set_resistivity(self, resistivity):
        """Change rho_e (scalar or per node); the next solve rebuilds the conductances."""
        self.resistivity = resistivity
        self._key = None

    def prepare(self, graph: ContactGraph) -> ConductionProblem:
        """Build (or keep) the Kirchhoff problem of ``graph``."""
        key = (id(graph), graph.revision, graph.n_nodes, graph.n_edges)
        if self.problem is not None and key == self._key:
            return self.problem
        params = dict(self.law_params)
        if "cache" in inspect.signature(_law(self.law)).parameters:
            params["cache"] = self._law_cache
        net = network_graph(graph, self.law, **params)
        c = conductance(net, self.resistivity, self.law, **params)
        electrodes = [s.resolve(net) for s in self.specs]
        solver = self.problem.solver if (self.problem is not None and not isinstance(self.solver, str)) else self.solver
        self.problem = ConductionProblem(net.n_nodes, net.edges, c, electrodes, solver=solver)
        self.bond_graph, self.graph, self.conductance, self._key = graph, net, c, key
        self.rebuilds += 1
        return self.problem

    def solve(self, graph: ContactGraph, values: Optional[Mapping[str, float]] = None) -> PotentialSolution:
        """Potentials, currents and electrode figures on ``graph`` (see ``PotentialSolution``)."""
        problem = self.prepare(graph)
        self.solution = problem.solve(values)
        return self.solution

    @property
    def equivalent_resistance(self) -> float:
        """R_eq [ohm] between the two ``measure`` electrodes of the last solution."""
        if self.solution is None or self.measure is None:
            raise RuntimeError("no solution yet, or fewer than two electrodes")
        return self.solution.equivalent_resistance(*self.measure)

    def summary(self) -> Dict[str, float]:
        """One history row of the last solution: R_eq, electrode potentials/currents, power,
        residual, solver figures, graph size."""
        sol = self.solution
        if sol is None:
            raise RuntimeError("no solution yet")
        row = {"R_eq": self.equivalent_resistance if self.measure else float("nan")}
        for name in sol.electrode_current:
            row[f"V_{name}"] = sol.electrode_potential[name]
            row[f"I_{name}"] = sol.electrode_current[name]
        row["joule_power"] = float(np.sum(sol.joule_power(self.conductance)))
        row["n_nodes"] = int(self.graph.n_nodes)
        row["n_edges"] = int(self.graph.n_edges)
        row["n_floating"] = int(sol.floating.sum())
        row["residual"] = sol.residual
        row["current_imbalance"] = sol.current_imbalance
        row["iterations"] = int(sol.info.get("iterations", 0))
        row["solve_time"] = float(sol.info.get("solve_time", 0.0))
        return row
