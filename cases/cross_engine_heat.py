"""The same heat-conduction problem in YADE (yade-electro's engine) and in LIGGGHTS 3.8.0
(``fix heat/gran/conduction``), compared particle by particle at every LIGGGHTS dump.

Two problems, both on particles that do not move (the contacts are fixed):

* ``two_spheres``: two copper spheres, r = 2 mm, centres 3.8 mm apart, 100 / 0 degC (the
  problem of cases/two_spheres.py), 0.2 s;
* ``floor``: the same packing, every particle at 0 degC, on an isothermal floor at 100 degC
  (LIGGGHTS' ``zplane`` wall with ``temperature``, YADE's ``Wall`` in ``walls=``), 1 s; the
  heat the particles stored is compared too;
* ``packing``: about 2,000 copper spheres (radii 0.9 and 1.1 mm, equal mass fractions) settled
  under gravity in a cylinder of radius 10 mm by LIGGGHTS (``settle`` template, soft
  Y = 5 MPa as LIGGGHTS users take it, so overlaps are about 1 % of r), then frozen; the
  lower half (z below the median) starts at 100 degC, the rest at 0 degC, 1 s.

LIGGGHTS integrates T with explicit Euler at its time step; the YADE side is
``HeatEngine(material=Material(), law='liggghts', reader=Reader(bonds='contacts'))`` on the same positions (atom id = body id +
1), Crank-Nicolson with ``thermal_dt`` = dump interval / ``calls_per_dump`` (100: 2e-4 s for
the two spheres, 5e-4 s for the packing, below 1/10 of the fastest particle time C / sum G).
(The explicit integrator sub-cycles for stability only: one step of 2e-3 s, 1/15 of the
decay time, decays 3.4 % too fast, as explicit Euler does.) The
figure: max |T_YADE - T_LIGGGHTS| over all particles at each dump, in per cent of the
temperature range (100 K); acceptance < 0.5 % at every dump.

The sqrt(pi) factor: LIGGGHTS' h_c = 4 k1 k2/(k1+k2) sqrt(pi a^2) = 2 sqrt(pi) k a, paper
002's ``contact`` law 2 k a. The two-sphere problem is also run with ``law='contact'``: its
decay time is sqrt(pi) = 1.7725 times LIGGGHTS' (fitted from the curves, side by side in
the JSON and the figure).

Run
---
    yade-electro -n -x cases/cross_engine_heat.py                     # both problems
    yade-electro -n -x cases/cross_engine_heat.py --problem two_spheres

Ends with one JSON line ``{"case": "cross_engine_heat", "problem": ..., "max_rel_diff_pct":
..., "problems": {...}}`` (``max_rel_diff_pct``: the worst over the problems run).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

_SCRIPT = __file__ if __file__.endswith("cross_engine_heat.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("cross_engine_heat.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

T_HOT, T_COLD = 373.15, 273.15      # K
COPPER = dict(conductivity=385.0, density=8900.0, specific_heat=172.0)   # paper 002 table III.1
PROBLEMS = ("two_spheres", "packing", "floor")


def copper(young=110e9):
    from yade_electro.liggghts import GranularMaterial
    return GranularMaterial(young=young, poisson=0.34, density=COPPER["density"], restitution=0.5, friction=0.5,
                            conductivity=COPPER["conductivity"], specific_heat=COPPER["specific_heat"])


def two_sphere_particles():
    from yade_electro.liggghts import particle_data
    return particle_data([[0.0, 0.0, 0.0], [3.8e-3, 0.0, 0.0]], 2e-3, COPPER["density"]), {1: T_HOT}, copper()


def settled_particles(n=2000, workdir="out/cross_engine_heat/settle", radius=0.010, seed=32452843):
    """About ``n`` copper spheres settled by LIGGGHTS in a cylinder of ``radius`` [m], with the
    lower half hot; returns (particle data, initial temperatures, material, settled packing)."""
    from yade_electro import liggghts as L
    mat = copper(young=5e6)
    r_classes = np.array([0.9e-3, 1.1e-3])
    bed_h = n * 4.0 / 3.0 * np.pi * np.mean(r_classes ** 3) / (0.58 * np.pi * radius ** 2)
    top = 2.6 * bed_h
    walls = [L.CylinderWall("z", radius), L.PlaneWall("z", 0.0)]
    region = L.CylinderRegion(radius - 1.2e-3, 1.2e-3, top)
    box = [[-radius - 2e-3, radius + 2e-3]] * 2 + [[-2e-3, top + 5e-3]]
    p = L.settle_packing(walls, region, n, r_classes, [0.5, 0.5], mat, box, timestep=2e-5, workdir=workdir,
                         settle_time=1.5, ke_threshold=1e-11, seed=seed)
    data = L.particle_data(p.centers, p.radii, COPPER["density"], ids=p.ids, box=box)
    zc = p.centers[:, 2]
    hot = p.ids[zc < np.median(zc)]
    return data, {int(i): T_HOT for i in hot}, mat, p


def liggghts_run(data, init, mat, timestep, steps, dump_every, workdir, floor=False, ranks=1):
    from yade_electro.liggghts import PlaneWall, heat_conduction_deck, run_heat_conduction
    walls = [PlaneWall("z", 0.0, temperature=T_HOT)] if floor else []
    deck = heat_conduction_deck(data, [mat], T_COLD, timestep, steps, dump_every, initial_temperature=init, walls=walls)
    return run_heat_conduction(deck, workdir, ranks=ranks)


def yade_run(data, init, mat, times, law, calls_per_dump=100, floor=False):
    """Temperatures [K] (len(times), n) of the particles (data order) in YADE with the heat
    engine at the sample ``times`` [s] (equally spaced from 0), and the engine's contacts at
    the end: {(atom id 1, atom id 2): G [W/K]}, and the heat the isothermal ``floor`` (a
    YADE ``Wall`` at z = 0, T_HOT) gave [J] (None without it)."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import wrapper as W
    from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Material, Reader, Wall
    from yade_electro.yade.spheres import add_spheres
    O = yade.Omega()
    O.reset()
    ymat = W.FrictMat(young=mat.young, poisson=mat.poisson, density=mat.density, frictionAngle=math.atan(mat.friction))
    ids = add_spheres(data.positions, data.radius, ymat, fixed=True, O=O)
    body_of_atom = dict(zip(data.ids.tolist(), ids))
    walls = []
    if floor:
        from yade import utils
        wall = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=ymat))
        walls = [Wall("floor", bodies=wall, temperature=T_HOT)]
    O.dt = 1e-6                        # nothing moves: the engine alone runs
    interval = float(times[1] - times[0])
    engine = HeatEngine(
        material=Material(density=mat.density, specific_heat=mat.specific_heat, conductivity=mat.conductivity),
        boundaries=walls,
        temperature=InitialTemperature(T_COLD, by_id={body_of_atom[a]: T for a, T in init.items()}),
        law=law,
        integrator=Integrator(theta="crank-nicolson", dt=interval / calls_per_dump),
        reader=Reader(bonds="contacts"),
        label=f"cross_{law}")
    O.engines = [engine.runner]
    out = []
    order = np.array(ids)
    for target in times:
        while engine.coupled.time < target - 1e-9 * interval:    # one call: one thermal_dt
            O.step()
        T = engine.temperature_by_id
        out.append([T[int(i)] for i in order])
    t_engine = engine.coupled.time
    pairs, G, _ = engine.contact_heat_flow()
    wall_heat = engine.wall_heat()["floor"] if floor else None
    atom_of_body = {b: a for a, b in body_of_atom.items()}
    contacts = {tuple(sorted((atom_of_body[int(i)], atom_of_body[int(j)]))): float(g)
                for (i, j), g in zip(pairs.tolist(), G.tolist())}
    engine.remove()
    if not math.isclose(t_engine, times[-1], rel_tol=1e-9):
        raise RuntimeError(f"the engine's clock reached {t_engine} s, not {times[-1]} s")
    return np.asarray(out), contacts, wall_heat


