"""Kirchhoff assembly, boundary conditions, solvers, currents and equivalent resistance.

The network: nodes with potentials u [V], edges with conductances c [S]. With the
incidence matrix A (row k: -1 at ``edges[k, 0]``, +1 at ``edges[k, 1]``) the nodal
matrix is K = A^T C A (a weighted graph Laplacian) and Kirchhoff's current law reads
K u = f, f the currents injected into the nodes [A].

Boundary conditions are *electrodes*: sets of nodes tied together by a perfect conductor
(one potential for all of them) that are either held at a fixed potential or fed with an
imposed total current. Each electrode becomes one super-node of the reduced system; nodes
that belong to no electrode may also receive injected currents.

Sign conventions
----------------
* ``branch_current[k]`` is the current flowing from node ``edges[k, 0]`` to node
  ``edges[k, 1]``: w = c (u_i - u_j) = -C A u.
* ``electrode_current[name]`` is the current the external circuit feeds *into the network*
  at that electrode (positive at the high-potential electrode of a resistor).
* R_eq(a, b) = (V_a - V_b) / I_a.

Floating clusters (connected parts of the network with no fixed-potential electrode and no
current) carry no current; their potential is undefined, it is set to 0 V and flagged in
``PotentialSolution.floating`` (a warning says how many nodes). A part with an imposed
current and no fixed-potential electrode has no return path and raises.
"""
from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field
from typing import Dict, Mapping, Optional, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from .errors import BoundaryConditionError, MaterialError, SolverError

