"""Spheres between YADE and LIGGGHTS: a YADE scene's spheres as LIGGGHTS particle data, and a
packing (made in LIGGGHTS or anywhere) put into a YADE scene, loose or bonded.

``scene_particle_data(O)`` gives :class:`yade_electro.liggghts.ParticleData` (atom id =
body id + 1, one atom type per YADE material, density from the material);
``add_spheres(centers, radii, material)`` appends spheres to ``O.bodies`` (a loose bed whose
contacts YADE finds); ``bonded_packing(centers, radii, shape)`` makes the
:class:`~yade_electro.packing.SpherePacking` that :func:`~.bonding.add_bonded_packing`
bonds.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from ..liggghts.datafile import particle_data
from .runtime import import_yade
from .scene import read_spheres

__all__ = ["scene_particle_data", "add_spheres", "bonded_packing"]


def scene_particle_data(O=None, mask: Optional[int] = None, box=None, padding=None):
    """The spheres of ``O`` (default ``yade.Omega()``) as LIGGGHTS particle data.

    Returns ``(data, materials)``: atom ids are body ids + 1 (LIGGGHTS counts from 1), atom
    type k + 1 is ``materials[k]``, the k-th YADE material met (the ``b.material`` objects),
    density each body's ``material.density`` [kg/m^3]."""
    O = O or import_yade().Omega()
    s = read_spheres(O, mask)
    mats, type_of, types, dens = [], {}, [], []
    for b in s.bodies:
        key = id(b.material)
        if key not in type_of:
            type_of[key] = len(mats) + 1
            mats.append(b.material)
        types.append(type_of[key])
        dens.append(float(b.material.density))
    data = particle_data(s.pos, s.radius, np.asarray(dens), types=np.asarray(types), ids=s.ids + 1, box=box,
                         padding=padding)
    return data, mats


def add_spheres(centers, radii, material=None, fixed: bool = False, color=None, O=None) -> list:
    """Append spheres at ``centers`` (n, 3) [m] with ``radii`` [m] to ``O.bodies``; returns
    their ids. ``material``: a YADE material (appended to ``O.materials`` when new), its id or
    label, or None for YADE's default. ``fixed``: every degree of freedom blocked (a static
    packing, e.g. for a heat run where nothing moves)."""
    yade = import_yade()
    O = O or yade.Omega()
    from yade import utils
    c = np.asarray(centers, dtype=float).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radii, dtype=float), (c.shape[0],))
    if not (np.all(np.isfinite(c)) and np.all(np.isfinite(r)) and np.all(r > 0)):
        raise ValueError("centres must be finite and radii finite and > 0 (m)")
    kw = {}
    if material is not None:
        if isinstance(material, (int, str)):
            kw["material"] = O.materials[material].id
        else:
            kw["material"] = material.id if material.id >= 0 else O.materials.append(material)
    if color is not None:
        kw["color"] = color
    ids = O.bodies.append([utils.sphere(tuple(p), float(rr), **kw) for p, rr in zip(c.tolist(), r.tolist())])
    if fixed:
        for i in ids:
            O.bodies[i].state.blockedDOFs = "xyzXYZ"
    return list(ids)


def bonded_packing(centers, radii, shape, seed: int = 0):
    """The :class:`~yade_electro.packing.SpherePacking` of given centres and radii in the
    container ``shape`` (a :mod:`yade_electro.geometry.shapes` shape or YADE predicate), for
    :func:`~.bonding.add_bonded_packing`: an imported packing bonded as a solid."""
    from ..geometry.shapes import as_shape
    from ..geometry.volumes import container_volume
    from ..packing import SpherePacking
    from ..packing.jamming import max_overlap
    c = np.asarray(centers, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).reshape(-1)
    shp = as_shape(shape)
    vol, method = container_volume(shp)
    r_mean = float(r.mean())
    return SpherePacking(centers=c, radii=r, container_volume=vol, volume_method=method,
                         volume_fraction=float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / vol), seed=seed, r_mean=r_mean,
                         r_mean_requested=r_mean, radius_scale=1.0,
                         max_overlap=float(max_overlap(c, r, shp)) / r_mean, time_s=0.0,
                         params={"source": "imported"}, shape=shp)
