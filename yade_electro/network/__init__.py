"""The transport core, physics-blind: one boundary vocabulary (fixed values, terminals,
injections, Robin terms, sources) with its thermal and electrical names, condensation of fixed
values, Kirchhoff networks with terminals, the theta-method integrator with sub-cycling, steady
solves, one policy for floating parts, and the energy ledger. Never imports YADE.
"""
from .boundary import (boundary_value, check_place, check_area, terminal_number, Condition, TerminalRole, FixedValue,
                       Terminal, Injection, Robin, Source, generic, check_condition)
from .condensation import ReducedSystem
from .heat_conditions import FixedTemperature, ThermalWall, HeatFlux, Convection, HeatSource
from .resolution import resolve_nodes, resolve_area, ResolvedConditions, resolve_conditions
from .conduction import ConductionProblem, solve_potential, equivalent_resistance
from .floating import (floating_message, warn_floating, no_steady_state_message, floating_parts,
                       hold_at_mean, solve_with_floating)
from .kirchhoff import (laplacian, network_components, electrode_value, edge_power, PotentialOrCurrent,
                        Electrode)
from .records import PotentialSolution, ThermalState, HeatStep, SteadyHeat, read_only_copy
from .structure import Words, GENERIC_WORDS, NetworkStructure
from .theta import theta_of, stable_time_step, THETA_NAMES
from .transient import HeatSolver
from . import grain_law as _grain_law     # registers the 'grains' law  # noqa: F401

__all__ = ["boundary_value", "check_place", "check_area", "terminal_number", "Condition", "TerminalRole", "FixedValue",
           "Terminal", "Injection", "Robin", "Source", "generic", "check_condition", "ReducedSystem", "FixedTemperature", "ThermalWall",
           "HeatFlux", "Convection", "HeatSource", "resolve_nodes", "resolve_area", "ResolvedConditions",
           "resolve_conditions", "ConductionProblem", "solve_potential", "equivalent_resistance",
           "floating_message", "warn_floating", "no_steady_state_message", "floating_parts", "hold_at_mean",
           "solve_with_floating", "laplacian", "network_components", "electrode_value", "edge_power",
           "PotentialOrCurrent", "Electrode", "PotentialSolution", "ThermalState", "HeatStep", "SteadyHeat",
           "read_only_copy", "Words", "GENERIC_WORDS", "NetworkStructure", "theta_of", "stable_time_step", "THETA_NAMES",
           "HeatSolver"]
