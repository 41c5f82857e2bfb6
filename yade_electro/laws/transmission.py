"""Transmission surfaces, volume fractions and eccentricity of the continuum model.

Paper 000 (section 2.1, after Terreros et al.): an element with n bonded neighbours is
seen as the regular polyhedron with n faces circumscribing it. Its transmission surface is
the area of one face of that polyhedron, ``S_i = alpha(n_i) r_i**2 / f_i``; its volume
fraction is sphere volume / polyhedron volume, ``fv_i = fv(n_i) * f_i``. ``f_i`` is 2
where the barycentre of the neighbours is off the element centre by more than 0.4 r_i
(free-surface elements), 1 otherwise.

The tabulated polyhedra are the five Platonic solids (n = 4, 6, 8, 12, 20); alpha and
fv are linearly interpolated between them. Outside the table:

* alpha is linearly extrapolated below n = 4 with the 4-6 slope (alpha(3) = 13.59, as
  the paper says) and held at the icosahedron value above n = 20;
* fv is linearly extrapolated down to n = 3 (fv(3) = 0.191) and held at that value for
  n < 3 (the extrapolation would turn negative at n = 1), held at fv(20) above n = 20.

Units: radii in metres, surfaces in m^2; alpha, fv, e and f are dimensionless.
"""
from __future__ import annotations

import numpy as np

from ..core.graph import ContactGraph

__all__ = [
    "POLYHEDRON_FACES", "POLYHEDRON_ALPHA", "POLYHEDRON_FV",
    "polyhedron_alpha", "polyhedron_volume_fraction", "eccentricity", "eccentricity_factor",
    "transmission_surface", "edge_transmission_surface", "volume_fraction", "exposed_area",
]

#: Face counts of the regular polyhedra (tetrahedron, cube, octahedron, dodecahedron, icosahedron).
POLYHEDRON_FACES = np.array([4, 6, 8, 12, 20])


def _platonic_face_area_unit_inradius() -> np.ndarray:
    """Face area of each Platonic solid whose inscribed sphere has radius 1 (exact formulas)."""
    s3, s5 = np.sqrt(3.0), np.sqrt(5.0)
    # (edge length for inradius 1, face area as a function of the edge)
    a_tet = 2.0 * np.sqrt(6.0)                       # r_in = a / (2 sqrt 6)
    a_cub = 2.0                                      # r_in = a / 2
    a_oct = np.sqrt(6.0)                             # r_in = a / sqrt 6
    a_dod = 2.0 / np.sqrt((25.0 + 11.0 * s5) / 10.0)  # r_in = a/2 sqrt((25 + 11 sqrt5)/10)
    a_ico = 12.0 / (s3 * (3.0 + s5))                 # r_in = a sqrt3 (3 + sqrt5) / 12
    tri = s3 / 4.0
    pent = np.sqrt(5.0 * (5.0 + 2.0 * s5)) / 4.0
    return np.array([tri * a_tet ** 2, a_cub ** 2, tri * a_oct ** 2, pent * a_dod ** 2, tri * a_ico ** 2])


#: alpha(n): face area of the n-faced regular polyhedron with unit inscribed sphere
#: (10.392, 4.000, 2.598, 1.388, 0.758).
POLYHEDRON_ALPHA = _platonic_face_area_unit_inradius()
#: fv(n): sphere volume / polyhedron volume = 4 pi / (n alpha) (0.302, 0.524, 0.605, 0.755, 0.829).
POLYHEDRON_FV = 4.0 * np.pi / (POLYHEDRON_FACES * POLYHEDRON_ALPHA)
for _a in (POLYHEDRON_ALPHA, POLYHEDRON_FV):
    _a.setflags(write=False)


def _piecewise_linear(n, values, low_extrapolate_min_n):
    """Linear interpolation in the polyhedron table, linear extrapolation below n = 4 down
    to ``low_extrapolate_min_n`` (held constant below), held constant above n = 20."""
    n = np.asarray(n, dtype=float)
    out = np.interp(n, POLYHEDRON_FACES, values)
    slope = (values[1] - values[0]) / (POLYHEDRON_FACES[1] - POLYHEDRON_FACES[0])
    low_values = values[0] + slope * (np.maximum(n, low_extrapolate_min_n) - POLYHEDRON_FACES[0])
    return np.where(n < POLYHEDRON_FACES[0], low_values, out)


