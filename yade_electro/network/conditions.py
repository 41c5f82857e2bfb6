"""Boundary conditions of the heat network: fixed temperatures, walls, fluxes, convection and
sources, checked on construction, and their resolution to node sets and per-node areas.

Units: SI (K or degC, W, W/m^2, W/(m^2 K), W/m^3, m^2).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError, MaterialError
from ..core.graph import ContactGraph
from ..core.materials import real_number
from ..core.selection import check_selector, select_nodes

__all__ = ["FixedTemperature", "ThermalWall", "HeatFlux", "Convection", "HeatSource", "resolve_nodes",
           "resolve_area", "ResolvedConditions", "resolve_conditions",
           "check_place"]


def boundary_value(name, v) -> float:
    """``v`` as a finite real number, or a BoundaryConditionError naming ``name``."""
    try:
        return real_number(name, v)
    except MaterialError as exc:
        raise BoundaryConditionError(str(exc)) from None


def check_place(what: str, name, *, elements=None, surface=None, wall=False, elements_key: str = "nodes",
                allow_wall: bool = False) -> None:
    """Check where a condition acts, the one check for electrodes and thermal conditions: a
    non-empty ``name`` and exactly one place, elements (``elements_key=``, a selector), a
    ``surface`` of the container, or (``allow_wall``) a wall of a granular bed; the surface and
    the selector are checked too. BoundaryConditionError saying what to give."""
    if not isinstance(name, str) or not name:
        raise BoundaryConditionError(f"{what} names must be non-empty strings, got {name!r}")
    options = (f"{elements_key}= (elements: a predicate, ids or a mask) or surface= (a surface of the container)"
               + (" or wall= (a wall of a granular bed)" if allow_wall else ""))
    given = (elements is not None) + (surface is not None) + bool(wall)
    if given != 1:
        raise BoundaryConditionError(f"{what} {name!r}: give {options}" + (", not both" if given > 1 else ""))
    if surface is not None:
        from ..geometry.boundary import check_surface
        check_surface(surface, f"{what} {name!r}")
    elif elements is not None:
        check_selector(elements, f"{what} {name!r}: {elements_key}")


def _check_bc(bc, kind):
    surface = getattr(bc, "surface", None)
    check_place(f"{kind} boundary condition", bc.name, elements=bc.nodes, surface=surface)
    if surface is not None:
        if getattr(bc, "area", None) is not None:
            raise BoundaryConditionError(f"{kind} boundary condition {bc.name!r}: a surface condition takes its areas "
                                         "from the boundary faces on the surface; do not give area=")
        return
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
    (:func:`~yade_electro.physics.thermal.heat_solver_on_graph`, ``ElectroThermalModel``), anything
    ``yade_electro.core.selection.select_nodes`` takes (callable, mask, graph ids): those
    elements are held at ``temperature``. ``surface``: a surface of the container
    (``shape.face('top')``, see :mod:`yade_electro.geometry.boundary`; needs ``ElectroThermalModel``):
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
                           boundary_value(f"fixed-temperature boundary condition {self.name!r}: temperature", self.temperature))


@dataclass(frozen=True)
class ThermalWall:
    """A wall of a granular bed (a YADE ``Wall``, ``Box`` or facet mesh) for the heat model.

    ``temperature`` [K]: the wall is isothermal at that value and every sphere touching it
    exchanges ``G (T_wall - T_i)`` through the contact (G from the contact law with the
    sphere-plane contact radius, :func:`yade_electro.geometry.contacts.plane_contact_radius`); None:
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
            object.__setattr__(self, "temperature", boundary_value(f"wall {self.name!r}: temperature", self.temperature))
        if self.conductivity is not None:
            lam = boundary_value(f"wall {self.name!r}: conductivity", self.conductivity)
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
        object.__setattr__(self, field_, boundary_value(f"heat-flux boundary condition {self.name!r}: {field_}",
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
        object.__setattr__(self, "t_inf", boundary_value(f"convection boundary condition {self.name!r}: t_inf", self.t_inf))


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
        object.__setattr__(self, field_, boundary_value(f"heat source {self.name!r}: {field_}", getattr(self, field_)))


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
                                     "node indices or use heat_solver_on_graph")
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


@dataclass(frozen=True, eq=False)
class ResolvedConditions:
    """The boundary conditions of a heat network resolved to node sets and per-node arrays.

    fixed_nodes : dict name -> node indices held at a fixed temperature (eliminated)
    links : dict name -> (node indices, conductances [W/K]) of fixed temperatures held at a surface
    fixed : (n,) bool, read-only: the eliminated fixed-temperature nodes
    power : (n,) imposed heat inputs [W] (fluxes and sources), 0 on fixed nodes
    h_area, h_area_t_inf : (n,) convection ``h A`` [W/K] and ``h A T_inf`` [W], 0 on fixed nodes
    nodes_of : dict name -> node indices of every condition
    """

    fixed_nodes: dict
    links: dict
    fixed: np.ndarray
    power: np.ndarray
    h_area: np.ndarray
    h_area_t_inf: np.ndarray
    nodes_of: dict


def resolve_conditions(n: int, fixed: Sequence[FixedTemperature], flux: Sequence[HeatFlux],
                       convection: Sequence[Convection], *, graph: Optional[ContactGraph] = None,
                       default_area=None, nodes_of: Optional[dict] = None, area_of: Optional[dict] = None,
                       link_of: Optional[dict] = None, power=None) -> ResolvedConditions:
    """Resolve the conditions of an ``n``-node heat network (see
    :class:`~yade_electro.network.transient.HeatSolver` for ``nodes_of``, ``area_of``,
    ``link_of`` and ``power``); raises BoundaryConditionError on duplicate names, overlapping
    fixed sets, and areas, conductances or powers that are not finite and >= 0."""
    fixed, flux, convection = list(fixed), list(flux), list(convection)
    names = [b.name for b in fixed + flux + convection]
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
    fixed_nodes = {}
    links = {}
    for k, b in enumerate(fixed):
        if b.name in link_of:
            nd = nodes(b)
            links[b.name] = (nd, per_node(link_of, b, nd, "link conductances (W/K)"))
            continue
        nd = nodes(b)
        clash = nd[owner[nd] >= 0]
        if clash.size:
            raise BoundaryConditionError(
                f"{clash.size} element(s) are in both fixed-temperature boundary conditions "
                f"{fixed[owner[clash[0]]].name!r} and {b.name!r}; make them disjoint")
        owner[nd] = k
        fixed_nodes[b.name] = nd
    is_fixed = owner >= 0
    is_fixed.setflags(write=False)
    q = np.zeros(n)
    for b in flux:
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
    for b in convection:
        nd = nodes(b)
        ha = b.h * (per_node(area_of, b, nd, "areas (m^2)") if b.name in area_of
                    else resolve_area(b, nd, n, default_area))
        np.add.at(hA, nd, ha)
        np.add.at(hAT, nd, ha * b.t_inf)
    hA[is_fixed] = 0.0
    hAT[is_fixed] = 0.0
    q[is_fixed] = 0.0
    every = {**fixed_nodes, **{k: v[0] for k, v in links.items()},
             **{b.name: nodes(b) for b in flux + convection}}
    return ResolvedConditions(fixed_nodes=fixed_nodes, links=links, fixed=is_fixed, power=q, h_area=hA,
                              h_area_t_inf=hAT, nodes_of=every)
