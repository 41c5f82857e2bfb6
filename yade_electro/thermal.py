"""Heat capacities, Joule sources, thermal boundary conditions and time integrators.

The lumped heat balance of a packing (paper 000 eq. 13 and 16, paper 003 eq. 14):

    C_i dT_i/dt = P_i + sum_j G_ij (T_j - T_i) + h_i A_i (T_inf,i - T_i) + Q_i

* ``C_i = rho c V_i / fv_i`` [J/K], the heat capacity of the volume the element stands for
  (:func:`heat_capacity`);
* ``P_i`` [W], half the Joule power ``eta w_ij^2 / c_ij`` of every bond of i
  (:func:`joule_sources`);
* ``G_ij = lambda S_ij / l_ij`` [W/K], the thermal conductance; any electrical conductance
  law gives it when called with the thermal resistivity 1/lambda
  (:func:`thermal_conductance`; the 'continuum' law gives exactly paper 000 eq. 16);
* convection ``h A (T_inf - T)`` on free-surface elements and imposed heat inputs ``Q_i``
  [W]; fixed-temperature node sets take the place of electrodes.

In matrix form ``C dT/dt = -M T + s`` with ``M = K + diag(h A)`` (K the Laplacian of G) and
``s = P + Q + h A T_inf``. :class:`HeatSolver` integrates it with the theta family (paper
003): ``(C/dt + theta M) T^{n+1} = (C/dt - (1 - theta) M) T^n + s``, sources constant over
the step; ``theta = 0`` is forward Euler (no solve), ``1/2`` Crank-Nicolson, ``1`` backward
Euler. Fixed-temperature nodes are eliminated from the unknowns.

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
from dataclasses import dataclass, field
from typing import Any, Optional, Sequence

import numpy as np

from .condensation import ReducedSystem
from .conductance import make_law
from .errors import BoundaryConditionError, MaterialError, SolverError, ThermalError
from .graph import ContactGraph
from .materials import edge_conductivity, positive_property, real_number
from .network import edge_power, edge_slots
from .selection import check_selector, select_nodes
from .solvers import CGSolver, DirectSolver, make_solver

_OWN_SOLVERS = (CGSolver, DirectSolver)
from .surfaces import eccentricity, volume_fraction as _volume_fraction

__all__ = ["heat_capacity", "edge_joule_power", "joule_sources", "electrical_power", "thermal_conductance",
           "resolve_nodes", "resolve_area",
           "exposed_area", "stable_time_step", "diffusion_time_step", "theta_of",
           "FixedTemperature", "ThermalWall", "HeatFlux", "Convection", "HeatSource", "ThermalState", "HeatStep", "HeatSolver",
           "SteadyHeat"]

log = logging.getLogger(__name__)

_THETA_NAMES = {"explicit": 0.0, "forward-euler": 0.0, "crank-nicolson": 0.5,
                "backward-euler": 1.0, "implicit": 1.0}


# ---------------------------------------------------------------------------------------
# material input
# ---------------------------------------------------------------------------------------
def heat_capacity(graph: ContactGraph, density, specific_heat, volume_fraction=None, cell_volume=None,
                  threshold: float = 0.4, factor: float = 2.0) -> np.ndarray:
    """Heat capacity C_i of every element [J/K].

    ``C_i = rho c V_i / fv_i`` (paper 000 eq. 13), V_i the sphere volume and fv_i the volume
    fraction of the continuum model (:func:`yade_electro.surfaces.volume_fraction`), so that
    the element carries the heat capacity of the polyhedron it stands for.

    Parameters
    ----------
    graph : ContactGraph
    density : float or (n,) [kg/m^3], > 0
    specific_heat : float or (n,) [J/(kg K)], > 0
    volume_fraction : float or (n,), optional
        Explicit fv_i (e.g. 1.0 for the paper's rod check); default from the bond graph.
    cell_volume : (n,) array [m^3], optional
        Volumes of the cells the elements stand for (e.g. Voronoi cells); then
        ``C_i = rho c V_cell_i`` and ``volume_fraction`` must not be given.
    threshold, factor : eccentricity rule of the default volume fraction.

    Raises
    ------
    MaterialError
        A non-positive or non-finite density, specific heat, volume fraction or cell volume.
    """
    n = graph.n_nodes
    rc = positive_property("density", density, n, " (kg/m^3)") * positive_property("specific_heat", specific_heat, n,
                                                                      " (J/(kg K))")
    if cell_volume is not None:
        if volume_fraction is not None:
            raise ValueError("give volume_fraction= or cell_volume=, not both")
        v = positive_property("cell_volume", cell_volume, n, " (m^3)")
        return np.broadcast_to(rc * v, (n,)).astype(float)
    if volume_fraction is None:
        fv = _volume_fraction(graph, threshold=threshold, factor=factor)
    else:
        fv = positive_property("volume_fraction", volume_fraction, n)
    return np.broadcast_to(rc * graph.volume / fv, (n,)).astype(float)


def thermal_conductance(graph: ContactGraph, conductivity, law="continuum", **params) -> np.ndarray:
    """Thermal conductance G_ij of every edge of ``graph`` [W/K]: ``lambda_edge g`` with the
    law's geometric factor g (for 'continuum', ``lambda S_ij / l_ij``, paper 000 eq. 16);
    per-node conductivities make an edge two half rods in series (harmonic mean).

    Raises
    ------
    MaterialError
        A non-positive or non-finite conductivity [W/(m K)].
    """
    lam = positive_property("thermal conductivity", conductivity, graph.n_nodes, " (W/(m K))")
    return edge_conductivity(lam, graph.edges) * make_law(law, **params).factor(graph, graph.edges)


def diffusion_time_step(graph: ContactGraph, conductivity, density, specific_heat) -> float:
    """Paper 000 eq. 14: ``l_min^2 / (2 alpha)`` [s], alpha = lambda / (rho c) (the largest
    over the nodes when properties vary). For comparison with :func:`stable_time_step`,
    which is the bound the integrators use."""
    n = graph.n_nodes
    alpha = (positive_property("thermal conductivity", conductivity, n) /
             (positive_property("density", density, n) * positive_property("specific_heat", specific_heat, n)))
    if graph.n_edges == 0:
        return math.inf
    return float(np.min(graph.length) ** 2 / (2.0 * np.max(alpha)))


# ---------------------------------------------------------------------------------------
# Joule heating
# ---------------------------------------------------------------------------------------
def edge_joule_power(branch_current, conductance, eta: float = 1.0) -> np.ndarray:
    """Heat released in every edge, ``eta u_ij w_ij = eta w_ij^2 / c_ij`` [W] (paper 000
    eq. 11); 0 on edges of zero conductance (they carry no current)."""
    if not (0.0 <= eta <= 1.0):
        raise ValueError(f"eta (share of the electrical power released as heat) must be in [0, 1], got {eta}")
    w = np.asarray(branch_current, dtype=float)
    c = np.asarray(conductance, dtype=float)
    if w.shape != c.shape or w.ndim != 1:
        raise ValueError(f"branch_current and conductance must be (m,) arrays of one shape, got {w.shape} "
                         f"and {c.shape}")
    return eta * edge_power(w, c)


def joule_sources(edges, branch_current, conductance, n_nodes: int, eta: float = 1.0) -> np.ndarray:
    """Joule power received by every node [W]: each edge's ``eta w^2 / c`` shared half and half
    by its two end nodes. The total equals ``eta * sum_e V_e I_e`` over the electrodes
    (:func:`electrical_power`) when no current is injected elsewhere."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    p = edge_joule_power(branch_current, conductance, eta)
    if p.shape[0] != edges.shape[0]:
        raise ValueError(f"one branch current per edge expected ({edges.shape[0]}), got {p.shape[0]}")
    return 0.5 * (np.bincount(edges[:, 0], p, n_nodes) + np.bincount(edges[:, 1], p, n_nodes))


def electrical_power(solution) -> float:
    """``sum_e V_e I_e`` over the electrodes of a PotentialSolution [W]: the power the external
    circuit delivers (Tellegen: equals the total Joule power of the network)."""
    return float(sum(solution.electrode_potential[k] * solution.electrode_current[k]
                     for k in solution.electrode_current))


# ---------------------------------------------------------------------------------------
# boundary conditions
# ---------------------------------------------------------------------------------------
def exposed_area(graph: ContactGraph, threshold: float = 0.4) -> np.ndarray:
    """Default exposed (free-surface) area A_i of every element [m^2] for convection and
    surface fluxes: ``pi r_i^2`` where the eccentricity e_i > ``threshold`` (the elements the
    continuum model treats as on the surface, f_i = 2), 0 elsewhere.

    This is a crude estimate (one great-circle disc per surface element; the face elements
    of a simple cubic lattice, e = 0.4 exactly, count as interior). When the surface
    exchange matters, pass the areas yourself (``area=`` of :class:`Convection` /
    :class:`HeatFlux`), e.g. the boundary faces of the Voronoi cells.
    """
    e = eccentricity(graph)
    return np.where(e > threshold * (1.0 + 1e-9), np.pi * graph.radius ** 2, 0.0)


def _finite(name, v):
    try:
        return real_number(name, v)
    except MaterialError as exc:
        raise BoundaryConditionError(str(exc)) from None


def _check_bc(bc, kind):
    if not isinstance(bc.name, str) or not bc.name:
        raise BoundaryConditionError(f"{kind} boundary condition names must be non-empty strings, got {bc.name!r}")
    surface = getattr(bc, "surface", None)
    if surface is not None:
        if bc.nodes is not None:
            raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: give nodes= (elements) or surface= "
                                         "(a surface of the container), not both")
        if getattr(bc, "area", None) is not None:
            raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: a surface condition takes its areas "
                                         "from the boundary faces on the surface; do not give area=")
        from .boundary import check_surface
        check_surface(surface, f"{kind} boundary condition {bc.name!r}")
        return
    if bc.nodes is None:
        raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: give nodes= (a selector: predicate, "
                                     "ids, mask) or surface= (a surface of the container)")
    check_selector(bc.nodes, f"{kind} boundary condition {bc.name!r}: nodes")
    area = getattr(bc, "area", None)
    if area is not None and not callable(area):
        try:
            a = np.asarray(area, dtype=float)
        except (TypeError, ValueError):
            raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: area must be a number or an array "
                                         f"of areas (m^2), got {area!r}") from None
        if a.ndim > 1 or not np.all(np.isfinite(a)) or np.any(a < 0):
            raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: areas must be finite and >= 0 "
                                         "(m^2), a scalar or one per element")


