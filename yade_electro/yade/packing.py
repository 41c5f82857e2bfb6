"""The packing recipe in one namespace, for YADE scripts: container shapes
(:mod:`yade_electro.geometry.shapes`), dense placement and statistics (:mod:`yade_electro.packing`)
and YADE bonding (:mod:`yade_electro.yade.bonding`; :func:`bonded_packing` bonds a packing made
elsewhere, e.g. by YADE's ``pack.randomDensePack``).

``from yade_electro.yade import packing as P`` then ``P.add_bonded_packing(P.dense_packing(
pack.inCylinder(...), n=5000))`` is the two-line recipe of paper 000 section 2.1. This module
holds no code of its own; it names what the three modules hold.
"""
from ..geometry.shapes import (Box, Cylinder, Difference, GridShape, Intersection, Shape, Sphere, Union, as_shape)
from ..geometry.volumes import container_volume
from ..packing import (DEFAULT_DETECTION_FACTOR, PACKING_VERSION, Refinement, SpherePacking, bond_pairs,
                       dense_packing, detection_factor_for_coordination, mean_radius_for_count, packing_statistics)
from .bonding import add_bonded_packing, steel_304L
from .spheres import bonded_packing

__all__ = [
    "Shape", "Cylinder", "Box", "Sphere", "Difference", "Intersection", "Union", "GridShape",
    "as_shape", "container_volume", "mean_radius_for_count", "SpherePacking", "dense_packing", "Refinement",
    "bond_pairs", "detection_factor_for_coordination", "packing_statistics",
    "add_bonded_packing", "bonded_packing", "steel_304L", "DEFAULT_DETECTION_FACTOR", "PACKING_VERSION",
]
