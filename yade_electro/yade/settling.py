"""Spheres settled under gravity in YADE, in an upright cylinder on a floor: the YADE side of
the packing cross-check with LIGGGHTS (:func:`yade_electro.liggghts.settle_packing` settles the
same spheres in LIGGGHTS).

Units: SI (m, s, kg, J, Pa).
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass

import numpy as np

from ..packing.placement import random_placement_in_cylinder
from .runtime import import_yade
from .spheres import add_spheres

__all__ = ["YadeSettledPacking", "settle_in_cylinder"]


@dataclass(frozen=True, eq=False)
class YadeSettledPacking:
    """Spheres settled in YADE: ``centers`` (n, 3) [m], ``radii`` [m], the body ``ids``, the
    simulated ``time`` [s] and ``steps`` it took, the kinetic energy per particle [J] at the
    end and whether it fell below the threshold (``settled``), the spheres ``lost`` (out of the
    container) and the wall-clock time ``wall_s`` [s]."""

    centers: np.ndarray
    radii: np.ndarray
    ids: np.ndarray
    time: float
    steps: int
    ke_per_particle: float
    settled: bool
    lost: int
    wall_s: float

    @property
    def n(self) -> int:
        return int(self.radii.size)


def settle_in_cylinder(radii, radius: float, region, material, timestep: float, *, settle_time: float = 3.0,
                       ke_threshold: float = 1e-10, seed: int = 1, segments: int = 96, chunk_time: float = 0.05,
                       progress: float = 10.0) -> YadeSettledPacking:
    """Settle spheres of ``radii`` [m] under gravity in YADE, as LIGGGHTS' ``settle`` deck does.

    The spheres start at random without overlap in ``region`` (a
    :class:`~yade_electro.liggghts.CylinderRegion`: radius, z_low, z_high) and fall into an
    upright cylinder of ``radius`` (a ``facetCylinder`` of ``segments`` facets) onto a floor
    (a ``Wall``) at z = 0. Contacts are Hertz-Mindlin (``MindlinPhys`` with the normal and
    tangential restitution of ``material``, a :class:`~yade_electro.liggghts.GranularMaterial`),
    no numerical damping, at ``timestep`` [s]. The run stops once the kinetic energy per
    particle (checked every ``chunk_time`` [s] of simulated time, after 0.1 s) is below
    ``ke_threshold`` [J], or at ``settle_time`` [s]; a line on stderr every ``progress`` [s].
    The scene is reset first and holds the settled bed at the end.
    """
    yade = import_yade()
    from yade import geom, utils
    from yade import wrapper as W
    O = yade.Omega()
    O.reset()
    radii = np.asarray(radii, dtype=float).reshape(-1)
    n = radii.size
    centers = random_placement_in_cylinder(radii, region.radius, region.z_low, region.z_high, seed)
    mat = W.FrictMat(young=material.young, poisson=material.poisson, density=material.density,
                     frictionAngle=math.atan(material.friction), label="grains")
    O.materials.append(mat)
    ids = np.asarray(add_spheres(centers, radii, mat, O=O))
    wall_h = region.z_high + 2e-3
    O.bodies.append(geom.facetCylinder((0, 0, 0.5 * wall_h), radius, wall_h, segmentsNumber=segments, wallMask=4,
                                       material=mat))
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=mat))
    e = material.restitution
    O.engines = [W.ForceResetter(),
                 W.InsertionSortCollider([W.Bo1_Sphere_Aabb(), W.Bo1_Facet_Aabb(), W.Bo1_Wall_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom(), W.Ig2_Facet_Sphere_ScGeom(),
                                    W.Ig2_Wall_Sphere_ScGeom()],
                                   [W.Ip2_FrictMat_FrictMat_MindlinPhys(en=W.MatchMaker(algo="val", val=e),
                                                                       es=W.MatchMaker(algo="val", val=e))],
                                   [W.Law2_ScGeom_MindlinPhys_Mindlin()]),
                 W.NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.0)]
    O.dt = timestep
    chunk = max(1, int(round(chunk_time / O.dt)))
    masses = np.array([O.bodies[int(i)].state.mass for i in ids])
    t0 = last = time.perf_counter()
    ke = float("inf")
    while O.time < settle_time:
        O.run(chunk, True)
        v = np.array([O.bodies[int(i)].state.vel for i in ids])
        ke = float(0.5 * np.sum(masses * np.sum(v ** 2, axis=1)) / n)
        now = time.perf_counter()
        if progress and now - last > progress:
            last = now
            print(f"[yade] t = {O.time:.2f} s of at most {settle_time:g} s, kinetic energy {ke:.2e} J per "
                  f"particle (target {ke_threshold:g}), {now - t0:.0f} s", file=sys.stderr, flush=True)
        if O.time > 0.1 and ke < ke_threshold:
            break
    pos = np.array([tuple(O.bodies[int(i)].state.pos) for i in ids])
    lost = int(np.sum((pos[:, 2] < -1e-3) | (np.hypot(pos[:, 0], pos[:, 1]) > radius + 1e-3)))
    return YadeSettledPacking(centers=pos, radii=radii, ids=ids, time=float(O.time), steps=int(O.iter),
                              ke_per_particle=ke, settled=bool(ke < ke_threshold), lost=lost,
                              wall_s=time.perf_counter() - t0)