def _required(bc, kind, field_, unit):
    if getattr(bc, field_) is None:
        raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: give {field_}= ({unit})")


@dataclass(frozen=True)
class FixedTemperature:
    """A fixed temperature [K or degC, as the model] on a node set or at a surface.

    ``nodes``: node indices (HeatSolver), or, when a graph is given
    (``HeatSolver.from_graph``, ``ElectroThermalModel``), anything
    ``yade_electro.selection.select_nodes`` takes (callable, mask, graph ids): those
    elements are held at ``temperature``. ``surface``: a surface of the container
    (``shape.face('top')``, see :mod:`yade_electro.boundary`; needs ``ElectroThermalModel``):
    the surface is held at ``temperature`` and each element with boundary faces on it
    exchanges heat with it through its half cell, ``lambda sum_f A_f / d_f`` [W/K] (the
    finite-volume Dirichlet condition). Give one of them."""

    name: str
    nodes: Any = None
    temperature: float = None
    surface: Any = None

    def __post_init__(self):
        _check_bc(self, "fixed-temperature")
        _required(self, "fixed-temperature", "temperature", "K")
        object.__setattr__(self, "temperature",
                           _finite(f"fixed-temperature boundary condition {self.name!r}: temperature", self.temperature))


@dataclass(frozen=True)
class ThermalWall:
    """A wall of a granular bed (a YADE ``Wall``, ``Box`` or facet mesh) for the heat model.

    ``temperature`` [K]: the wall is isothermal at that value and every sphere touching it
    exchanges ``G (T_wall - T_i)`` through the contact (G from the contact law with the
    sphere-plane contact radius, :func:`yade_electro.contacts.plane_contact_radius`); None:
    adiabatic (its contacts carry no heat). ``conductivity`` [W/(m K)]: the wall's material
    (default the particles'); a contact takes the harmonic mean of the two, as a contact
    between two particles of different materials does. The heat a wall gives goes into the
    history (``wall_heat:<name>``, cumulative J) and into ``boundary_heat``."""

    name: str
    temperature: Optional[float] = None
    conductivity: Optional[float] = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise BoundaryConditionError(f"wall names must be non-empty strings, got {self.name!r}")
        if self.temperature is not None:
            object.__setattr__(self, "temperature", _finite(f"wall {self.name!r}: temperature", self.temperature))
        if self.conductivity is not None:
            lam = _finite(f"wall {self.name!r}: conductivity", self.conductivity)
            if not lam > 0:
                raise BoundaryConditionError(f"wall {self.name!r}: conductivity must be > 0 (W/(m K)), got {lam}")
            object.__setattr__(self, "conductivity", lam)

    @property
    def isothermal(self) -> bool:
        return self.temperature is not None


