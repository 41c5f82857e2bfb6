"""Finite-element reference for the DEM cases (scikit-fem, gmsh meshes).

Solves the same steady conduction, Joule heating, heat conduction and thermo-elastic
(:mod:`.thermoelastic`) problems as the DEM model, on the same geometries, with tetrahedral P1/P2 Lagrange elements, so that each DEM
case compares with one function call (:mod:`.references`). It is itself checked against
closed forms (:mod:`.closed_forms`) and converges under refinement (:mod:`.convergence`);
see docs/fem.md. Needs scikit-fem (PyPI, pure Python) and, for curved or notched
geometries, gmsh's Python API (Debian package python3-gmsh). SI units.
"""
from .closed_forms import (adiabatic_joule_temperature, bar_resistance, coax_resistance,
                           edge_crack_increment, joule_parabola, slab_temperature)
from .convergence import Convergence, converged, richardson
from .meshes import (CrackedBarGeometry, MeshError, NotchedBarGeometry, PlateGeometry, box_mesh, coax_mesh,
                     cracked_bar_mesh, mesh_size, notched_bar_mesh, plate_mesh, rod_mesh)
from .potential import PotentialSolution, make_basis, solve_potential
from .probing import ProbeError, line_points, probe_matrix, slab_average, subdomain_average
from .references import (STEEL_304L, Material, cracked_bar, cracked_bar_reference, notched_bar, notched_bar_reference,
                         plate_potential, plate_reference, rod_joule_heating, rod_reference,
                         rod_resistance, slab_conduction)
from .thermal import ThermalResult, joule_heating, steady_temperature, transient_conduction
from .thermoelastic import ThermoElasticResult, thermal_stress

__all__ = [
    "adiabatic_joule_temperature", "bar_resistance", "coax_resistance", "joule_parabola",
    "slab_temperature", "edge_crack_increment", "CrackedBarGeometry", "cracked_bar_mesh", "cracked_bar",
    "cracked_bar_reference", "Convergence", "converged", "richardson", "MeshError",
    "NotchedBarGeometry", "PlateGeometry", "box_mesh", "coax_mesh", "mesh_size",
    "notched_bar_mesh", "plate_mesh", "rod_mesh", "PotentialSolution", "make_basis",
    "solve_potential", "ProbeError", "line_points", "probe_matrix", "slab_average",
    "subdomain_average", "STEEL_304L", "Material", "notched_bar", "notched_bar_reference",
    "plate_potential", "plate_reference", "rod_joule_heating", "rod_reference",
    "rod_resistance", "slab_conduction", "ThermalResult", "joule_heating",
    "steady_temperature", "transient_conduction", "ThermoElasticResult", "thermal_stress",
]
