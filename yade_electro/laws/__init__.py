"""Geometric factors g [m] of the edges, as pure functions behind one registry: 'continuum'
(paper 000's transmission surfaces), 'voronoi', 'contact', 'liggghts'. A conductance is g times a
material value (g / rho_e, lambda g).
"""
from .factors import (conductance, geometric_factor, conductance_laws, register_conductance_law, make_law,
                      check_law_name, is_contact_law, unregister_conductance_law, contact_radius,
                      edge_lengths, ConductanceLaw)
from .factor_network import FactorNetwork
from .law import Law
from .transmission import (POLYHEDRON_FACES, POLYHEDRON_ALPHA, POLYHEDRON_FV, polyhedron_alpha,
                           polyhedron_volume_fraction, eccentricity, eccentricity_factor,
                           transmission_surface, edge_transmission_surface, volume_fraction, exposed_area)

__all__ = ["conductance", "geometric_factor", "conductance_laws", "register_conductance_law", "make_law",
           "check_law_name", "is_contact_law", "unregister_conductance_law", "contact_radius",
           "edge_lengths", "ConductanceLaw", "FactorNetwork", "Law", "POLYHEDRON_FACES", "POLYHEDRON_ALPHA",
           "POLYHEDRON_FV", "polyhedron_alpha", "polyhedron_volume_fraction", "eccentricity",
           "eccentricity_factor", "transmission_surface", "edge_transmission_surface", "volume_fraction",
           "exposed_area"]
