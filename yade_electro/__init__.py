"""yade-electro: electrical conduction, Joule heating and heat conduction in DEM packings.

The core (this package's top-level modules and ``yade_electro.packing``) is plain numpy/scipy
and never imports YADE; ``yade_electro.yade`` adapts it to a running YADE simulation and
``yade_electro.liggghts`` writes LIGGGHTS input decks. SI units everywhere.

The package namespace names the main objects; the modules keep their own names
(``yade_electro.conductance`` is the module of the conductance laws).
"""
from .errors import (ElectroError, GraphError, BoundaryConditionError, MaterialError,
                     SolverError, ThermalError)
from .graph import ContactGraph
from .materials import Material
from .surfaces import (transmission_surface, edge_transmission_surface, volume_fraction,
                       eccentricity, polyhedron_alpha, polyhedron_volume_fraction)
from .conductance import conductance_laws, register_conductance_law, make_law, geometric_factor
from .network import (Electrode, PotentialSolution, ConductionProblem, laplacian, solve_potential,
                      equivalent_resistance)
from .solvers import make_solver, solver_names, DirectSolver, CGSolver, DeflatedCGSolver, AMGSolver
from .history import History
from .electrical import ElectricalModel, ElectrodeSpec
from .thermal import (heat_capacity, thermal_conductance, joule_sources, HeatSolver, FixedTemperature,
                      HeatFlux, Convection, HeatSource, SteadyHeat)
from .coupled import ElectroThermalModel
from .boundary import boundary_areas, surface_contact, SurfaceContact
from .geometry import Box, Cylinder, Sphere, Plane, as_shape
from .probes import probe, line_probe, plane_probe, section_mean, region_mean, slab_means, element_gradients

__version__ = "0.2.0"
