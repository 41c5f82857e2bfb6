"""Two spheres in contact exchanging heat (paper 002, case 4): the granular heat engine against
the closed form.

Two copper spheres, r = 2 mm, centres 3.8 mm apart (0.2 mm overlap), at rest in YADE
(frictional contact, both held), start at 100 and 0 degC. The only heat path is their contact,
of conductance H = k g, g the law's geometric factor of the contact circle of radius
a = sqrt(r^2 - (d/2)^2) = 0.6245 mm:

* ``contact`` (paper 002): H = 2 k a;
* ``liggghts`` (LIGGGHTS ``heat/gran/conduction``): H = (4 k1 k2 / (k1 + k2)) sqrt(pi a^2) = 2 sqrt(pi) k a.

Each sphere carries C = rho c (4/3) pi r^3 (``volume_fraction = 1``: a particle is its own
volume). Closed form: T_mean stays 50 degC and T_1 - T_2 = 100 K exp(-H (1/C_1 + 1/C_2) t).

Material (paper 002 table III.1): k = 385 W/(m K), rho = 8900 kg/m^3, c = 172 J/(kg K). The
table's diffusivity 2.5e-7 m^2/s does not follow from them (k / (rho c) = 2.5e-4 m^2/s); the
three values are used as given, the diffusivity is not used.

The engine (``HeatEngine``, ``bonds='contacts'``: every sphere-sphere contact conducts) runs
every step with a fixed thermal step dt = tau / 200 (tau = C / (2 H), the decay time of the
difference), Crank-Nicolson, for 5 tau. The error is max |T - T_exact| over both spheres and
all steps, in per cent of the initial difference (100 K).

Run
---
    yade-electro -n -x cases/two_spheres.py                 # both laws
    yade-electro -n -x cases/two_spheres.py --law contact
    yade-electro batch cases/two_spheres.table cases/two_spheres.py

Ends with one JSON line: ``{"case": "two_spheres", "law": ..., "max_error_pct": ..., "laws":
{law: {...}}}`` (``law`` and ``max_error_pct`` over the laws run).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

_SCRIPT = __file__ if __file__.endswith("two_spheres.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("two_spheres.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

RADIUS = 2e-3            # m
DISTANCE = 3.8e-3        # m, centre to centre (0.2 mm overlap)
CONDUCTIVITY = 385.0     # W/(m K)
DENSITY = 8900.0         # kg/m^3
SPECIFIC_HEAT = 172.0    # J/(kg K)
T_HOT, T_COLD = 373.15, 273.15   # K
LAWS = ("contact", "liggghts")
#: geometric factor g [m] of each law for the contact circle of radius a
FACTOR = {"contact": lambda a: 2.0 * a, "liggghts": lambda a: 2.0 * math.sqrt(math.pi) * a}


def contact_circle_radius(r1=RADIUS, r2=RADIUS, d=DISTANCE) -> float:
    """a [m] of two overlapping spheres (lens of the overlap)."""
    x = (r1 ** 2 - r2 ** 2 + d ** 2) / (2 * d)
    return math.sqrt(r1 ** 2 - x ** 2)


def sphere_capacity() -> float:
    """C = rho c (4/3) pi r^3 [J/K] of one sphere."""
    return DENSITY * SPECIFIC_HEAT * 4.0 / 3.0 * math.pi * RADIUS ** 3


def contact_conductance(law) -> float:
    """H = k g [W/K] of the contact for the law."""
    return CONDUCTIVITY * FACTOR[law](contact_circle_radius())


def decay_time(law) -> float:
    """tau = C / (2 H) [s], the decay time of the temperature difference."""
    return sphere_capacity() / (2.0 * contact_conductance(law))


def closed_form(t, law):
    """(T_1, T_2) [K] at times t [s] for the law: the difference decays as exp(-t / tau)."""
    t = np.asarray(t, float)
    mean, half = 0.5 * (T_HOT + T_COLD), 0.5 * (T_HOT - T_COLD) * np.exp(-t / decay_time(law))
    return mean + half, mean - half


def run_law(law, steps_per_tau=200, taus=5.0, theta="crank-nicolson"):
    """Two spheres in YADE with the heat engine; returns the figures and the curves."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import utils
    from yade import wrapper as W
    from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Law, Material, Reader
    O = yade.Omega()
    O.reset()
    mat = O.materials.append(W.FrictMat(young=110e9, poisson=0.34, density=DENSITY, frictionAngle=0.3))
    ids = O.bodies.append([utils.sphere((0, 0, 0), RADIUS, material=mat),
                           utils.sphere((DISTANCE, 0, 0), RADIUS, material=mat)])
    for i in ids:
        O.bodies[i].state.blockedDOFs = "xyzXYZ"
    O.engines = [W.ForceResetter(), W.InsertionSortCollider([W.Bo1_Sphere_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom()], [W.Ip2_FrictMat_FrictMat_FrictPhys()],
                                   [W.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 W.NewtonIntegrator(damping=0.0)]
    O.dt = 1e-7
    O.step()                               # the contact exists before the engine's first call
    tau = decay_time(law)
    dt = tau / steps_per_tau
    engine = HeatEngine(
        material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        temperature=InitialTemperature(T_COLD, by_id={ids[0]: T_HOT}),
        law=Law(law, volume_fraction=1.0),
        integrator=Integrator(theta=theta, dt=dt),
        reader=Reader(bonds="contacts"),
        label=f"two_spheres_{law}")
    O.engines = O.engines + [engine.runner]
    n = int(round(taus * steps_per_tau))
    t, T1, T2 = [], [], []
    for _ in range(n):
        O.step()
        T = engine.temperature_by_id
        t.append(engine.coupled.time)
        T1.append(T[ids[0]])
        T2.append(T[ids[1]])
    t, T1, T2 = map(np.asarray, (t, T1, T2))
    e1, e2 = closed_form(t, law)
    err = 100.0 * np.max(np.abs(np.concatenate([T1 - e1, T2 - e2]))) / (T_HOT - T_COLD)
    mean_drift = float(np.max(np.abs(0.5 * (T1 + T2) - 0.5 * (T_HOT + T_COLD))))
    g = engine.coupled.network.factor if hasattr(engine.coupled.network, "factor") else None
    out = {"law": law, "max_error_pct": float(err), "tau_s": tau, "thermal_dt_s": dt, "steps": n,
           "contact_radius_m": contact_circle_radius(), "H_W_per_K": contact_conductance(law),
           "engine_factor_m": (float(np.asarray(g)[0]) if g is not None and np.size(g) else None),
           "mean_drift_K": mean_drift, "T_final": [float(T1[-1]), float(T2[-1])]}
    engine.remove()
    return out, (t, T1, T2, e1, e2)


def plot(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for law, (t, T1, T2, e1, e2) in curves.items():
        k = max(1, len(t) // 25)
        ax.plot(t[::k] * 1e3, T1[::k] - 273.15, "o", ms=3, label=f"{law}: DEM")
        ax.plot(t[::k] * 1e3, T2[::k] - 273.15, "o", ms=3, color=ax.lines[-1].get_color())
        ax.plot(t * 1e3, e1 - 273.15, "k-", lw=0.8)
        ax.plot(t * 1e3, e2 - 273.15, "k-", lw=0.8)
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("T [degC]")
    ax.set_title("two copper spheres: DEM (dots) and closed form (lines)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--law", default="all", choices=("all",) + LAWS)
    ap.add_argument("--steps-per-tau", type=int, default=200)
    ap.add_argument("--theta", default="crank-nicolson")
    ap.add_argument("--out", default="out/two_spheres")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("law",))
    laws = LAWS if args.law == "all" else (args.law,)
    os.makedirs(args.out, exist_ok=True)
    rows, curves = {}, {}
    for law in laws:
        rows[law], curves[law] = run_law(law, args.steps_per_tau, theta=args.theta)
        r = rows[law]
        print(f"two spheres, {law}: H = {r['H_W_per_K']:.4f} W/K, tau = {1e3 * r['tau_s']:.2f} ms, max error "
              f"{r['max_error_pct']:.2e} % of 100 K, mean drift {r['mean_drift_K']:.1e} K", flush=True)
    png = plot(curves, os.path.join(args.out, f"two_spheres_{args.law}.png"))
    out = {"case": "two_spheres", "law": ",".join(laws), "max_error_pct": max(r["max_error_pct"] for r in rows.values()),
           "laws": rows, "png": png}
    with open(os.path.join(args.out, f"two_spheres_{args.law}.json"), "w") as fh:
        json.dump(out, fh)
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
