"""The transport core, physics-blind: condensation of fixed values, Kirchhoff networks with
electrodes, the heat network's boundary conditions, the theta-method integrator with sub-cycling,
steady solves and the energy ledger. Never imports YADE.
"""
from .condensation import ReducedSystem
from .conditions import (FixedTemperature, ThermalWall, HeatFlux, Convection, HeatSource, resolve_nodes,
                         resolve_area, ResolvedConditions, resolve_conditions, check_place)
from .conduction import ConductionProblem, solve_potential, equivalent_resistance
from .floating import (floating_message, warn_floating, no_steady_state_message, floating_parts,
                       hold_at_mean, solve_with_floating)
from .kirchhoff import (laplacian, network_components, electrode_value, edge_power, PotentialOrCurrent,
                        Electrode)
from .records import PotentialSolution, ThermalState, HeatStep, SteadyHeat, read_only_copy
from .theta import theta_of, stable_time_step, THETA_NAMES
from .transient import HeatSolver

__all__ = ["ReducedSystem", "FixedTemperature", "ThermalWall", "HeatFlux", "Convection", "HeatSource",
           "resolve_nodes", "resolve_area", "ResolvedConditions", "resolve_conditions", "check_place",
           "ConductionProblem", "solve_potential", "equivalent_resistance", "floating_message",
           "warn_floating", "no_steady_state_message", "floating_parts", "hold_at_mean",
           "solve_with_floating", "laplacian", "network_components", "electrode_value", "edge_power",
           "PotentialOrCurrent", "Electrode", "PotentialSolution", "ThermalState", "HeatStep", "SteadyHeat",
           "read_only_copy", "theta_of", "stable_time_step", "THETA_NAMES", "HeatSolver"]
