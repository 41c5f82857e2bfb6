"""Kirchhoff networks with electrodes: structure kept, conductances updated in place, currents and
an equivalent resistance that is a property of the network, not of the excitation.

The network: nodes with potentials u [V], edges with conductances c [S]. With the incidence
matrix A (row k: -1 at ``edges[k, 0]``, +1 at ``edges[k, 1]``) the nodal matrix is
K = A^T C A (a weighted graph Laplacian) and Kirchhoff's current law reads K u = f, f the
currents injected into the nodes [A].

Electrodes are node sets tied by a perfect conductor (one potential for all of them), either
held at a fixed potential or fed an imposed total current. They are the Dirichlet groups of a
:class:`~yade_electro.network.condensation.ReducedSystem`; the unknowns are the other nodes.

How a solve works (:class:`ConductionProblem`)
----------------------------------------------
For every electrode e the *characteristic potential* phi_e (1 V on e, 0 V on every other
electrode) is solved once per set of conductances: K_uu phi_e = -K_ud 1_e. In a connected
part with p electrodes the phi sum to 1, so p - 1 solves suffice (one for the usual two
electrodes). They give the electrodes' conductance matrix (Dirichlet-to-Neumann map)

    S = K_dd + K_du Phi,        I = S V (+ j, the part of node injections)

with I the currents fed into the network at the electrodes. Any electrode values then cost no
solve at all: imposed-current electrodes get their potentials from a small dense system,
u = Phi V, and

* ``R_eq(a, b)`` is computed from S alone: the two-terminal resistance between a and b with
  the other electrodes left open (floating), exact whatever potentials or currents are
  applied (also at 1 V / 1 V, where the applied current is 0);
* changing an electrode value never re-solves; a change of conductances re-solves warm
  (the previous phi as start) with the kept solver setup.

Sign conventions
----------------
* ``branch_current[k]`` flows from node ``edges[k, 0]`` to node ``edges[k, 1]``:
  w = c (u_i - u_j).
* ``electrode_current[name]`` is the current the external circuit feeds *into the network*
  at that electrode (positive at the high-potential electrode of a resistor).

Connected parts with no electrode, and parts whose only electrodes carry imposed currents
that are all 0, are floating (:mod:`yade_electro.network.floating`, the one policy for current
and heat): their potential is undefined, kept at 0 V and flagged in
``PotentialSolution.floating`` (a warning says how many nodes). A part with a non-zero imposed
current and no fixed-potential electrode has no return path and raises.

Units: SI (S, V, A, ohm, W).
"""
from __future__ import annotations

import logging
import time
from typing import Mapping, Optional, Sequence

import numpy as np
import scipy.linalg

from .condensation import ReducedSystem
from .floating import warn_floating
from .kirchhoff import Electrode, electrode_value, network_components
from .records import PotentialSolution
from .structure import NetworkStructure, Words
from ..core.errors import BoundaryConditionError, SolverError

__all__ = ["ConductionProblem", "solve_potential", "equivalent_resistance", "ELECTRICAL_WORDS"]

#: the electrical words of a network's messages
ELECTRICAL_WORDS = Words(conductance="conductances must be finite and >= 0 (check resistivity and radii)")

log = logging.getLogger(__name__)


def _ro(a):
    a = np.asarray(a)
    a.setflags(write=False)
    return a


