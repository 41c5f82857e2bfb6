"""Sphere packings of a container, numpy/scipy only (no YADE): radii (:mod:`.radii`),
placement by jamming (:mod:`.jamming`, :mod:`.dense`), the on-disk cache (:mod:`.cache`) and
bond/quality statistics (:mod:`.statistics`). YADE bonding is in ``yade_electro.yade.bonding``.
"""
from .dense import PACKING_VERSION, SpherePacking, dense_packing
from .grading import Refinement
from .radii import mean_radius_for_count, uniform_radii
from .statistics import DEFAULT_DETECTION_FACTOR, bond_pairs, detection_factor_for_coordination, packing_statistics

__all__ = ["PACKING_VERSION", "SpherePacking", "dense_packing", "Refinement", "mean_radius_for_count", "uniform_radii",
           "DEFAULT_DETECTION_FACTOR", "bond_pairs", "detection_factor_for_coordination", "packing_statistics"]
