"""Thermal expansion of a bonded packing against closed forms (issue 34's checks).

A steel-like bonded packing (``add_bonded_packing``'s CohFrictMat, E_bond = 210 GPa,
alpha = 1.2e-5 1/K, dT = 100 K) expands through :class:`~yade_electro.yade.ThermalExpansion`
(``mode='bonds'``: the bonds' rest lengths grow) while YADE relaxes it (NewtonIntegrator,
damping 0.5) until the unbalanced force is below 1e-4 and the measured figure has settled:

``moduli``
    The packing's own E and nu, measured first on the bar (4 x 4 x 12 mm box): its end layers
    held in z only (rollers), the top one moved by 1e-4 of the length at a constant speed;
    E = reaction / area / axial strain, nu = - lateral / axial strain, the strains fitted on
    the middle third (the end layers, held rigid, are no part of the gauge: the strain from
    their displacement is 1.6 % smaller at 2,000 elements).
``free_expansion``
    The free bar heated uniformly: strain alpha dT from the fit of the displacements against
    the positions (all three axes, the worst); also the largest bond force over the clamped
    bar's (target 1e-3).
``clamped_bar``
    The bar with its end layers held in z (rollers) heated uniformly: sigma = -E alpha dT,
    from the reaction on the end layers over the cross-section (E from ``moduli``).
``linear_field``
    The free bar with T linear along it (dT_max = 100 K): no stress. error_pct = 100 x the
    mean over the elements of the largest absolute principal Love-Weber stress, over
    E alpha dT_max.
``bimetal``
    A free strip of two bonded layers of equal thickness (24 x 4 x 2 mm, h = 4 mm across the
    layers, L = 6 h; alpha 1e-5 and 2e-5 1/K, same material otherwise, so E and nu are
    equal) heated by 100 K: Timoshenko's (1925) curvature with
    m = n = 1, kappa = 1.5 (a2 - a1) dT / h, against the curvature of the fit of the
    displacements across the strip.

Run::

    yade-electro -n -x cases/thermal_expansion.py            # 10,000 elements per check
    yade-electro -n -x cases/thermal_expansion.py --quick    # 2,000 (the CI test)

Prints one JSON line per check (``check``, ``error_pct`` and its figures), then one summary
line; ``--out`` also writes them to a JSON file.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith("thermal_expansion.py")
                                       else __file__))
if os.path.dirname(HERE) not in sys.path:
    sys.path.insert(0, os.path.dirname(HERE))

from yade_electro.geometry.shapes import Box  # noqa: E402
from yade_electro.packing import dense_packing  # noqa: E402

ALPHA, DT, T0 = 1.2e-5, 100.0, 293.0


def _say(msg):
    sys.stderr.write(f"[thermal_expansion] {msg}\n")
    sys.stderr.flush()


def new_bar(n, size, seed=1, cache_dir=None, second_material_above=None):
    """A fresh scene with a bonded packing of ``n`` spheres in the box ``size`` (m), every
    sphere at T0. With ``second_material_above=y``, the spheres above y get a second material
    (a copy of the first, labelled 'steel_b'). Returns the bodies and the packing."""
    from yade import O
    from yade_electro.yade import ensure_thermal_state
    from yade_electro.yade.bonding import add_bonded_packing, steel_304L
    O.reset()
    pk = dense_packing(Box((0, 0, 0), tuple(size)), n=n, seed=seed, cache_dir=cache_dir)
    ids = add_bonded_packing(pk, damping=0.5)
    bodies = [O.bodies[i] for i in ids]
    ensure_thermal_state(bodies)
    for b in bodies:
        b.state.temp = T0
    if second_material_above is not None:
        mid = O.materials.append(steel_304L(label="steel_b"))
        for b in bodies:
            if b.state.pos[1] > second_material_above:
                b.material = O.materials[mid]
    return bodies, pk


def positions(bodies):
    return np.array([tuple(b.state.pos) for b in bodies])


def relax(figure, min_steps=1000, chunk=500, max_steps=60000, rtol=2e-4, unbalanced=1e-4):
    """Run YADE until ``figure()`` changed by less than ``rtol`` (relative) over each of the
    last two chunks and, with ``unbalanced`` (no body held: YADE's measure counts the held
    bodies' reactions), the unbalanced force is below it. Returns (figure, steps)."""
    from yade import O, utils
    O.run(min_steps, True)
    steps, history = min_steps, [figure()]
    while steps < max_steps:
        O.run(chunk, True)
        steps += chunk
        history.append(figure())
        if os.environ.get("TE_DEBUG"):
            _say(f"  {steps} {history[-1]:.8g} unbalanced {utils.unbalancedForce():.2e}")
        calm = all(abs(a - b) <= rtol * max(abs(a), 1e-300) for a, b in zip(history[-2:], history[-3:-1]))
        if len(history) >= 3 and calm and (unbalanced is None or utils.unbalancedForce() < unbalanced):
            return history[-1], steps
    _say(f"not settled after {max_steps} steps (figure {history[-1]:.6g}, unbalanced {utils.unbalancedForce():.2e})")
    return history[-1], steps


def fitted_strain(x0, x, axis):
    """The slope of the displacement along ``axis`` against the position along it."""
    return float(np.polyfit(x0[:, axis], x[:, axis] - x0[:, axis], 1)[0])


def end_layers(x0, r_mean):
    z = x0[:, 2]
    return z < z.min() + 1.2 * r_mean, z > z.max() - 1.2 * r_mean


def reaction(bodies, chosen):
    """Sum of the z forces [N] on the ``chosen`` bodies."""
    from yade import O
    return float(sum(O.forces.f(b.id)[2] for b, c in zip(bodies, chosen) if c))


def expansion(**kw):
    from yade import O
    from yade_electro.yade import ThermalExpansion
    e = ThermalExpansion(alpha=kw.pop("alpha", ALPHA), mode=kw.pop("mode", "bonds"), iterPeriod=500, **kw)
    O.engines = O.engines + [e.runner]
    return e


def heat(bodies, engine, T):
    for b, t in zip(bodies, np.broadcast_to(T, (len(bodies),)).tolist()):
        b.state.temp = t
    engine.step()                       # applied now (the runner goes on every 500 steps)


def moduli(n, size, cache_dir):
    """E and nu of the bar with roller ends (module doc)."""
    bodies, pk = new_bar(n, size, cache_dir=cache_dir)
    x0 = positions(bodies)
    bot, top = end_layers(x0, pk.r_mean)
    L = x0[:, 2].max() - x0[:, 2].min()
    eps0 = float(os.environ.get("TE_EPS0", 1e-4))
    # the top layer is moved at a constant speed (a jump of the bodies would strain the bonds
    # in their normal direction only: YADE's shear springs integrate relative velocities)
    from yade import O
    ramp = 2000
    for b, lo, hi in zip(bodies, bot, top):
        if lo or hi:
            b.state.blockedDOFs = "z"
            b.state.vel = (0, 0, -eps0 * L / (ramp * O.dt) if hi else 0.0)
    O.run(ramp, True)
    for b, hi in zip(bodies, top):
        if hi:
            b.state.vel = (0, 0, 0)
    eps0 = float(np.mean([x0[k, 2] - b.state.pos[2] for k, b in enumerate(bodies) if top[k]])) / L
    area = size[0] * size[1]
    F, steps = relax(lambda: reaction(bodies, top), unbalanced=None)
    x = positions(bodies)
    mid = np.abs(x0[:, 2] - x0[:, 2].mean()) < L / 6
    # strains of the middle third: the end layers, held rigid, are no part of the gauge
    ex, ey, ez = (fitted_strain(x0[mid], x[mid], a) for a in range(3))
    E = F / area / -ez
    nu = -0.5 * (ex + ey) / ez
    return {"check": "moduli", "E_Pa": E, "nu": nu, "strain_ends": -eps0, "strain_middle_third": ez, "steps": steps, "elements": len(bodies),
            "r_mean_m": pk.r_mean}


def clamped_bar(n, size, E, cache_dir):
    bodies, pk = new_bar(n, size, cache_dir=cache_dir)
    x0 = positions(bodies)
    bot, top = end_layers(x0, pk.r_mean)
    for b, lo, hi in zip(bodies, bot, top):
        if lo or hi:
            b.state.blockedDOFs = "z"
    e = expansion()
    heat(bodies, e, T0 + DT)
    area = size[0] * size[1]
    F, steps = relax(lambda: reaction(bodies, top), unbalanced=None)
    sigma = -F / area
    target = -E * ALPHA * DT
    s = e.element_stress()
    mid = np.abs(x0[:, 2] - x0[:, 2].mean()) < (x0[:, 2].max() - x0[:, 2].min()) / 6
    V = e.element_volumes()[mid]
    lw = float(np.einsum("n,n->", V, s[mid, 2, 2]) / V.sum())
    fn, _ = e.bond_forces()
    return {"check": "clamped_bar", "error_pct": 100 * abs(sigma - target) / abs(target), "sigma_Pa": sigma,
            "sigma_closed_form_Pa": target, "love_weber_mid_third_Pa": lw, "bond_force_max_N": float(np.abs(fn).max()),
            "steps": steps, "elements": len(bodies)}


def free_expansion(n, size, clamped_force, cache_dir):
    bodies, _ = new_bar(n, size, cache_dir=cache_dir)
    x0 = positions(bodies)
    e = expansion()
    heat(bodies, e, T0 + DT)
    worst = lambda: max(abs(fitted_strain(x0, positions(bodies), a) - ALPHA * DT) for a in range(3))  # noqa: E731
    _, steps = relax(lambda: fitted_strain(x0, positions(bodies), 2))
    x = positions(bodies)
    strains = [fitted_strain(x0, x, a) for a in range(3)]
    fn, _ = e.bond_forces()
    return {"check": "free_expansion", "error_pct": 100 * worst() / (ALPHA * DT), "strain_xyz": strains,
            "strain_closed_form": ALPHA * DT, "bond_force_ratio": float(np.abs(fn).max() / clamped_force),
            "steps": steps, "elements": len(bodies)}


def linear_field(n, size, E, cache_dir):
    bodies, _ = new_bar(n, size, cache_dir=cache_dir)
    x0 = positions(bodies)
    z = x0[:, 2]
    T = T0 + DT * (z - z.min()) / (z.max() - z.min())
    e = expansion()
    heat(bodies, e, T)

    def mean_principal():
        s = e.element_stress()
        return float(np.mean(np.abs(np.linalg.eigvalsh(s)).max(axis=1)))
    m, steps = relax(mean_principal, rtol=1e-2)
    x = positions(bodies)
    # the free body's strain is alpha T(z): its fitted axial strain is alpha times the mean rise
    return {"check": "linear_field", "error_pct": 100 * m / (E * ALPHA * DT), "mean_abs_principal_Pa": m,
            "reference_Pa": E * ALPHA * DT, "axial_strain": fitted_strain(x0, x, 2),
            "steps": steps, "elements": len(bodies)}


def bimetal(n, size, cache_dir):
    h = size[1]
    bodies, _ = new_bar(n, size, cache_dir=cache_dir, second_material_above=0.5 * h)
    x0 = positions(bodies)
    e = expansion(alpha={"steel_304L": 1e-5, "steel_b": 2e-5})
    heat(bodies, e, T0 + DT)

    def curvature():
        x = positions(bodies)
        u = x[:, 1] - x0[:, 1]
        X, Y = x0[:, 0] - x0[:, 0].mean(), x0[:, 1] - x0[:, 1].mean()
        A = np.column_stack([np.ones_like(X), X, X * X, Y, Y * Y, X * Y])
        c = np.linalg.lstsq(A, u, rcond=None)[0]
        return -2.0 * c[2]                 # u_y = -kappa x^2 / 2: bent towards the less expanding layer
    kappa, steps = relax(curvature, rtol=2e-4, max_steps=120000)
    target = 1.5 * (2e-5 - 1e-5) * DT / h
    return {"check": "bimetal", "error_pct": 100 * abs(kappa - target) / target, "curvature_per_m": kappa,
            "curvature_timoshenko_per_m": target, "thickness_m": h, "length_m": size[0], "steps": steps,
            "elements": len(bodies)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10000, help="elements per check")
    ap.add_argument("--quick", action="store_true", help="2,000 elements per check (the CI test)")
    ap.add_argument("--checks", default="free_expansion,clamped_bar,linear_field,bimetal")
    ap.add_argument("--out", default=None, help="also write the lines to this JSON file")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    n = 2000 if args.quick else args.n
    checks = [c for c in args.checks.split(",") if c]
    W = 4e-3
    bar = (W, W, 3 * W)
    strip = (6 * W, W, W / 2)
    lines, t0 = [], time.time()

    def emit(row):
        row = dict(row, wall_s=round(time.time() - t0, 1))
        print(json.dumps(row), flush=True)
        lines.append(row)
    mod = {}
    if set(checks) & {"clamped_bar", "free_expansion", "linear_field"}:
        _say(f"moduli: {n} elements")
        mod = moduli(n, bar, args.cache_dir)
        emit(mod)
    clamped = None
    if "clamped_bar" in checks or "free_expansion" in checks:
        _say("clamped bar")
        clamped = clamped_bar(n, bar, mod["E_Pa"], args.cache_dir)
        if "clamped_bar" in checks:
            emit(clamped)
    if "free_expansion" in checks:
        _say("free expansion")
        emit(free_expansion(n, bar, clamped["bond_force_max_N"], args.cache_dir))
    if "linear_field" in checks:
        _say("linear field")
        emit(linear_field(n, bar, mod["E_Pa"], args.cache_dir))
    if "bimetal" in checks:
        _say("bimetal strip")
        emit(bimetal(n, strip, args.cache_dir))
    summary = {"case": "thermal_expansion", "elements": n,
               "error_pct": {r["check"]: r["error_pct"] for r in lines if "error_pct" in r},
               "E_Pa": mod.get("E_Pa"), "nu": mod.get("nu"), "wall_s": round(time.time() - t0, 1)}
    print(json.dumps(summary), flush=True)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(lines + [summary], fh, indent=1)
    return lines + [summary]


if __name__ == "__main__":
    main()