class ConductionProblem(NetworkStructure):
    """Kirchhoff network with electrodes, kept for repeated solves (see module doc).

    Building it checks the electrodes and the connected parts. Then:

    * :meth:`solve` with other electrode values costs no linear solve;
    * :meth:`update_conductance` with new values on the same edges updates the matrices in
      place, keeps the solver setup (``solver.update``) and re-solves warm at the next
      :meth:`solve`; the structure is rebuilt only when the connected parts change (an edge
      dropped to 0 that splits the network, or one that joins two parts);
    * :meth:`update_edges` takes a new edge set: a subset of the current one (bonds broke) is
      a value update with zeros; other sets rebuild the structure.

    Parameters
    ----------
    n_nodes : int
    edges : (m, 2) int array
    conductance : (m,) array [S], >= 0
    electrodes : sequence of Electrode
        Or the generic :class:`~yade_electro.network.boundary.Terminal` (``value=`` a fixed
        potential, ``rate=`` an imposed current).
    injection : (n,) currents injected into nodes [A], optional
    solver : name or solver object (see :mod:`yade_electro.solvers.registry`); 'auto' by size
    coords : (n, 3) node positions [m], optional (for the coarse space of 'cg-deflated')
    """

    WORDS = ELECTRICAL_WORDS

    def __init__(self, n_nodes: int, edges, conductance, electrodes: Sequence[Electrode],
                 injection=None, solver="auto", coords=None):
        self._init_structure(n_nodes, edges, conductance, solver, coords)
        n = self.n
        self.electrodes = list(electrodes)
        for e in self.electrodes:
            if getattr(e, "ROLE", None) != "terminal" or getattr(e, "nodes", None) is None:
                raise BoundaryConditionError(f"electrodes must be Electrode(name, nodes, potential=|current=) or "
                                             f"Terminal(name, nodes, value=|rate=) objects, got {e!r}")
        if not self.electrodes:
            raise BoundaryConditionError("no electrode given: at least one fixed-potential electrode is needed")
        names = [e.name for e in self.electrodes]
        if len(set(names)) != len(names):
            raise BoundaryConditionError(f"electrode names must be unique, got {names}")
        self.names = names
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
        self._owner = owner
        self.injection = None
        if injection is not None:
            f = np.asarray(injection, dtype=float)
            if f.shape != (n,) or not np.all(np.isfinite(f)):
                raise BoundaryConditionError(f"injection must be a finite array of shape ({n},)")
            self.injection = f if np.any(f != 0) else None
        self.value_updates = 0
        self.basis_solves = 0
        self._phi = None                 # (nu, ne) characteristic potentials, warm start
        self._build()
        self._check_return_paths([e.amount for e in self.electrodes])

    # -- structure ------------------------------------------------------------------------
    @property
    def c(self) -> np.ndarray:
        """The conductances [S] (one per edge)."""
        return self.conductance

    def _components(self, c):
        """Connected parts through conducting edges, electrodes counted as super-nodes."""
        n, ne = self.n, len(self.electrodes)
        # tie each electrode's nodes through a virtual node n + k
        el_nodes = np.flatnonzero(self._owner >= 0)
        ties = np.column_stack([el_nodes, self.n + self._owner[el_nodes]])
        e = np.concatenate([self.edges[c > 0], ties])
        ncomp, label = network_components(n + ne, e)
        return label[:n], label[n:]

    def _build(self):
        n = self.n
        node_label, el_label = self._components(self.c)
        has_el = np.zeros(node_label.max() + 1 if n else 1, bool)
        has_el[el_label] = True
        exclude = ~has_el[node_label]
        old_phi = self._phi
        old_sys = getattr(self, "system", None)
        self.system = ReducedSystem(n, self.edges, [e.nodes for e in self.electrodes], exclude=exclude)
        self.system.assemble(self.c)
        self._node_label, self._el_label = node_label, el_label
        self._exclude = exclude
        nfl = int(exclude.sum())
        self.floating_structural = exclude
        if nfl:
            ncl = np.unique(node_label[exclude]).size
            warn_floating(nfl, ncl, "electrode", "a potential of 0 V", stacklevel=5)
        nu = self.system.n_unknowns
        self._kept_solver(self.system.unknown_nodes, self.edges[self.c > 0])
        # warm start carried over through node potentials
        if old_phi is not None and old_sys is not None:
            phi = np.zeros((nu, len(self.electrodes)))
            keep = old_sys.unknown_index[self.system.unknown_nodes]
            ok = keep >= 0
            phi[ok] = old_phi[keep[ok]]
            self._phi = phi
        else:
            self._phi = None
        self._basis_valid = False
        self._last = None
        self._history = {}
        self.structure_builds += 1
        # per part: its electrodes and unknowns
        self._parts = {}
        ulab = node_label[self.system.unknown_nodes]
        for k, lab in enumerate(el_label):
            self._parts.setdefault(int(lab), []).append(k)
        self._part_unknowns = {lab: np.flatnonzero(ulab == lab) for lab in self._parts}
        self.component_of_electrode = {e.name: int(el_label[k]) for k, e in enumerate(self.electrodes)}

    def update_conductance(self, conductance) -> str:
        """New conductances on the same edges [S]. Returns 'values' (in-place update, solver
        setup kept) or 'structure' (the connected parts changed: rebuilt)."""
        c = self._check_conductance(conductance)
        same_parts = np.array_equal(c > 0, self.c > 0)
        self.conductance = c
        self._last = None
        self._basis_valid = False
        if not same_parts:
            node_label, el_label = self._components(c)
            if self._same_partition(node_label, el_label):
                same_parts = True
        if same_parts:
            Kuu, _ = self.system.assemble(c)
            self.solver.update(Kuu)
            self.value_updates += 1
            return "values"
        self._build()
        return "structure"

    def _same_partition(self, node_label, el_label) -> bool:
        """True when the new parts give the same unknowns and the same electrodes per part."""
        has_el = np.zeros(node_label.max() + 1, bool)
        has_el[el_label] = True
        if not np.array_equal(~has_el[node_label], self._exclude):
            return False
        # electrodes grouped the same way
        old, new = self._el_label, el_label
        return bool(np.array_equal(old[:, None] == old[None, :], new[:, None] == new[None, :]))

    def update_edges(self, edges, conductance) -> str:
        """A new edge set with its conductances. A subset of the current edges keeps the
        structure (the missing edges get conductance 0); anything else rebuilds it."""
        edges = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
        c_new = np.asarray(conductance, dtype=float)
        if c_new.shape != (edges.shape[0],):
            raise ValueError(f"conductance must have one value per edge ({edges.shape[0]}), got {c_new.shape}")
        full = self._on_subset(edges, c_new)
        if full is not None:
            return self.update_conductance(full)
        self.edges = edges
        self.conductance = self._check_conductance(c_new)
        self._build()
        return "structure"

    # -- solving ----------------------------------------------------------------------------
    def _basis(self):
        """phi (nu, ne) and S (ne, ne) for the current conductances (solved when stale)."""
        if self._basis_valid:
            return
        sys_ = self.system
        nu, ne = sys_.n_unknowns, len(self.electrodes)
        phi = np.zeros((nu, ne)) if self._phi is None else self._phi
        residual, iterations = 0.0, 0
        t = time.perf_counter()
        Kuu, Kud = sys_.Kuu, sys_.Kud
        for lab, ks in self._parts.items():
            rows = self._part_unknowns[lab]
            if rows.size == 0:
                continue
            for k in ks[:-1]:
                unit = np.zeros(ne)
                unit[k] = 1.0
                b = -(Kud @ unit)                  # column k of K_ud, without a sparse slice
                x0 = self._projected_start(Kuu, b, k, phi[:, k])
                x, info = self.solver.solve(Kuu, b, x0=x0)
                phi[:, k] = x
                self._remember(k, x)
                residual = max(residual, float(info.get("residual", 0.0)))
                iterations += int(info.get("iterations", 0))
                self.basis_solves += 1
            last = ks[-1]
            phi[:, last] = 0.0
            phi[rows, last] = 1.0 - (phi[rows][:, ks[:-1]].sum(axis=1) if len(ks) > 1 else 0.0)
        if not np.all(np.isfinite(phi)):
            raise SolverError("the potential solve returned non-finite values")
        self._phi = phi
        S = sys_.Kdd.toarray() + (sys_.Kdu @ phi if nu else 0.0)
        # S is a Laplacian on the electrodes (symmetric, rows summing to 0: a common potential
        # drives no current); impose both exactly, so that two-terminal figures are consistent
        S = 0.5 * (S + S.T)
        np.fill_diagonal(S, 0.0)
        np.fill_diagonal(S, -S.sum(axis=1))
        self._S = S
        self._u_inj, self._j_inj = None, np.zeros(ne)
        if self.injection is not None:
            f_u = self.injection[sys_.unknown_nodes]
            x, info = self.solver.solve(Kuu, f_u, x0=getattr(self, "_u_inj_prev", None))
            self._u_inj = self._u_inj_prev = x
            residual = max(residual, float(info.get("residual", 0.0)))
            iterations += int(info.get("iterations", 0))
            f_g = np.bincount(self._owner[self._owner >= 0], self.injection[self._owner >= 0], ne)
            self._j_inj = (sys_.Kdu @ x if nu else np.zeros(ne)) - f_g
        self._basis_info = {"solver": getattr(self.solver, "name", type(self.solver).__name__),
                            "iterations": iterations, "residual": residual,
                            "basis_time": time.perf_counter() - t, "n_unknowns": int(nu)}
        self._basis_valid = True

    #: earlier solutions kept per electrode for the projected warm start
    HISTORY = 4

    def _remember(self, k, x):
        hist = self._history.setdefault(k, [])
        hist.append(x.copy())
        del hist[:-self.HISTORY]

    def _projected_start(self, A, b, k, x_prev):
        """The start of a re-solve: the A-norm best combination of the last solutions of the
        same right-hand side (Fischer, Comput. Methods Appl. Mech. Engrg. 163, 1998), which
        follows a smoothly changing sequence (rho_e(T) step after step, a straining packing)
        much closer than the last solution alone, and is never worse than it in the A-norm.
        The kept solutions are made orthonormal first (QR): successive solutions differ by
        1e-5 of their size under rho_e(T), and the Gram matrix of the solutions themselves
        then loses the differences to rounding (a start at 4e-7 of ||b|| instead of 1e-9)."""
        hist = self._history.get(k) or []
        if len(hist) < 2:
            return x_prev
        # scipy's economic QR: a sixth of numpy's time on these tall, thin matrices
        Q, R = scipy.linalg.qr(np.column_stack(hist[::-1]), mode="economic", check_finite=False)
        d = np.abs(np.diag(R))
        Q = Q[:, d > 1e-14 * d[0]] if d[0] > 0 else Q[:, :0]
        if Q.shape[1] == 0:
            return x_prev
        G = Q.T @ (A @ Q)
        try:
            y = np.linalg.solve(G, Q.T @ b)
        except np.linalg.LinAlgError:
            return x_prev
        x0 = Q @ y
        return x0 if np.all(np.isfinite(x0)) else x_prev

    def _check_return_paths(self, vals):
        fixed = np.array([e.fixed for e in self.electrodes])
        for lab, ks in self._parts.items():
            if fixed[ks].any():
                continue
            inj = 0.0
            if self.injection is not None:
                inj = np.abs(self.injection[self._node_label == lab]).sum()
            if any(vals[k] != 0 for k in ks) or inj > 0:
                names = [self.names[k] for k in ks]
                raise BoundaryConditionError(
                    "an imposed current has no return path: a connected part of the network carries an "
                    f"imposed current (electrodes {names}{' and node injections' if inj else ''}) but no "
                    "fixed-potential electrode; ground one electrode (potential=0) in that part")
        if self.injection is not None:
            lone = self._exclude & (self.injection != 0)
            if np.any(lone):
                raise BoundaryConditionError(
                    "an imposed current has no return path: node injections fall on a part of the network "
                    "with no electrode (node injections); connect it or ground it")

    def solve(self, values: Optional[Mapping[str, float]] = None) -> PotentialSolution:
        """Potentials and currents for electrode ``values`` (name -> V or A; default the
        electrodes' own values). Costs a linear solve only when the conductances changed."""
        t0 = time.perf_counter()
        vals = [e.amount for e in self.electrodes]
        if values:
            idx = {nm: k for k, nm in enumerate(self.names)}
            for name, v in values.items():
                if name not in idx:
                    raise BoundaryConditionError(f"no electrode named {name!r}; have {sorted(idx)}")
                vals[idx[name]] = electrode_value(name, v)
        key = tuple(vals)
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        self._check_return_paths(vals)
        fresh = not self._basis_valid
        self._basis()
        fixed = np.array([e.fixed for e in self.electrodes])
        vals = np.asarray(vals, dtype=float)
        S, j = self._S, self._j_inj
        V = np.where(fixed, vals, 0.0)
        floating_parts = []
        for lab, ks in self._parts.items():
            ks = np.asarray(ks)
            cur = ks[~fixed[ks]]
            fix = ks[fixed[ks]]
            if cur.size == 0:
                continue
            if fix.size == 0:            # all currents zero (checked above): no reference
                floating_parts.append(lab)
                continue
            rhs = vals[cur] - S[np.ix_(cur, fix)] @ V[fix] - j[cur]
            V[cur] = np.linalg.solve(S[np.ix_(cur, cur)], rhs)
        sys_ = self.system
        xu = self._phi @ V if sys_.n_unknowns else np.zeros(0)
        if self._u_inj is not None:
            xu = xu + self._u_inj
        u = sys_.expand(xu, V)
        floating = self._exclude.copy()
        for lab in floating_parts:
            floating |= self._node_label == lab
        u[floating] = 0.0
        w = self.c * (u[self.edges[:, 0]] - u[self.edges[:, 1]])
        I = np.where(fixed, S @ V + j, vals)
        I[np.isin(self._el_label, floating_parts)] = 0.0
        total_in = I.sum() + (self.injection.sum() if self.injection is not None else 0.0)
        scale = float(np.max(np.abs(I))) if I.size else 0.0
        imbalance = abs(total_in) / scale if scale > 0 else 0.0
        info = dict(self._basis_info)
        # what this call did: the linear solves only when the conductances changed
        info["basis_iterations"] = info["iterations"]
        if not fresh:
            info["iterations"], info["basis_time"] = 0, 0.0
        info["solve_time"] = time.perf_counter() - t0
        info["setup"] = bool(getattr(self.solver, "n_setups", 0))
        sol = PotentialSolution(
            potential=_ro(u), branch_current=_ro(w),
            electrode_potential={nm: float(V[k]) for k, nm in enumerate(self.names)},
            electrode_current={nm: float(I[k]) for k, nm in enumerate(self.names)},
            floating=_ro(floating), residual=float(info["residual"]), current_imbalance=float(imbalance),
            component_of_electrode=dict(self.component_of_electrode), conductance_matrix=_ro(S.copy()),
            info=info)
        self._last = (key, sol)
        return sol

    @property
    def floating(self) -> np.ndarray:
        """Nodes in parts with no electrode (bool, (n,))."""
        return self._exclude


def solve_potential(n_nodes: int, edges, conductance, electrodes: Sequence[Electrode], injection=None,
                    solver="auto") -> PotentialSolution:
    """One-shot potential solve; see :class:`ConductionProblem` to solve repeatedly."""
    return ConductionProblem(n_nodes, edges, conductance, electrodes, injection, solver).solve()


def equivalent_resistance(n_nodes: int, edges, conductance, nodes_a, nodes_b, solver="auto") -> float:
    """R_eq [ohm] between two node sets (inf if they are not connected)."""
    sol = solve_potential(n_nodes, edges, conductance,
                          [Electrode("a", nodes_a, potential=1.0), Electrode("b", nodes_b, potential=0.0)],
                          solver=solver)
    return sol.equivalent_resistance("a", "b")
