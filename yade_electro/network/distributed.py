"""Conduction and heat on a network split between MPI ranks: every call is collective.

Each rank passes its share (:class:`~yade_electro.network.partition.LocalNetwork`: owned
nodes, the ghosts they touch, the edges with an owned end) and per-edge and per-owned-node
values; no rank holds the whole graph. The results are on the owned nodes (and, where a
value of a ghost is needed, fetched from its owner), and the totals (electrode currents,
R_eq, heat content) are summed over the ranks, so every rank gets the same totals.

* :class:`PartitionedConduction`: the steady potential with fixed-potential electrodes,
  branch currents, electrode currents, R_eq and Joule heat per element, as
  :class:`~yade_electro.network.conduction.ConductionProblem` gives them serially;
* :class:`PartitionedHeat`: ``C dT/dt = -K T + s`` by the theta method (theta = 0 needs no
  solve: one product with the distributed matrix, whose ghost columns PETSc fetches), with
  fixed temperatures eliminated, as :class:`~yade_electro.network.transient.HeatSolver`.

Floating parts (connected to no fixed value) follow the serial policy of
:mod:`yade_electro.network.floating`: in a steady potential they keep 0 V and one warning
says how many elements in how many parts. They are found without gathering the graph: the
parts of each rank's share are labelled by their smallest key, and the labels are passed
across the ranks until no rank's changes.

Units: S, V, A, W for conduction; W/K, J/K, K, W, s for heat.
"""
from __future__ import annotations

import math
import warnings
from typing import Mapping, Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError, ThermalError
from ..core.graph import connected_parts
from ..solvers.measured import MeasuredChoice
from ..solvers.partitioned import GhostExchange, PartitionedSystem, mpi_comm, number_unknowns, summed
from .floating import floating_message
from .partition import LocalNetwork, OwnedRows
from .theta import theta_of

__all__ = ["PartitionedConduction", "PartitionedHeat", "spread_over_parts", "out_of_owned"]


def spread_over_parts(network: LocalNetwork, exchange: GhostExchange, owned_values, op: str = "min") -> np.ndarray:
    """Each owned node's value made the ``op`` ('min' or 'max') over its whole connected part,
    across the ranks (collective). Rounds: one per rank boundary a part crosses, plus one."""
    n, nl = network.n_owned, network.n_local
    _, comp = connected_parts(nl, network.edges)
    reduce = np.minimum if op == "min" else np.maximum
    v = np.asarray(owned_values).copy()
    while True:
        full = exchange.local(v)
        best = np.full(comp.max() + 1 if nl else 0, full.max() if op == "min" else full.min()) if nl else full
        if nl:
            reduce.at(best, comp, full)
            new = best[comp[:n]]
        else:
            new = v
        changed = exchange.comm.allreduce(int(np.count_nonzero(new != v)))
        v = new
        if changed == 0:
            return v


class _Share:
    """What both physics set up on a share: the ghost exchange, the unknowns, the rows."""

    def __init__(self, network: LocalNetwork, fixed_owned, comm, preconditioner, rtol, pos, spacing, options,
                 exchange: Optional[GhostExchange] = None, smoother: str = "icc"):
        self.network = network
        self.comm = mpi_comm(comm)
        self.exchange = GhostExchange(network, self.comm) if exchange is None else exchange
        fixed = np.asarray(fixed_owned, dtype=bool)
        if fixed.shape != (network.n_owned,):
            raise ValueError(f"one fixed flag per owned node ({network.n_owned}), got {fixed.shape}")
        self.unknown, self.n_global = number_unknowns(self.exchange, fixed)
        self.rows = OwnedRows(network, self.unknown)
        coords = None if pos is None else np.asarray(pos, dtype=float).reshape(-1, 3)[self.rows.free_owned]
        if preconditioner in ("deflation", "auto") and coords is None:
            raise ValueError(f"preconditioner={preconditioner!r} needs pos= (the owned nodes' positions, m) and "
                             "spacing=")

        def make(name):
            return PartitionedSystem(self.rows, self.n_global, self.comm, preconditioner=name, rtol=rtol,
                                     coords=coords, spacing=spacing, options=options, smoother=smoother)
        # 'auto': the run's first solves measure the candidates, the fastest is kept
        self.system = MeasuredChoice(make, self.comm) if preconditioner == "auto" else make(preconditioner)

    def edge_values(self, values, error, message: str) -> np.ndarray:
        """``values`` as one finite float >= 0 per edge of the share, else ``error(message)``."""
        c = np.asarray(values, dtype=float)
        if c.shape != (self.network.edges.shape[0],) or not np.all(np.isfinite(c)) or np.any(c < 0):
            raise error(message)
        return c