@dataclass(frozen=True)
class HeatFlux:
    """Heat fed into a node set or through a surface: ``power`` [W] in total, shared in
    proportion to ``area`` (equal shares when ``area`` is None), or ``flux`` [W/m^2] times
    each node's ``area``. Negative values extract heat.

    ``area``: scalar (every node) or (n,) array over all nodes [m^2]; None = equal shares
    (power) or :func:`exposed_area` (flux, needs a graph). ``surface`` (instead of
    ``nodes``): the elements with boundary faces on it, with their faces' areas."""

    name: str
    nodes: Any = None
    power: Optional[float] = None
    flux: Optional[float] = None
    area: Any = None
    surface: Any = None

    def __post_init__(self):
        _check_bc(self, "heat-flux")
        if (self.power is None) == (self.flux is None):
            raise BoundaryConditionError(f"heat-flux boundary condition {self.name!r}: give exactly one of power= "
                                         "(W, total) or flux= (W/m^2)")
        field_ = "power" if self.power is not None else "flux"
        object.__setattr__(self, field_, _finite(f"heat-flux boundary condition {self.name!r}: {field_}",
                                                 getattr(self, field_)))


@dataclass(frozen=True)
class Convection:
    """Convection ``h A_i (t_inf - T_i)`` [W] on a node set: ``h`` [W/(m^2 K)] >= 0, ``t_inf`` the
    ambient temperature, ``area`` scalar or (n,) [m^2] (None = :func:`exposed_area`).
    ``surface`` (instead of ``nodes``): on the boundary faces of that surface of the
    container, in series with each element's half cell: ``sum_f A_f / (1/h + d_f/lambda)``."""

    name: str
    nodes: Any = None
    h: float = None
    t_inf: float = None
    area: Any = None
    surface: Any = None

    def __post_init__(self):
        _check_bc(self, "convection")
        _required(self, "convection", "h", "W/(m^2 K)")
        _required(self, "convection", "t_inf", "K")
        try:
            h = real_number(f"convection boundary condition {self.name!r}: h", self.h)
        except MaterialError as exc:
            raise MaterialError(f"{exc} (W/(m^2 K))") from None
        if h < 0:
            raise MaterialError(f"convection boundary condition {self.name!r}: h must be >= 0 (W/(m^2 K)), got {h}")
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "t_inf", _finite(f"convection boundary condition {self.name!r}: t_inf", self.t_inf))


