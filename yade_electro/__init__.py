"""yade-electro: electrical conduction, Joule heating and heat conduction in DEM packings.

The core (this package's top-level modules) is plain numpy/scipy and never imports YADE;
``yade_electro.yade`` adapts it to a running YADE simulation and ``yade_electro.liggghts``
writes LIGGGHTS input decks. SI units everywhere.
"""
from .errors import (ElectroError, GraphError, BoundaryConditionError, MaterialError,
                     SolverError, ThermalError)
from .graph import ContactGraph
from .surfaces import (transmission_surface, edge_transmission_surface, volume_fraction,
                       eccentricity, polyhedron_alpha, polyhedron_volume_fraction)
from .conductance import conductance, conductance_laws, register_conductance_law
from .network import (Electrode, PotentialSolution, laplacian, solve_potential,
                      equivalent_resistance, make_solver, DirectSolver, CGSolver)

__version__ = "0.1.0"
from .engine import ElectricalModel, ElectrodeSpec, History
from .thermal import (heat_capacity, thermal_conductance, joule_sources, HeatSolver, FixedTemperature,
                      HeatFlux, Convection)
from .coupled import ElectroThermalModel