class PartitionedConduction:
    """The steady potential of this rank's share, electrodes held at fixed potentials.

    Parameters
    ----------
    network : LocalNetwork
    conductance : (m,) edge conductances [S] of the share's edges
    electrode_of : (n_owned,) int
        The electrode each owned node belongs to (index into ``names``), -1 for none.
    names : sequence of electrode names; ``values`` their potentials [V] (a mapping or a sequence)
    comm : mpi4py or petsc4py communicator (default: all ranks)
    preconditioner : 'deflation' (default, needs ``pos`` and ``spacing``), 'hypre', 'gamg', 'jacobi',
        or 'auto' (the first solves measure deflation and GAMG, the faster is kept:
        :class:`~yade_electro.solvers.measured.MeasuredChoice`)
    pos : (n_owned, 3) positions [m]; spacing : mean neighbour spacing [m]
    smoother : the deflation's smoother, 'icc' or 'jacobi' (see PartitionedSystem)
    currents : per electrode, an imposed current [A] (fed into the network) or None (held at
        its potential in ``values``); default None for all. An imposed current is met by
        superposition: a solve with those electrodes at 0 V, one per such electrode at 1 V
        (the others at 0 V), and their potentials from the small system of the currents (each
        a re-solve on the kept setup).
    links : (n_electrodes, n_owned) conductances [S] joining owned nodes to an electrode held
        apart from them (a wall or surface electrode: a node at the electrode's potential that
        is not an element); None: none. Which nodes are linked (> 0) is part of the structure
        (:meth:`links_fit`); the values may change (:meth:`update_conductance`).
    """

    def __init__(self, network: LocalNetwork, conductance, electrode_of, names: Sequence[str], values, *,
                 comm=None, preconditioner: str = "deflation", rtol: float = 1e-10, pos=None,
                 spacing: Optional[float] = None, options: Optional[dict] = None, smoother: str = "icc",
                 links=None, currents=None):
        self.names = [str(n) for n in names]
        self.imposed = self._imposed(currents)
        el = np.asarray(electrode_of, dtype=np.int64)
        if el.shape != (network.n_owned,) or (el.size and (el.min() < -1 or el.max() >= len(self.names))):
            raise BoundaryConditionError(f"electrode_of must give, per owned node, an index into the {len(self.names)} "
                                         "electrode names or -1")
        self.values = self._values(values)
        comm = mpi_comm(comm)
        ex = GhostExchange(network, comm)
        self.links = self._links(links, network.n_owned)
        self.linked = self.links > 0
        held = summed(comm, np.bincount(el[el >= 0], minlength=len(self.names)) + self.linked.sum(axis=1), np.int64)
        empty = [n for n, k in zip(self.names, held) if k == 0]
        if empty:
            raise BoundaryConditionError(f"electrode(s) {empty} hold or touch no element on any rank: check their "
                                         "selection (a wall electrode: is the bed pressed against it?)")
        reach = spread_over_parts(network, ex, ((el >= 0) | self.linked.any(axis=0)).astype(np.int64), op="max")
        self.floating = reach == 0
        part = spread_over_parts(network, ex, network.owned_key, op="min")
        # the parts each electrode touches (its elements' labels, from every rank)
        touched = comm.allgather([np.unique(np.concatenate([part[el == k], part[self.linked[k]]]))
                                  for k in range(len(self.names))])
        self._parts_of = [set(np.concatenate([t[k] for t in touched]).tolist()) for k in range(len(self.names))]
        n_float = int(comm.allreduce(int(np.count_nonzero(self.floating))))
        if n_float:
            heads = int(comm.allreduce(int(np.count_nonzero(self.floating & (part == network.owned_key)))))
            if comm.Get_rank() == 0:
                warnings.warn(floating_message(n_float, heads, "electrode", "a potential of 0 V"), stacklevel=2)
        self._share = _Share(network, (el >= 0) | self.floating, comm, preconditioner, rtol, pos, spacing, options,
                             exchange=ex, smoother=smoother)
        self.electrode_of = el
        self._el_local = ex.local(np.where(self.floating, len(self.names), el))
        self._x = {}
        self.update_conductance(conductance)

    def _imposed(self, currents) -> np.ndarray:
        """The imposed currents [A] per electrode, NaN where held at a potential."""
        if currents is None:
            return np.full(len(self.names), np.nan)
        if isinstance(currents, Mapping):
            currents = [currents.get(n) for n in self.names]
        out = np.array([np.nan if v is None else float(v) for v in currents])
        if out.shape != (len(self.names),) or np.any(np.isinf(out)):
            raise BoundaryConditionError(f"currents: one finite value (A) or None per electrode {self.names}")
        if np.all(np.isfinite(out)):
            raise BoundaryConditionError(f"every electrode of {self.names} has an imposed current: hold one at a "
                                         "potential (potential=0, the ground) to give the current a return path")
        return out

    def _links(self, links, n: int) -> np.ndarray:
        if links is None:
            return np.zeros((len(self.names), n))
        g = np.asarray(links, dtype=float)
        if g.shape != (len(self.names), n) or not np.all(np.isfinite(g)) or np.any(g < 0):
            raise BoundaryConditionError(f"links must be finite conductances >= 0 (S), shaped (electrodes, owned "
                                         f"nodes) = ({len(self.names)}, {n}), got shape {g.shape}")
        return g

    def links_fit(self, links) -> bool:
        """True when ``links`` join the same nodes to the same electrodes as the kept
        structure (then :meth:`update_conductance` takes them; else build anew). Local: the
        caller joins the ranks' answers."""
        return bool(np.array_equal(self._links(links, self.network.n_owned) > 0, self.linked))

    def _values(self, values) -> np.ndarray:
        if isinstance(values, Mapping):
            missing = [n for n in self.names if n not in values]
            if missing:
                raise BoundaryConditionError(f"no potential given for electrode(s) {missing}")
            v = [values[n] for n in self.names]
        else:
            v = list(values)
            if len(v) != len(self.names):
                raise BoundaryConditionError(f"{len(v)} potentials for {len(self.names)} electrodes")
        v = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(v)):
            raise BoundaryConditionError(f"electrode potentials must be finite (V), got {v.tolist()}")
        return v

    @property
    def held(self) -> np.ndarray:
        """(n_local,) bool: the local nodes (owned, then ghosts) that are an electrode's own
        elements, held at its potential."""
        return (self._el_local >= 0) & (self._el_local < len(self.names))

    @property
    def network(self) -> LocalNetwork:
        return self._share.network

    def close(self):
        """Free the solver's PETSc objects (collective); the object is not usable after."""
        self._share.system.destroy()

    def update_conductance(self, conductance, links=None):
        """New edge conductances [S], same edges, and new link conductances (same linked
        nodes: :meth:`links_fit`) when given (collective); the setup is kept."""
        s = self._share
        c = self.conductance = s.edge_values(conductance, BoundaryConditionError,
                                             "conductances must be finite and >= 0 (S), one per edge of the share")
        if links is not None:
            if not self.links_fit(links):
                raise BoundaryConditionError("the links join other nodes than the kept structure's: build anew")
            self.links = self._links(links, self.network.n_owned)
        s.system.set_values(s.rows.values(c, self.links.sum(axis=0)), s.exchange)

    def solve(self, values=None, currents=None):
        """The potential [V] on the local nodes (owned, then ghosts) (collective): the
        electrodes at ``values`` (V), or, for those with an imposed current (``currents``, as
        the constructor's; default the kept ones), at the potentials that feed it."""
        if values is not None:
            self.values = self._values(values)
        if currents is not None:
            self.imposed = self._imposed(currents)
        fed = np.flatnonzero(np.isfinite(self.imposed))
        if fed.size == 0:
            return self._solve_at(self.values, "held")
        self._check_return_paths(fed)
        base = self.values.copy()
        base[fed] = 0.0
        phi = self._solve_at(base, "held")
        I0, iterations = self._currents(), int(self.info["iterations"])
        unit, S = [], np.zeros((fed.size, fed.size))
        for col, k in enumerate(fed):                # each fed electrode at 1 V, every other at 0 V
            v = np.zeros(len(self.names))
            v[k] = 1.0
            unit.append(self._solve_at(v, int(k)))
            S[:, col] = self._currents()[fed]
            iterations += int(self.info["iterations"])
        U = np.linalg.solve(S, self.imposed[fed] - I0[fed])
        base[fed] = U
        self.values = base
        self.potential = phi + sum(u * p for u, p in zip(U, unit))
        self.info = dict(self.info, iterations=iterations, solves=1 + fed.size)
        return self.potential

    def _solve_at(self, values, key):
        """One solve with the electrodes at ``values`` [V]; ``key`` names the start kept for it."""
        s = self._share
        self.values = np.asarray(values, dtype=float)
        fixed = np.append(self.values, 0.0)[self._el_local]
        rhs = s.rows.fixed_rhs(self.conductance, fixed) + (self.values @ self.links)[s.rows.free_owned]
        x, self.info = s.system.solve(rhs, x0=self._x.get(key))
        self._x[key] = x
        own = fixed[:self.network.n_owned].copy()
        own[s.rows.free_owned] = x
        self.potential = s.exchange.local(own)
        return self.potential

    def _check_return_paths(self, fed):
        """BoundaryConditionError when an electrode with an imposed current is joined (through
        the parts it touches and the electrodes they hold) to no electrode held at a potential."""
        group = list(range(len(self.names)))         # electrodes joined by the parts they share

        def root(k):
            while group[k] != k:
                k = group[k]
            return k
        for a in range(len(self.names)):
            for b in range(a + 1, len(self.names)):
                if self._parts_of[a] & self._parts_of[b]:
                    group[root(a)] = root(b)
        grounded = {root(k) for k in range(len(self.names)) if not np.isfinite(self.imposed[k])}
        lone = [self.names[k] for k in fed if root(int(k)) not in grounded]
        if lone:
            raise BoundaryConditionError(
                f"an imposed current has no return path: electrode(s) {lone} touch no part of the network that "
                "also holds an electrode at a potential; ground one electrode (potential=0) in that part")

    def branch_current(self) -> np.ndarray:
        """Current [A] of each edge of the share, from its first node to its second."""
        e = self.network.edges
        return self.conductance * (self.potential[e[:, 0]] - self.potential[e[:, 1]])

    def link_currents(self) -> np.ndarray:
        """(n_electrodes, n_owned) current [A] of each link, from its electrode into the node."""
        return self.links * (self.values[:, None] - self.potential[None, :self.network.n_owned])

    def _currents(self) -> np.ndarray:
        """Current [A] leaving each electrode into the network, summed over the ranks: through
        its elements' edges and links, and through its links."""
        out = out_of_owned(self.network, self.branch_current()) - self.link_currents().sum(axis=0)
        el = self.electrode_of
        mine = np.bincount(el[el >= 0], out[el >= 0], len(self.names)) + self.link_currents().sum(axis=1)
        return summed(self._share.comm, mine)

    def electrode_currents(self) -> dict:
        """Current [A] leaving each electrode into the network, summed over the ranks."""
        return dict(zip(self.names, self._currents().tolist()))

    def electrode_potentials(self) -> dict:
        """Potential [V] of each electrode (an imposed current's: the one that feeds it)."""
        return dict(zip(self.names, self.values.tolist()))

    def equivalent_resistance(self, a: Optional[str] = None, b: Optional[str] = None) -> float:
        """(V_a - V_b) / I_a between two electrodes [ohm] (the first two by default); inf when
        no connected part holds elements of both."""
        a = self.names[0] if a is None else a
        b = self.names[1] if b is None else b
        ka, kb = self.names.index(a), self.names.index(b)
        if not (self._parts_of[ka] & self._parts_of[kb]):
            return float("inf")                 # no path joins them (the serial rule: never a huge finite R)
        i = self.electrode_currents()[a]
        return float((self.values[ka] - self.values[kb]) / i) if i != 0 else float("inf")

    def joule_power(self) -> np.ndarray:
        """Joule heat [W] of each owned node: each edge's c dV^2 shared half and half by its
        ends, and its links' c dV^2."""
        e = self.network.edges
        p = self.conductance * (self.potential[e[:, 0]] - self.potential[e[:, 1]]) ** 2
        n = self.network.n_owned
        out = np.zeros(n)
        for col in (0, 1):
            mine = e[:, col] < n
            out += 0.5 * np.bincount(e[mine, col], p[mine], n)
        if self.linked.any():                   # a link's heat is its element's, as serially
            out += (self.links * (self.values[:, None] - self.potential[None, :n]) ** 2).sum(axis=0)
        return out


