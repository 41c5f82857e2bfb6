"""Dense packings of a container (placement only; numpy/scipy, no YADE): the recipe equivalent
to GranOO's *Cooker* (paper 000, section 2.1).

Random centres inside the container are relaxed with FIRE on a harmonic overlap energy
(sphere-sphere overlaps and penetration of the exact container wall) while the radii are
scaled up, bisecting on the scale at which the packing jams (:mod:`.jamming`). The result is
the last *unjammed* state: the spheres do not overlap (up to a tolerance), lie inside the
container and touch its walls. Results are cached on disk (:mod:`.cache`). Bonding them in
YADE is :func:`yade_electro.yade.bonding.add_bonded_packing`.

Units: SI (metres, cubic metres, seconds).
"""
from __future__ import annotations

import json
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from ..geometry.shapes import Shape, as_shape
from ..geometry.volumes import container_volume
from .cache import cache_key, cache_path, load_cached, store
from .grading import Refinement, graded_cloud
from .jamming import Relaxer, jam, max_overlap, shrink_to_remove_overlaps
from .radii import mean_radius_for_count, uniform_radii

__all__ = ["SpherePacking", "dense_packing", "PACKING_VERSION"]

log = logging.getLogger(__name__)

PACKING_VERSION = 2  # bump when the placement algorithm changes (invalidates the cache)


@dataclass(frozen=True, eq=False)
class SpherePacking:
    """Spheres filling a container (placement only, no bonds).

    Attributes
    ----------
    centers : (n, 3) float array
        Sphere centres [m].
    radii : (n,) float array
        Sphere radii [m].
    container_volume : float
        Volume of the container [m^3].
    volume_method : str
        ``"exact"`` or the Monte Carlo settings used for ``container_volume``.
    volume_fraction : float
        ``sum(4/3 pi r^3) / container_volume``.
    seed : int
        Seed of the random generator (radii and initial positions).
    r_mean : float
        Mean of ``radii`` [m].
    r_mean_requested : float
        Eq. 1 radius (from ``n``) or the ``r_mean`` asked for [m]; the spheres are scaled
        by ``radius_scale`` from it (< 1 when the packing jams first).
    radius_scale : float
        ``radii / (radii drawn at r_mean_requested)``.
    max_overlap : float
        Largest overlap ``r_i + r_j - d_ij`` between spheres, or penetration of the
        container wall, divided by ``r_mean`` (<= 0 means no overlap).
    time_s : float
        Wall time of the generation [s] (of the original run when read from the cache).
    from_cache : bool
        True when read from the disk cache.
    params : dict
        Every parameter of the generation (also the cache key) and solver counters.
    shape : Shape
        The container (not stored in the cache; the caller's).
    """

    centers: np.ndarray
    radii: np.ndarray
    container_volume: float
    volume_method: str
    volume_fraction: float
    seed: int
    r_mean: float
    r_mean_requested: float
    radius_scale: float
    max_overlap: float
    time_s: float
    from_cache: bool = False
    params: dict = field(default_factory=dict)
    shape: Shape = field(default=None, repr=False)

    @property
    def n(self) -> int:
        return int(self.radii.size)

    def distance_to_surface(self, points=None) -> np.ndarray:
        """Distance of ``points`` (default: the centres) to the container boundary [m]
        (>= 0 inside)."""
        return -self.shape.sdf(self.centers if points is None else points)