@dataclass(frozen=True)
class HeatSource:
    """A heat source inside the solid, on a node set (``nodes``; None = every element):
    ``power`` [W] in total or ``density`` [W/m^3], shared in proportion to the elements'
    volumes (the volumes the heat capacities stand for). Negative values are sinks."""

    name: str
    nodes: Any = None
    power: Optional[float] = None
    density: Optional[float] = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise BoundaryConditionError(f"heat source names must be non-empty strings, got {self.name!r}")
        if self.nodes is not None:
            check_selector(self.nodes, f"heat source {self.name!r}: nodes")
        if (self.power is None) == (self.density is None):
            raise BoundaryConditionError(f"heat source {self.name!r}: give exactly one of power= (W, total) or "
                                         "density= (W/m^3)")
        field_ = "power" if self.power is not None else "density"
        object.__setattr__(self, field_, _finite(f"heat source {self.name!r}: {field_}", getattr(self, field_)))


def resolve_nodes(bc, n: int, graph: Optional[ContactGraph]) -> np.ndarray:
    """Node indices of a boundary condition's ``nodes`` (a selector with a graph, else node
    indices or a mask); BoundaryConditionError when it selects nothing."""
    if getattr(bc, "surface", None) is not None:
        raise BoundaryConditionError(f"thermal boundary condition {bc.name!r} is a surface: resolve it through "
                                     "ElectroThermalModel (which knows the container), or give nodes=")
    if graph is not None:
        return select_nodes(graph, bc.nodes, bc.name, "thermal boundary condition")
    if callable(bc.nodes):
        raise BoundaryConditionError(f"thermal boundary condition {bc.name!r}: a selector needs a graph; give "
                                     "node indices or use HeatSolver.from_graph")
    a = np.asarray(bc.nodes)
    if a.dtype == bool:
        if a.shape != (n,):
            raise BoundaryConditionError(f"{bc.name!r}: mask has shape {a.shape}, expected ({n},)")
        nodes = np.flatnonzero(a)
    else:
        nodes = np.unique(a.astype(np.int64).reshape(-1))
        if nodes.size and (nodes.min() < 0 or nodes.max() >= n):
            raise BoundaryConditionError(f"{bc.name!r}: node index out of range 0..{n - 1}")
    if nodes.size == 0:
        raise BoundaryConditionError(f"thermal boundary condition {bc.name!r} selects no element")
    return nodes


