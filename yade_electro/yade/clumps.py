"""Clumps of spheres in a granular bed, on the YADE side: the members' shares of their
clump's volume, and the temperature written on each clump body (the model's side is
:mod:`yade_electro.network.lumping`).

Units: m^3, K, J/K.
"""
from __future__ import annotations

import numpy as np

from ..network.lumping import member_volumes
from .scene import ensure_thermal_state

__all__ = ["clump_volume_fraction", "write_clump_temperatures"]


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


def write_clump_temperatures(O, reader, ids, temperature, capacity) -> int:
    """Write on each clump body (``b.state.temp``) the capacity-weighted mean temperature [K]
    of its members among the spheres of body ids ``ids``; returns how many clumps."""
    labels = reader.clump_labels(ids)
    member = labels >= 0
    if not np.any(member):
        return 0
    clumps, inv = np.unique(labels[member], return_inverse=True)
    C = np.asarray(capacity, float)[member]
    T = np.bincount(inv, C * np.asarray(temperature, float)[member], clumps.size) / np.bincount(inv, C, clumps.size)
    bodies = [O.bodies[int(c)] for c in clumps]
    ensure_thermal_state(bodies)
    for b, t in zip(bodies, T.tolist()):
        b.state.temp = t
    return int(clumps.size)