def dense_packing(predicate, n=None, r_mean=None, dispersion=0.25, seed=0, cache_dir=None, refine=None,
                  **opts) -> SpherePacking:
    """Fill a container densely with spheres (placement only; numpy/scipy, no YADE).

    The radii are uniform in ``r_mean * [1 - dispersion/2, 1 + dispersion/2]``. Random
    centres are relaxed with FIRE on a soft-sphere overlap energy, including the exact
    container wall, while the radii are scaled up; the scale is bisected until the packing
    jams (O'Hern et al. 2003). The last unjammed state is kept and shrunk by the tiny
    factor that removes its residual overlaps, so the spheres do not overlap, lie inside the
    container and touch its walls.

    Parameters
    ----------
    predicate : Shape or YADE predicate
        The container (see :func:`as_shape`), e.g. ``Cylinder((0,0,0), (0,0,5e-3), 1e-3)``
        or ``pack.inCylinder((0,0,0), (0,0,5e-3), 1e-3)``.
    n : int, optional
        Wanted number of spheres; ``r_mean`` then follows paper eq. 1 with ``fraction``.
    r_mean : float, optional
        Wanted mean radius [m] (instead of ``n``); ``n = round(fraction V / (4/3 pi
        r_mean^3))``.
    dispersion : float
        Relative width of the uniform radius distribution (paper: 0.25).
    seed : int
        Seed of ``numpy.random.default_rng`` (radii and initial positions).
    cache_dir : str or Path or False, optional
        Where results are cached as ``.npz`` (key: hash of all parameters); default
        ``$YADE_ELECTRO_CACHE`` or ``~/.cache/yade_electro``. ``False`` disables the cache.
    refine : Refinement, optional
        Smaller elements in a region (:class:`~yade_electro.packing.grading.Refinement`), with
        ``n``: the initial centres are drawn with a number density proportional to
        ``size^-3`` and the radii in proportion to the size at each centre; eq. 1 on those
        sizes gives the radius far from the region.
    **opts
        ``fraction`` (0.63) of eq. 1; ``method``: ``"jam"`` (default, no overlap, the
        radii stop growing where the packing jams) or ``"target"`` (keep the eq. 1 radii,
        i.e. the requested fraction, and minimise the overlaps, which then remain, a few %
        of r_mean); ``tol`` (2e-3) overlap tolerance of the relaxation in units of r_mean;
        ``ds_min`` (2.5e-4) resolution of the bisection on the radius scale; ``max_steps``
        (3000) FIRE steps per trial; ``phi_start`` (0.35) initial volume fraction; ``skin``
        (0.4) Verlet skin in units of r_mean; ``volume_samples`` (4e6) Monte Carlo points for
        the volume of a non-primitive container.

    Returns
    -------
    SpherePacking

    Raises
    ------
    ValueError
        For inconsistent arguments (both or neither of ``n``/``r_mean``, unknown options,
        a container the spheres cannot fit in).
    """
    defaults = dict(fraction=0.63, method="jam", tol=2e-3, ds_min=2.5e-4, max_steps=3000,
                    phi_start=0.35, skin=0.4, volume_samples=4_000_000)
    unknown = set(opts) - set(defaults)
    if unknown:
        raise ValueError(f"unknown option(s) {sorted(unknown)}; valid: {sorted(defaults)}")
    o = {**defaults, **opts}
    if o["method"] not in ("jam", "target"):
        raise ValueError(f"method must be 'jam' or 'target', got {o['method']!r}")
    if (n is None) == (r_mean is None):
        raise ValueError("give exactly one of n (number of spheres) or r_mean (mean radius [m])")
    if refine is not None and not isinstance(refine, Refinement):
        raise ValueError(f"refine must be a Refinement(region=..., factor=..., width=...) "
                         f"(yade_electro.packing.grading), got {refine!r}")
    if refine is not None and n is None:
        raise ValueError("a graded packing (refine=...) takes n, the number of spheres, not r_mean")
    shape = as_shape(predicate)
    t0 = time.perf_counter()
    volume, vmethod = container_volume(shape, n_samples=int(o["volume_samples"]))
    if n is not None:
        n = int(n)
        if n < 2:
            raise ValueError(f"n must be >= 2, got {n}")
        r_req = mean_radius_for_count(volume, n, o["fraction"])
    else:
        r_req = float(r_mean)
        if not r_req > 0:
            raise ValueError(f"r_mean must be > 0 [m], got {r_mean}")
        n = int(round(o["fraction"] * volume / (4.0 / 3.0 * np.pi * r_req ** 3)))
        if n < 2:
            raise ValueError(f"r_mean={r_req} m is too large for a container of volume "
                             f"{volume:.4g} m^3 ({n} sphere(s)); use a smaller r_mean")
    key = dict(version=PACKING_VERSION, shape=shape.key(), n=n, r_mean=r_req,
               dispersion=float(dispersion), seed=int(seed),
               **({"refine": refine.key()} if refine is not None else {}),
               **{k: (float(v) if isinstance(v, (int, float)) and k != "max_steps" else v)
                  for k, v in o.items()})
    blob = cache_key(key, shape)
    path = cache_path(blob, cache_dir)
    hit = load_cached(path)
    if hit is not None:
        centers, radii, meta = hit
        return SpherePacking(centers, radii, shape=shape, from_cache=True, **meta)

    cloud = None
    if refine is not None:          # the centres first, the radii follow the size at each (same n, seed)
        cloud = graded_cloud(shape, refine, n, float(dispersion), np.random.default_rng(int(seed)))
        r_req /= float(np.mean(cloud[1] ** 3)) ** (1.0 / 3.0)      # eq. 1 on the graded sizes: far from the region
    rng = np.random.default_rng(int(seed))
    rho = uniform_radii(n, 1.0, float(dispersion), rng) if cloud is None else cloud[1]  # units of r_req
    log.info("dense_packing: %d spheres, r_mean %.4g m, container %.4g m^3 (%s)", n, r_req,
             volume, vmethod)
    x, s, info = jam(shape, rho, r_req, rng, phi_start=o["phi_start"], s_max=1.0,
                      tol=o["tol"], ds0=0.02, ds_min=o["ds_min"], max_steps=int(o["max_steps"]),
                      skin=o["skin"], volume=volume, initial=None if cloud is None else cloud[0] / r_req)
    if o["method"] == "target" and s < 1.0:
        rel = Relaxer(shape, rho, r_req, skin=o["skin"])
        x, _, _, steps = rel.minimise(x, 1.0, o["tol"], 10 * int(o["max_steps"]),
                                      window=1000, stall=0.99)
        info["fire_steps"] += steps
        s = 1.0
    centers, radii = x * r_req, s * rho * r_req
    if o["method"] == "jam":
        # shrink by the factor that removes the residual overlaps (<= tol r_mean)
        eps = shrink_to_remove_overlaps(centers, radii, shape)
        if eps > 0:
            radii = radii * (1.0 - eps)
            s *= 1.0 - eps
    ov = max_overlap(centers, radii, shape)
    r_m = float(radii.mean())
    info["radius_scale"] = float(s)
    meta = dict(container_volume=volume, volume_method=vmethod,
                volume_fraction=float(np.sum(4.0 / 3.0 * np.pi * radii ** 3) / volume),
                seed=int(seed), r_mean=r_m, r_mean_requested=r_req, radius_scale=float(s),
                max_overlap=ov / r_m, time_s=time.perf_counter() - t0,
                params={**json.loads(blob), **info})
    log.info("dense_packing: fraction %.4f, max overlap %.2g r_mean, %.1f s",
             meta["volume_fraction"], meta["max_overlap"], meta["time_s"])
    store(path, centers, radii, meta)
    return SpherePacking(centers, radii, shape=shape, **meta)