def resolve_area(bc, nodes, n, default_area) -> np.ndarray:
    if bc.area is None:
        if default_area is None:
            raise BoundaryConditionError(f"thermal boundary condition {bc.name!r}: no area given and no graph to "
                                         "estimate the exposed area from; pass area= (m^2, scalar or per node)")
        a = np.asarray(default_area, dtype=float)[nodes]
    else:
        a = np.asarray(bc.area, dtype=float)
        if a.ndim == 0:
            a = np.full(nodes.size, float(a))
        elif a.shape == (n,):
            a = a[nodes]
        else:
            raise BoundaryConditionError(f"thermal boundary condition {bc.name!r}: area must be a scalar or an ({n},) "
                                         f"array, got shape {a.shape}")
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise BoundaryConditionError(f"thermal boundary condition {bc.name!r}: areas must be finite and >= 0 (m^2)")
    return a


# ---------------------------------------------------------------------------------------
# stability
# ---------------------------------------------------------------------------------------
def stable_time_step(capacity, edges, conductance, h_area=None, fixed=None) -> float:
    """Largest forward-Euler step keeping the maximum principle [s]:
    ``min_i C_i / (sum_j G_ij + h_i A_i)`` over the free nodes (``fixed`` a boolean mask of
    fixed-temperature nodes); inf when no free node exchanges heat."""
    C = np.asarray(capacity, dtype=float)
    n = C.shape[0]
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    g = np.asarray(conductance, dtype=float)
    d = np.bincount(e[:, 0], g, n) + np.bincount(e[:, 1], g, n)
    if h_area is not None:
        d = d + np.asarray(h_area, dtype=float)
    free = np.ones(n, bool) if fixed is None else ~np.asarray(fixed, bool)
    sel = free & (d > 0)
    return float(np.min(C[sel] / d[sel])) if np.any(sel) else math.inf


def theta_of(theta) -> float:
    """theta from a number in [0, 1] or a name ('explicit', 'crank-nicolson', 'backward-euler')."""
    if isinstance(theta, (bool, np.bool_)) or theta is None:
        raise ValueError(f"theta must be 'explicit', 'crank-nicolson', 'backward-euler' or a number in [0, 1], "
                         f"got {theta!r}")
    if isinstance(theta, str):
        try:
            return _THETA_NAMES[theta.lower()]
        except KeyError:
            raise ValueError(f"unknown integrator {theta!r}; known: {', '.join(sorted(_THETA_NAMES))} "
                             "or a number in [0, 1]") from None
    try:
        t = float(theta)
    except (TypeError, ValueError):
        raise ValueError(f"theta must be a name ({', '.join(sorted(_THETA_NAMES))}) or a number in [0, 1], "
                         f"got {theta!r}") from None
    if not (0.0 <= t <= 1.0):
        raise ValueError(f"theta must be in [0, 1], got {theta}")
    return t


# ---------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------
def _ro(a):
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class ThermalState:
    """Temperatures (n,) [K] at ``time`` [s] (a read-only copy)."""

    temperature: np.ndarray
    time: float


@dataclass(frozen=True)
class HeatStep:
    """What one :meth:`HeatSolver.advance` did (energies in J over the step).

    source_energy : the given sources (e.g. Joule) on free nodes, integrated over dt
    absorbed_energy : given sources that fell on fixed-temperature nodes (taken by the thermostat)
    flux_energy : imposed heat fluxes (HeatFlux)
    convection_energy : heat received from the ambient by convection (negative when cooling)
    boundary_energy : heat received from the fixed-temperature nodes
    heat_change : sum_i C_i (T_i^{n+1} - T_i^n) over free nodes; equals the sum of the four
        inputs above (to rounding) for every theta
    """

    time: float
    dt: float
    n_substeps: int
    source_energy: float
    absorbed_energy: float
    flux_energy: float
    convection_energy: float
    boundary_energy: float
    heat_change: float
    info: dict = field(default_factory=dict, compare=False)

    @property
    def balance_error(self) -> float:
        """|heat_change - inputs| / max(|terms|): a check of the integration's energy balance."""
        inputs = self.source_energy + self.flux_energy + self.convection_energy + self.boundary_energy
        scale = max(abs(self.heat_change), abs(self.source_energy), abs(self.flux_energy),
                    abs(self.convection_energy), abs(self.boundary_energy)) or 1.0
        return abs(self.heat_change - inputs) / scale


