"""Physics layers on the transport core: electrical (c = g / rho_e(T)), thermal (G = lambda g,
capacities, Joule sources), the coupled electro-thermal model (the one owner of time and energy) and
thermo-mechanics (thermal strain, bond rest-length and radius growth, Love-Weber stress).
"""
from .coupled import ElectroThermalModel
from .expansion import AlphaTable, element_stress, thermal_strain
from .electrical import ElectrodeSpec, ElectricalModel, electrode_specs
from .integrator import Integrator, MODEL_OPTIONS
from .thermal import (heat_capacity, thermal_conductance, diffusion_time_step, edge_joule_power,
                      joule_sources, cell_joule_sources, electrical_power, heat_solver_on_graph, surface_conditions,
                      source_power)
from .walls import WallContacts

__all__ = ["ElectroThermalModel", "ElectrodeSpec", "ElectricalModel", "electrode_specs", "Integrator",
           "MODEL_OPTIONS", "heat_capacity", "thermal_conductance", "diffusion_time_step",
           "edge_joule_power", "joule_sources", "cell_joule_sources", "electrical_power", "heat_solver_on_graph",
           "surface_conditions", "source_power", "WallContacts", "AlphaTable", "element_stress", "thermal_strain"]
