"""Bonded packings in YADE: spheres added to ``O.bodies`` with a cohesive material, and every
pair closer than ``detection_factor * (r_i + r_j)`` bonded by YADE itself, without prestress.

The placement is :func:`yade_electro.packing.dense_packing` (numpy only); this module is the
YADE half of the recipe (``CohFrictMat`` or ``JCFpmMat`` bonds).

Units: SI.
"""
from __future__ import annotations

import logging
import time

import numpy as np

from ..packing.statistics import DEFAULT_DETECTION_FACTOR
from ..core.progress import Progress

__all__ = ["steel_304L", "add_bonded_packing"]

log = logging.getLogger(__name__)

#: spheres added to ``O.bodies`` per call (a progress line can come between two)
APPEND_CHUNK = 20000

#: from this many spheres on, the collider sorts along the packing's longest extent (YADE's
#: default is x). Below, x as before: the order of YADE's interactions, and so of the graph's
#: edges, stays what the figures of the cases were made with.
SORT_ALONG_LONGEST_FROM = 200_000


def _step_showing_progress(O, progress: Progress, note: str) -> None:
    """One ``O.step()``, run in YADE's background thread so that a long one (the collider's
    first sort and the bonding of every pair) prints progress lines; its errors are raised
    here, by ``O.wait()``."""
    O.run(1, False)
    pause = 0.005
    while O.running:
        time.sleep(pause)
        pause = min(2 * pause, 0.5)
        progress.waiting(note)
    O.wait()


def steel_304L(**overrides):
    """A ``CohFrictMat`` for 304L stainless steel (E = 210 GPa, nu = 0.3, 7900 kg/m^3).

    The bond strengths (``normalCohesion = shearCohesion = 5.2e8`` Pa, about the tensile
    strength) and the friction angle (atan 0.5) are placeholders, not a calibration of the
    bonded model; calibrate them (e.g. on a tensile test) before any fracture study.
    """
    from yade.wrapper import CohFrictMat
    kw = dict(young=210e9, poisson=0.3, density=7900.0, frictionAngle=float(np.arctan(0.5)),
              isCohesive=True, normalCohesion=5.2e8, shearCohesion=5.2e8,
              momentRotationLaw=True, label="steel_304L")
    kw.update(overrides)
    return CohFrictMat(**kw)


