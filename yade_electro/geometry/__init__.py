"""Shapes and space: containers and their faces (CSG), tessellation, clipping, bounded
Voronoi cells and faces, surface contact of boundary cells, pair search and wall/facet geometry.
"""
from .boundary import (SurfaceContact, surface_contact, half_cell_length, SavedSurface, SurfaceMembership,
                       check_surface, boundary_areas, BoundaryOfGraph)
from .cell_clipping import (order_polygon, clip_polygon, polygon_area, tangent_planes, clipped_area,
                            sampled_area, clipped_by_planes, cell_halfspaces, interior_point, clipped_volume,
                            unit_grid, sampled_volume, sampled_boundary)
from .cells import BoundedCells, _piece_planes, _protrusion_integral, bounded_cells
from .clipping import FaceSet, order_polygons, polygon_vector_area, clip, volumes, concat, face_areas
from .contacts import (sphere_tree, candidate_pairs, periodic_candidate_pairs, cell_widths,
                       new_wall_contacts, max_displacement, WallGeometry, wall_candidates, wall_overlaps,
                       plane_contact_radius, triangle_distance, quaternion_matrices, facet_vertices)
from .ghosts import ghost_points, tessellate_with_ghosts, progress_lines
from .shapes import (Shape, Cylinder, Box, Sphere, Difference, Intersection, Union, GridShape, as_shape,
                     as_surface)
from .volumes import container_volume
from .surface_mesh import MeshShape, read_stl
from .surfaces import SurfaceSelector, Plane, OnSurface
from .tessellation import Tessellation, tessellate, circumcentres
from .voronoi import voronoi_faces, VoronoiFaces, voronoi_cell_volumes, cell_volume_of

__all__ = ["SurfaceContact", "surface_contact", "half_cell_length", "SavedSurface", "SurfaceMembership",
           "check_surface", "boundary_areas", "BoundaryOfGraph", "order_polygon", "clip_polygon",
           "polygon_area", "tangent_planes", "clipped_area", "sampled_area", "clipped_by_planes",
           "cell_halfspaces", "interior_point", "clipped_volume", "unit_grid", "sampled_volume",
           "sampled_boundary", "BoundedCells", "_piece_planes", "_protrusion_integral", "bounded_cells",
           "FaceSet", "order_polygons", "polygon_vector_area", "clip", "volumes", "concat", "face_areas",
           "sphere_tree", "candidate_pairs", "periodic_candidate_pairs", "cell_widths", "new_wall_contacts",
           "max_displacement", "WallGeometry", "wall_candidates", "wall_overlaps", "plane_contact_radius",
           "triangle_distance", "quaternion_matrices", "facet_vertices", "ghost_points",
           "tessellate_with_ghosts", "progress_lines", "MeshShape", "read_stl", "Shape", "Cylinder", "Box", "Sphere", "Difference",
           "Intersection", "Union", "GridShape", "as_shape", "container_volume", "as_surface",
           "SurfaceSelector", "Plane", "OnSurface", "Tessellation", "tessellate", "circumcentres",
           "voronoi_faces", "VoronoiFaces", "voronoi_cell_volumes", "cell_volume_of"]
