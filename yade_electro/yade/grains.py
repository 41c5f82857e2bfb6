"""Resolved grains as YADE bodies (issue 35): each grain a clump of its template's spheres,
added with :func:`add_grain` into a :class:`~yade_electro.network.grain_law.GrainSet`, and
the ``'grains'`` law made with the DEM's normal forces between grains (:func:`grain_law`).

A grain's spheres are its template's dense packing (:func:`~yade_electro.packing.grains.grain_template`):
YADE moves them as one rigid clump and finds the contacts between grains through them; the
heat engine (``Reader(bonds='contacts', clumps='resolved')``) conducts inside each grain
through its template's Voronoi cells and across contacts through the contact resistance
(:mod:`yade_electro.network.grain_law`).

Units: m, N.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from ..laws.law import Law
from ..network.grain_contact import contact_resistance_value
from ..network.grain_law import GrainSet
from ..network.grains import GrainTemplate
from .runtime import import_yade

__all__ = ["add_grain", "GrainForces", "grain_law"]


def add_grain(grains: GrainSet, template: GrainTemplate, position=(0.0, 0.0, 0.0), rotation=None,
              material=None, O=None) -> int:
    """Append one grain of ``template`` at the pose ``x = R x_template + position`` [m] as a
    clump of the template's spheres (``O.bodies.appendClumped``) and add it to ``grains``;
    returns the clump's body id. ``rotation``: a 3x3 rotation matrix (default identity);
    ``material``: a YADE material or its label (default: the scene's last)."""
    yade = import_yade()
    O = O if O is not None else yade.Omega()
    R = np.eye(3) if rotation is None else np.asarray(rotation, float)
    if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise ValueError(f"rotation must be a 3x3 rotation matrix (orthonormal, det +1), got {rotation!r}")
    t = np.asarray(position, float)
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ValueError(f"position must be 3 finite numbers (m), got {position!r}")
    centres = template.placed(R, t)
    kw = {} if material is None else dict(material=material)
    spheres = [yade.utils.sphere(tuple(map(float, c)), float(r), **kw) for c, r in zip(centres, template.radii)]
    clump, members = O.bodies.appendClumped(spheres)
    grains.add(template, members)
    return int(clump)


class GrainForces:
    """``f(pairs (k, 2) of grain indices) -> (k,)`` the forces [N] pressing those grains
    together now: the norm of the sum of ``phys.normalForce + phys.shearForce`` over the
    interactions between their members (YADE's, read at each call; the spheres' contacts are
    tilted against the grains' faces, so their shear forces carry a part of the load)."""

    def __init__(self, grains: GrainSet, O=None):
        self.grains = grains
        self._O = O

    def __call__(self, pairs) -> np.ndarray:
        O = self._O if self._O is not None else import_yade().Omega()
        pairs = np.sort(np.asarray(pairs, np.int64).reshape(-1, 2), axis=1)
        total = np.zeros((pairs.shape[0], 3))
        ids1, ids2, forces = [], [], []
        for inter in O.interactions:
            phys = inter.phys
            if phys is None or not hasattr(phys, "normalForce"):
                continue
            ids1.append(inter.id1)
            ids2.append(inter.id2)
            f = phys.normalForce + phys.shearForce if hasattr(phys, "shearForce") else phys.normalForce
            forces.append(tuple(f))
        if ids1 and pairs.size:
            g1, g2 = self.grains.locate(ids1)[0], self.grains.locate(ids2)[0]
            F = np.asarray(forces, float) * np.where(g1 < g2, 1.0, -1.0)[:, None]   # from the lower grain's side
            n = max(self.grains.n, 1)
            want = pairs[:, 0] * n + pairs[:, 1]
            order = np.argsort(want)
            key = np.minimum(g1, g2) * n + np.maximum(g1, g2)
            at = np.minimum(np.searchsorted(want[order], key), want.size - 1)
            hit = (g1 >= 0) & (g2 >= 0) & (g1 != g2) & (want[order][at] == key)
            np.add.at(total, order[at[hit]], F[hit])
        return np.linalg.norm(total, axis=1)


def grain_law(grains: GrainSet, contact_resistance, film: float = 0.0, O=None, **params) -> Law:
    """``Law('grains', ...)`` for the engines, with the grains' normal forces read from YADE
    (:class:`GrainForces`) when ``contact_resistance`` is ``f(pressure [Pa]) -> R_c``."""
    if not callable(contact_resistance):
        contact_resistance = contact_resistance_value(contact_resistance)     # refused here, in the script
    force: Optional[GrainForces] = GrainForces(grains, O) if callable(contact_resistance) else None
    return Law("grains", grains=grains, contact_resistance=contact_resistance, film=film, normal_force=force, **params)