def add_bonded_packing(packing, material=None, detection_factor=DEFAULT_DETECTION_FACTOR,
                       engines="default", damping=0.2, dt_safety=0.5, color=None):
    """Add a packing to ``O.bodies`` and bond neighbours with cohesive YADE interactions.

    Every pair with ``|x_i - x_j| < detection_factor (r_i + r_j)`` (see :func:`bond_pairs`)
    is bonded by YADE: one step with an engine list whose ``Bo1_Sphere_Aabb.
    aabbEnlargeFactor`` and ``Ig2_Sphere_Sphere_ScGeom6D.interactionDetectionFactor``
    equal ``detection_factor``, whose Ip2 sets the cohesion now and whose law is the
    cohesive law the simulation will use; no integrator runs during that step, so nothing
    moves. The factors are then reset to 1 and cohesion is not given to later contacts. With
    ``CohFrictMat``, each bond's reference normal displacement (``CohFrictPhys.unp``) is set
    to its initial penetration (negative across a gap), so the bonded packing starts
    stress-free instead of pulling the gaps shut, and one more step with every sphere held
    flushes the bonding step's forces (``O.iter`` advances by 2 in all).

    The packing's container (``packing.shape``) is kept in the scene (``O.tags``, saved with
    it): the engines then know the solid without being told, use the ``voronoi`` law by
    default and take surface boundary conditions (``container.face(...)``).

    Parameters
    ----------
    packing : SpherePacking
        From :func:`dense_packing`.
    material : yade Material or int or str, optional
        A ``CohFrictMat`` (default :func:`steel_304L`) or ``JCFpmMat`` instance, or the id
        or label of a material already in ``O.materials``.
    detection_factor : float
        >= 1; 1.04 (gap below ~8 % of r_mean) gives the paper's coordination of 6.7 on the
        5,000-element rod (see docs/packing.md).
    engines : "default" or list or None
        ``"default"``: ForceResetter, InsertionSortCollider, InteractionLoop with the
        cohesive law, NewtonIntegrator(damping) and ``O.dt = dt_safety * PWaveTimeStep()``.
        A list: installed as ``O.engines`` after bonding (its functors must accept the
        bond types: ScGeom6D + CohFrictPhys, or ScGeom + JCFpmPhys). None: the bonding
        engines are left in place (factors reset to 1, no integrator) and ``O.dt`` untouched.
    damping : float
        NewtonIntegrator numerical damping of the default engines.
    dt_safety : float
        Fraction of ``PWaveTimeStep()`` used for ``O.dt`` with the default engines.
    color : 3-tuple, optional
        Colour of the spheres.

    Returns
    -------
    list of int
        Body ids of the spheres, in the order of ``packing.centers``.
    """
    import yade
    from yade import utils
    from yade import wrapper as W
    O = yade.Omega()
    k = float(detection_factor)
    if not k >= 1.0:
        raise ValueError(f"detection_factor must be >= 1, got {k}")
    if material is None:
        mat_id = O.materials.append(steel_304L())
    elif isinstance(material, (int, str)):
        mat_id = O.materials[material].id
    else:
        mat_id = material.id if material.id >= 0 else O.materials.append(material)
    mat = O.materials[mat_id]
    kind = type(mat).__name__
    if kind == "CohFrictMat":
        if not mat.isCohesive:
            raise ValueError("the CohFrictMat must have isCohesive=True to be bonded")
        ig2 = W.Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=k)
        ip2 = W.Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True,
                                                        setCohesionOnNewContacts=False)
        law = W.Law2_ScGeom6D_CohFrictPhys_CohesionMoment()
    elif kind == "JCFpmMat":
        ig2 = W.Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=k)
        ip2 = W.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)
        law = W.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()
    else:
        raise ValueError(f"material must be a CohFrictMat or a JCFpmMat, got {kind}")
    kw = {} if color is None else {"color": tuple(color)}
    n_spheres = int(packing.radii.shape[0])
    progress = Progress("bonding", f"{n_spheres:,} spheres added to O.bodies", n_spheres)
    ids = []
    centers, radii = packing.centers.tolist(), packing.radii.tolist()
    for lo in range(0, n_spheres, APPEND_CHUNK):
        ids += O.bodies.append([utils.sphere(tuple(c), float(r), material=mat_id, **kw)
                                for c, r in zip(centers[lo:lo + APPEND_CHUNK], radii[lo:lo + APPEND_CHUNK])])
        progress.update(len(ids))
    progress.done()
    bo1 = W.Bo1_Sphere_Aabb(aabbEnlargeFactor=k)
    collider = W.InsertionSortCollider([bo1])
    if n_spheres >= SORT_ALONG_LONGEST_FROM:
        # the collider's first sweep checks every pair whose bounds overlap along its sort axis:
        # along the packing's longest extent there are fewest (a 200k rod, 2 x 5 mm: 38 -> 14 s)
        extent = packing.centers.max(axis=0) - packing.centers.min(axis=0)
        collider.sortAxis = int(np.argmax(extent))
    # The cohesive law itself runs during the bonding step (YADE's InteractionLoop keeps the law
    # functor it first used for an interaction: a stand-in law would stay in use for the bonds).
    # With CohFrictMat it must not break the bonds across gaps before their reference distance
    # (unp) is set: the material's strengths are made unlimited for that step, then each bond
    # gets its real adhesions (YADE's own formula: strength * min(r1, r2)^2).
    # (JCFpm stores the initial distance itself.)
    strengths = None
    if kind == "CohFrictMat":
        strengths = (mat.normalCohesion, mat.shearCohesion)
        mat.normalCohesion = mat.shearCohesion = 1e300
    loop = W.InteractionLoop([ig2], [ip2], [law])
    saved_engines, saved_dt = O.engines, O.dt
    newton = W.NewtonIntegrator(damping=damping, dead=True)  # the collider wants one
    O.engines = [W.ForceResetter(), collider, loop, newton]
    O.dt = min(O.dt, utils.PWaveTimeStep()) if O.dt > 0 else utils.PWaveTimeStep()
    try:
        _step_showing_progress(O, Progress("bonding", f"YADE's bonding step on {n_spheres:,} spheres"),
                               "collision detection and bonds (one step, share done unknown)")
    finally:
        if strengths is not None:
            mat.normalCohesion, mat.shearCohesion = strengths
    O.dt = saved_dt
    bo1.aabbEnlargeFactor = 1.0
    ig2.interactionDetectionFactor = 1.0
    if kind == "CohFrictMat":
        ip2.setCohesionNow = False
    else:
        ip2.cohesiveTresholdIteration = O.iter  # no cohesion for later contacts
    ours = np.zeros(max(ids) + 1, dtype=bool)
    ours[ids] = True
    radius = np.zeros(ours.shape[0])
    radius[ids] = packing.radii
    radius, ours = radius.tolist(), ours.tolist()
    n_ours = len(ours)
    n_bonds = 0
    progress = Progress("bonding", "bonds set stress-free", len(O.interactions))
    for k, i in enumerate(O.interactions):
        a, b = i.id1, i.id2
        if a < n_ours and b < n_ours and ours[a] and ours[b]:
            if kind == "CohFrictMat":
                ph = i.phys
                ph.unp = i.geom.penetrationDepth
                ph.normalForce = (0, 0, 0)
                ph.shearForce = (0, 0, 0)
                r2 = min(radius[a], radius[b]) ** 2
                ph.normalAdhesion = strengths[0] * r2
                ph.shearAdhesion = strengths[1] * r2
            n_bonds += 1
        if k % 4096 == 0:
            progress.update(k)
    progress.done()
    if kind == "CohFrictMat":
        # the forces of the bonding step (unp still 0 then: every gap pulled) stay in YADE's force
        # container until an integrator has consumed them; consume them in one step with every
        # sphere held, so they never act
        held = [(b, b.state.blockedDOFs) for b in (O.bodies[i] for i in ids)]
        for b, _ in held:
            b.state.blockedDOFs = "xyzXYZ"
        newton.dead = False
        O.dt = min(saved_dt, utils.PWaveTimeStep()) if saved_dt > 0 else utils.PWaveTimeStep()
        _step_showing_progress(O, Progress("bonding", "the step that flushes the bonding forces"), "running")
        newton.dead = True
        O.dt = saved_dt
        for b, dofs in held:
            b.state.blockedDOFs = dofs
            b.state.vel = b.state.angVel = (0, 0, 0)
    log.info("add_bonded_packing: %d spheres, %d bonds (detection factor %.4g)", len(ids),
             n_bonds, k)
    if engines == "default":
        newton.dead = False
        O.engines = [W.ForceResetter(), collider, loop, newton]
        O.dt = dt_safety * utils.PWaveTimeStep()
    elif engines is None:
        pass  # bonding engines stay, the integrator still dead
    else:
        O.engines = list(engines)
    del saved_engines
    shape = getattr(packing, "shape", None)
    if shape is not None:
        from .persistence import add_container
        try:
            add_container(O, shape, ids)
        except Exception as exc:        # a shape that is not data (a function inside): the engines then need container=
            log.warning("add_bonded_packing: the packing's container cannot be kept with the scene (%s); give "
                        "container= to the engines", exc)
    return list(ids)

