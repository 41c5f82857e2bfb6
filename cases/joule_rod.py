"""Adiabatic Joule heating of the rod (paper 000, section 3.3, figure 11).

The bonded 5,000-element rod of the rod case (R = 1 mm, L = 5 mm, steel 304L: rho_e =
0.73e-6 ohm m, rho = 7900 kg/m^3, c = 500 J/(kg K), lambda = 15 W/(m K)) is built in YADE
exactly as in ``cases/rod_resistance.py`` (same packing, bonds and electrode layers); an
``ElectroThermalEngine`` holds 1 V between the end electrodes, eta = 1, no thermal boundary
condition (adiabatic), T0 = 293.15 K, and advances the temperatures by ``thermal_dt`` =
1 ms per call for 10 calls (0.01 s). The temperatures are written to the YADE bodies
(``b.state.temp``); the script checks them.

Theory (uniform field between the electrode planes, which sit on the element centres at
z = r_mean and z = L - r_mean, as for R_th):

    T(t) = T0 + (V / L_eff)^2 / rho_e * t / (rho c),   L_eff = L - 2 r_mean

Two DEM models
--------------
* ``continuum`` (paper 000): bond conductances from the transmission surfaces, heat
  capacities ``C_i = rho c V_i / fv_i`` (paper eq. 13);
* ``voronoi``: conductances from the bounded Voronoi faces, capacities ``C_i = rho c
  V_cell_i`` from the bounded Voronoi cell volumes
  (:func:`yade_electro.geometry.voronoi.voronoi_cell_volumes`; they fill the rod: their sum is
  pi R^2 L to 3e-5).

What is compared, and the error sources
---------------------------------------
The heat balance is exact in the DEM for every integrator (adiabatic, sources constant),
so the capacity-weighted mean rise is ``dT_mean = P_dem t / sum C``, with P_dem = V^2 /
R_dem. Against the theory (power P_th = V^2 / R_th released in the volume pi R^2 L_eff):

    dT_mean / dT_th = (R_th / R_dem) * (rho c pi R^2 L / sum C) * (L_eff / L)
                    =  power factor  *  capacity factor         *  electrode-layer factor

* power factor: the resistance error of the model (continuum +13 %, i.e. 0.884; voronoi
  +0.13 %, i.e. 0.999);
* capacity factor: the solid's heat capacity over the model's (continuum 1.114: sum V_i /
  fv_i is 10 % below the rod volume, the model's fv(n) = 0.57 against the packing's 0.60
  and the eccentric elements' fv doubled; voronoi 1.0000, the cells fill the rod);
* electrode-layer factor L_eff / L = 0.970 at 5,000 elements: the theory heats the volume
  between the electrode planes only, while the DEM's adiabatic rod spreads the same heat
  over the whole rod, electrode layers included (they receive half of the power of their
  bonds and heat by conduction). This is the set-up, not a model error, so the comparisons
  that measure the model are:

  1. **core temperature** (the headline): the capacity-weighted mean of the elements in
     the middle half of the rod (L/4 < z < 3L/4, more than 6 thermal diffusion lengths
     sqrt(alpha t) = 0.2 mm from the electrode layers) against T(t) above; it sees the
     local power and capacity densities of the model;
  2. **rod mean temperature** against the energy balance of the whole rod, T0 + V^2 / R_th
     t / (rho c pi R^2 L) (= power factor x capacity factor);
  3. and, for the record, the rod mean against T(t) above (all three factors).

  Measured at 5,000 elements, seed 1 (seeds 2, 3 in docs/results/joule_rod_seeds.csv): voronoi
  core -0.17 %, rod mean vs energy balance -0.09 %; continuum -2.7 % and -1.6 %. The core's own
  figures are printed too: the potential gradient in the core is 0.9989 (voronoi) and 0.998
  (continuum) of V / L_eff (the equipotential of a rough layer of electrode elements is not
  exactly at their mean centre plane z = r_mean), so the core heats 0.2-0.4 % slower from the
  field alone; the core's heating rate P / C is 0.998 (voronoi) and 0.971 (continuum: core
  under-conduction 0.944 against the capacity deficit) of the theory. Under voronoi the Joule
  heat is given by the cells (``Integrator(joule_sharing='auto')``, the default): each slab of
  the rod between the end slabs gets 0.9982-0.9983 of the theory's power density (0.995-1.000
  with the links' half-and-half sharing, core -0.20 %). The integrator makes no difference (the
  heat balance is exact; the core temperatures agree to 1e-5).

Run
---
    yade-electro -n -x cases/joule_rod.py                      # 5,000 elements, both models, 3 integrators
    yade-electro -n -x cases/joule_rod.py --n 1000 --laws voronoi --thetas backward-euler

Writes ``out/joule_rod/joule_rod.csv`` (one row per model x integrator), the history CSV of
every run, ``joule_rod.png`` (T(t) against theory) and ends with one JSON line. Importable
(``run_joule``) by the tests.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("joule_rod.py") else (sys.argv[0] if sys.argv and sys.argv[0].endswith("joule_rod.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import rod_resistance as rod  # noqa: E402
from caselib import apply_batch_table  # noqa: E402
from yade_electro.yade.runtime import import_yade  # noqa: E402

DENSITY = 7900.0        # kg/m^3 (304L, paper 000 Table II)
SPECIFIC_HEAT = 500.0   # J/(kg K)
CONDUCTIVITY = 15.0     # W/(m K)
T0 = 293.15             # K
VOLTAGE = 1.0           # V
DURATION = 0.01         # s
THETAS = ("explicit", "crank-nicolson", "backward-euler")
LAWS = ("continuum", "voronoi")
PAPER_ERROR_PCT = 1.4


def theoretical_temperature(t, r_mean, voltage=VOLTAGE, rho=rod.RHO_304L, length=rod.LENGTH,
                            density=DENSITY, specific_heat=SPECIFIC_HEAT, T0=T0):
    """T(t) = T0 + (V / L_eff)^2 / rho_e t / (rho c), L_eff = L - 2 r_mean [K]."""
    l_eff = length - 2.0 * r_mean
    return T0 + (voltage / l_eff) ** 2 / rho * np.asarray(t, dtype=float) / (density * specific_heat)


def run_joule(n=5000, seed=1, law="voronoi", theta="backward-euler", thermal_dt=1e-3, n_calls=10,
              voltage=VOLTAGE, gap=0.1, core=(0.25, 0.75), cache_dir=None, history=None):
    """Build the bonded rod in YADE, heat it with the ElectroThermalEngine for ``n_calls``
    calls of ``thermal_dt`` [s] and return a dict of figures (see the module doc); the
    time series is under ``'series'`` (time [s], T_mean, T_core, T_theory [K]). Resets YADE."""
    yade = import_yade()
    from yade import pack
    from yade_electro.yade import ElectroThermalEngine, Electrode, Integrator, Law, Material, Output
    from yade_electro.yade import packing as P

    O = yade.Omega()
    O.reset()
    container = pack.inCylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS)
    packing = P.dense_packing(container, n=n, seed=seed, cache_dir=cache_dir)
    shape = P.as_shape(container)
    ids = np.asarray(P.add_bonded_packing(packing))
    r_mean = float(np.mean(packing.radii))
    z = packing.centers[:, 2]
    bottom, top = rod.end_layers(z, packing.radii, r_mean, gap)
    # with the voronoi law the capacities are its bounded cell volumes (the default)
    law_params = {"container": shape} if law == "voronoi" else None
    t0 = time.perf_counter()
    engine = ElectroThermalEngine(
        material=Material(resistivity=rod.RHO_304L, density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=[
            Electrode("top", select=ids[top], potential=voltage),
            Electrode("bottom", select=ids[bottom], potential=0.0)],
        temperature=T0,
        law=Law(law, **(law_params or {})),
        integrator=Integrator(theta=theta, dt=thermal_dt, eta=1.0),
        output=Output(history=history),
        iterPeriod=1,
        label="joule_rod")
    O.engines = O.engines + [engine.runner]
    O.run(int(n_calls), True)
    t_run = time.perf_counter() - t0

    coupled = engine.coupled
    g = coupled.graph
    C = np.asarray(coupled.capacity)
    rows = engine.history.rows
    series_t = np.array([0.0] + [r["time"] for r in rows])
    series_mean = np.array([T0] + [r["T_mean"] for r in rows])
    # core temperature: recorded only at the end (the engine keeps no per-element history),
    # plus the mean-based series for the plot
    in_core = (g.pos[:, 2] > core[0] * rod.LENGTH) & (g.pos[:, 2] < core[1] * rod.LENGTH)
    T = np.asarray(engine.temperature)
    T_core = float(np.sum(C[in_core] * T[in_core]) / np.sum(C[in_core]))
    # diagnostics of the core: field (slope of the potential along z) and heating rate
    # (Joule power over heat capacity of the core elements), both over their theory
    u = np.asarray(coupled.solution.potential)
    field = float(np.polyfit(g.pos[in_core, 2], u[in_core], 1)[0])
    src = np.asarray(coupled.sources)
    rate_th = (voltage / (rod.LENGTH - 2.0 * r_mean)) ** 2 / rod.RHO_304L / (DENSITY * SPECIFIC_HEAT)
    core_rate_ratio = float(np.sum(src[in_core]) / np.sum(C[in_core]) / rate_th)
    # the temperatures on the YADE bodies
    body_T = np.array([O.bodies[int(i)].state.temp for i in engine.body_ids])
    is_thermal = all(isinstance(O.bodies[int(i)].state, yade.ThermalState) for i in engine.body_ids)

    t_end = float(series_t[-1])
    R_dem = float(rows[-1]["R_eq"])
    R_th = rod.theoretical_resistance(r_mean)
    l_eff = rod.LENGTH - 2.0 * r_mean
    v_rod = math.pi * rod.RADIUS ** 2 * rod.LENGTH
    rc = DENSITY * SPECIFIC_HEAT
    dT_th = float(theoretical_temperature(t_end, r_mean, voltage) - T0)
    dT_mean = float(series_mean[-1] - T0)
    dT_rod_th = voltage ** 2 / R_th * t_end / (rc * v_rod)        # energy balance of the whole rod
    power_factor = R_th / R_dem
    capacity_factor = rc * v_rod / float(C.sum())
    layer_factor = l_eff / rod.LENGTH
    engine.remove()
    return {
        "case": "joule_rod", "n": int(g.n_nodes), "n_target": int(n), "seed": int(seed), "law": law,
        "theta": theta, "thermal_dt": float(thermal_dt), "t_end": t_end, "r_mean": r_mean, "L_eff": l_eff,
        "T_theory": T0 + dT_th, "T_mean": T0 + dT_mean, "T_core": T_core,
        "dT_theory": dT_th, "dT_mean": dT_mean, "dT_core": T_core - T0, "dT_rod_energy_balance": dT_rod_th,
        "error_core_pct": 100.0 * ((T_core - T0) / dT_th - 1.0),
        "error_mean_vs_energy_balance_pct": 100.0 * (dT_mean / dT_rod_th - 1.0),
        "error_mean_vs_theory_pct": 100.0 * (dT_mean / dT_th - 1.0),
        "power_factor": power_factor, "capacity_factor": capacity_factor, "layer_factor": layer_factor,
        "core_field_ratio": field / (voltage / l_eff), "core_rate_ratio": core_rate_ratio,
        "R_dem": R_dem, "R_th": R_th, "joule_power": float(rows[-1]["joule_power"]),
        "sum_capacity": float(C.sum()), "rod_capacity": rc * v_rod,
        "energy_balance_error": abs(float(rows[-1]["heat_content"]) - float(rows[-1]["joule_energy"]))
        / float(rows[-1]["joule_energy"]),
        "body_temp_max_diff": float(np.max(np.abs(body_T - T))), "bodies_have_thermal_state": bool(is_thermal),
        "n_core": int(in_core.sum()), "n_substeps_per_call": int(rows[-1]["n_substeps"]),
        "n_potential_solves": int(rows[-1]["n_potential_solves"]),
        "dt_critical": float(coupled.time_steps()["critical"]), "dt_paper": float(coupled.time_steps()["paper"]),
        "t_run_s": t_run,
        "series": {"time": series_t.tolist(), "T_mean": series_mean.tolist(),
                   "T_theory": theoretical_temperature(series_t, r_mean, voltage).tolist()},
    }


SUMMARY_KEYS = ("n", "seed", "law", "theta", "t_end", "r_mean", "T_theory", "T_core", "T_mean",
                "error_core_pct", "error_mean_vs_energy_balance_pct", "error_mean_vs_theory_pct",
                "power_factor", "capacity_factor", "layer_factor", "core_field_ratio", "core_rate_ratio", "R_dem", "R_th", "sum_capacity",
                "rod_capacity", "energy_balance_error", "body_temp_max_diff", "n_substeps_per_call",
                "dt_critical", "dt_paper", "t_run_s")


def plot(rows, path):
    """T(t) of every run against the theory (figure 11 of the paper)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    ref = rows[0]
    t = np.array(ref["series"]["time"])
    tt = np.linspace(0, t[-1], 50)
    ax.plot(tt * 1e3, theoretical_temperature(tt, ref["r_mean"]), "k-", lw=1.5,
            label="theory (V/L_eff)^2/rho_e t/(rho c)")
    marks = {"explicit": "o", "crank-nicolson": "s", "backward-euler": "^"}
    colours = {"continuum": "C3", "voronoi": "C0"}
    for r in rows:
        s = r["series"]
        ax.plot(np.array(s["time"]) * 1e3, s["T_mean"], marks.get(r["theta"], "x"), mfc="none",
                color=colours.get(r["law"], "C2"), label=f"{r['law']}, {r['theta']}: rod mean")
        ax.plot([r["t_end"] * 1e3], [r["T_core"]], marks.get(r["theta"], "x"), ms=9,
                color=colours.get(r["law"], "C2"))
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("temperature [K]")
    ax.set_title(f"rod, {ref['n']} elements, 1 V, adiabatic (filled: core mean at t_end)")
    ax.legend(fontsize=7)
    labels = [f"{r['law']}\n{r['theta']}" for r in rows]
    x = np.arange(len(rows))
    w = 0.27
    ax2.bar(x - w, [r["error_core_pct"] for r in rows], w, label="core vs T(t)")
    ax2.bar(x, [r["error_mean_vs_energy_balance_pct"] for r in rows], w, label="rod mean vs energy balance")
    ax2.bar(x + w, [r["error_mean_vs_theory_pct"] for r in rows], w, label="rod mean vs T(t)")
    ax2.axhline(PAPER_ERROR_PCT, color="k", ls="--", lw=0.8)
    ax2.axhline(-PAPER_ERROR_PCT, color="k", ls="--", lw=0.8, label="paper's |error| 1.4 %")
    ax2.axhline(0, color="k", lw=0.5)
    ax2.set_xticks(x)
    ax2.set_xticklabels(labels, fontsize=7)
    ax2.set_ylabel("error of the temperature rise at t_end [%]")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _params(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--laws", default=",".join(LAWS))
    ap.add_argument("--thetas", default=",".join(THETAS))
    ap.add_argument("--dt", type=float, default=1e-3, help="thermal step per engine call [s]")
    ap.add_argument("--calls", type=int, default=10, help="engine calls (t_end = calls x dt)")
    ap.add_argument("--voltage", type=float, default=VOLTAGE)
    ap.add_argument("--out", default="out/joule_rod")
    args = ap.parse_args(argv)
    return apply_batch_table(args, attrs={"law": "laws"})   # under yade-batch: n, seed, law


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for law in args.laws.split(","):
        for theta in args.thetas.split(","):
            hist = os.path.join(args.out, f"joule_rod_n{args.n}_s{args.seed}_{law}_{theta}_history.csv")
            r = run_joule(args.n, args.seed, law=law, theta=theta, thermal_dt=args.dt, n_calls=args.calls,
                          voltage=args.voltage, history=hist)
            rows.append(r)
            print(f"{law:9s} {theta:14s} n={r['n']} T_theory={r['T_theory']:.3f} K  core {r['T_core']:.3f} K "
                  f"({r['error_core_pct']:+.2f} %)  rod mean {r['T_mean']:.3f} K (vs energy balance "
                  f"{r['error_mean_vs_energy_balance_pct']:+.2f} %, vs T(t) {r['error_mean_vs_theory_pct']:+.2f} %)"
                  f"  factors: power {r['power_factor']:.4f} capacity {r['capacity_factor']:.4f} layers "
                  f"{r['layer_factor']:.4f}  [{r['t_run_s']:.1f} s]", flush=True)
    import csv
    stem = os.path.join(args.out, "joule_rod" if args.n == 5000 else f"joule_rod_n{args.n}")
    with open(stem + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(SUMMARY_KEYS))
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in SUMMARY_KEYS})
    with open(stem + "_series.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["law", "theta", "time", "T_mean", "T_theory"])
        for r in rows:
            s = r["series"]
            for k in range(len(s["time"])):
                w.writerow([r["law"], r["theta"], f"{s['time'][k]:.6g}", f"{s['T_mean'][k]:.9g}",
                            f"{s['T_theory'][k]:.9g}"])
    plot(rows, stem + ".png")
    print("error sources: rod mean / T(t) = power factor (R_th/R_dem) x capacity factor "
          "(rho c V_rod / sum C) x electrode-layer factor (L_eff/L); the core temperature sees the first two "
          "only locally (module doc)")
    print(f"wrote {stem}.csv, {stem}_series.csv, {stem}.png and the run histories in {args.out}")
    summary = {"case": "joule_rod", "n": rows[0]["n"], "seed": args.seed, "paper_error_pct": PAPER_ERROR_PCT,
               "runs": [{k: r[k] for k in SUMMARY_KEYS} for r in rows]}
    for law in {r["law"] for r in rows}:
        sel = [r for r in rows if r["law"] == law]
        summary[f"error_core_pct_{law}"] = max((r["error_core_pct"] for r in sel), key=abs)
        summary[f"error_mean_vs_energy_balance_pct_{law}"] = max((r["error_mean_vs_energy_balance_pct"] for r in sel),
                                                                 key=abs)
        summary[f"error_mean_vs_theory_pct_{law}"] = max((r["error_mean_vs_theory_pct"] for r in sel), key=abs)
    print(json.dumps(summary))
    return summary


if __name__ == "__main__":
    main()
