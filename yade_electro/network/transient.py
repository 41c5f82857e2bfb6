"""The heat network in time: ``C dT/dt = -M T + s``, integrated by the theta method (paper 003).

``M = K + diag(h A)`` (K the Laplacian of the conductances G, h A the convection) and
``s = P + Q + h A T_inf`` (sources, imposed inputs, ambient); the physics of each term is in
:mod:`yade_electro.physics.thermal`. :class:`HeatSolver` takes
``(C/dt + theta M) T^{n+1} = (C/dt - (1 - theta) M) T^n + s``, sources constant over the step;
``theta = 0`` is forward Euler (no solve), ``1/2`` Crank-Nicolson, ``1`` backward Euler.
Fixed-temperature nodes are eliminated from the unknowns.
Stability of the explicit scheme
--------------------------------
Forward Euler keeps every new temperature a convex combination of the old ones (so no
oscillation and no growth) when ``dt <= dt_crit = min_i C_i / M_ii`` over the free nodes
(:func:`stable_time_step`, the diagonal/Gershgorin bound; for two equal elements it is
exactly the stability limit C/G). For ``theta < 1/2`` the bound is ``dt_crit / (1 - 2
theta)``. A requested step above ``safety * bound`` is split into ``n_sub = ceil(dt /
(safety * bound))`` equal sub-steps, or raises :class:`ThermalError` when sub-cycling is
off. Paper 000 eq. 14 quotes ``l_min^2 / (2 alpha)``, alpha = lambda / (rho c)
(:func:`diffusion_time_step`); it ignores the volume fractions, the surfaces and the
number of neighbours (it is the 1D bound), so it is reported for comparison only: on a simple
cubic lattice the lumped bound is about 4x smaller (interior elements C/sum G = (2/3) r^2 /
alpha against the paper's 2 r^2 / alpha; edge and corner elements lower still), so a step
taken from eq. 14 alone would be unstable. ``theta >= 1/2`` has no step limit; only ``theta = 1`` keeps
the maximum principle at any step (Crank-Nicolson oscillates for steps far above dt_crit).

Units: SI (kg/m^3, J/(kg K), W/(m K), W/(m^2 K), K or degC, J/K, W, s).
"""
from __future__ import annotations

import logging
import math
from typing import Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError, SolverError, ThermalError
from ..core.graph import ContactGraph
from ..core.materials import positive_property
from ..laws.transmission import exposed_area
from ..solvers.cg import CGSolver
from ..solvers.base import DirectSolver
from .condensation import ReducedSystem
from .boundary import boundary_value
from .resolution import resolve_conditions
from .records import HeatStep, ThermalState, read_only_copy as _ro
from .steady import SteadyHeatSolve
from .structure import NetworkStructure, Words
from .theta import theta_of

_OWN_SOLVERS = (CGSolver, DirectSolver)

__all__ = ["HeatSolver", "THERMAL_WORDS"]

#: the thermal words of a network's messages
THERMAL_WORDS = Words(conductance="thermal conductances must be finite and >= 0 (W/K); check the conductivity")

log = logging.getLogger(__name__)



