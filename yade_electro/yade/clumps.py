"""Clumps of spheres in a granular bed, on the YADE side: the members' shares of their
clump's volume, and the temperature written on each clump body (the model's side is
:mod:`yade_electro.network.lumping`).

Units: m^3, K, J/K.
"""
from __future__ import annotations

import numpy as np

from ..network.lumping import member_volumes
from .writeback import TemperatureWriter

__all__ = ["clump_volume_fraction", "ClumpTemperatures"]


def clump_volume_fraction(reader):
    """``f(graph) -> (n,)`` for a granular model's ``volume_fraction``: 1 for a sphere, its
    sphere's volume over its share of the clump's volume for a member (:func:`member_volumes`),
    so that a clump's capacity is that of its volume, not of its members' spheres added."""
    def fraction(graph):
        labels = reader.clump_labels(graph.ids)
        if not np.any(labels >= 0):
            return np.ones(graph.n_nodes)
        sphere = 4.0 / 3.0 * np.pi * np.asarray(graph.radius, float) ** 3
        return sphere / member_volumes(graph.pos, graph.radius, labels)
    fraction.without_clumps = 1.0     # what it is on spheres alone (a distributed run, which refuses clumps)
    return fraction


class ClumpTemperatures:
    """Writes on each clump body (``b.state.temp``) the capacity-weighted mean temperature [K]
    of its members, through a :class:`~yade_electro.yade.writeback.TemperatureWriter` whose kept
    handles are the clump bodies of the reader's last full read (taken again only when the
    element set changed)."""

    def __init__(self):
        self._writer = TemperatureWriter()
        self._reads, self._clumps, self._bodies = None, None, []

    def write(self, O, reader, ids, temperature, capacity) -> int:
        """The clumps of the spheres of body ids ``ids`` with their members' ``temperature``
        [K] and ``capacity`` [J/K]; returns how many clumps were written."""
        labels = reader.clump_labels(ids)
        member = labels >= 0
        if not np.any(member):
            return 0
        clumps, inv = np.unique(labels[member], return_inverse=True)
        if self._reads != reader.full_reads or not np.array_equal(clumps, self._clumps):
            self._reads, self._clumps = reader.full_reads, clumps
            self._bodies = [O.bodies[int(c)] for c in clumps]
        C = np.asarray(capacity, float)[member]
        T = np.bincount(inv, C * np.asarray(temperature, float)[member], clumps.size) / np.bincount(inv, C, clumps.size)
        self._writer.write(self._bodies, T)
        return int(clumps.size)
