"""Heat conduction with Joule sources: ``rho_c dT/dt = div(lambda grad T) + |grad V|^2 / rho``.

Time integration is the theta method on the finite-element system

    (M / dt + theta A) T^{n+1} = (M / dt - (1 - theta) A) T^n
                                 + theta f^{n+1} + (1 - theta) f^n,

with M the (consistent, or row-lumped) heat-capacity matrix, A = K + H (conduction plus
convection on the tagged faces) and f = Joule load + h T_inf load. theta = 1 is backward
Euler (first order, L-stable), 1/2 Crank-Nicolson (second order). Fixed temperatures are
eliminated; the heat they take or give is the residual of the system at their dofs, so the
energy balance

    heat gained = Joule energy + convective heat in + heat in through fixed temperatures

holds to round-off and is reported as a consistency check.

With a temperature-dependent resistivity rho(T) = rho0 (1 + beta (T - T0)) the potential is
re-solved at every step; f^{n+1} is found by ``coupling_iterations`` fixed-point passes
(1: f^{n+1} = f(T^n), first order in dt; 2 and more: predictor-corrector).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import diags
from skfem import FacetBasis, asm

from ..core.errors import BoundaryConditionError, MaterialError, ThermalError
from .potential import (DirichletSolver, PotentialSolution, _diffusion, _mass, _source,
                        _as_points, dirichlet_dofs, field_at_quadrature, make_basis,
                        solve_potential)
from .probing import line_points, probe_matrix, slab_average, subdomain_average

__all__ = ["joule_heating", "transient_conduction", "steady_temperature", "ThermalResult"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class ThermalResult:
    """Outcome of a transient thermal run.

    Attributes
    ----------
    times : ndarray (nrec,)
        Recorded times [s] (t = 0 first).
    probe_points : ndarray (npts, 3)
    probe_temperatures : ndarray (nrec, npts)
        Temperature at the probe points [K].
    mean_temperatures : ndarray (nrec,)
        Volume-mean temperature [K].
    basis : skfem.CellBasis
    T : ndarray
        Final temperature field at the dofs [K].
    potential : PotentialSolution or None
        The last potential solved (Joule heating only).
    joule_energy : float
        Joule heat released over the run [J].
    heat_gained : float
        Increase of the heat content, integral of rho_c (T_end - T_0) [J].
    boundary_heat : dict
        Heat entering through each fixed-temperature or convective boundary [J].
    resistance : ndarray (nrec,) or None
        Two-electrode equivalent resistance at the recorded times [ohm].
    voltage, current : ndarray (nrec,) or None
        Electrode voltage [V] and current [A] at the recorded times.
    """

    times: np.ndarray
    probe_points: np.ndarray
    probe_temperatures: np.ndarray
    mean_temperatures: np.ndarray
    basis: object = field(repr=False)
    T: np.ndarray = field(repr=False)
    potential: PotentialSolution | None = field(repr=False)
    joule_energy: float
    heat_gained: float
    boundary_heat: dict
    resistance: np.ndarray | None = None
    voltage: np.ndarray | None = None
    current: np.ndarray | None = None

    @property
    def energy_balance_error(self) -> float:
        """``|gained - (Joule + boundary)|`` / max(``|gained|``, ``|Joule|``, ``|boundary|``) (round-off)."""
        supplied = self.joule_energy + sum(self.boundary_heat.values())
        scale = max(abs(self.heat_gained), abs(self.joule_energy),
                    *(abs(v) for v in self.boundary_heat.values()), 1e-300)
        return abs(self.heat_gained - supplied) / scale

    def probe(self, points, tol: float = 1e-6) -> np.ndarray:
        """Final temperature [K] at points (npts, 3) or one point (3,) [m]."""
        return probe_matrix(self.basis, _as_points(points), tol) @ self.T

    def profile(self, start, end, n: int = 101) -> tuple:
        """Final temperature along a segment: (s [m], T [K])."""
        s, x = line_points(start, end, n)
        return s, self.probe(x.T)

    def slab_average(self, axis: int, edges) -> np.ndarray:
        """Final temperature averaged over slabs along ``axis`` [K]."""
        return slab_average(self.basis, self.T, axis, edges)

    def subdomain_average(self, name: str) -> float:
        """Final temperature averaged over a named subdomain of the mesh [K]."""
        sub = self.basis.mesh.subdomains or {}
        if name not in sub:
            raise KeyError(f"no subdomain {name!r}; the mesh has {sorted(sub)}")
        return subdomain_average(self.basis, self.T, sub[name])


# --------------------------------------------------------------------------- thermal system
class _ThermalSystem:
    """Matrices of the heat problem on one basis: M, K + H, convective load, fixed dofs."""

    def __init__(self, basis, lambda_, rho_c, fixed_T, convection, lumped):
        self.basis = basis
        lam = field_at_quadrature(basis, lambda_, "lambda_")
        rc = field_at_quadrature(basis, rho_c, "rho_c")
        self.M = asm(_mass, basis, c=rc)
        if lumped:
            self.M = diags(np.asarray(self.M.sum(axis=1)).ravel()).tocsr()
        A = asm(_diffusion, basis, k=lam)
        self.g = np.zeros(basis.N)
        self.conv = {}
        known = sorted((basis.mesh.boundaries or {}).keys())
        for tag, (h, t_inf) in (convection or {}).items():
            if tag not in known:
                raise BoundaryConditionError(f"unknown boundary {tag!r}; this mesh has {known}")
            if not (np.isfinite(h) and h >= 0 and np.isfinite(t_inf)):
                raise MaterialError(f"convection on {tag!r} needs h >= 0 [W/m^2/K] and a "
                                    f"finite T_inf [K], got {(h, t_inf)!r}")
            fb = FacetBasis(basis.mesh, basis.elem, facets=basis.mesh.boundaries[tag])
            Hm = asm(_mass, fb, c=float(h))
            gv = asm(_source, fb, q=float(h) * float(t_inf))
            self.conv[tag] = (Hm, gv)
            A = A + Hm
            self.g = self.g + gv
        self.A = A.tocsr()
        fixed_T = dict(fixed_T or {})
        self.groups, self.D, self.xD = dirichlet_dofs(basis, fixed_T)

    def boundary_rates(self, T):
        """Heat flow into the domain through each convective boundary [W]."""
        return {tag: float(np.sum(gv - Hm @ T)) for tag, (Hm, gv) in self.conv.items()}


def _integrate(system, T0_field, t_end, dt, theta, source, probes, record_every, on_record):
    """Theta-method loop; ``source(T)`` returns the Joule load vector at temperature T."""
    if not (np.isfinite(t_end) and t_end > 0 and np.isfinite(dt) and dt > 0):
        raise ThermalError(f"t_end and dt must be positive, got t_end={t_end}, dt={dt}")
    if not 0.0 <= theta <= 1.0:
        raise ThermalError(f"theta must be in [0, 1], got {theta}")
    nsteps = int(round(t_end / dt))
    if nsteps < 1 or abs(nsteps * dt - t_end) > 1e-9 * t_end:
        raise ThermalError(f"t_end = {t_end} s is not a whole number of steps dt = {dt} s")
    M, A, g = system.M, system.A, system.g
    lhs = (M / dt + theta * A).tocsr()
    rhs_m = (M / dt - (1.0 - theta) * A).tocsr()
    solver = DirichletSolver(lhs, system.D)
    P = probe_matrix(system.basis, probes) if probes is not None else None
    T = T0_field.copy()
    T[system.D] = system.xD
    ones_m = np.asarray(M.sum(axis=0)).ravel()   # ones^T M: heat content = ones_m @ T
    heat0 = float(ones_m @ T0_field)
    q_old = source(T)
    joule = 0.0
    bnd = {tag: 0.0 for tag in list(system.conv) + list(system.groups)}
    times, temps, means = [0.0], [P @ T if P is not None else np.zeros(0)], [float(ones_m @ T)]
    on_record(T)
    for n in range(1, nsteps + 1):
        rhs_base = rhs_m @ T + (1.0 - theta) * q_old + g
        q_used = q_old
        T_new = solver.solve(rhs_base + theta * q_used, system.xD)
        if source.varies:
            for _ in range(source.iterations - 1):
                q_used = source(T_new)
                T_new = solver.solve(rhs_base + theta * q_used, system.xD)
            q_next = source(T_new)
        else:
            q_next = q_old
        if system.D.size:  # heat in through fixed temperatures = residual at their dofs
            res = lhs @ T_new - (rhs_base + theta * q_used)
            for tag, dofs in system.groups.items():
                bnd[tag] += float(np.sum(res[dofs])) * dt
        if system.conv:
            r_old, r_new = system.boundary_rates(T), system.boundary_rates(T_new)
            for tag in r_old:
                bnd[tag] += dt * (theta * r_new[tag] + (1.0 - theta) * r_old[tag])
        joule += dt * (theta * q_used.sum() + (1.0 - theta) * q_old.sum())
        T, q_old = T_new, q_next
        if not np.all(np.isfinite(T)):
            raise ThermalError(f"non-finite temperature at step {n} (t = {n * dt:.3g} s): "
                               "explicit step too large?")
        if n % record_every == 0 or n == nsteps:
            times.append(n * dt)
            temps.append(P @ T if P is not None else np.zeros(0))
            means.append(float(ones_m @ T))
            on_record(T)
    means = np.asarray(means) / ones_m.sum()
    heat_gained = float(ones_m @ T) - heat0
    return T, np.asarray(times), np.asarray(temps), means, joule, heat_gained, bnd


class _JouleSource:
    """Joule load vector as a function of temperature (solved once if rho does not vary)."""

    def __init__(self, basis, rho, dirichlet_V, beta, T_ref, current, iterations):
        self.basis, self.rho, self.dirichlet = basis, rho, dict(dirichlet_V)
        self.beta, self.T_ref, self.current = float(beta), float(T_ref), current
        if not np.isfinite(self.beta):
            raise MaterialError(f"beta must be finite, got {beta!r}")
        self.varies = self.beta != 0.0
        self.iterations = max(1, int(iterations))
        self.last = None
        self._const = None
        if current is not None:
            if len(self.dirichlet) != 2 or len(set(self.dirichlet.values())) != 2:
                raise BoundaryConditionError("an imposed current needs exactly two electrodes "
                                             "with different potentials")
        self.high = max(self.dirichlet, key=self.dirichlet.get)
        self.rho_q = field_at_quadrature(basis, rho, "rho")

    def potential(self, T=None) -> PotentialSolution:
        """Potential with rho at temperature T (dofs), scaled to the imposed current."""
        rho = self.rho_q
        if self.varies and T is not None:
            rho = rho * (1.0 + self.beta * (np.asarray(self.basis.interpolate(T)) - self.T_ref))
        sol = solve_potential(self.basis.mesh, rho, self.dirichlet, basis=self.basis)
        if self.current is not None:
            s = self.current / sol.currents[self.high]
            sol = PotentialSolution(basis=sol.basis, u=sol.u * s, conductivity=sol.conductivity,
                                    dirichlet={k: v * s for k, v in sol.dirichlet.items()},
                                    currents={k: v * s for k, v in sol.currents.items()},
                                    stiffness=sol.stiffness)
        return sol

    def __call__(self, T):
        if not self.varies and self._const is not None:
            return self._const
        self.last = self.potential(T)
        q = self.last.joule_source(self.basis)
        if not self.varies:
            self._const = q
        return q


def _initial_field(basis, T0):
    if callable(T0):
        T = np.asarray(T0(basis.doflocs), dtype=float)
        if T.shape != (basis.N,):
            raise ThermalError("a callable T0 must map points (3, n) to n temperatures")
        return T
    T = np.asarray(T0, dtype=float)
    if T.ndim == 0:
        return np.full(basis.N, float(T))
    if T.shape != (basis.N,):
        raise ThermalError(f"T0 must be a number, a callable of x (3, n) or an array of "
                           f"{basis.N} dof values; got shape {T.shape}")
    return T.copy()


def joule_heating(mesh, rho, lambda_, rho_c, dirichlet_V: dict, t_end: float, dt: float,
                  theta: float = 1.0, T0=293.15, fixed_T: dict | None = None,
                  convection: dict | None = None, beta: float = 0.0, current: float | None = None,
                  probes=None, order: int = 1, lumped: bool = False,
                  coupling_iterations: int = 2, record_every: int = 1) -> ThermalResult:
    """Transient Joule heating: potential solve, Joule sources, theta-method heat equation.

    Parameters
    ----------
    mesh : skfem.MeshTet
        Mesh with named boundaries.
    rho : float, ndarray or callable
        Electrical resistivity at ``T0`` [ohm m] (see ``field_at_quadrature``).
    lambda_ : float, ndarray or callable
        Thermal conductivity [W/m/K].
    rho_c : float, ndarray or callable
        Volumetric heat capacity density * c [J/m^3/K].
    dirichlet_V : dict
        Electrode name -> potential [V].
    t_end, dt : float
        Duration and step [s]; t_end must be a whole number of steps.
    theta : float
        1 backward Euler (default), 0.5 Crank-Nicolson, 0 explicit (stability is yours).
    T0 : float, ndarray or callable
        Initial temperature [K] (number, dof array, or callable of x (3, n)); it is also the
        reference temperature of rho(T).
    fixed_T : dict, optional
        Boundary name -> fixed temperature [K]. Default: none (adiabatic).
    convection : dict, optional
        Boundary name -> (h [W/m^2/K], T_inf [K]).
    beta : float
        Temperature coefficient of resistivity [1/K]: rho(T) = rho (1 + beta (T - T0)).
        0 (default) solves the potential once.
    current : float, optional
        Impose this current [A] entering through the higher-potential electrode instead of
        the potentials (they are rescaled at every solve).
    probes : array (npts, 3), optional
        Points where the temperature history is recorded [m].
    order : int
        1 or 2 (same Lagrange element for V and T).
    lumped : bool
        Row-lumped heat capacity (P1 only sensible).
    coupling_iterations : int
        Fixed-point passes per step when rho depends on T.
    record_every : int
        Record every that many steps (and the last one).

    Returns
    -------
    ThermalResult
    """
    basis = make_basis(mesh, order)
    T_init = _initial_field(basis, T0)
    T_ref = float(np.mean(T_init)) if (callable(T0) or np.ndim(T0)) else float(T0)
    src = _JouleSource(basis, rho, dirichlet_V, beta, T_ref, current, coupling_iterations)
    system = _ThermalSystem(basis, lambda_, rho_c, fixed_T, convection, lumped)
    probes = None if probes is None else _as_points(probes)
    rec = {"R": [], "V": [], "I": []}
    two = len(dirichlet_V) >= 2
    hi, lo = (sorted(dirichlet_V, key=dirichlet_V.get, reverse=True)[:2] if two
              else (None, None))

    def on_record(T):
        sol = src.last
        if sol is not None and two:
            rec["V"].append(sol.dirichlet[hi] - sol.dirichlet[lo])
            rec["I"].append(sol.currents[hi])
            rec["R"].append(rec["V"][-1] / rec["I"][-1])

    T, times, temps, means, joule, gained, bnd = _integrate(
        system, T_init, t_end, dt, theta, src, probes, int(record_every), on_record)
    arr = (lambda k: np.asarray(rec[k]) if rec[k] else None)  # noqa: E731
    pts = probes.T if probes is not None else np.zeros((0, 3))
    return ThermalResult(times=times, probe_points=pts,
                         probe_temperatures=temps, mean_temperatures=means, basis=basis, T=T,
                         potential=src.last, joule_energy=float(joule), heat_gained=gained,
                         boundary_heat=bnd, resistance=arr("R"), voltage=arr("V"),
                         current=arr("I"))


class _NoSource:
    varies = False
    iterations = 1
    last = None

    def __init__(self, n):
        self._z = np.zeros(n)

    def __call__(self, T):
        return self._z


def transient_conduction(mesh, lambda_, rho_c, T0, t_end: float, dt: float,
                         fixed_T: dict | None = None, convection: dict | None = None,
                         theta: float = 1.0, probes=None, order: int = 1, lumped: bool = False,
                         record_every: int = 1) -> ThermalResult:
    """Transient heat conduction without sources (e.g. the slab of paper 003).

    Parameters are those of :func:`joule_heating` without the electrical ones; boundaries
    not named in ``fixed_T`` or ``convection`` are insulated.

    Returns
    -------
    ThermalResult
    """
    basis = make_basis(mesh, order)
    system = _ThermalSystem(basis, lambda_, rho_c, fixed_T, convection, lumped)
    probes = None if probes is None else _as_points(probes)
    T, times, temps, means, joule, gained, bnd = _integrate(
        system, _initial_field(basis, T0), t_end, dt, theta, _NoSource(basis.N), probes,
        int(record_every), lambda T: None)
    pts = probes.T if probes is not None else np.zeros((0, 3))
    return ThermalResult(times=times, probe_points=pts,
                         probe_temperatures=temps, mean_temperatures=means, basis=basis, T=T,
                         potential=None, joule_energy=0.0, heat_gained=gained, boundary_heat=bnd)


def steady_temperature(potential: PotentialSolution, lambda_, fixed_T: dict | None = None,
                       convection: dict | None = None) -> np.ndarray:
    """Steady temperature [K] with the Joule sources of ``potential`` (same basis).

    Needs at least one fixed-temperature or convective boundary (else no steady state).

    Returns
    -------
    ndarray
        Temperature at the dofs of ``potential.basis``.
    """
    if not fixed_T and not convection:
        raise BoundaryConditionError("a steady temperature needs a fixed temperature or a "
                                     "convective boundary (adiabatic heating never settles)")
    basis = potential.basis
    system = _ThermalSystem(basis, lambda_, 1.0, fixed_T, convection, False)
    b = potential.joule_source(basis) + system.g
    return DirichletSolver(system.A, system.D).solve(b, system.xD)