# ---------------------------------------------------------------------------------------
# the integrator
# ---------------------------------------------------------------------------------------
class HeatSolver(NetworkStructure, SteadyHeatSolve):
    """Lumped heat conduction on a network, advanced step by step with the theta method.

    The structure (the fixed-temperature sets condensed out, the sparsity pattern, the linear
    solver and its setup) is kept; :meth:`update_values` changes conductances and capacities
    in place and :meth:`update_edges` takes a new edge set (a subset keeps the structure).
    Temperatures, time and the energy ledger are owned here and survive both.

    Parameters
    ----------
    capacity : (n,) heat capacities C_i [J/K], > 0
    edges : (m, 2) node indices
    conductance : (m,) thermal conductances G_ij [W/K], >= 0
    temperature : float or (n,) initial temperatures; fixed-temperature nodes take their value
    conditions : sequence of boundary conditions
        Fixed values, injections and Robin terms (:mod:`~yade_electro.network.boundary`), by
        their thermal names ``FixedTemperature``, ``HeatFlux``, ``Convection`` or the generic
        ``FixedValue``, ``Injection``, ``Robin``.
    theta : float in [0, 1] or 'explicit' (0), 'crank-nicolson' (1/2), 'backward-euler' (1, default)
    subcycle : bool
        For theta < 1/2, split a step above the stable one into sub-steps (default) or raise.
    safety : float in (0, 1]
        Fraction of the stability bound used as the largest (sub-)step (default 0.9).
    max_substeps : int
        Refuse (ThermalError) a step that would need more explicit sub-steps than this.
    solver : linear solver name or object for theta > 0 (default 'cg': Jacobi-CG on the
        temperature change of the step, warm-started from the previous change, to a relative
        residual of 1e-12 of that change; the setup is kept while the structure is;
        'cg-deflated', 'direct' also work, the matrix is SPD)
    time : initial time [s]
    energy : dict, optional
        Energy ledger to continue (see ``energy``), e.g. of a solver this one replaces. The
        ledger [J]: ``source``, ``absorbed``, ``flux``, ``convection``, ``boundary`` (see
        :class:`HeatStep`) and ``exchange`` (:meth:`record_exchange`).
    graph : ContactGraph, optional
        Lets boundary conditions use selectors / graph ids and default exposed areas.
    area : (n,) exposed areas [m^2], optional
        Default areas of Convection/HeatFlux(flux=) (else :func:`exposed_area` of ``graph``).
    nodes_of : dict name -> node indices, optional
        Already resolved node sets of the boundary conditions (used instead of their ``nodes``).
    area_of : dict name -> areas [m^2] of the nodes of ``nodes_of[name]``, optional
        Resolved areas of flux and convection conditions (surface conditions: their boundary
        faces' areas; convection: the area in series with the half cells).
    link_of : dict name -> conductances [W/K] of the nodes of ``nodes_of[name]``, optional
        A fixed temperature held at a surface: each node exchanges ``G_i (T_s - T_i)`` with it
        (the half-cell conductance); such a set is not eliminated, and its heat counts in
        ``boundary`` like the eliminated sets'.
    power : (n,) heat sources [W] held constant (HeatSource), optional; counted in ``flux``
    coords : (n, 3) node positions [m], optional (coarse space of 'cg-deflated')

    Notes
    -----
    Sources given to :meth:`advance` are held constant over the step. Sources on
    fixed-temperature nodes are taken by the thermostat (reported as ``absorbed_energy``);
    convection does not act on fixed nodes. The state (temperatures, time) changes only when
    a step succeeds: a non-finite source or result raises :class:`ThermalError` and leaves it
    as it was.
    """

    RTOL = 1e-12
    WORDS = THERMAL_WORDS

    def __init__(self, capacity, edges, conductance, temperature, *, conditions: Sequence = (), theta="backward-euler",
                 subcycle: bool = True, safety: float = 0.9, max_substeps: int = 100000, solver="cg",
                 time: float = 0.0, energy: Optional[dict] = None, graph: Optional[ContactGraph] = None, area=None,
                 nodes_of: Optional[dict] = None, area_of: Optional[dict] = None, link_of: Optional[dict] = None,
                 power=None, coords=None):
        C = self._check_capacity(capacity)
        n = C.shape[0]
        if graph is not None and graph.n_nodes != n:
            raise ValueError(f"the graph has {graph.n_nodes} nodes, capacity {n}")
        self._init_structure(n, edges, conductance, solver, coords)
        self.theta = theta_of(theta)
        if not (0.0 < safety <= 1.0):
            raise ValueError(f"safety must be in (0, 1], got {safety}")
        self.subcycle, self.safety, self.max_substeps = bool(subcycle), float(safety), int(max_substeps)
        self.graph = graph
        #: what the floating messages advise for elements joined to nothing (an engine says how
        #: its reader leaves them out)
        self.alone_remedy = "leave them out of the model"
        default_area = area if area is not None else (exposed_area(graph) if graph is not None else None)
        if default_area is not None:
            default_area = np.asarray(default_area, dtype=float)
            if default_area.shape != (n,):
                raise ValueError(f"area must be an ({n},) array, got {default_area.shape}")

        # boundary conditions -> node sets and per-node arrays
        self.conditions = list(conditions)
        self.fixed_bcs = [b for b in self.conditions if getattr(b, "ROLE", None) == "fixed"]
        r = resolve_conditions(n, self.conditions, graph=graph,
                               default_area=default_area, nodes_of=nodes_of, area_of=area_of, link_of=link_of,
                               power=power)
        self._fixed_nodes, self._links, self.fixed = r.fixed_nodes, r.links, r.fixed
        self._fixed_value = {b.name: float(b.field("value")) for b in self.fixed_bcs}
        self._conv_hA, self._conv_hAT = r.h_area, r.h_area_t_inf
        self._terms = r.terms
        self.flux_power = _ro(r.power)
        self._refresh_links()
        self.nodes_of = r.nodes_of

        self.capacity = _ro(C)
        self.conductance = _ro(self.conductance)
        self._build_structure()

        T = np.broadcast_to(np.asarray(temperature, dtype=float), (n,)).copy()
        self._apply_fixed(T)
        if not np.all(np.isfinite(T)):
            raise ThermalError(f"initial temperatures must be finite; non-finite at nodes "
                               f"{np.flatnonzero(~np.isfinite(T))[:10].tolist()}")
        self._T = T
        self.time = float(time)
        self.steps = 0
        self.substeps = 0
        self.energy = dict(source=0.0, absorbed=0.0, flux=0.0, convection=0.0, boundary=0.0, exchange=0.0)
        if energy:
            self.energy.update({k: float(v) for k, v in energy.items() if k in self.energy})
        #: heat [J] that entered through each linked condition since the start (walls, surfaces)
        self.link_energy = {k: float((energy or {}).get(f"link:{k}", 0.0)) for k in self._links}

    # -- structure and values ---------------------------------------------------------------------
    @staticmethod
    def _check_capacity(capacity):
        C = np.asarray(capacity, dtype=float)
        if C.ndim != 1 or C.size == 0:
            raise ValueError(f"capacity must be an (n,) array, got shape {C.shape}")
        positive_property("heat capacity", C, C.shape[0], " (J/K)")
        return C

    def _build_structure(self):
        groups = [self._fixed_nodes[b.name] for b in self.fixed_bcs if b.name in self._fixed_nodes]
        self.system = ReducedSystem(self.n, self.edges, groups)
        self._u = self.system.unknown_nodes
        self._d = np.flatnonzero(self.fixed)
        self._kept_solver(self._u, self.edges, **({"rtol": self.RTOL} if isinstance(self._solver_spec, str)
                                                   and self._solver_spec != "direct" else {}))
        self._A = None
        self._A_key = None
        self._dT_prev = None
        self.structure_builds += 1
        self._assemble()

    def _assemble(self):
        """Fill the kept matrices from the current conductances and capacities."""
        self.system.assemble(self.conductance, diagonal=self.h_area[self._u])
        self._Muu, self._Mud = self.system.Kuu, self.system.Kud
        self._Cu = self.capacity[self._u]
        M_diag = self.system.unknown_diagonal()
        sel = M_diag > 0
        self.critical_time_step = float(np.min(self._Cu[sel] / M_diag[sel])) if np.any(sel) else math.inf
        self._A_key = None                      # the theta matrix is refilled at the next step

    def update_values(self, conductance=None, capacity=None):
        """New conductances (same edges) [W/K] and/or capacities [J/K], in place: the structure
        and the solver setup are kept."""
        if conductance is not None:
            self.conductance = _ro(self._check_conductance(conductance))
        if capacity is not None:
            C = self._check_capacity(capacity)
            if C.shape != (self.n,):
                raise ValueError(f"capacity must have {self.n} values, got {C.shape}")
            self.capacity = _ro(C)
        self._assemble()

    def update_edges(self, edges, conductance, capacity=None) -> str:
        """A new edge set: a subset of the current one keeps the structure ('values'), another
        one rebuilds it ('structure'); temperatures, time and energies are kept."""
        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        G = self._check_conductance(conductance, edges.shape[0])
        full = self._on_subset(edges, G)
        if full is not None:
            self.update_values(full, capacity)
            return "values"
        self.edges = edges
        self.conductance = _ro(G)
        if capacity is not None:
            self.capacity = _ro(self._check_capacity(capacity))
        self._build_structure()
        return "structure"

    def set_links(self, name: str, nodes, conductance, assemble: bool = True):
        """New nodes and conductances G_i [W/K] of a fixed temperature held through links
        (a surface condition, or a wall whose contacts changed): a change of the diagonal
        only, the structure and the solver setup are kept. ``assemble=False`` leaves the
        matrices to the next :meth:`update_values` (one assembly for several changes)."""
        if name not in self._links:
            raise BoundaryConditionError(f"no linked fixed-temperature condition named {name!r}; have "
                                         f"{sorted(self._links)}")
        nd = np.asarray(nodes, dtype=np.int64).reshape(-1)
        g = np.asarray(conductance, dtype=float).reshape(-1)
        if g.shape != nd.shape or not np.all(np.isfinite(g)) or np.any(g < 0):
            raise BoundaryConditionError(f"links of {name!r}: conductances must be finite, >= 0 and one per node "
                                         f"({nd.size}), got shape {g.shape}")
        if nd.size and (nd.min() < 0 or nd.max() >= self.n):
            raise BoundaryConditionError(f"links of {name!r}: node index out of range 0..{self.n - 1}")
        g = np.where(self.fixed[nd], 0.0, g)
        self._links[name] = (nd, g)
        self.nodes_of[name] = nd
        self._refresh_links()
        if assemble:
            self._assemble()

    def link_flows(self, temperature=None) -> dict:
        """Heat flow [W] into the network through each linked condition at ``temperature``
        (default the current one): sum_i G_i (T_s - T_i)."""
        T = self._T if temperature is None else np.asarray(temperature, dtype=float)
        return {k: float(np.sum(g * (self._fixed_value[k] - T[nd]))) for k, (nd, g) in self._links.items()}

    # -- state -----------------------------------------------------------------------------------
    def _apply_fixed(self, T):
        for name, nodes in self._fixed_nodes.items():
            T[nodes] = self._fixed_value[name]

    def _refresh_links(self):
        """What the linked fixed temperatures add on each node: the diagonal sum G_i (into
        ``h_area``) and the right-hand side sum G_i T_s (fixed nodes take neither)."""
        G, GT = np.zeros(self.n), np.zeros(self.n)
        for name, (nd, g_link) in self._links.items():
            G += np.bincount(nd, g_link, self.n)
            GT += np.bincount(nd, g_link * self._fixed_value[name], self.n)
        G[self.fixed] = 0.0
        GT[self.fixed] = 0.0
        self._link_G, self._link_GT = G, GT
        self.h_area = _ro(self._conv_hA + G)
        self._hAT = self._conv_hAT + GT

    def boundary_flows(self, temperature=None) -> dict:
        """Heat flow [W] the network receives through each boundary condition at
        ``temperature`` (default the current one), by name: a fixed temperature (from its held
        elements into the rest, or through its links), a convection ``sum h A (T_inf - T)``, an
        imposed flux or source (its rate); negative when heat leaves."""
        T = self._T if temperature is None else np.asarray(temperature, dtype=float)
        out = {}
        names = [b.name for b in self.fixed_bcs if b.name in self._fixed_nodes]
        if names and self._d.size:
            flux = self.system.group_flux(T[self._u], self._fixed_group_values())
            out.update(zip(names, (float(f) for f in flux)))
        out.update(self.link_flows(T))
        for b in self.conditions:
            term = self._terms.get(b.name)
            if term is None:
                continue
            nd, values = term
            if b.ROLE == "robin":
                out[b.name] = float(np.sum(values * (float(b.field("ambient")) - T[nd])))
            else:
                out[b.name] = float(np.sum(values))
        return out

    def _fixed_group_values(self):
        return np.array([self._fixed_value[b.name] for b in self.fixed_bcs if b.name in self._fixed_nodes], dtype=float)

    @property
    def temperature(self) -> np.ndarray:
        """Current temperatures (read-only copy)."""
        return _ro(self._T)

    @property
    def state(self) -> ThermalState:
        return ThermalState(self.temperature, self.time)

    def set_temperature(self, temperature):
        """Replace the temperatures (fixed nodes keep their imposed value); non-finite raise
        ThermalError and change nothing."""
        T = np.broadcast_to(np.asarray(temperature, dtype=float), (self.n,)).copy()
        if not np.all(np.isfinite(T)):
            raise ThermalError(f"non-finite temperatures at nodes {np.flatnonzero(~np.isfinite(T))[:10].tolist()}; "
                               "the state is unchanged")
        self._apply_fixed(T)
        self._T = T

    def record_exchange(self, joules: float):
        """Add ``joules`` [J] to the ledger's ``exchange``: heat that entered the network with
        elements added, or left it with elements removed or resized (said by the owner that
        changes the element set; no step makes it)."""
        j = float(joules)
        if not np.isfinite(j):
            raise ThermalError(f"record_exchange: non-finite heat {joules!r}")
        self.energy["exchange"] += j

    def set_fixed_temperature(self, name: str, temperature: float):
        """Change the value of a fixed-temperature set (from the next step on)."""
        if name not in self._fixed_value:
            raise BoundaryConditionError(f"no fixed-temperature set named {name!r}; have {sorted(self._fixed_value)}")
        self._fixed_value[name] = boundary_value(f"fixed temperature {name!r}", temperature)
        if name in self._links:
            self._refresh_links()
        else:
            self._T[self._fixed_nodes[name]] = self._fixed_value[name]

    @property
    def fixed_values(self) -> dict:
        """Current values of the fixed-temperature sets."""
        return dict(self._fixed_value)

    def heat_content(self, reference) -> float:
        """``sum_i C_i (T_i - reference)`` [J]."""
        return float(np.sum(self.capacity * (self._T - reference)))

    def allowed_time_step(self) -> float:
        """Largest (sub-)step the integrator takes in one go [s] (inf for theta >= 1/2)."""
        if self.theta >= 0.5:
            return math.inf
        return self.safety * self.critical_time_step / (1.0 - 2.0 * self.theta)

    # -- stepping --------------------------------------------------------------------------------
    def _matrix(self, h):
        """C/h + theta M on the unknowns: one matrix object, refilled in place."""
        key = (h, self.theta)
        if self._A is None:
            self._A = self._Muu.copy()
            self._A_key = None
        if self._A_key != key:
            self._A.data[:] = self.theta * self._Muu.data
            self._A.data[self.system.diagonal_slots] += self._Cu / h
            self._solver.update(self._A)
            self._A_key = key
        return self._A

    def _check_dt(self, dt):
        try:
            dt = float(dt)
        except (TypeError, ValueError):
            raise ValueError(f"dt must be a number, got {dt!r}") from None
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be finite and > 0 (s), got {dt}")
        return dt

    def substeps_for(self, dt: float) -> int:
        """Number of sub-steps a step ``dt`` takes (raises ThermalError if sub-cycling is off
        and dt is above the allowed step)."""
        dt = self._check_dt(dt)
        allowed = self.allowed_time_step()
        if dt <= allowed:
            return 1
        if not self.subcycle:
            raise ThermalError(
                f"time step {dt:.6g} s is above the stable step of the theta={self.theta:g} scheme "
                f"({allowed:.6g} s = safety {self.safety:g} x dt_crit {self.critical_time_step:.6g} s"
                f"{'' if self.theta == 0 else ' / (1 - 2 theta)'}); reduce dt, allow sub-cycling "
                "(subcycle=True) or use theta='backward-euler'")
        n_sub = int(math.ceil(dt / allowed))
        if n_sub > self.max_substeps:
            raise ThermalError(f"time step {dt:.6g} s needs {n_sub} explicit sub-steps of at most {allowed:.3g} s "
                               f"(max_substeps={self.max_substeps}); use theta='backward-euler' or a smaller dt")
        return n_sub

    def trial(self, dt: float, sources=None):
        """Temperatures after a step ``dt`` with ``sources`` [W per node], without changing the
        state. Returns ``(T_new, HeatStep)``."""
        dt = self._check_dt(dt)
        n = self.n
        if sources is None:
            src = np.zeros(n)
        else:
            src = np.asarray(sources, dtype=float)
            if src.shape != (n,):
                raise ValueError(f"sources must be an ({n},) array (W per node), got shape {src.shape}")
            if not np.all(np.isfinite(src)):
                raise ThermalError(f"non-finite heat sources at nodes {np.flatnonzero(~np.isfinite(src))[:10].tolist()}; "
                                   "the state is unchanged (check the electrical solution)")
        n_sub = self.substeps_for(dt)
        h = dt / n_sub
        u, d, th = self._u, self._d, self.theta
        T = self._T.copy()
        Tg = self._fixed_group_values()
        MudTd = self._Mud @ Tg if Tg.size else np.zeros(u.size)
        s_u = src[u] + self.flux_power[u] + self._hAT[u]
        Tu = T[u]
        Tu_theta_sum = np.zeros(u.size)
        info = {"theta": th, "iterations": 0}
        with np.errstate(over="ignore", invalid="ignore"):
            for _ in range(n_sub):
                if th == 0.0:
                    Tu_new = Tu + h / self._Cu * (s_u - self._Muu @ Tu - MudTd)
                else:
                    # delta form: (C/h + theta M) dT = s - M T^n - M_ud T_d, so that the solver's
                    # relative tolerance applies to the change (and the energy balance stays exact)
                    rhs = s_u - self._Muu @ Tu - MudTd
                    if not np.all(np.isfinite(rhs)) or not np.isfinite(np.linalg.norm(rhs)):
                        Tu = np.where(np.isfinite(rhs), np.inf, rhs)    # the step would overflow
                        break
                    refilled = self._A_key != (h, self.theta)
                    A = self._matrix(h)
                    # the rounding level of the right-hand side: no solve can go below it
                    floor = 1e-13 * (np.linalg.norm(s_u) + np.linalg.norm(self._Muu @ Tu) + np.linalg.norm(MudTd))
                    x0 = self._dT_prev if self._dT_prev is not None and self._dT_prev.shape == rhs.shape else None
                    try:
                        if isinstance(self._solver, _OWN_SOLVERS):
                            dT, sinfo = self._solver.solve(A, rhs, x0=x0, atol=floor)
                        else:
                            dT, sinfo = self._solver.solve(A, rhs, x0=x0)
                    except (SolverError, RuntimeError, ArithmeticError) as exc:
                        raise ThermalError(
                            f"the linear solve of the theta={th:g} step failed ({exc}); the state is unchanged. "
                            f"With dt = {h:.3g} s, C/dt is {np.min(self._Cu / h):.3g} W/K at the least: on a "
                            "network with no fixed temperature and no convection a step this long leaves the "
                            "matrix numerically singular; take a shorter step") from exc
                    info["iterations"] += int(sinfo.get("iterations", 0))
                    info["solver"] = sinfo.get("solver")
                    info["setup"] = bool(info.get("setup", False) or sinfo.get("setup", False))
                    info["update"] = bool(info.get("update", False) or refilled)
                    self._dT_prev = dT
                    Tu_new = Tu + dT
                Tu_theta_sum += th * Tu_new + (1.0 - th) * Tu
                Tu = Tu_new
                if not np.all(np.isfinite(Tu)):
                    break
        if not np.all(np.isfinite(Tu)):
            bad = u[~np.isfinite(Tu)]
            raise ThermalError(
                f"non-finite temperatures at nodes {bad[:10].tolist()} after a step of {dt:.6g} s at t = "
                f"{self.time:.6g} s (theta={th:g}, {n_sub} sub-step(s)); the state is unchanged: check the "
                "sources and material data, or reduce dt")
        T[u] = Tu
        # energies (exact discrete balance of the theta scheme)
        Tth_u = Tu_theta_sum / n_sub
        boundary = dt * float(np.sum(self.system.group_flux(Tth_u, Tg))) if d.size else 0.0
        boundary += dt * float(np.sum(self._link_GT[u] - self._link_G[u] * Tth_u))
        if self._links:
            Tth = self._T.copy()
            Tth[u] = Tth_u
            info["link_energy"] = {k: dt * v for k, v in self.link_flows(Tth).items()}
        convection = dt * float(np.sum(self._conv_hAT[u] - self._conv_hA[u] * Tth_u))
        step = HeatStep(time=self.time + dt, dt=dt, n_substeps=n_sub,
                        source_energy=dt * float(np.sum(src[u])), absorbed_energy=dt * float(np.sum(src[d])),
                        flux_energy=dt * float(np.sum(self.flux_power[u])), convection_energy=convection,
                        boundary_energy=boundary,
                        heat_change=float(np.sum(self._Cu * (Tu - self._T[u]))), info=info)
        return T, step

    def advance(self, dt: float, sources=None) -> HeatStep:
        """Advance the temperatures by ``dt`` [s] with nodal ``sources`` [W] held constant.

        Raises
        ------
        ValueError
            dt not finite and > 0, sources of the wrong shape.
        ThermalError
            Non-finite sources or temperatures (the state is left as it was), or a step above
            the stable one with sub-cycling off.
        """
        T, step = self.trial(dt, sources)
        self._T = T
        self.time = step.time
        self.steps += 1
        self.substeps += step.n_substeps
        e = self.energy
        e["source"] += step.source_energy
        e["absorbed"] += step.absorbed_energy
        e["flux"] += step.flux_energy
        e["convection"] += step.convection_energy
        e["boundary"] += step.boundary_energy
        for k, v in step.info.get("link_energy", {}).items():
            self.link_energy[k] = self.link_energy.get(k, 0.0) + v
        return step