def contact_agreement(lig_contacts, yade_contacts, conductivity):
    """Contacts found by one engine only, and the largest relative difference of the
    conductances of the common ones (LIGGGHTS' h_c = 2 k sqrt(A), its dumped area A)."""
    h = {tuple(sorted((int(a), int(b)))): 2.0 * conductivity * math.sqrt(area)
         for a, b, area in zip(lig_contacts["id1"], lig_contacts["id2"], lig_contacts["contact_area"])}
    common = sorted(set(h) & set(yade_contacts))
    rel = [abs(yade_contacts[k] / h[k] - 1.0) for k in common]
    return {"contacts_liggghts_only": len(set(h) - set(yade_contacts)),
            "contacts_yade_only": len(set(yade_contacts) - set(h)), "contacts_common": len(common),
            "conductance_max_rel_diff": float(max(rel)) if rel else None}


def decay_time(t, T1, T2):
    """tau [s] of the difference T1 - T2 = D0 exp(-t / tau), least squares on log."""
    d = np.asarray(T1) - np.asarray(T2)
    ok = d > 1e-6 * d[0]
    return float(-1.0 / np.polyfit(np.asarray(t)[ok], np.log(d[ok]), 1)[0])


def compare(problem, out_dir, n=2000, calls_per_dump=100, settled_bed=None, liggghts_ranks=1):
    """Run ``problem`` in both engines; returns its figures and curves. ``settled_bed``: the
    result of :func:`settled_particles` for the packing problems (made here when None)."""
    work = os.path.join(out_dir, problem)
    floor = problem == "floor"
    if problem == "two_spheres":
        data, init, mat = two_sphere_particles()
        timestep, steps, dump_every, extra = 1e-5, 20000, 2000, {}
    else:
        if settled_bed is None:
            settled_bed = settled_particles(n, os.path.join(out_dir, "settle"))
        data, init, mat, settled = settled_bed
        if floor:
            init = {}                       # every particle cold, the floor hot
        timestep, steps, dump_every = 1e-4, 10000, 500
        extra = {"n": data.n, "settled": bool(settled.settled), "settle_time_s": settled.time,
                 "settle_ke_per_particle_J": settled.ke_per_particle, "settle_wall_s": settled.run.elapsed_s}
    lig = liggghts_run(data, init, mat, timestep, steps, dump_every, work, floor, ranks=liggghts_ranks)
    table = lig.temperature_table()
    times = table.index.to_numpy()
    T_lig = table[data.ids.tolist()].to_numpy()
    T_yade, yade_contacts, wall_heat = yade_run(data, init, mat, times, "liggghts", calls_per_dump, floor)
    diff = 100.0 * np.max(np.abs(T_yade - T_lig), axis=1) / (T_HOT - T_COLD)
    contacts0 = lig.contacts[min(lig.contacts)]
    row = {"problem": problem, "n": data.n, "max_rel_diff_pct": float(diff.max()),
           "rel_diff_pct_per_dump": diff.tolist(), "dumps": len(times), "t_end_s": float(times[-1]),
           "liggghts_timestep_s": timestep, "yade_thermal_dt_s": float(times[1] - times[0]) / calls_per_dump,
           "liggghts_contacts": int(len(contacts0)), "liggghts_wall_s": lig.run.elapsed_s,
           **contact_agreement(lig.contacts[max(lig.contacts)], yade_contacts, mat.conductivity), **extra}
    curves = {"t": times, "diff": diff}
    if problem == "two_spheres":
        T_contact, _, _ = yade_run(data, init, mat, times, "contact", calls_per_dump)
        tau = {"liggghts_engine": decay_time(times, T_lig[:, 0], T_lig[:, 1]),
               "yade_liggghts_law": decay_time(times, T_yade[:, 0], T_yade[:, 1]),
               "yade_contact_law": decay_time(times, T_contact[:, 0], T_contact[:, 1])}
        if liggghts_ranks == 1:
            h_lig = -float(contacts0["heat_flux"].iloc[0]) / (T_HOT - T_COLD)
        else:
            # decomposed, the step-0 pair dump sees the other rank's sphere as a ghost whose
            # temperature is not forwarded yet (0 K): take the flux of the next dump, over the
            # temperature difference of that time (the contact does not move)
            step = sorted(lig.contacts)[1]
            c1 = lig.contacts[step]
            T1 = lig.temperatures[step].set_index("id")["Temp"]
            i, j = int(c1["id1"].iloc[0]), int(c1["id2"].iloc[0])
            h_lig = -float(c1["heat_flux"].iloc[0]) / (T1[i] - T1[j])
        row.update({"tau_s": tau, "tau_ratio_contact_over_liggghts": tau["yade_contact_law"] / tau["liggghts_engine"],
                    "sqrt_pi": math.sqrt(math.pi), "h_c_liggghts_W_per_K": h_lig,
                    "h_c_2ka_W_per_K": 2.0 * COPPER["conductivity"] * math.sqrt(float(contacts0["contact_area"].iloc[0])
                                                                               / math.pi),
                    "T_final_liggghts": T_lig[-1].tolist(), "T_final_yade": T_yade[-1].tolist()})
        row["h_c_ratio"] = row["h_c_liggghts_W_per_K"] / row["h_c_2ka_W_per_K"]
        curves.update(T_lig=T_lig, T_yade=T_yade, T_contact=T_contact)
    elif floor:
        C = data.mass * mat.specific_heat
        stored_lig = float(np.sum(C * (T_lig[-1] - T_COLD)))
        stored_yade = float(np.sum(C * (T_yade[-1] - T_COLD)))
        floor_contacts = int(np.sum(data.positions[:, 2] < data.radius))
        row.update({"floor_contacts": floor_contacts, "heat_stored_liggghts_J": stored_lig,
                    "heat_stored_yade_J": stored_yade, "wall_heat_yade_J": wall_heat,
                    "heat_rel_diff": stored_yade / stored_lig - 1.0})
        low = data.positions[:, 2] < 3 * data.radius.max()
        curves.update(mean_low_lig=T_lig[:, low].mean(axis=1), mean_low_yade=T_yade[:, low].mean(axis=1),
                      mean_lig=T_lig.mean(axis=1), mean_yade=T_yade.mean(axis=1))
    else:
        hot = np.isin(data.ids, list(init))
        curves.update(mean_hot_lig=T_lig[:, hot].mean(axis=1), mean_hot_yade=T_yade[:, hot].mean(axis=1),
                      mean_cold_lig=T_lig[:, ~hot].mean(axis=1), mean_cold_yade=T_yade[:, ~hot].mean(axis=1))
    return row, curves


