"""Placement by jamming, numpy/scipy only.

FIRE relaxation of a soft-sphere overlap energy with the exact container wall, while the
radii grow (the O'Hern et al. 2003 protocol).

Everything here works in units of a reference radius ``r0`` (positions ``x``, radii
``rho``); :func:`yade_electro.packing.dense_packing` converts to metres.
"""
from __future__ import annotations

import logging
import math
import sys
import time

import numpy as np
from scipy.spatial import cKDTree


__all__ = ["Relaxer", "random_inside", "jam", "max_overlap", "shrink_to_remove_overlaps", "morton_order",
           "SPATIAL_ORDER_FROM"]

log = logging.getLogger(__name__)

#: seconds between two progress lines of a long jamming run
PROGRESS_EVERY = 10.0

#: from this many spheres on, the jamming works on the spheres in a space-filling-curve
#: (Morton) order, with its pair list sorted and the wall terms evaluated on the spheres near
#: the wall only (see :func:`jam`). Below it the packings are the same to the last bit as
#: before this option existed (the cached packings and every figure made from them).
SPATIAL_ORDER_FROM = 200_000


def _spread_bits(v):
    """The low 21 bits of each of ``v`` (int64) moved to every third bit (a Morton code's axis)."""
    v = v.astype(np.uint64) & np.uint64(0x1FFFFF)
    for shift, mask in ((32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF), (8, 0x100F00F00F00F00F),
                        (4, 0x10C30C30C30C30C3), (2, 0x1249249249249249)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def morton_order(x) -> np.ndarray:
    """The permutation that sorts points ``x`` (n, 3) along a Morton (Z-order) curve of 2^21
    cells per axis over their bounding cube: neighbours in space end up near each other in
    memory, which is what the pair forces' scattered reads and writes need at 1M spheres."""
    x = np.asarray(x, dtype=float)
    lo = x.min(axis=0)
    span = max(float(np.max(x.max(axis=0) - lo)), 1e-300)
    q = np.minimum(((x - lo) * ((2 ** 21 - 1) / span)).astype(np.int64), 2 ** 21 - 1)
    key = _spread_bits(q[:, 0]) | (_spread_bits(q[:, 1]) << np.uint64(1)) | (_spread_bits(q[:, 2]) << np.uint64(2))
    return np.argsort(key, kind="stable")


def pair_forces_numpy(x, rho, s, p):
    """The numpy form of the sphere-sphere forces (see :meth:`Relaxer.forces`): forces
    (n, 3), the overlaps of the overlapping pairs in pair order, the largest overlap."""
    n = x.shape[0]
    i, j = p[:, 0], p[:, 1]
    d = x[j] - x[i]
    d2 = np.einsum("ij,ij->i", d, d)
    rs = s * (rho[i] + rho[j])
    m = d2 < rs * rs
    F = np.zeros((n, 3))
    if not np.any(m):
        return F, np.zeros(0), 0.0
    i, j, d, rs = i[m], j[m], d[m], rs[m]
    dist = np.sqrt(d2[m])
    ov = rs - dist
    f = d * (ov / np.maximum(dist, 1e-12))[:, None]
    for k in range(3):
        F[:, k] += np.bincount(j, f[:, k], n) - np.bincount(i, f[:, k], n)
    return F, ov, float(ov.max())


class NumpyFireSteps:
    """The FIRE operations of :class:`yade_electro.native.FireSteps` in numpy, in the exact
    expressions the jamming has always used (the packings below SPATIAL_ORDER_FROM spheres
    keep their bits): the fallback, and the small packings' path."""

    @staticmethod
    def power(F, v):
        """(max_i |F_i|, F.v, |v|, |F|)."""
        return (np.sqrt(np.max(np.einsum("ij,ij->i", F, F))), np.einsum("ij,ij->", F, v),
                np.sqrt(np.einsum("ij,ij->", v, v)), np.sqrt(np.einsum("ij,ij->", F, F)))

    @staticmethod
    def move(x, v, F, a, b, dt):
        """v = a v + b F (a = 0: v = 0), v += dt F, x += dt v, in place."""
        if a == 0.0:
            v[:] = 0.0
        else:
            v *= a                      # in place: the same bits, no new arrays
            v += b * F
        v += F * dt
        x += v * dt

    @staticmethod
    def max_move(x, ref) -> float:
        d = x - ref
        return np.sqrt(np.max(np.einsum("ij,ij->i", d, d)))


class Relaxer:
    """Soft-sphere overlap energy minimiser in units of the mean radius.

    The energy ``U = 1/2 sum_pairs max(0, s(rho_i + rho_j) - d_ij)^2 + 1/2 sum_i max(0,
    sdf(x_i) + s rho_i)^2`` is minimised with FIRE (Bitzek et al. 2006) using a Verlet pair
    list.
    """

    def __init__(self, shape, rho, r0, skin=0.4, native=True, spatial=False):
        self.shape, self.rho, self.r0, self.skin = shape, rho, r0, skin
        self.native = bool(native)
        # spatial: the spheres come in a space-filling-curve order (the caller's), the pair
        # list is sorted and the wall terms are evaluated on the wall's candidates only
        self.spatial = bool(spatial)
        self.wall_candidates = None
        self._fire = None           # the compiled FIRE steps (spatial mode), once built
        self._F = None
        self.rho_max = float(rho.max())
        self.pairs = None
        self.x_ref = None
        self.s_ref = None
        self.n_rebuild = 0
        self.n_force = 0

    def fire_steps(self):
        """The compiled FIRE steps (:class:`yade_electro.native.FireSteps`) in spatial mode,
        None otherwise (numpy then)."""
        if not self.spatial or not self.native:
            return None
        if self._fire is None:
            from ..native import FireSteps
            self._fire = FireSteps()
        return self._fire

    def _fire_ops(self):
        """The FIRE operations: compiled in spatial mode, numpy otherwise."""
        return self.fire_steps() or NumpyFireSteps

    def _pairs(self, x, s):
        if self.pairs is not None:
            disp = self._fire_ops().max_move(x, self.x_ref)
            if 2 * disp + 2 * (s - self.s_ref) * self.rho_max < self.skin:
                return self.pairs
        cut = 2 * s * self.rho_max + self.skin
        fire = self.fire_steps()
        if fire is not None:        # sorted by the first sphere: a cell grid, in C
            self.pairs = fire.pairs_within(x, cut)
        else:
            self.pairs = cKDTree(x).query_pairs(cut, output_type="ndarray")
        if self.spatial:
            if fire is None:
                # pairs in the spheres' (spatial) order: the scatter of the forces walks
                # memory forwards instead of at random
                key = self.pairs[:, 0].astype(np.int64) * x.shape[0] + self.pairs[:, 1]
                self.pairs = self.pairs[np.argsort(key)]
            # the spheres that can touch a wall before the next rebuild: until then each
            # sphere moves and grows by less than skin/2 together (the test above), and g is
            # a signed distance, so g + s rho rises by less than skin/2 on each wall term
            near = np.zeros(x.shape[0], dtype=bool)
            for g, _ in self.shape.wall_terms(x * self.r0):
                near |= g / self.r0 + s * self.rho > -self.skin
            self.wall_candidates = np.flatnonzero(near)
        self.x_ref, self.s_ref = x.copy(), s
        self.n_rebuild += 1
        return self.pairs

    def _pair_forces(self, x, s, p):
        """Sphere-sphere forces, overlaps (in pair order) and the largest: compiled
        (:func:`yade_electro.native.soft_sphere_forces`, the same bits) unless ``native`` is
        False (the numpy form, the tests' reference)."""
        if self.native:
            from ..native import soft_sphere_forces
            return soft_sphere_forces(x, self.rho, s, p)
        return pair_forces_numpy(x, self.rho, s, p)

    def forces(self, x, s):
        """Forces (n, 3) and the largest overlap (sphere-sphere or wall penetration)."""
        self.n_force += 1
        p = self._pairs(x, s)
        fire = self.fire_steps()
        if fire is not None:
            if self._F is None or self._F.shape != x.shape:
                self._F = np.empty_like(x)
            F = self._F
            energy, maxov, _ = fire.pair_forces(x, self.rho, s, p, F)
        else:
            F, ov, maxov = self._pair_forces(x, s, p)
            energy = 0.5 * float(ov @ ov) if ov.size else 0.0
        if self.spatial:
            cand = self.wall_candidates
            xw, rad = x[cand], s * self.rho[cand]
        else:
            cand, xw, rad = None, x, s * self.rho
        for g, normal in self.shape.wall_terms(xw * self.r0):
            phi = g / self.r0 + rad
            w = np.flatnonzero(phi > 0)
            if w.size:
                F[w if cand is None else cand[w]] -= phi[w, None] * normal(w)
                maxov = max(maxov, float(phi[w].max()))
                energy += 0.5 * float(phi[w] @ phi[w])
        self.energy = energy
        return F, maxov

    def minimise(self, x, s, tol, max_steps, dt0=0.1, dt_max=0.5, window=200, stall=0.7, progress=None):
        """FIRE from ``x`` at scale ``s``. Returns (x, max_overlap, status, steps) where
        status is "ok" (max overlap < tol), "jammed" (the energy fell by less than a factor
        ``stall`` over the last ``window`` steps, or the forces balance with overlaps left)
        or "budget" (max_steps reached). ``progress(step, max_steps, max_overlap)``, if
        given, is called every 50 steps (it prints, or not, as it likes)."""
        x = np.array(x, dtype=float, order="C", copy=True)
        v = np.zeros_like(x)
        dt, alpha, n_pos = dt0, 0.1, 0
        ops = self._fire_ops()
        F, maxov = self.forces(x, s)
        e_hist = []
        for step in range(1, max_steps + 1):
            if maxov < tol:
                return x, maxov, "ok", step
            if step % window == 0:
                e_hist.append(self.energy)
                if len(e_hist) >= 2 and e_hist[-1] > stall * e_hist[-2]:
                    return x, maxov, "jammed", step
            fmax, P, vn, fn = ops.power(F, v)
            if fmax < 1e-3 * maxov:
                return x, maxov, "jammed", step
            if P > 0:
                a, b = 1 - alpha, alpha * vn / max(fn, 1e-300)       # v = a v + b F
                n_pos += 1
                if n_pos > 5:
                    dt = min(dt * 1.1, dt_max)
                    alpha *= 0.99
            else:
                a, b = 0.0, 0.0
                dt *= 0.5
                alpha, n_pos = 0.1, 0
            ops.move(x, v, F, a, b, dt)
            F, maxov = self.forces(x, s)
            if progress is not None and step % 50 == 0:
                progress(step, max_steps, maxov)
        return x, maxov, ("ok" if maxov < tol else "budget"), max_steps


def random_inside(shape, rad, r0, rng, max_rounds=200):
    """Uniform random centres (dimensionless, units of r0) with sdf <= -rad (or <= 0 if a
    sphere does not fit anywhere)."""
    lo, hi = shape.bounds()
    lo, hi = lo / r0, hi / r0
    n = rad.size
    out = np.empty((n, 3))
    todo = np.arange(n)
    for _ in range(max_rounds):
        m = todo.size
        if m == 0:
            return out
        cand = lo + (hi - lo) * rng.random((4 * m + 16, 3))
        sd = shape.sdf(cand * r0) / r0
        ok = cand[sd <= 0]
        sd_ok = sd[sd <= 0]
        take = min(m, ok.shape[0])
        # accept a candidate for a given sphere only if the sphere fits
        fits = sd_ok[:take] <= -rad[todo[:take]]
        idx = todo[:take][fits]
        out[idx] = ok[:take][fits]
        todo = np.concatenate([todo[:take][~fits], todo[take:]])
    raise ValueError("could not place the spheres inside the container: the radii are too "
                     "large for it (ask for more spheres or a smaller r_mean)")


def jam(shape, rho, r0, rng, *, phi_start, s_max, tol, ds0, ds_min, max_steps, skin, volume, initial=None):
    """Grow the radius scale ``s`` from ``phi_start`` to jamming (bisection on ``s``). A run
    longer than :data:`PROGRESS_EVERY` seconds prints a progress line that often.

    From :data:`SPATIAL_ORDER_FROM` spheres on, the relaxation works on the spheres sorted
    along a Morton curve of the initial cloud (the spheres move little afterwards, so the
    order stays spatial) and the result is put back in the original order: the same
    algorithm, other rounding (the forces are summed in another order). Its FIRE steps are
    compiled (:class:`yade_electro.native.FireSteps`): on a jittered lattice of 1M spheres a
    step with its share of list rebuilds takes 148 ms instead of 513 ms."""
    phi_nom = float(np.sum(4 / 3 * np.pi * (rho * r0) ** 3)) / volume  # fraction at s = 1
    s = min(s_max, (phi_start / phi_nom) ** (1 / 3))
    # the initial cloud: uniform, or given (a graded cloud, units of r0)
    x = random_inside(shape, s * rho, r0, rng) if initial is None else np.array(initial, float)
    order = morton_order(x) if rho.size >= SPATIAL_ORDER_FROM else None
    if order is not None:
        x, rho = x[order], rho[order]
    rel = Relaxer(shape, rho, r0, skin=skin, spatial=order is not None)
    t0 = time.perf_counter()
    clock = {"last": t0, "what": "the initial random cloud"}

    def within_trial(step, budget, overlap):       # a trial longer than PROGRESS_EVERY shows progress too
        now = time.perf_counter()
        if now - clock["last"] >= PROGRESS_EVERY:
            clock["last"] = now
            print(f"[packing] {x.shape[0]} spheres: relaxing {clock['what']}: FIRE step {step} of at most "
                  f"{budget}, largest overlap {overlap:.2g} r_mean (tolerance {tol:g}), {now - t0:.0f} s so far",
                  file=sys.stderr, flush=True)

    x, ov, status, steps = rel.minimise(x, s, tol, 20 * max_steps, progress=within_trial)
    total = steps
    if status != "ok":
        raise RuntimeError(f"could not remove the overlaps of the initial random cloud "
                           f"(fraction {phi_start}); max overlap {ov:.3g} r_mean")
    x_ok, s_ok, ds = x, s, ds0
    trials = 0
    t_trials = time.perf_counter()
    while ds >= ds_min and s_ok < s_max:
        now = time.perf_counter()
        if now - clock["last"] >= PROGRESS_EVERY:     # long work shows progress (stderr)
            clock["last"] = now
            left = max(0.0, math.log2(ds / ds_min)) + 1.0
            print(f"[packing] {x.shape[0]} spheres: volume fraction {phi_nom * s_ok ** 3:.4f}, growth step {ds:.2g} "
                  f"(stops below {ds_min:g}: at least {left:.0f} more trials of about {(now - t_trials) / max(trials, 1):.0f} s, "
                  f"{trials} done in {now - t_trials:.0f} s)", file=sys.stderr, flush=True)
        s_try = min(s_max, s_ok * (1 + ds))
        clock["what"] = f"trial {trials + 1} (volume fraction {phi_nom * s_try ** 3:.4f})"
        x_try, ov, status, steps = rel.minimise(x_ok, s_try, tol, max_steps, progress=within_trial)
        total += steps
        trials += 1
        log.debug("jam: s=%.5f fraction=%.4f %s in %d steps (ds=%.2g)", s_try,
                  phi_nom * s_try ** 3, status, steps, ds)
        if status == "ok":
            x_ok, s_ok = x_try, s_try
            ds = min(ds * 1.5, 0.05)
        else:
            ds *= 0.5
    info = dict(fire_steps=int(total), trials=trials, pair_rebuilds=rel.n_rebuild,
                radius_scale=float(s_ok))
    if order is not None:
        info["spatial_order"] = True
        x_back = np.empty_like(x_ok)
        x_back[order] = x_ok
        x_ok = x_back
    return x_ok, s_ok, info




def max_overlap(centers, radii, shape) -> float:
    """Largest sphere-sphere overlap or wall penetration [m] (negative: none)."""
    tree = cKDTree(centers)
    p = tree.query_pairs(2 * radii.max(), output_type="ndarray")
    worst = -np.inf
    if len(p):
        d = np.linalg.norm(centers[p[:, 1]] - centers[p[:, 0]], axis=1)
        worst = float(np.max(radii[p[:, 0]] + radii[p[:, 1]] - d))
    if shape is not None:
        worst = max(worst, float(np.max(shape.sdf(centers) + radii)))
    return worst


def shrink_to_remove_overlaps(centers, radii, shape) -> float:
    """Smallest relative shrink ``eps`` of all radii after which no pair overlaps and no
    sphere crosses the container's wall constraints (plus 1e-9 for rounding)."""
    eps = 0.0
    p = cKDTree(centers).query_pairs(2 * radii.max(), output_type="ndarray")
    if len(p):
        d = np.linalg.norm(centers[p[:, 1]] - centers[p[:, 0]], axis=1)
        rs = radii[p[:, 0]] + radii[p[:, 1]]
        eps = max(eps, float(np.max((rs - d) / rs)))
    for g, _ in shape.wall_terms(centers):
        eps = max(eps, float(np.max((g + radii) / radii)))
    return eps + 1e-9 if eps > 0 else 0.0
