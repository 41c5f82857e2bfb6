"""yade-electro: electrical conduction, Joule heating and heat conduction in DEM packings.

A packing is a network: nodes are particles, edges are bonds or contacts with a geometric
factor g [m] from a conductance law; a conductance is g times a material value (g / rho_e for
current, lambda g for heat). The transport core solves that network for potentials or
temperatures, steady or in time; the physics layers say what a conductance, a capacity and a
source are; the YADE adapter (:mod:`yade_electro.yade`) runs it as engines inside a YADE
simulation, the LIGGGHTS adapter (:mod:`yade_electro.liggghts`) writes and runs decks to
cross-check against. SI units everywhere.

The layers, each importing only from the ones below it (a contract checked in CI):

============================  =========================================================
:mod:`yade_electro.yade`      engines in ``O.engines``, scene reading, bonding, launcher
:mod:`yade_electro.liggghts`  LIGGGHTS data files, decks, runner and dumps
``physics`` ``packing``       electrical / thermal / coupled models; sphere packings;
``post`` ``fem``              probes, VTK and plots; scikit-fem references
:mod:`yade_electro.network`   the transport core: fixed values, electrodes, heat network
``solvers`` ``laws``          linear solvers; geometric factors of the conductance laws
:mod:`yade_electro.geometry`  shapes, faces, tessellation, Voronoi cells, pair search
:mod:`yade_electro.native`    compiled kernels
:mod:`yade_electro.core`      the contact graph, materials, selections, history, errors
============================  =========================================================

The names below are the main objects; each subpackage lists its own in its ``__all__``.
"""
from .core import (BoundaryConditionError, ContactGraph, ElectroError, GraphError, History, Material,
                   MaterialError, SolverError, ThermalError)
from .geometry import (Box, Cylinder, MeshShape, Plane, Sphere, SurfaceContact, as_shape, boundary_areas,
                       surface_contact)
from .laws import (conductance_laws, eccentricity, edge_transmission_surface, geometric_factor, make_law,
                   polyhedron_alpha, polyhedron_volume_fraction, register_conductance_law, transmission_surface,
                   volume_fraction)
from .solvers import AMGSolver, CGSolver, DeflatedCGSolver, DirectSolver, make_solver, solver_names
from .network import (ConductionProblem, Convection, Electrode, FixedTemperature, FixedValue, HeatFlux, HeatSolver,
                      HeatSource, Injection, PotentialSolution, Robin, Source, SteadyHeat, Terminal, ThermalWall,
                      equivalent_resistance, laplacian, solve_potential)
from .physics import (ElectricalModel, ElectrodeSpec, ElectroThermalModel, heat_capacity, heat_solver_on_graph,
                      joule_sources, thermal_conductance)
from .post import (element_gradients, line_probe, plane_probe, probe, region_mean, section_mean, slab_means)

__version__ = "0.3.0"

__all__ = [
    # errors
    "ElectroError", "GraphError", "BoundaryConditionError", "MaterialError", "SolverError", "ThermalError",
    # data
    "ContactGraph", "Material", "History",
    # geometry
    "Box", "Cylinder", "MeshShape", "Sphere", "Plane", "as_shape", "boundary_areas", "surface_contact", "SurfaceContact",
    # conductance laws
    "conductance_laws", "register_conductance_law", "make_law", "geometric_factor", "transmission_surface",
    "edge_transmission_surface", "volume_fraction", "eccentricity", "polyhedron_alpha",
    "polyhedron_volume_fraction",
    # solvers
    "make_solver", "solver_names", "DirectSolver", "CGSolver", "DeflatedCGSolver", "AMGSolver",
    # the transport core
    "FixedValue", "Terminal", "Injection", "Robin", "Source",
    "Electrode", "PotentialSolution", "ConductionProblem", "laplacian", "solve_potential", "equivalent_resistance",
    "HeatSolver", "FixedTemperature", "HeatFlux", "Convection", "HeatSource", "ThermalWall", "SteadyHeat",
    # physics
    "ElectricalModel", "ElectrodeSpec", "ElectroThermalModel", "heat_capacity", "thermal_conductance",
    "joule_sources", "heat_solver_on_graph",
    # post-processing
    "probe", "line_probe", "plane_probe", "section_mean", "region_mean", "slab_means", "element_gradients",
    "__version__",
]