def plot(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 1 + len(curves), figsize=(4.6 * (1 + len(curves)), 3.8))
    ax = axes[0]
    for name, c in curves.items():
        on = c["diff"] > 0                   # t = 0: both start from the same temperatures
        ax.semilogy(c["t"][on], c["diff"][on], "o-", ms=3, label=name)
    ax.axhline(0.5, color="r", lw=0.8, ls="--", label="target 0.5 %")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("max |T_YADE - T_LIGGGHTS| [% of 100 K]")
    ax.legend(fontsize=8)
    for ax, (name, c) in zip(axes[1:], curves.items()):
        t = c["t"]
        if name == "two_spheres":
            for j, lab in ((0, "hot"), (1, "cold")):
                ax.plot(t, c["T_lig"][:, j] - 273.15, "ks", ms=4, mfc="none", label=f"LIGGGHTS {lab}" if j == 0 else None)
                ax.plot(t, c["T_yade"][:, j] - 273.15, "b.-", label="YADE, liggghts law" if j == 0 else None)
                ax.plot(t, c["T_contact"][:, j] - 273.15, "g--", label="YADE, contact law (2ka)" if j == 0 else None)
            ax.set_title("two copper spheres: h_c ratio sqrt(pi)")
        elif name == "floor":
            ax.plot(t, c["mean_low_lig"] - 273.15, "ks", ms=4, mfc="none", label="LIGGGHTS")
            ax.plot(t, c["mean_low_yade"] - 273.15, "b.-", label="YADE: spheres within 3 r of the floor")
            ax.plot(t, c["mean_lig"] - 273.15, "ks", ms=4, mfc="none")
            ax.plot(t, c["mean_yade"] - 273.15, "g.-", label="YADE: all")
            ax.set_title("packing on a floor at 100 degC")
        else:
            ax.plot(t, c["mean_hot_lig"] - 273.15, "ks", ms=4, mfc="none", label="LIGGGHTS")
            ax.plot(t, c["mean_hot_yade"] - 273.15, "b.-", label="YADE")
            ax.plot(t, c["mean_cold_lig"] - 273.15, "ks", ms=4, mfc="none")
            ax.plot(t, c["mean_cold_yade"] - 273.15, "b.-")
            ax.set_title("packing: mean T of the hot and cold halves")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("T [degC]")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--problem", default="all", choices=("all",) + PROBLEMS)
    ap.add_argument("--n", type=int, default=2000, help="particles of the packing problem")
    ap.add_argument("--calls-per-dump", type=int, default=100)
    ap.add_argument("--out", default="out/cross_engine_heat")
    ap.add_argument("--liggghts-ranks", type=int, default=1,
                    help="MPI processes of each LIGGGHTS run (mpiexec -n; the same heat results as 1)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    problems = PROBLEMS if args.problem == "all" else (args.problem,)
    os.makedirs(args.out, exist_ok=True)
    rows, curves = {}, {}
    # the packing and floor problems share one settled packing
    bed = settled_particles(args.n, os.path.join(args.out, "settle")) if set(problems) - {"two_spheres"} else None
    for problem in problems:
        rows[problem], curves[problem] = compare(problem, args.out, args.n, args.calls_per_dump, bed,
                                                 liggghts_ranks=args.liggghts_ranks)
        r = rows[problem]
        print(f"cross-engine heat, {problem} ({r['n']} particles, {r['liggghts_contacts']} contacts): max |dT| "
              f"{r['max_rel_diff_pct']:.2e} % of the range over {r['dumps']} dumps; contacts in one engine only: "
              f"{r['contacts_liggghts_only']} / {r['contacts_yade_only']}, conductances differ by at most "
              f"{r['conductance_max_rel_diff']:.1e}", flush=True)
        if problem == "floor":
            print(f"  {r['floor_contacts']} floor contacts; heat stored {r['heat_stored_liggghts_J']:.4f} J (LIGGGHTS), "
                  f"{r['heat_stored_yade_J']:.4f} J (YADE; its floor gave {r['wall_heat_yade_J']:.4f} J)", flush=True)
        if problem == "two_spheres":
            print(f"  h_c LIGGGHTS / 2ka = {r['h_c_ratio']:.5f}, tau(contact law) / tau(LIGGGHTS) = "
                  f"{r['tau_ratio_contact_over_liggghts']:.5f}; sqrt(pi) = {math.sqrt(math.pi):.5f}", flush=True)
    png = plot(curves, os.path.join(args.out, f"cross_engine_heat_{args.problem}.png"))
    out = {"case": "cross_engine_heat", "problem": ",".join(problems), "liggghts_ranks": args.liggghts_ranks,
           "max_rel_diff_pct": max(r["max_rel_diff_pct"] for r in rows.values()), "problems": rows, "png": png}
    with open(os.path.join(args.out, f"cross_engine_heat_{args.problem}.json"), "w") as fh:
        json.dump(out, fh)
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
