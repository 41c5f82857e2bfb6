"""Results of the network solves, as frozen records of read-only arrays.

:class:`PotentialSolution` (a potential solve), :class:`ThermalState`, :class:`HeatStep`
(one transient heat step) and :class:`SteadyHeat` (a steady heat solve). Units: SI.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict

import numpy as np

from ..core.errors import BoundaryConditionError
from .kirchhoff import edge_power

__all__ = ["PotentialSolution", "ThermalState", "HeatStep", "SteadyHeat", "read_only_copy"]


@dataclass(frozen=True, eq=False)
class PotentialSolution:
    """Result of one potential solve (SI units: V, A, ohm).

    Attributes
    ----------
    potential : (n,) node potentials [V] (0 on floating clusters)
    branch_current : (m,) current from ``edges[k,0]`` to ``edges[k,1]`` [A]
    electrode_potential, electrode_current : dict name -> V, A (current fed into the network)
    floating : (n,) bool, nodes in parts with no potential reference (no current, potential 0)
    residual : largest relative residual of the linear solves behind this solution
    current_imbalance : ``|sum of electrode currents + injections|`` / max ``|electrode current|``
    component_of_electrode : dict name -> connected part label
    conductance_matrix : (ne, ne) S [S], electrode currents I = S V (+ injection part)
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
    conductance_matrix: np.ndarray = None
    info: dict = field(default_factory=dict)

    def equivalent_resistance(self, a: str, b: str) -> float:
        """R_eq [ohm] between electrodes a and b, the other electrodes left open (floating):
        a property of the network, exact for any applied values; inf when a and b are not
        connected."""
        names = list(self.electrode_current)
        for e in (a, b):
            if e not in self.electrode_current:
                raise BoundaryConditionError(f"no electrode named {e!r}; have {sorted(names)}")
        if a == b:
            raise BoundaryConditionError(f"R_eq needs two different electrodes, got {a!r} twice")
        comp = self.component_of_electrode
        if comp[a] != comp[b]:
            return float("inf")
        return _two_terminal_resistance(self.conductance_matrix, names, comp, a, b)

    def joule_power(self, conductance) -> np.ndarray:
        """Power dissipated in each edge, w^2 / c [W] (see :func:`edge_power`)."""
        return edge_power(self.branch_current, conductance)


def _two_terminal_resistance(S, names, comp, a, b) -> float:
    idx = [k for k, nm in enumerate(names) if comp[nm] == comp[a]]
    ia, ib = names.index(a), names.index(b)
    others = [k for k in idx if k not in (ia, ib)]
    Saa = S[np.ix_([ia, ib], [ia, ib])]
    if others:
        Sao = S[np.ix_([ia, ib], others)]
        Soo = S[np.ix_(others, others)]
        Saa = Saa - Sao @ np.linalg.solve(Soo, Sao.T)
    g = -Saa[0, 1]
    scale = float(np.max(np.abs(S))) if S.size else 0.0
    if not g > 1e-14 * scale:
        return float("inf")
    return float(1.0 / g)


def read_only_copy(a) -> np.ndarray:
    """A read-only float copy of ``a``."""
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

    Attributes
    ----------
    source_energy : float
        The given sources (e.g. Joule) on free nodes, integrated over dt.
    absorbed_energy : float
        Given sources that fell on fixed-temperature nodes (taken by the thermostat).
    flux_energy : float
        Imposed heat fluxes (HeatFlux).
    convection_energy : float
        Heat received from the ambient by convection (negative when cooling).
    boundary_energy : float
        Heat received from the fixed-temperature nodes.
    heat_change : float
        ``sum_i C_i (T_i^{n+1} - T_i^n)`` over free nodes; equals the sum of the four inputs
        above (to rounding) for every theta.
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
        """``|heat_change - inputs|`` / max(``|terms|``): a check of the integration's energy balance."""
        inputs = self.source_energy + self.flux_energy + self.convection_energy + self.boundary_energy
        scale = max(abs(self.heat_change), abs(self.source_energy), abs(self.flux_energy),
                    abs(self.convection_energy), abs(self.boundary_energy)) or 1.0
        return abs(self.heat_change - inputs) / scale


@dataclass(frozen=True, eq=False)
class SteadyHeat:
    """A steady temperature field (:meth:`HeatSolver.steady`); powers in W.

    Attributes
    ----------
    temperature : (n,) array
        Temperatures [K].
    source_power, flux_power : float
        The given sources, and the imposed fluxes and heat sources, on free nodes [W].
    convection_power : float
        Heat received from the ambient [W] (negative: lost to it).
    boundary_power : float
        Heat received from the fixed temperatures [W] (negative: taken by them).
    iterations, residual : int, float
        Of the linear solve (relative residual).
    floating : (n,) bool array
        Nodes in parts that reach no fixed temperature and no convection: with no heat put
        into them they keep their mean temperature (:mod:`yade_electro.network.floating`).
    """

    temperature: np.ndarray
    source_power: float
    flux_power: float
    convection_power: float
    boundary_power: float
    iterations: int
    residual: float
    floating: np.ndarray = None

    @property
    def balance_error(self) -> float:
        """``|sum of the powers|`` / max ``|power|``: zero at the exact steady state."""
        terms = (self.source_power, self.flux_power, self.convection_power, self.boundary_power)
        return abs(sum(terms)) / (max(abs(t) for t in terms) or 1.0)