class PartitionedHeat:
    """``C dT/dt = -K T - h A (T - T_inf) + P`` on this rank's share, by the theta method.

    Parameters
    ----------
    network : LocalNetwork
    capacity : (n_owned,) heat capacities [J/K] > 0
    conductance : (m,) thermal conductances [W/K] of the share's edges
    temperature : float or (n_owned,) initial temperatures [K]
    fixed : (n_owned,) float, NaN where free, the held temperature [K] elsewhere; optional
    h_area, t_inf : (n_owned,) convection h A [W/K] and ambient temperature [K]; optional
    theta : as :func:`~yade_electro.network.theta.theta_of` (default backward Euler)
    safety, max_substeps : the explicit sub-steps' fraction of the stable step and their limit
    smoother : the deflation's smoother, 'icc' or 'jacobi' (see PartitionedSystem)
    links : dict name -> temperature [K] of fixed temperatures held apart from the nodes (an
        isothermal wall) and joined to them by conductances set by :meth:`set_links`; the heat
        each gives is in ``link_energy`` [J] and :meth:`link_flows` [W]
    """

    def __init__(self, network: LocalNetwork, capacity, conductance, temperature, *, fixed=None, h_area=None,
                 t_inf=None, theta="backward-euler", comm=None, preconditioner: str = "deflation",
                 rtol: float = 1e-12, pos=None, spacing: Optional[float] = None, options: Optional[dict] = None,
                 safety: float = 0.9, max_substeps: int = 100000, smoother: str = "icc", links=None):
        n = network.n_owned
        self.safety, self.max_substeps, self.substeps = float(safety), int(max_substeps), 0
        self.link_names = list(links or {})
        self.link_value = np.array([float(v) for v in (links or {}).values()])
        self.link_G = np.zeros((len(self.link_names), n))
        self.link_energy = {k: 0.0 for k in self.link_names}
        C = np.asarray(capacity, dtype=float)
        if C.shape != (n,) or not np.all(np.isfinite(C)) or np.any(C <= 0):
            raise ThermalError(f"heat capacities must be finite and > 0 (J/K), one per owned node ({n})")
        self.capacity = C
        self.fixed = np.full(n, np.nan) if fixed is None else np.asarray(fixed, dtype=float)
        self.h_area = np.zeros(n) if h_area is None else np.asarray(h_area, dtype=float)
        self.t_inf = np.zeros(n) if t_inf is None else np.asarray(t_inf, dtype=float)
        self.theta = theta_of(theta)
        held = ~np.isnan(self.fixed)
        self._share = _Share(network, held, comm, preconditioner, rtol, pos, spacing, options, smoother=smoother)
        self._held = held
        T = np.broadcast_to(np.asarray(temperature, dtype=float), (n,)).copy()
        T[held] = self.fixed[held]
        self.T = T
        self.time = 0.0
        self._dT = None
        self.update_conductance(conductance)

    @property
    def network(self) -> LocalNetwork:
        return self._share.network

    def close(self):
        """Free the solver's PETSc objects (collective); the object is not usable after."""
        self._share.system.destroy()

    def update_conductance(self, conductance):
        """New edge conductances [W/K], same edges (collective)."""
        self.conductance = self._share.edge_values(
            conductance, ThermalError, "thermal conductances must be finite and >= 0 (W/K), one per edge of the share")
        self._dt = None                         # the step matrix is made again at the next step

    def set_links(self, name: str, conductance):
        """The conductances [W/K] joining each owned node to the linked fixed temperature
        ``name`` now (0: not touching); a value change, from the next step on."""
        if name not in self.link_names:
            raise ThermalError(f"no linked fixed temperature named {name!r}; have {self.link_names}")
        g = np.asarray(conductance, dtype=float)
        if g.shape != (self.network.n_owned,) or not np.all(np.isfinite(g)) or np.any(g < 0):
            raise ThermalError(f"links of {name!r}: conductances must be finite and >= 0 (W/K), one per owned node")
        k = self.link_names.index(name)
        if not np.array_equal(g, self.link_G[k]):
            self.link_G[k] = g
            self._dt = None                     # the step matrix is made again at the next step

    def link_flows(self, T_owned=None) -> dict:
        """Heat flow [W] into the network through each linked fixed temperature, all ranks."""
        T = self.T if T_owned is None else np.asarray(T_owned, dtype=float)
        mine = (self.link_G * (self.link_value[:, None] - T[None, :])).sum(axis=1)
        return dict(zip(self.link_names, summed(self._share.comm, mine).tolist())) if self.link_names else {}

    @property
    def _hA(self) -> np.ndarray:
        """h A plus the links' conductances [W/K] per owned node (what leaves to fixed ambients)."""
        return self.h_area + self.link_G.sum(axis=0)

    def _free(self, a):
        return np.asarray(a)[self._share.rows.free_owned]

    def flow(self, T_owned=None) -> np.ndarray:
        """``(K T)_i + h_i A_i T_i`` [W] on every owned node: the heat it gives its neighbours
        (fixed ones too) and the ambient's h A T part, links included (collective: ghosts from
        their owners)."""
        T0 = self.T if T_owned is None else np.asarray(T_owned, dtype=float)
        T = self._share.exchange.local(T0)
        e = self.network.edges
        return out_of_owned(self.network, self.conductance * (T[e[:, 0]] - T[e[:, 1]])) + self._hA * T0

    def stable_time_step(self) -> float:
        """The forward-Euler bound min C_i / (sum_j G_ij + h_i A_i) over the free nodes [s], all ranks."""
        from mpi4py import MPI
        e, n = self.network.edges, self.network.n_owned
        d = self._hA
        for col in (0, 1):
            mine = e[:, col] < n
            d += np.bincount(e[mine, col], self.conductance[mine], n)
        sel = (d > 0) & ~self._held
        mine = float(np.min(self.capacity[sel] / d[sel])) if np.any(sel) else np.inf
        return self._share.comm.allreduce(mine, op=MPI.MIN)

    def advance(self, dt: float, power=None) -> np.ndarray:
        """A step of ``dt`` [s] with sources ``power`` [W] per owned node held over it; returns
        the owned temperatures [K] (collective). The change dT of the free nodes solves
        ``(C/dt + theta K_uu) dT = s - K T`` (no solve for theta = 0). For theta < 1/2 a step
        above ``safety`` times the stable one is split into equal sub-steps, as serially
        (:class:`~yade_electro.network.transient.HeatSolver`); ``substeps`` says how many. A
        failed step leaves the state as it was."""
        if not (dt > 0 and np.isfinite(dt)):
            raise ThermalError(f"the time step must be finite and > 0 (s), got {dt}")
        n = self.network.n_owned
        P = np.zeros(n) if power is None else np.asarray(power, dtype=float)
        if P.shape != (n,) or not np.all(np.isfinite(P)):
            raise ThermalError(f"sources must be finite (W), one per owned node ({n})")
        self.substeps = 1
        if self.theta < 0.5:
            largest = self.safety * self.stable_time_step() / (1.0 - 2.0 * self.theta)
            if dt > largest:
                self.substeps = int(math.ceil(dt / largest))
                if self.substeps > self.max_substeps:
                    raise ThermalError(f"dt = {dt:.3e} s needs {self.substeps} explicit sub-steps (stable step "
                                       f"{largest:.3e} s), more than max_substeps = {self.max_substeps}; take "
                                       "smaller steps or theta >= 1/2")
        T = self.T
        flows = np.zeros(len(self.link_names))
        for _ in range(self.substeps):
            T, T_theta = self._step(T, dt / self.substeps, P)
            flows += (self.link_G * (self.link_value[:, None] - T_theta[None, :])).sum(axis=1)
        self.T = T
        self.time += dt
        if self.link_names:                     # at the scheme's theta-point: the exact discrete balance
            got = summed(self._share.comm, flows * (dt / self.substeps))
            for k, name in enumerate(self.link_names):
                self.link_energy[name] += float(got[k])
        return T

    def _step(self, T0, h, P):
        """One (sub-)step of ``h`` [s]: (T at its end, T at its theta point)."""
        s, th = self._share, self.theta
        ambient = self.h_area * self.t_inf + self.link_value @ self.link_G     # (0, n) links: zeros
        rhs = self._free(ambient + P - self.flow(T0))
        Cdt = self.capacity / h
        if th == 0.0:
            dT = rhs / self._free(Cdt)
        else:
            if self._dt != h:                   # the step matrix for this step and these conductances
                s.system.set_values(s.rows.values(th * self.conductance, th * self._hA + Cdt), s.exchange)
            dT, self.info = s.system.solve(rhs, x0=self._dT)
            self._dT = dT
        self._dt = h
        new = self._free(T0) + dT
        if not np.all(np.isfinite(new)):
            raise ThermalError("the heat step gave non-finite temperatures; the state is kept")
        T, T_theta = T0.copy(), T0.copy()
        T[s.rows.free_owned] = new
        T_theta[s.rows.free_owned] = self._free(T0) + th * dT
        return T, T_theta

    def heat_content(self, reference: float = 0.0) -> float:
        """sum C (T - reference) [J] over all ranks."""
        return float(summed(self._share.comm, [self.capacity @ (self.T - reference)])[0])


def out_of_owned(network: LocalNetwork, per_edge) -> np.ndarray:
    """Sum over each owned node's edges of ``per_edge`` (a flow from an edge's first node to
    its second), counted out of the node."""
    n, e = network.n_owned, network.edges
    out = np.zeros(n)
    for col, sign in ((0, 1.0), (1, -1.0)):
        mine = e[:, col] < n
        out += np.bincount(e[mine, col], sign * per_edge[mine], n)
    return out
