"""The template of a resolved grain: a dense packing of its shape with the 'voronoi' law's
network inside (:class:`~yade_electro.network.grains.GrainTemplate`; issue 35).

Units: m, m^3.
"""
from __future__ import annotations

import numpy as np

from ..network.grains import GrainTemplate

__all__ = ["grain_template"]


def grain_template(shape, n: int, seed: int = 1, cache_dir=None, gap: float = 0.1) -> GrainTemplate:
    """The template of a grain of ``shape`` made of about ``n`` elements: a dense packing,
    bonded where the gap is under ``gap`` times the radii's sum, the 'voronoi' law inside."""
    from scipy.spatial import cKDTree
    from ..core.graph import ContactGraph
    from ..laws.factors import make_law
    from .dense import dense_packing
    pk = dense_packing(shape, n=n, seed=seed, cache_dir=cache_dir)
    c, r = pk.centers, pk.radii
    pairs = cKDTree(c).query_pairs(2.0 * (1.0 + gap) * float(r.max()), output_type="ndarray")
    d = np.linalg.norm(c[pairs[:, 0]] - c[pairs[:, 1]], axis=1)
    graph = ContactGraph(c, r, pairs[d < (1.0 + gap) * (r[pairs[:, 0]] + r[pairs[:, 1]])])
    law = make_law("voronoi", container=pk.shape)
    edges = np.asarray(law.network(graph), np.int64)
    return GrainTemplate(pk.shape, c, r, edges, np.asarray(law.factor(graph, edges), float),
                         np.asarray(law.cell_volumes(graph), float))
