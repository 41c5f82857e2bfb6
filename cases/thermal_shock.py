"""Thermal shock: a hot alumina strip quenched at its two long faces (issue 34, item 5).

A bonded strip (8 mm along x, 2 mm along y, 0.4 mm along z), stress-free at T_w + dT, has its
two faces y = 0 and y = 2 mm held at the water's T_w = 293 K from t = 0 (an infinite Biot
number: ``FixedTemperature`` on the container's faces); the other faces are adiabatic and every
face is free. ``HeatEngine`` cools it, ``ThermalExpansion(mode='bonds')`` (reference: the hot
state) contracts the cooled layers, which the warm core holds in tension, and YADE's cohesive
law breaks the bonds (``CohFrictMat``, ``fragile``). The heat runs on its own clock (one
thermal step ``--dt`` per call) and YADE relaxes ``--steps`` mechanical steps between calls.

Alumina (99 %): E about 370 GPa (the bonds' modulus is set so; the strip's own E_x is measured),
alpha 8e-6 1/K, lambda 30 W/(m K), rho 3900 kg/m^3, c 880 J/(kg K); bond cohesion ``--strength``.

What is checked, and against what:

1. **Thermal stress before any crack, against the closed form.** For a long free strip whose
   temperature varies across its width only, sigma_xx(y) = E alpha (T_avg - T(y)) plus the
   bending term, which vanishes here by symmetry (Timoshenko & Goodier, *Theory of
   Elasticity*, sec. 150). The DEM's sigma_xx in ten slabs across y (the central 4 mm, away
   from the free ends) is compared with the formula applied to the DEM's own temperature
   profile in the same slabs, with the strip's E_x measured by the pull below:
   ``stress_error_pct`` = RMS difference over the largest |sigma|, at the last call before the
   first broken bond.
2. **The onset against the strength.** The strip is also pulled along x at T_w (its grip moved at
   a constant speed): its strength sigma_f and E_x. Cracks should start when the cooled surface
   layer reaches sigma_f: ``surface_stress_at_onset_over_strength`` is the surface layers'
   sigma_xx at the last call before the first break over sigma_f. Hasselman's critical quench
   for this geometry (uniaxial surface stress E alpha dT at an infinite Biot number, the
   first-crack criterion of the thermal-shock literature) is dT_c = sigma_f / (E alpha):
   ``dT_over_dT_c``.
3. **Number and spacing of cracks against the published trend.** Broken bonds within half the
   width of each quenched face are grouped into cracks along x (a gap of more than 1.5
   diameters separates two cracks; a crack has at least 3 broken bonds). Quenched alumina
   plates (Jiang et al., 50 x 10 x 1 mm plates dropped from 300-600 C into 20 C water) show
   edge cracks perpendicular to the quenched edge, more and closer together at larger dT, of
   unequal lengths (a hierarchy of 2-3 classes). ``--sweep`` runs two quenches (dT = 2 and 4
   dT_c) and reports the number, the mean spacing and the length classes of each; the
   published figures are shapes and trends, not numbers we can fit, and the comparison is
   stated as such.

Energy: the heat engine's ledger (heat content change against the heat through the quenched
faces) is in the JSON (``ledger_error``).

VTK (``--out/vtk``): elements (temperature, sigma_xx, broken bonds) and every initial bond
(``broken`` = 1) at the end of each quench.

Run::

    yade-electro -n -x cases/thermal_shock.py                     # 8,000 elements, dT = 4 dT_c
    yade-electro -n -x cases/thermal_shock.py --sweep             # dT = 2 and 4 dT_c
    yade-electro -n -x cases/thermal_shock.py --quick             # 2,500 elements (the CI test)

Ends with one JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_NAME = "thermal_shock.py"
HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith(_NAME) else __file__))
for d in (HERE, os.path.dirname(HERE)):
    if d not in sys.path:
        sys.path.insert(0, d)

import thermal_cracking as TC  # noqa: E402

SIZE = (8e-3, 2e-3, 0.4e-3)   # m: x (length), y (width, quenched at y = 0 and y = SIZE[1]), z
BOND_YOUNG = 920e9            # Pa: the bonds' modulus (E_x of the strip comes out about 0.4 of it)
POISSON = 0.3                 # CohFrictMat ks/kn, as 304L's bonds
DENSITY = 3900.0              # kg/m^3
SPECIFIC_HEAT = 880.0         # J/(kg K)
CONDUCTIVITY = 30.0           # W/(m K)
ALPHA = 8e-6                  # 1/K
T_WATER = 293.0               # K
STRENGTH = 1.0e9              # Pa, the bonds' normal and shear cohesion
CENTRAL = 2e-3                # m: slabs and surface layers leave out this much at each free end


def _say(msg):
    sys.stderr.write(f"[thermal_shock] {msg}\n")
    sys.stderr.flush()


def alumina(strength):
    from yade.wrapper import CohFrictMat
    return CohFrictMat(young=BOND_YOUNG, poisson=POISSON, density=DENSITY, frictionAngle=float(np.arctan(0.5)),
                       isCohesive=True, normalCohesion=float(strength), shearCohesion=float(strength),
                       momentRotationLaw=True, fragile=True, label="alumina")


def build(n, seed, strength, temperature, cache_dir=None):
    """Reset YADE's scene and add the bonded strip, every element at ``temperature`` [K].
    Returns (ids, bodies, reference positions, radii, container)."""
    from yade import O
    from yade_electro.yade import ensure_thermal_state
    from yade_electro.yade import packing as P
    O.reset()
    box = P.Box((0, 0, 0), SIZE)
    pk = P.dense_packing(box, n=n, seed=seed, cache_dir=cache_dir)
    ids = np.asarray(P.add_bonded_packing(pk, material=alumina(strength), damping=0.5))
    bodies = [O.bodies[int(i)] for i in ids]
    ensure_thermal_state(bodies)
    for b in bodies:
        b.state.temp = float(temperature)
    return ids, bodies, pk.centers.copy(), pk.radii.copy(), box


def positions(bodies):
    return np.array([tuple(b.state.pos) for b in bodies])


def pull(n, seed, strength, cache_dir=None, strain=1e-3, steps=20000, every=250):
    """The strip pulled along x at T_w (module doc, item 2): E_x, the slope of the stress
    against the middle third's strain between 30 and 70 % of the peak (a least-squares line:
    the start of the pull, a wave front, is left out), and the strength (the peak force over
    the section)."""
    from yade import O
    ids, bodies, x0, radii, _ = build(n, seed, strength, T_WATER, cache_dir)
    r_mean = float(radii.mean())
    lo = x0[:, 0] < x0[:, 0].min() + 1.2 * r_mean
    hi = x0[:, 0] > x0[:, 0].max() - 1.2 * r_mean
    mid = np.abs(x0[:, 0] - 0.5 * SIZE[0]) < SIZE[0] / 6
    speed = strain * SIZE[0] / (steps * O.dt)
    for k in np.flatnonzero(lo):
        bodies[k].state.blockedDOFs = "x"
    for k in np.flatnonzero(hi):
        bodies[k].state.blockedDOFs = "x"
        bodies[k].state.vel = (speed, 0, 0)
    area = SIZE[1] * SIZE[2]
    records = []
    for _ in range(steps // every):
        O.run(every, True)
        stress = -float(sum(O.forces.f(int(i))[0] for i in ids[hi])) / area
        x = positions(bodies)
        eps = float(np.polyfit(x0[mid, 0], x[mid, 0] - x0[mid, 0], 1)[0])
        records.append((stress, eps))
        peak = max(s for s, _ in records)
        if peak > 0 and stress < 0.2 * peak:
            break
    s, e = np.array(records).T
    k = int(np.argmax(s))
    band = np.flatnonzero((s[:k + 1] >= 0.3 * s[k]) & (s[:k + 1] <= 0.7 * s[k]))
    if band.size < 3:
        raise RuntimeError(f"the pull reached its peak in {k + 1} records: too fast to fit E_x; give more steps")
    return {"strength_Pa": float(s[k]), "E_x_Pa": float(np.polyfit(e[band], s[band], 1)[0]), "strain_at_peak": float(e[k]),
            "pull_elements": int(ids.size)}


def cracks(pairs, broken, x0, face_y, r_mean, min_bonds=3, gap=1.5):
    """The cracks growing from the face at y = ``face_y``: broken bonds within half the width
    of it, grouped along x (a gap over ``gap`` diameters starts a new crack). Returns a list of
    (x centre [m], depth from the face [m], bonds)."""
    mid = 0.5 * (x0[pairs[:, 0]] + x0[pairs[:, 1]])
    near = broken & (np.abs(mid[:, 1] - face_y) < 0.5 * SIZE[1])
    if not near.any():
        return []
    m = mid[near]
    order = np.argsort(m[:, 0])
    m = m[order]
    cut = np.flatnonzero(np.diff(m[:, 0]) > gap * 2 * r_mean) + 1
    out = []
    for grp in np.split(np.arange(m.shape[0]), cut):
        if grp.size >= min_bonds:
            out.append((float(m[grp, 0].mean()), float(np.max(np.abs(m[grp, 1] - face_y))) + r_mean, int(grp.size)))
    return out


def crack_figures(found):
    """Number, spacing and length classes of the cracks of both faces (``found``: one list per
    face, from :func:`cracks`)."""
    spacings, depths = [], []
    for face in found:
        xs = sorted(x for x, _, _ in face)
        spacings += list(np.diff(xs))
        depths += [d for _, d, _ in face]
    depths = np.array(depths)
    return {"cracks_per_face": [len(f) for f in found],
            "mean_spacing_m": float(np.mean(spacings)) if spacings else None,
            "spacing_over_width": float(np.mean(spacings) / SIZE[1]) if spacings else None,
            "depth_m": sorted(depths.tolist(), reverse=True),
            "long_cracks": int(np.sum(depths > 0.5 * depths.max())) if depths.size else 0,
            "short_cracks": int(np.sum(depths <= 0.5 * depths.max())) if depths.size else 0}


def plot_cracks(pairs, broken, x0, r_mean, path, title):
    """The crack facets in the x-y plane: each broken bond as the trace of the face between its
    two elements (a segment of one diameter through the bond's midpoint, across the bond; red),
    over the strip's element centres (grey)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    a, b = x0[pairs[broken, 0], :2], x0[pairs[broken, 1], :2]
    mid, d = 0.5 * (a + b), b - a
    across = np.column_stack([-d[:, 1], d[:, 0]]) / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
    seg = np.stack([mid - r_mean * across, mid + r_mean * across], axis=1) * 1e3
    fig, ax = plt.subplots(figsize=(8, 2.6))
    ax.plot(x0[:, 0] * 1e3, x0[:, 1] * 1e3, ".", color="0.8", ms=1)
    ax.add_collection(LineCollection(seg, colors="r", linewidths=1.5))
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm] (quenched at 0 and 2)")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def quench(n, dT, E, strength_f, seed=1, strength=STRENGTH, t_end=0.03, dt=5e-4, dt0=1e-5, growth=1.25, steps=300,
           tol=0.01, max_extra=10, out_dir=None, cache_dir=None, nbins=10):
    """One quench by ``dT`` [K] (module doc); returns its figures. Thermal steps grow from
    ``dt0`` by ``growth`` per call up to ``dt`` [s]; after each call YADE relaxes ``steps``
    steps, and more (the engines idle) until the elements' mean |force| is below ``tol`` of the
    bonds' mean |normal force| (at most ``max_extra`` more chunks)."""
    from yade import O
    from yade_electro.yade import FixedTemperature, HeatEngine, Integrator, Material, Output, ThermalExpansion
    t_start = time.time()
    T_hot = T_WATER + dT
    ids, bodies, x0, radii, box = build(n, seed, strength, T_hot, cache_dir)
    r_mean = float(radii.mean())
    heat = HeatEngine(material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
                      boundaries=[FixedTemperature("water_lo", surface=box.face("y-"), temperature=T_WATER),
                                  FixedTemperature("water_hi", surface=box.face("y+"), temperature=T_WATER)],
                      temperature=T_hot, integrator=Integrator(theta="backward-euler", dt=dt0),
                      output=Output(write_back=None), iterPeriod=steps, label="shock_heat")
    expansion = ThermalExpansion(alpha=ALPHA, mode="bonds", reference_temperature=T_hot, iterPeriod=steps,
                                 label="shock_expansion")
    for r in (heat.runner, expansion.runner):
        r.initRun = True
    O.engines = O.engines + [heat.runner, expansion.runner]
    bonds = TC.InitialBonds(ids)
    pairs = bonds.pairs
    central = np.abs(x0[:, 0] - 0.5 * SIZE[0]) < 0.5 * SIZE[0] - CENTRAL
    edges = np.linspace(0.0, SIZE[1], nbins + 1)
    slab = np.clip(np.searchsorted(edges, x0[:, 1], side="right") - 1, 0, nbins - 1)
    surface = central & ((x0[:, 1] < 2 * r_mean) | (x0[:, 1] > SIZE[1] - 2 * r_mean))
    volume = expansion.element_volumes()
    order = np.searchsorted(heat.body_ids, ids)
    rows, before, k_before = [], None, -1

    def unbalanced(read):
        """The elements' mean |force| over the bonds' mean |normal force| (all are free here)."""
        fn, _ = expansion.bond_forces(read)
        f = np.mean([np.linalg.norm(O.forces.f(int(i))) for i in ids])
        return float(f / max(np.abs(fn).mean(), 1e-300))

    call, dt_k = 0, dt0
    while heat.coupled.time < t_end - 1e-12:
        heat.thermal_dt = min(dt_k, t_end - heat.coupled.time)
        O.run(steps, True)                   # the engines' call, then YADE relaxes
        read = expansion.read_interactions()
        extra, ub = 0, unbalanced(read)
        while ub > tol and extra < max_extra:   # until quasi-static: the engines wait meanwhile
            for r in (heat.runner, expansion.runner):
                r.dead = True
            O.run(steps, True)
            for r in (heat.runner, expansion.runner):
                r.dead = False
            read = expansion.read_interactions()
            extra, ub = extra + 1, unbalanced(read)
        call, dt_k = call + 1, dt_k * growth
        T = heat.temperature[order]
        s = expansion.element_stress(read)[:, 0, 0]      # the scene the last check read
        broken = bonds.broken()
        w = volume * central
        T_bin = np.bincount(slab, w * T, nbins) / np.bincount(slab, w, nbins)
        s_bin = np.bincount(slab, w * s, nbins) / np.bincount(slab, w, nbins)
        h = heat.history.rows[-1]
        row = {"time_s": float(h["time"]), "T_surface_K": float(np.mean(T[surface])), "T_core_K": float(T_bin[nbins // 2]),
               "surface_sxx_Pa": float(np.sum(volume[surface] * s[surface]) / volume[surface].sum()),
               "broken_bonds": int(broken.sum()), "heat_content_J": float(h["heat_content"]),
               "boundary_heat_J": float(h["boundary_heat"]), "T_bin": T_bin, "s_bin": s_bin}
        row.update(unbalanced=ub, relax_chunks=1 + extra)
        rows.append(row)
        if not broken.any():
            before, k_before = row, len(rows) - 1
        if len(rows) % 5 == 1 or (broken.any() and len(rows) > 1 and not rows[-2]["broken_bonds"]):
            _say(f"dT {dT:.0f} K, t {row['time_s'] * 1e3:.2f} ms: surface {row['T_surface_K']:.0f} K, core "
                 f"{row['T_core_K']:.0f} K, surface sigma_xx {row['surface_sxx_Pa'] / 1e6:.0f} MPa, broken {row['broken_bonds']}")
    # the closed form on the DEM's own profile, at the last call without a broken bond
    ref = before or rows[0]
    y = 0.5 * (edges[1:] + edges[:-1])
    T_avg = float(np.mean(ref["T_bin"]))
    bend = 12.0 * float(np.mean(ref["T_bin"] * (y - y.mean()))) / SIZE[1] ** 2
    closed = E * ALPHA * (T_avg + bend * (y - y.mean()) - ref["T_bin"])
    err = float(np.sqrt(np.mean((ref["s_bin"] - closed) ** 2)) / np.max(np.abs(closed)))
    found = [cracks(pairs, broken, x0, 0.0, r_mean), cracks(pairs, broken, x0, SIZE[1], r_mean)]
    last = rows[-1]
    ledger = last["heat_content_J"] - last["boundary_heat_J"]
    out = {"dT_K": dT, "dT_over_dT_c": dT * E * ALPHA / strength_f, "elements": int(ids.size), "r_mean_m": r_mean,
           "stress_check_time_s": ref["time_s"], "stress_error_pct": 100.0 * err,
           "stress_check_penetration_over_r_mean": float(np.sqrt(CONDUCTIVITY / (DENSITY * SPECIFIC_HEAT) * ref["time_s"])
                                                         / r_mean),
           "stress_profile_dem_Pa": ref["s_bin"].tolist(), "stress_profile_closed_form_Pa": closed.tolist(),
           "onset_time_s": rows[k_before + 1]["time_s"] if k_before + 1 < len(rows) and last["broken_bonds"] else None,
           "surface_stress_at_onset_over_strength": (before["surface_sxx_Pa"] / strength_f
                                                     if before is not None and last["broken_bonds"] else None),
           "broken_bonds": last["broken_bonds"], **crack_figures(found),
           "ledger_error": abs(ledger) / abs(last["boundary_heat_J"]) if last["boundary_heat_J"] else None,
           "t_end_s": last["time_s"], "calls": len(rows), "max_unbalanced": max(r["unbalanced"] for r in rows),
           "relax_chunks": int(sum(r["relax_chunks"] for r in rows)), "wall_s": round(time.time() - t_start, 1)}
    if out_dir:
        from yade_electro.post.vtk import write_bonds, write_elements
        d = os.path.join(out_dir, "vtk")
        os.makedirs(d, exist_ok=True)
        nb = np.zeros(ids.size)
        np.add.at(nb, pairs[broken].ravel(), 1.0)
        pos = positions(bodies)
        out["png"] = plot_cracks(pairs, broken, x0, r_mean, os.path.join(out_dir, f"shock_n{ids.size}_dT{dT:.0f}.png"),
                                 f"{ids.size} elements, dT = {dT:.0f} K = {out['dT_over_dT_c']:.1f} dT_c, "
                                 f"t = {last['time_s'] * 1e3:.0f} ms")
        out["vtk"] = {
            "elements": write_elements(os.path.join(d, f"shock_dT{dT:.0f}_elements.vtu"), pos, radii,
                                       {"temperature_K": T, "s_xx_Pa": s, "broken_bonds": nb}),
            "bonds": write_bonds(os.path.join(d, f"shock_dT{dT:.0f}_bonds.vtu"), pos, pairs,
                                 {"broken": broken.astype(float)})}
    heat.remove()
    expansion.remove()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=8000)
    ap.add_argument("--quick", action="store_true", help="2,500 elements, 200 steps per call")
    ap.add_argument("--sweep", action="store_true", help="dT = 2 and 4 dT_c")
    ap.add_argument("--factor", type=float, default=4.0, help="dT over Hasselman's dT_c (without --sweep)")
    ap.add_argument("--t-end", type=float, default=0.03, help="quench time [s]")
    ap.add_argument("--dt", type=float, default=5e-4, help="thermal step [s]")
    ap.add_argument("--steps", type=int, default=300, help="mechanical steps between two calls")
    ap.add_argument("--strength", type=float, default=STRENGTH, help="bond cohesion [Pa]")
    ap.add_argument("--out", default="out/thermal_shock")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    if args.quick:
        args.n, args.steps = 2500, 200
    _say(f"the strip pulled at {T_WATER:.0f} K: E_x and strength")
    p = pull(args.n, 1, args.strength, cache_dir=args.cache_dir)
    dT_c = p["strength_Pa"] / (p["E_x_Pa"] * ALPHA)
    _say(f"E_x {p['E_x_Pa'] / 1e9:.1f} GPa, strength {p['strength_Pa'] / 1e6:.1f} MPa: dT_c {dT_c:.1f} K")
    factors = (2.0, 4.0) if args.sweep else (args.factor,)
    quenches = [quench(args.n, f * dT_c, p["E_x_Pa"], p["strength_Pa"], strength=args.strength, t_end=args.t_end,
                       dt=args.dt, steps=args.steps, out_dir=args.out, cache_dir=args.cache_dir) for f in factors]
    out = {"case": "thermal_shock", **p, "dT_c_K": dT_c, "quenches": quenches}
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
