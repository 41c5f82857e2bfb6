"""The thermal names of the boundary vocabulary (:mod:`yade_electro.network.boundary`): a fixed
temperature, a heat flux, convection and a heat source are a fixed value, an injection, a Robin
condition and a source, checked by their one check; a wall of a granular bed.

Units: SI (K or degC, W, W/m^2, W/(m^2 K), W/m^3, m^2).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Dict, Optional

from ..core.errors import BoundaryConditionError
from .boundary import Condition, boundary_value

__all__ = ["FixedTemperature", "ThermalWall", "HeatFlux", "Convection", "HeatSource"]


@dataclass(frozen=True)
class FixedTemperature(Condition):
    """A fixed temperature [K or degC, as the model] on a node set or at a surface.

    ``nodes``: node indices (HeatSolver), or, when a graph is given
    (:func:`~yade_electro.physics.thermal.heat_solver_on_graph`, ``ElectroThermalModel``), anything
    ``yade_electro.core.selection.select_nodes`` takes (callable, mask, graph ids): those
    elements are held at ``temperature``. ``surface``: a surface of the container
    (``shape.face('top')``, see :mod:`yade_electro.geometry.boundary`; needs ``ElectroThermalModel``):
    the surface is held at ``temperature`` and each element with boundary faces on it
    exchanges heat with it through its half cell, ``lambda sum_f A_f / d_f`` [W/K] (the
    finite-volume Dirichlet condition). Give one of them."""

    ROLE: ClassVar[str] = "fixed"
    KIND: ClassVar[str] = "fixed-temperature boundary condition"
    FIELDS: ClassVar[Dict[str, str]] = {"value": "temperature"}
    UNITS: ClassVar[Dict[str, str]] = {"value": "K"}

    name: str
    nodes: Any = None
    temperature: float = None
    surface: Any = None


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
class HeatFlux(Condition):
    """Heat fed into a node set or through a surface: ``power`` [W] in total, shared in
    proportion to ``area`` (equal shares when ``area`` is None), or ``flux`` [W/m^2] times
    each node's ``area``. Negative values extract heat.

    ``area``: scalar (every node) or (n,) array over all nodes [m^2]; None = equal shares
    (power) or :func:`exposed_area` (flux, needs a graph). ``surface`` (instead of
    ``nodes``): the elements with boundary faces on it, with their faces' areas."""

    ROLE: ClassVar[str] = "injection"
    KIND: ClassVar[str] = "heat-flux boundary condition"
    FIELDS: ClassVar[Dict[str, str]] = {"rate": "power", "density": "flux"}
    UNITS: ClassVar[Dict[str, str]] = {"rate": "W", "density": "W/m^2"}

    name: str
    nodes: Any = None
    power: Optional[float] = None
    flux: Optional[float] = None
    area: Any = None
    surface: Any = None


@dataclass(frozen=True)
class Convection(Condition):
    """Convection ``h A_i (t_inf - T_i)`` [W] on a node set: ``h`` [W/(m^2 K)] >= 0, ``t_inf`` the
    ambient temperature, ``area`` scalar or (n,) [m^2] (None = :func:`exposed_area`).
    ``surface`` (instead of ``nodes``): on the boundary faces of that surface of the
    container, in series with each element's half cell: ``sum_f A_f / (1/h + d_f/lambda)``."""

    ROLE: ClassVar[str] = "robin"
    KIND: ClassVar[str] = "convection boundary condition"
    FIELDS: ClassVar[Dict[str, str]] = {"coefficient": "h", "ambient": "t_inf"}
    UNITS: ClassVar[Dict[str, str]] = {"coefficient": "W/(m^2 K)", "ambient": "K"}

    name: str
    nodes: Any = None
    h: float = None
    t_inf: float = None
    area: Any = None
    surface: Any = None


@dataclass(frozen=True)
class HeatSource(Condition):
    """A heat source inside the solid, on a node set (``nodes``; None = every element):
    ``power`` [W] in total or ``density`` [W/m^3], shared in proportion to the elements'
    volumes (the volumes the heat capacities stand for). Negative values are sinks."""

    ROLE: ClassVar[str] = "source"
    KIND: ClassVar[str] = "heat source"
    FIELDS: ClassVar[Dict[str, str]] = {"rate": "power", "density": "density"}
    UNITS: ClassVar[Dict[str, str]] = {"rate": "W", "density": "W/m^3"}

    name: str
    nodes: Any = None
    power: Optional[float] = None
    density: Optional[float] = None