@dataclass(frozen=True, eq=False)
class SteadyHeat:
    """A steady temperature field (:meth:`HeatSolver.steady`); powers in W.

    temperature : (n,) [K]
    source_power, flux_power : the given sources and the imposed fluxes / heat sources on free nodes
    convection_power : heat received from the ambient (negative: lost to it)
    boundary_power : heat received from the fixed temperatures (negative: taken by them)
    iterations, residual : of the linear solve (relative residual)
    """

    temperature: np.ndarray
    source_power: float
    flux_power: float
    convection_power: float
    boundary_power: float
    iterations: int
    residual: float

    @property
    def balance_error(self) -> float:
        """|sum of the powers| / max |power|: zero at the exact steady state."""
        terms = (self.source_power, self.flux_power, self.convection_power, self.boundary_power)
        return abs(sum(terms)) / (max(abs(t) for t in terms) or 1.0)


# ---------------------------------------------------------------------------------------
# the integrator
# ---------------------------------------------------------------------------------------
class HeatSolver:
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
    fixed, flux, convection : sequences of FixedTemperature, HeatFlux, Convection
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

    def __init__(self, capacity, edges, conductance, temperature, *, fixed: Sequence[FixedTemperature] = (),
                 flux: Sequence[HeatFlux] = (), convection: Sequence[Convection] = (), theta="backward-euler",
                 subcycle: bool = True, safety: float = 0.9, max_substeps: int = 100000, solver="cg",
                 time: float = 0.0, energy: Optional[dict] = None, graph: Optional[ContactGraph] = None, area=None,
                 nodes_of: Optional[dict] = None, area_of: Optional[dict] = None, link_of: Optional[dict] = None,
                 power=None, coords=None):
        C = self._check_capacity(capacity)
        n = C.shape[0]
        if graph is not None and graph.n_nodes != n:
            raise ValueError(f"the graph has {graph.n_nodes} nodes, capacity {n}")
        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if edges.size and (edges.min() < 0 or edges.max() >= n):
            raise ValueError(f"edge node index out of range 0..{n - 1}")
        self.theta = theta_of(theta)
        if not (0.0 < safety <= 1.0):
            raise ValueError(f"safety must be in (0, 1], got {safety}")
        self.subcycle, self.safety, self.max_substeps = bool(subcycle), float(safety), int(max_substeps)
        self.n, self.graph = n, graph
        self.edges = edges
        G = self._check_conductance(conductance, edges.shape[0])
        default_area = area if area is not None else (exposed_area(graph) if graph is not None else None)
        if default_area is not None:
            default_area = np.asarray(default_area, dtype=float)
            if default_area.shape != (n,):
                raise ValueError(f"area must be an ({n},) array, got {default_area.shape}")

        # boundary conditions -> node sets and per-node arrays
        self.fixed_bcs, self.flux_bcs, self.convection_bcs = list(fixed), list(flux), list(convection)
        names = [b.name for b in self.fixed_bcs + self.flux_bcs + self.convection_bcs]
        if len(set(names)) != len(names):
            raise BoundaryConditionError(f"thermal boundary condition names must be unique, got {names}")
        nodes_of = dict(nodes_of or {})
        area_of, link_of = dict(area_of or {}), dict(link_of or {})

        def nodes(bc):
            if bc.name in nodes_of:
                nd = np.asarray(nodes_of[bc.name], dtype=np.int64)
                if bc.name in area_of or bc.name in link_of:
                    return nd                   # aligned with its areas / conductances
                return np.unique(nd)
            return resolve_nodes(bc, n, graph)

        def per_node(table, bc, nd, what):
            a = np.asarray(table[bc.name], dtype=float)
            if a.shape != nd.shape or not np.all(np.isfinite(a)) or np.any(a < 0):
                raise BoundaryConditionError(f"thermal boundary condition {bc.name!r}: {what} must be finite, >= 0 "
                                             f"and one per node of the condition ({nd.size})")
            return a
        owner = np.full(n, -1, dtype=np.int64)
        self._fixed_nodes = {}
        self._links = {}
        for k, b in enumerate(self.fixed_bcs):
            if b.name in link_of:
                nd = nodes(b)
                self._links[b.name] = (nd, per_node(link_of, b, nd, "link conductances (W/K)"))
                continue
            nd = nodes(b)
            clash = nd[owner[nd] >= 0]
            if clash.size:
                raise BoundaryConditionError(
                    f"{clash.size} element(s) are in both fixed-temperature boundary conditions "
                    f"{self.fixed_bcs[owner[clash[0]]].name!r} and {b.name!r}; make them disjoint")
            owner[nd] = k
            self._fixed_nodes[b.name] = nd
        self._fixed_value = {b.name: float(b.temperature) for b in self.fixed_bcs}
        self.fixed = owner >= 0
        self.fixed.setflags(write=False)
        q = np.zeros(n)
        for b in self.flux_bcs:
            nd = nodes(b)
            if b.name in area_of:
                a = per_node(area_of, b, nd, "areas (m^2)")
                if b.power is not None:
                    if a.sum() <= 0:
                        raise BoundaryConditionError(f"heat-flux boundary condition {b.name!r}: the areas sum to 0")
                    np.add.at(q, nd, b.power * a / a.sum())
                else:
                    np.add.at(q, nd, b.flux * a)
            elif b.power is not None:
                if b.area is None:
                    share = np.full(nd.size, 1.0 / nd.size)
                else:
                    a = resolve_area(b, nd, n, None)
                    if a.sum() <= 0:
                        raise BoundaryConditionError(f"heat-flux boundary condition {b.name!r}: the areas sum to 0")
                    share = a / a.sum()
                np.add.at(q, nd, b.power * share)
            else:
                np.add.at(q, nd, b.flux * resolve_area(b, nd, n, default_area))
        if power is not None:
            pw = np.asarray(power, dtype=float)
            if pw.shape != (n,) or not np.all(np.isfinite(pw)):
                raise BoundaryConditionError(f"power (heat sources) must be a finite ({n},) array (W per node)")
            q += pw
        hA, hAT = np.zeros(n), np.zeros(n)
        for b in self.convection_bcs:
            nd = nodes(b)
            ha = b.h * (per_node(area_of, b, nd, "areas (m^2)") if b.name in area_of
                        else resolve_area(b, nd, n, default_area))
            np.add.at(hA, nd, ha)
            np.add.at(hAT, nd, ha * b.t_inf)
        hA[self.fixed] = 0.0
        hAT[self.fixed] = 0.0
        q[self.fixed] = 0.0
        self._conv_hA, self._conv_hAT = hA, hAT
        self.flux_power = _ro(q)
        self._refresh_links()
        self.nodes_of = {**self._fixed_nodes, **{k: v[0] for k, v in self._links.items()},
                         **{b.name: nodes(b) for b in self.flux_bcs + self.convection_bcs}}

        self._solver_spec = solver
        self._coords = None if coords is None else np.asarray(coords, dtype=float)
        self._solver = None
        self.structure_builds = 0
        self.capacity = _ro(C)
        self.conductance = _ro(G)
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

    @staticmethod
    def _check_conductance(conductance, m):
        G = np.asarray(conductance, dtype=float)
        if G.shape != (m,):
            raise ValueError(f"conductance must have one value per edge ({m}), got {G.shape}")
        if not np.all(np.isfinite(G)) or np.any(G < 0):
            raise MaterialError("thermal conductances must be finite and >= 0 (W/K); check the conductivity")
        return G

    def _build_structure(self):
        groups = [self._fixed_nodes[b.name] for b in self.fixed_bcs if b.name in self._fixed_nodes]
        self.system = ReducedSystem(self.n, self.edges, groups)
        self._u = self.system.unknown_nodes
        self._d = np.flatnonzero(self.fixed)
        nu = self._u.size
        if self._solver is None or isinstance(self._solver_spec, str):
            self._solver = make_solver(self._solver_spec, n_unknowns=nu,
                                       **({"rtol": self.RTOL} if isinstance(self._solver_spec, str)
                                          and self._solver_spec != "direct" else {}))
        if self._coords is not None and nu:
            e = self.edges
            d = self._coords[e[:, 1]] - self._coords[e[:, 0]]
            spacing = float(np.mean(np.sqrt(np.einsum("ij,ij->i", d, d)))) if e.size else None
            self._solver.set_geometry(self._coords[self._u], spacing)
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
            self.conductance = _ro(self._check_conductance(conductance, self.edges.shape[0]))
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
        slots = edge_slots(self.edges, edges, self.n)
        if slots is not None:
            full = np.zeros(self.edges.shape[0])
            full[slots] = G
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

    @property
    def solver(self):
        """The linear solver of the implicit steps (kept while the structure is)."""
        return self._solver

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
        self._fixed_value[name] = _finite(f"fixed temperature {name!r}", temperature)
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
                f"{'' if self.theta == 0 else f' / (1 - 2 theta)'}); reduce dt, allow sub-cycling "
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

    # -- steady state ------------------------------------------------------------------------
    def _check_sinks(self):
        """Every connected part of the free nodes must reach a fixed temperature or a
        convection: else its steady temperature is not defined."""
        import scipy.sparse.csgraph as csg
        u = self._u
        if u.size == 0:
            return
        n_parts, label = csg.connected_components(self._Muu, directed=False)
        sink = np.zeros(n_parts, bool)
        np.logical_or.at(sink, label, self.h_area[u] > 0)
        if self._Mud is not None and self._Mud.shape[1]:
            touches = np.asarray(abs(self._Mud).sum(axis=1)).ravel() > 0
            np.logical_or.at(sink, label, touches)
        if not np.all(sink):
            lost = int(np.sum(~sink[label]))
            raise ThermalError(
                f"{lost} element(s) in {int(np.sum(~sink))} connected part(s) reach no fixed temperature and no "
                "convection: their steady temperature is not defined (any heat put in has nowhere to go). Add a "
                "FixedTemperature or a Convection there, or integrate in time (advance)")

    def steady(self, sources=None, apply: bool = True, rtol: float = 1e-12) -> SteadyHeat:
        """The steady temperatures ``M T = s`` with the given ``sources`` [W per node] (plus the
        fluxes, heat sources, convection and fixed temperatures of this solver); they replace
        the current temperatures when ``apply`` (the clock does not move). Raises ThermalError
        when some part of the network has no fixed temperature and no convection.

        The linear solver is ``'auto'`` (:func:`yade_electro.solvers.auto_solver_name`: the
        deflated CG from 80 unknowns on), kept across calls, to ``rtol`` relative residual."""
        n = self.n
        src = np.zeros(n) if sources is None else np.asarray(sources, dtype=float)
        if src.shape != (n,) or not np.all(np.isfinite(src)):
            raise ThermalError(f"sources must be a finite ({n},) array (W per node)")
        self._check_sinks()
        u = self._u
        Tg = self._fixed_group_values()
        rhs = src[u] + self.flux_power[u] + self._hAT[u]
        if Tg.size:
            rhs = rhs - self._Mud @ Tg
        T = self._T.copy()
        info = {"iterations": 0, "residual": 0.0}
        if u.size:
            if getattr(self, "_steady_solver", None) is None or self._steady_key != id(self.system):
                self._steady_solver = make_solver("auto", n_unknowns=u.size, rtol=rtol)
                if self._coords is not None:
                    e = self.edges
                    d = self._coords[e[:, 1]] - self._coords[e[:, 0]]
                    spacing = float(np.mean(np.sqrt(np.einsum("ij,ij->i", d, d)))) if e.size else None
                    self._steady_solver.set_geometry(self._coords[u], spacing)
                self._steady_key = id(self.system)
                self._steady_A = None
            if self._steady_A is None:
                self._steady_A = self._Muu.copy()
            else:
                self._steady_A.data[:] = self._Muu.data
                self._steady_solver.update(self._steady_A)
            try:
                Tu, info = self._steady_solver.solve(self._steady_A, rhs, x0=T[u])
            except (SolverError, RuntimeError, ArithmeticError) as exc:
                raise ThermalError(f"the steady heat solve failed ({exc}); the temperatures are unchanged") from exc
            if not np.all(np.isfinite(Tu)):
                raise ThermalError("the steady heat solve gave non-finite temperatures; the temperatures are "
                                   "unchanged (check the sources and conductances)")
            T[u] = Tu
        Tu = T[u]
        boundary = float(np.sum(self.system.group_flux(Tu, Tg))) if self._d.size else 0.0
        boundary += float(np.sum(self._link_GT[u] - self._link_G[u] * Tu))
        out = SteadyHeat(temperature=_ro(T), source_power=float(np.sum(src[u])),
                         flux_power=float(np.sum(self.flux_power[u])),
                         convection_power=float(np.sum(self._conv_hAT[u] - self._conv_hA[u] * Tu)),
                         boundary_power=boundary, iterations=int(info.get("iterations", 0)),
                         residual=float(info.get("residual", 0.0)))
        if apply:
            self._T = T
            self._dT_prev = None
        return out

    # -- construction from a graph ----------------------------------------------------------
    @classmethod
    def from_graph(cls, graph: ContactGraph, density, specific_heat, conductivity, temperature, *,
                   law="continuum", law_params: Optional[dict] = None, volume_fraction=None,
                   cell_volume=None, **kw) -> "HeatSolver":
        """A solver on ``graph``: capacities by :func:`heat_capacity`, conductances by
        :func:`thermal_conductance` with ``law``; other keywords go to the constructor."""
        C = heat_capacity(graph, density, specific_heat, volume_fraction=volume_fraction, cell_volume=cell_volume)
        G = thermal_conductance(graph, conductivity, law, **(law_params or {}))
        kw.setdefault("coords", graph.pos)
        return cls(C, graph.edges, G, temperature, graph=graph, **kw)
