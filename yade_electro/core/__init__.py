"""Data with no physics and no solver: the contact graph, materials, node selections, the
history table, progress reports, errors and thread limits. Units: SI.
"""
from .errors import ElectroError, GraphError, BoundaryConditionError, MaterialError, SolverError, ThermalError
from .graph import ContactGraph
from .history import History
from .materials import (Material, positive_property, real_number, edge_resistivity, edge_conductivity,
                        electrical_conductance, thermal_conductance_of)
from .progress import PROGRESS_EVERY, Progress
from .selection import Selector, check_selector, select_nodes, Membership
from .threads import blas_threads, limit_blas_threads, apply_default_limit

__all__ = ["ElectroError", "GraphError", "BoundaryConditionError", "MaterialError", "SolverError",
           "ThermalError", "ContactGraph", "History", "Material", "positive_property", "real_number",
           "edge_resistivity", "edge_conductivity", "electrical_conductance", "thermal_conductance_of",
           "PROGRESS_EVERY", "Progress", "Selector", "check_selector", "select_nodes", "Membership",
           "blas_threads", "limit_blas_threads", "apply_default_limit"]