def polyhedron_alpha(n) -> np.ndarray:
    """Dimensionless transmission surface alpha(n) of an element with n neighbours.

    Linear between the Platonic solids, extrapolated linearly below 4 neighbours
    (alpha(3) = 13.59, alpha(1) = 19.98), constant above 20.
    """
    return _piecewise_linear(n, POLYHEDRON_ALPHA, -np.inf)


def polyhedron_volume_fraction(n) -> np.ndarray:
    """Volume fraction fv(n) of an element with n neighbours (before the eccentricity factor).

    Linear between the Platonic solids, extrapolated down to n = 3 (0.191) and held there
    below, constant above 20.
    """
    return _piecewise_linear(n, POLYHEDRON_FV, 3.0)


def eccentricity(graph: ContactGraph) -> np.ndarray:
    """e_i = ``|x_i - mean_j x_j|`` / r_i over the bonded neighbours j of each node (0 for a
    node without neighbours)."""
    d = graph.neighbour_barycentre() - graph.pos
    return np.sqrt(np.einsum("ij,ij->i", d, d)) / graph.radius


def eccentricity_factor(e, threshold: float = 0.4, factor: float = 2.0) -> np.ndarray:
    """f_i = ``factor`` where e_i > ``threshold``, else 1 (paper 000 eq. 3).

    The comparison is strict with a relative tolerance of 1e-9, so the face elements of a
    simple cubic lattice, whose eccentricity is exactly 0.4, keep f = 1 whatever the
    rounding of their coordinates.
    """
    e = np.asarray(e, dtype=float)
    return np.where(e > threshold * (1.0 + 1e-9), float(factor), 1.0)


def transmission_surface(graph: ContactGraph, threshold: float = 0.4, factor: float = 2.0) -> np.ndarray:
    """S_i = alpha(n_i) r_i^2 / f_i of each node [m^2] (paper 000 eq. 3)."""
    f = eccentricity_factor(eccentricity(graph), threshold, factor)
    return polyhedron_alpha(graph.degree) * graph.radius ** 2 / f


def edge_transmission_surface(graph: ContactGraph, node_surface=None, **kw) -> np.ndarray:
    """S_ij = sqrt(S_i S_j) of each edge [m^2] (paper 000 eq. 5)."""
    s = transmission_surface(graph, **kw) if node_surface is None else np.asarray(node_surface)
    return np.sqrt(s[graph.edges[:, 0]] * s[graph.edges[:, 1]])


def volume_fraction(graph: ContactGraph, threshold: float = 0.4, factor: float = 2.0) -> np.ndarray:
    """fv_i = fv(n_i) * f_i of each node, the sphere's share of the volume it stands for.

    Paper 000 applies the eccentricity factor multiplying here where it divides S_i.
    Values above 1 (possible for surface elements with many neighbours) are kept as they
    are: they are what the paper's model prescribes.
    """
    f = eccentricity_factor(eccentricity(graph), threshold, factor)
    return polyhedron_volume_fraction(graph.degree) * f


def exposed_area(graph: ContactGraph, threshold: float = 0.4) -> np.ndarray:
    """Default exposed (free-surface) area A_i of every element [m^2] for convection and
    surface fluxes: ``pi r_i^2`` where the eccentricity e_i > ``threshold`` (the elements the
    continuum model treats as on the surface, f_i = 2), 0 elsewhere.

    This is a crude estimate (one great-circle disc per surface element; the face elements
    of a simple cubic lattice, e = 0.4 exactly, count as interior). When the surface
    exchange matters, pass the areas yourself (``area=`` of :class:`Convection` /
    :class:`HeatFlux`), e.g. the boundary faces of the Voronoi cells.
    """
    e = eccentricity(graph)
    return np.where(e > threshold * (1.0 + 1e-9), np.pi * graph.radius ** 2, 0.0)