__all__ = ["Electrode", "PotentialSolution", "ConductionProblem", "laplacian", "solve_potential", "edge_power",
           "equivalent_resistance", "make_solver", "DirectSolver", "CGSolver", "solver_names"]

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------------------------
# assembly
# ---------------------------------------------------------------------------------------
def laplacian(edges, conductance, n_nodes: int) -> sp.csr_matrix:
    """K = A^T C A of a network [S]: symmetric, rows summing to zero.

    Parameters
    ----------
    edges : (m, 2) int array of node indices
    conductance : (m,) array of edge conductances [S], >= 0
    n_nodes : number of nodes
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    c = np.asarray(conductance, dtype=float)
    if c.shape != (edges.shape[0],):
        raise ValueError(f"conductance must have one value per edge ({edges.shape[0]}), got {c.shape}")
    i, j = edges[:, 0], edges[:, 1]
    diag = np.bincount(i, c, n_nodes) + np.bincount(j, c, n_nodes)
    rows = np.concatenate([i, j, np.arange(n_nodes)])
    cols = np.concatenate([j, i, np.arange(n_nodes)])
    vals = np.concatenate([-c, -c, diag])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_nodes, n_nodes))


# ---------------------------------------------------------------------------------------
# solvers: one protocol, solve(A, b, x0=None) -> (x, info); setup kept while A is the same object
# ---------------------------------------------------------------------------------------
class _Solver:
    name = "?"

    def __init__(self):
        self._A = None
        self.setup_time = 0.0

    def _ensure_setup(self, A):
        if A is not self._A:
            t = time.perf_counter()
            self._setup(A)
            self._A = A
            self.setup_time = time.perf_counter() - t
            return True
        return False

    def _setup(self, A):  # pragma: no cover - abstract
        raise NotImplementedError

    @staticmethod
    def _residual(A, x, b):
        nb = np.linalg.norm(b)
        r = np.linalg.norm(A @ x - b)
        return r / nb if nb > 0 else r


class DirectSolver(_Solver):
    """Sparse LU (SuperLU, COLAMD ordering) of the reduced SPD system; the factorisation is
    kept and reused while the matrix object is unchanged. Exact to rounding."""

    name = "direct"

    def _setup(self, A):
        self._lu = spla.splu(sp.csc_matrix(A), permc_spec="COLAMD")

    def solve(self, A, b, x0=None):
        fresh = self._ensure_setup(A)
        x = self._lu.solve(np.asarray(b, dtype=float))
        return x, {"solver": self.name, "iterations": 0, "residual": self._residual(A, x, b),
                   "setup": fresh, "setup_time": self.setup_time}


class CGSolver(_Solver):
    """Preconditioned conjugate gradient (the paper's choice) for the SPD reduced system.

    Parameters
    ----------
    rtol : float
        Stop when ||A x - b|| <= rtol ||b|| (default 1e-10, enough for current conservation
        to 1e-9 relative).
    preconditioner : {'amg', 'jacobi', 'none'}
        'amg' = smoothed-aggregation algebraic multigrid (PyAMG) V-cycle; 'jacobi' = the
        diagonal. 'amg' falls back to 'jacobi' with a warning when PyAMG is not installed.
    maxiter : int, optional
        Default 10 n.
    """

    name = "cg"

    def __init__(self, rtol: float = 1e-10, preconditioner: str = "jacobi", maxiter: Optional[int] = None):
        super().__init__()
        if preconditioner not in ("amg", "jacobi", "none"):
            raise ValueError(f"preconditioner must be 'amg', 'jacobi' or 'none', got {preconditioner!r}")
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must be in (0, 1), got {rtol}")
        if preconditioner == "amg":
            try:
                import pyamg  # noqa: F401
            except ImportError:
                warnings.warn("PyAMG is not installed: CG falls back to the Jacobi preconditioner "
                              "(install it with `make install` or `pip install pyamg`)", stacklevel=2)
                preconditioner = "jacobi"
        self.rtol = rtol
        self.preconditioner = preconditioner
        self.maxiter = maxiter

    def _setup(self, A):
        A = sp.csr_matrix(A)
        self._Acsr = A
        if self.preconditioner == "amg":
            import pyamg
            ml = pyamg.smoothed_aggregation_solver(A, symmetry="symmetric", max_coarse=200)
            self._M = ml.aspreconditioner(cycle="V")
        elif self.preconditioner == "jacobi":
            d = A.diagonal()
            if np.any(d <= 0):
                raise SolverError("the matrix has a non-positive diagonal entry: a node with no "
                                  "conducting edge was left among the unknowns")
            inv = 1.0 / d
            self._M = lambda r: inv * r
        else:
            self._M = lambda r: r

    def solve(self, A, b, x0=None):
        fresh = self._ensure_setup(A)
        A = self._Acsr
        b = np.asarray(b, dtype=float)
        n = b.shape[0]
        nb = np.linalg.norm(b)
        x = np.zeros(n) if x0 is None else np.array(x0, dtype=float, copy=True)
        if nb == 0:
            x[:] = 0.0
            return x, {"solver": self.name, "iterations": 0, "residual": 0.0, "setup": fresh,
                       "setup_time": self.setup_time}
        tol = self.rtol * nb
        maxiter = self.maxiter or 10 * n + 10
        M = self._M
        r = b - A @ x
        rn = np.linalg.norm(r)
        it = 0
        if rn > tol:
            z = M(r)
            p = z.copy()
            rz = r @ z
            while it < maxiter:
                it += 1
                q = A @ p
                pq = p @ q
                if pq <= 0:
                    raise SolverError("CG broke down (p.Ap <= 0): the matrix is not positive definite; "
                                      "check for negative conductances")
                a = rz / pq
                x += a * p
                r -= a * q
                rn = np.linalg.norm(r)
                if rn <= tol:
                    break
                z = M(r)
                rz_new = r @ z
                p *= rz_new / rz
                p += z
                rz = rz_new
        res = np.linalg.norm(b - A @ x) / nb
        if not np.all(np.isfinite(x)):
            raise SolverError("CG produced non-finite potentials; check conductances for inf/nan")
        if res > 10 * self.rtol:
            raise SolverError(f"CG did not converge: relative residual {res:.3e} > rtol {self.rtol:g} "
                              f"after {it} iterations; raise maxiter or use solver='direct'")
        return x, {"solver": self.name, "preconditioner": self.preconditioner, "iterations": it,
                   "residual": res, "setup": fresh, "setup_time": self.setup_time}


_SOLVERS = {"direct": DirectSolver, "cg": CGSolver,
            "cg-amg": lambda **kw: CGSolver(preconditioner="amg", **kw),
            "cg-jacobi": lambda **kw: CGSolver(preconditioner="jacobi", **kw)}


def solver_names() -> tuple:
    return tuple(sorted(_SOLVERS))


def make_solver(solver="cg", **kw):
    """A solver object from a name ('cg' = 'cg-jacobi', 'cg-amg', 'direct') or pass an object
    with a ``solve(A, b, x0=None) -> (x, info)`` method through."""
    if hasattr(solver, "solve"):
        return solver
    try:
        return _SOLVERS[solver](**kw)
    except KeyError:
        raise ValueError(f"unknown solver {solver!r}; known: {', '.join(solver_names())}") from None


# ---------------------------------------------------------------------------------------
# boundary conditions
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Electrode:
    """A set of nodes tied by a perfect conductor, at a fixed potential or fed a current.

    Parameters
    ----------
    name : str
    nodes : int array
        Node indices (not body ids; see ``ContactGraph.index_of``).
    potential : float, optional
        Fixed potential [V].
    current : float, optional
        Imposed total current [A] fed into the network (its potential is then an unknown).
        Give exactly one of ``potential`` and ``current``.
    """

    name: str
    nodes: np.ndarray
    potential: Optional[float] = None
    current: Optional[float] = None

    def __post_init__(self):
        nodes = np.unique(np.asarray(self.nodes, dtype=np.int64).reshape(-1))
        if nodes.size == 0:
            raise BoundaryConditionError(f"electrode {self.name!r} selects no element: check its "
                                         "predicate/box, ids or mask against the packing")
        if (self.potential is None) == (self.current is None):
            raise BoundaryConditionError(f"electrode {self.name!r}: give exactly one of potential= "
                                         "(fixed potential, V) or current= (imposed current, A)")
        v = self.potential if self.potential is not None else self.current
        if not np.isfinite(v):
            raise BoundaryConditionError(f"electrode {self.name!r}: value must be finite, got {v}")
        nodes.setflags(write=False)
        object.__setattr__(self, "nodes", nodes)

    @property
    def fixed(self) -> bool:
        return self.potential is not None

    @property
    def value(self) -> float:
        return float(self.potential if self.fixed else self.current)


# ---------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class PotentialSolution:
    """Result of one potential solve (SI units: V, A, ohm).

    Attributes
    ----------
    potential : (n,) node potentials [V] (0 on floating clusters)
    branch_current : (m,) current from ``edges[k,0]`` to ``edges[k,1]`` [A]
    electrode_potential, electrode_current : dict name -> V, A (current fed into the network)
    floating : (n,) bool, nodes in clusters with no electrode (no current, potential undefined)
    residual : relative residual ||K x - b|| / ||b|| of the reduced system
    current_imbalance : |sum of electrode currents + injections| / max |electrode current|
    info : solver information (name, iterations, times)
    """

    potential: np.ndarray
    branch_current: np.ndarray
    electrode_potential: Dict[str, float]
    electrode_current: Dict[str, float]
    floating: np.ndarray
    residual: float
    current_imbalance: float
    component_of_electrode: Dict[str, int]
    info: dict = field(default_factory=dict)

    def equivalent_resistance(self, a: str, b: str) -> float:
        """R_eq = (V_a - V_b) / I_a [ohm] between electrodes a and b; inf when they are not
        connected (no current flows)."""
        for e in (a, b):
            if e not in self.electrode_current:
                raise BoundaryConditionError(f"no electrode named {e!r}; have {sorted(self.electrode_current)}")
        if self.component_of_electrode[a] != self.component_of_electrode[b]:
            return float("inf")
        dv = self.electrode_potential[a] - self.electrode_potential[b]
        i = self.electrode_current[a]
        scale = max(abs(v) for v in self.electrode_current.values()) or 1.0
        if abs(i) <= 1e-14 * scale or i == 0.0:
            return float("inf") if dv != 0 else float("nan")
        return dv / i

    def joule_power(self, conductance) -> np.ndarray:
        """Power dissipated in each edge, w^2 / c [W] (see :func:`edge_power`)."""
        return edge_power(self.branch_current, conductance)


def edge_power(branch_current, conductance) -> np.ndarray:
    """Power dissipated in each edge, w^2 / c [W]; 0 on edges of zero conductance (they
    carry no current)."""
    c = np.asarray(conductance, dtype=float)
    out = np.zeros_like(c)
    nz = c > 0
    out[nz] = np.asarray(branch_current, dtype=float)[nz] ** 2 / c[nz]
    return out


# ---------------------------------------------------------------------------------------
# the problem: structure (graph, conductances, electrode node sets) fixed, values free
# ---------------------------------------------------------------------------------------
class ConductionProblem:
    """Reduced Kirchhoff system of a network with electrodes, kept for repeated solves.

    Building it checks the boundary conditions and the cluster structure; ``solve`` can then
    be called many times with other electrode values (and reuses the solver's setup and the
    previous solution as starting guess).

    Parameters
    ----------
    n_nodes : int
    edges : (m, 2) int array
    conductance : (m,) array [S]
    electrodes : sequence of Electrode
    injection : (n,) array of currents injected into nodes [A], optional
    solver : name or solver object (see ``make_solver``)
    """

    def __init__(self, n_nodes: int, edges, conductance, electrodes: Sequence[Electrode],
                 injection=None, solver="cg"):
        self.n = n = int(n_nodes)
        self.edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        c = np.asarray(conductance, dtype=float)
        if c.shape != (self.edges.shape[0],):
            raise ValueError(f"conductance must have one value per edge ({self.edges.shape[0]}), got {c.shape}")
        if not np.all(np.isfinite(c)) or np.any(c < 0):
            raise MaterialError("conductances must be finite and >= 0 (check resistivity and radii)")
        self.c = c
        self.electrodes = list(electrodes)
        if not self.electrodes:
            raise BoundaryConditionError("no electrode given: at least one fixed-potential electrode is needed")
        names = [e.name for e in self.electrodes]
        if len(set(names)) != len(names):
            raise BoundaryConditionError(f"electrode names must be unique, got {names}")
        owner = np.full(n, -1, dtype=np.int64)
        for k, e in enumerate(self.electrodes):
            outside = e.nodes[(e.nodes < 0) | (e.nodes >= n)]
            if outside.size:
                raise BoundaryConditionError(f"electrode {e.name!r} names node {outside[-1]} but the "
                                             f"network has {n} nodes (indices 0..{n - 1})")
            clash = e.nodes[owner[e.nodes] >= 0]
            if clash.size:
                other = self.electrodes[owner[clash[0]]].name
                raise BoundaryConditionError(
                    f"{clash.size} element(s) belong to both electrodes {other!r} and {e.name!r} "
                    f"(e.g. node {clash[0]}); make the selections disjoint")
            owner[e.nodes] = k
        self.injection = None
        if injection is not None:
            f = np.asarray(injection, dtype=float)
            if f.shape != (n,) or not np.all(np.isfinite(f)):
                raise BoundaryConditionError(f"injection must be a finite array of shape ({n},)")
            self.injection = f
        self._owner = owner
        self._build()
        self.solver = make_solver(solver)
        self._x_prev = None

    def _build(self):
        n, ne = self.n, len(self.electrodes)
        owner = self._owner
        free = np.flatnonzero(owner < 0)
        nf = free.size
        # reduced index of every node: free nodes first, then one super-node per electrode
        ridx = np.empty(n, dtype=np.int64)
        ridx[free] = np.arange(nf)
        ridx[owner >= 0] = nf + owner[owner >= 0]
        nr = nf + ne
        re = ridx[self.edges]
        keep = (re[:, 0] != re[:, 1]) & (self.c > 0)
        Kr = laplacian(re[keep], self.c[keep], nr)
        ncomp, label = connected_components(Kr, directed=False)
        fixed = np.array([e.fixed for e in self.electrodes], dtype=bool)
        el_rows = nf + np.arange(ne)
        comp_fixed = np.zeros(ncomp, dtype=bool)
        comp_fixed[label[el_rows[fixed]]] = True
        # currents without a return path
        comp_current = np.zeros(ncomp, dtype=bool)
        for k, e in enumerate(self.electrodes):
            if not e.fixed and e.current != 0:
                comp_current[label[el_rows[k]]] = True
        if self.injection is not None:
            nzf = np.flatnonzero(self.injection[free] != 0)
            comp_current[label[nzf]] = True
        bad = comp_current & ~comp_fixed
        if np.any(bad):
            names = [e.name for k, e in enumerate(self.electrodes) if bad[label[el_rows[k]]] and not e.fixed]
            raise BoundaryConditionError(
                "an imposed current has no return path: a connected part of the network carries an "
                f"imposed current (electrodes {names or 'none; node injections'}) but no fixed-potential "
                "electrode; ground one electrode (potential=0) in that part")
        solved = comp_fixed[label]
        unknown = solved.copy()
        unknown[el_rows[fixed]] = False
        self._nf, self._nr, self._ridx, self._free = nf, nr, ridx, free
        self._Kr, self._label = Kr, label
        self._unknown = np.flatnonzero(unknown)
        self._dirichlet = el_rows[fixed]
        self._fixed = fixed
        Kr_csr = Kr.tocsr()
        self._Kuu = Kr_csr[self._unknown][:, self._unknown].tocsr()
        self._Kud = Kr_csr[self._unknown][:, self._dirichlet].tocsr()
        self._floating_r = ~solved
        self.floating = self._floating_r[ridx]
        nfl = int(self.floating.sum())
        if nfl:
            ncl = np.unique(label[~solved]).size
            warnings.warn(f"{nfl} element(s) in {ncl} cluster(s) are connected to no fixed-potential "
                          "electrode: they carry no current and their potential is set to 0 V "
                          "(see PotentialSolution.floating)", stacklevel=3)
        self.component_of_electrode = {e.name: int(label[el_rows[k]]) for k, e in enumerate(self.electrodes)}

    def solve(self, values: Optional[Mapping[str, float]] = None, x0=None) -> PotentialSolution:
        """Solve for the potentials.

        Parameters
        ----------
        values : mapping name -> value, optional
            New potentials [V] / currents [A] for some electrodes (kind unchanged).
        x0 : initial guess of the unknown reduced potentials; default the previous solution.
        """
        t0 = time.perf_counter()
        vals = np.array([e.value for e in self.electrodes], dtype=float)
        if values:
            idx = {e.name: k for k, e in enumerate(self.electrodes)}
            for name, v in values.items():
                if name not in idx:
                    raise BoundaryConditionError(f"no electrode named {name!r}; have {sorted(idx)}")
                if not np.isfinite(v):
                    raise BoundaryConditionError(f"electrode {name!r}: value must be finite, got {v}")
                vals[idx[name]] = float(v)
        nf, nr = self._nf, self._nr
        # right-hand side on the reduced nodes
        f_r = np.zeros(nr)
        if self.injection is not None:
            np.add.at(f_r, self._ridx, self.injection)
        f_r[nf:][~self._fixed] += vals[~self._fixed]
        xd = vals[self._fixed]
        b = f_r[self._unknown] - self._Kud @ xd
        if x0 is None:
            x0 = self._x_prev
        if self._unknown.size:
            xu, info = self.solver.solve(self._Kuu, b, x0=x0)
        else:
            xu, info = np.zeros(0), {"solver": "none", "iterations": 0, "residual": 0.0}
        if not np.all(np.isfinite(xu)):
            raise SolverError("the potential solve returned non-finite values")
        self._x_prev = xu
        x = np.zeros(nr)
        x[self._unknown] = xu
        x[self._dirichlet] = xd
        u = x[self._ridx]
        i, j = self.edges[:, 0], self.edges[:, 1]
        w = self.c * (u[i] - u[j])
        net = self._Kr @ x                      # current leaving each reduced node into the bonds
        el_rows = nf + np.arange(len(self.electrodes))
        # net current leaving an electrode into the network = external feed + node injections on it
        inj_el = f_r[el_rows] - np.where(self._fixed, 0.0, vals)
        el_current = np.where(self._fixed, net[el_rows] - inj_el, vals)
        el_pot = x[el_rows]
        total_in = el_current.sum() + (self.injection.sum() if self.injection is not None else 0.0)
        scale = np.max(np.abs(el_current)) if el_current.size else 0.0
        imbalance = abs(total_in) / scale if scale > 0 else 0.0
        info = dict(info)
        info["solve_time"] = time.perf_counter() - t0
        info["n_unknowns"] = int(self._unknown.size)
        return PotentialSolution(
            potential=_ro(u), branch_current=_ro(w),
            electrode_potential={e.name: float(el_pot[k]) for k, e in enumerate(self.electrodes)},
            electrode_current={e.name: float(el_current[k]) for k, e in enumerate(self.electrodes)},
            floating=_ro(self.floating.copy()), residual=float(info.get("residual", 0.0)),
            current_imbalance=float(imbalance), component_of_electrode=dict(self.component_of_electrode),
            info=info)


def _ro(a):
    a = np.asarray(a)
    a.setflags(write=False)
    return a


def solve_potential(n_nodes: int, edges, conductance, electrodes: Sequence[Electrode], injection=None,
                    solver="cg") -> PotentialSolution:
    """One-shot potential solve; see :class:`ConductionProblem` to solve repeatedly."""
    return ConductionProblem(n_nodes, edges, conductance, electrodes, injection, solver).solve()


def equivalent_resistance(n_nodes: int, edges, conductance, nodes_a, nodes_b, solver="cg") -> float:
    """R_eq [ohm] between two node sets held at 1 V and 0 V (inf if they are not connected)."""
    sol = solve_potential(n_nodes, edges, conductance,
                          [Electrode("a", nodes_a, potential=1.0), Electrode("b", nodes_b, potential=0.0)],
                          solver=solver)
    return sol.equivalent_resistance("a", "b")
