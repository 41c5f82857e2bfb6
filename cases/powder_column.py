"""Current through a pressed column of spheres: the electrical resistance of Hertz contacts
against the force (the chain part of the powder-column case of the granular issue).

A simple-cubic column of N steel spheres (r = 1 mm) along z in YADE, Hertz-Mindlin contacts
(``Ip2_FrictMat_FrictMat_MindlinPhys``, ``Law2_ScGeom_MindlinPhys_Mindlin``), the bottom sphere
held, the top one pushed down with a force F (``O.forces.setPermF``), every sphere free along
z only (a straight chain). At each F the column is relaxed until every contact carries F to
1e-6, then the electrical engine (``bonds='contacts'``, law ``contact``: g = 2 a, conductance
2 a / rho_e) gives R between the top and bottom spheres.

Exact chain result: N - 1 identical contacts in series, R = (N - 1) rho_e / (2 a) with the
Hertz radius a = (3 F R* / (4 E*))^(1/3), R* = r / 2, E* = E / (2 (1 - nu^2)): log R against
log F has slope -1/3. Both contact-radius models of the law are run: ``hertz`` (a = sqrt(R*
delta), the Hertz radius from the overlap) must give the exact result; ``geometric`` (the lens
of the overlap, about sqrt(2) times larger) gives R about 1/sqrt(2) of it, with a slope that
tends to -1/3 as the overlap vanishes.

The column stands on a plate (a YADE ``Wall``, same steel) that is also an electrode: a third
engine (``R_plate``) measures between the top sphere and the plate (``electrodes={'plate':
dict(wall=plate_id, ...)}``), through the N - 1 sphere-sphere contacts and the sphere-plate
contact, whose Hertz radius is a_w = (3 F r / (4 E*))^(1/3) (R* = r: a sphere on a half-space;
the law's plane radius a = sqrt(r delta)) and whose constriction is again rho_e / (2 a_w) (the
sphere's and the plate's halves, rho_e / (4 a_w) each): R = (N - 1) rho_e / (2 a) + rho_e /
(2 a_w), slope -1/3 as well. Measured: YADE's ``Ip2_FrictMat_FrictMat_MindlinPhys`` gives a
sphere-wall contact the reduced radius r / 2 (as if the wall were a second sphere of the same
radius; ``plate_r_star_over_r`` = F / (4/3 E* delta^(3/2)))^2 / r, from the overlap, is 0.5000),
so its overlap is 2^(1/3) times the Hertz one and R_plate comes out 0.88 % below the Hertz
value; against the contact YADE actually makes (``R_plate_yade``, R* = r / 2) it agrees to
1e-5 %.

Not here yet: a random packing pressed between two plates.

Run
---
    yade-electro -n -x cases/powder_column.py [--n 10]

Ends with one JSON line: ``{"case": "powder_column", "slope": ..., "slope_error_pct": ...,
"max_R_error_pct": ..., ...}`` (``slope``: the ``hertz`` radius model).
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

_SCRIPT = __file__ if __file__.endswith("powder_column.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("powder_column.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

RADIUS = 1e-3           # m
YOUNG = 200e9           # Pa
POISSON = 0.3
DENSITY = 7800.0        # kg/m^3
RESISTIVITY = 1e-7      # ohm m
FORCES = tuple(np.logspace(0, 2, 7))   # N
MODELS = ("hertz", "geometric")


def effective_modulus(E=YOUNG, nu=POISSON) -> float:
    """E* [Pa] of two identical spheres: E / (2 (1 - nu^2))."""
    return E / (2.0 * (1.0 - nu ** 2))


def hertz_radius(F, r=RADIUS) -> np.ndarray:
    """a = (3 F R* / (4 E*))^(1/3) [m] of two identical spheres pressed by F [N]."""
    return (3.0 * np.asarray(F, float) * (r / 2.0) / (4.0 * effective_modulus())) ** (1.0 / 3.0)


def chain_resistance(F, n, r=RADIUS) -> np.ndarray:
    """R [ohm] of n spheres in a row pressed by F: (n - 1) rho_e / (2 a)."""
    return (n - 1) * RESISTIVITY / (2.0 * hertz_radius(F, r))


def plate_radius(F, r=RADIUS) -> np.ndarray:
    """Hertz radius [m] of a sphere pressed by F onto a plate of the same material: R* = r."""
    return (3.0 * np.asarray(F, float) * r / (4.0 * effective_modulus())) ** (1.0 / 3.0)


def plate_chain_resistance(F, n, r=RADIUS, r_star=None) -> np.ndarray:
    """R [ohm] from the top sphere to the plate: the chain plus rho_e / (2 a_w), a_w the
    radius a = sqrt(r delta) of the overlap delta that a Hertz contact of reduced radius
    ``r_star`` (default r: a sphere on a half-space) takes under F."""
    r_star = r if r_star is None else r_star
    delta = (3.0 * np.asarray(F, float) / (4.0 * effective_modulus() * np.sqrt(r_star))) ** (2.0 / 3.0)
    return chain_resistance(F, n, r) + RESISTIVITY / (2.0 * np.sqrt(r * delta))


def press(O, ids, F, tol=1e-6, chunk=2000, max_chunks=60):
    """Set the force on the top sphere and relax until every contact carries F to ``tol``;
    returns (contact forces, steps)."""
    O.forces.setPermF(ids[-1], (0, 0, -float(F)))
    steps = 0
    for _ in range(max_chunks):
        O.run(chunk, True)
        steps += chunk
        fn = np.array([abs(i.phys.normalForce[2]) for i in O.interactions if i.isReal])
        if fn.size == len(ids) and np.max(np.abs(fn / F - 1.0)) < tol:
            return fn, steps
    raise RuntimeError(f"the column did not settle under {F} N within {steps} steps "
                       f"(contact forces {fn.tolist()})")


def run(n=10, forces=FORCES, progress=print):
    """The column in YADE; returns the figures."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import utils
    from yade import wrapper as W
    from yade_electro.yade import ElectricalEngine
    O = yade.Omega()
    O.reset()
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=POISSON, density=DENSITY, frictionAngle=0.3))
    gap = 2 * RADIUS * (1 - 1e-7)         # a touch of overlap: the contacts exist from the start
    plate = O.bodies.append(utils.wall(-RADIUS * (1 - 1e-7), axis=2, sense=1, material=mat))
    ids = O.bodies.append([utils.sphere((0, 0, k * gap), RADIUS, material=mat) for k in range(n)])
    for i in ids:
        O.bodies[i].state.blockedDOFs = "xyXYZ"
    O.engines = [W.ForceResetter(), W.InsertionSortCollider([W.Bo1_Sphere_Aabb(), W.Bo1_Wall_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom(), W.Ig2_Wall_Sphere_ScGeom()],
                                   [W.Ip2_FrictMat_FrictMat_MindlinPhys()],
                                   [W.Law2_ScGeom_MindlinPhys_Mindlin()]),
                 W.NewtonIntegrator(damping=0.7)]
    O.dt = 0.3 * utils.PWaveTimeStep()
    O.step()
    engines = {m: ElectricalEngine(RESISTIVITY, {"top": dict(select=[ids[-1]], potential=1.0),
                                                 "bottom": dict(select=[ids[0]], potential=0.0)},
                                   law="contact", law_params=dict(radius=m), bonds="contacts", iterPeriod=10 ** 9,
                                   geometry_every=1, move_tolerance=1e-12, write_back=None, label=f"column_{m}")
               for m in MODELS}
    engines["plate"] = ElectricalEngine(RESISTIVITY, {"top": dict(select=[ids[-1]], potential=1.0),
                                                      "plate": dict(wall=plate, potential=0.0)},
                                        law="contact", law_params=dict(radius="hertz"), bonds="contacts",
                                        iterPeriod=10 ** 9, write_back=None, label="column_plate")
    rows = []
    for F in forces:
        fn, steps = press(O, ids, F)
        row = {"F": float(F), "steps": steps, "force_error": float(np.max(np.abs(fn / F - 1.0))),
               "R_exact": float(chain_resistance(F, n))}
        row["a_hertz"] = float(hertz_radius(F))
        row["R_plate_exact"] = float(plate_chain_resistance(F, n))
        # the overlap YADE's Mindlin law gives the sphere-plate contact under F, and the reduced
        # radius it implies: F = 4/3 E* sqrt(R*) delta^(3/2)
        for m, e in engines.items():
            e.step()
            row[f"R_{m}"] = float(e.equivalent_resistance)
            exact = row["R_plate_exact"] if m == "plate" else row["R_exact"]
            row[f"R_error_pct_{m}"] = 100.0 * (row[f"R_{m}"] / exact - 1.0)
        nodes, dl = engines["plate"].reader.wall_contacts("plate")
        row["plate_overlap"] = float(dl[0])
        row["plate_r_star_over_r"] = float((3 * F / (4 * effective_modulus() * dl[0] ** 1.5)) ** 2 / RADIUS)
        row["R_plate_yade"] = float(plate_chain_resistance(F, n, r_star=row["plate_r_star_over_r"] * RADIUS))
        row["R_error_pct_plate_vs_yade_wall"] = 100.0 * (row["R_plate"] / row["R_plate_yade"] - 1.0)
        rows.append(row)
        progress(f"F = {F:7.3f} N: R hertz {row['R_hertz']:.5e} ohm ({row['R_error_pct_hertz']:+.4f} %), geometric "
                 f"{row['R_geometric']:.5e} ({row['R_error_pct_geometric']:+.2f} %), exact {row['R_exact']:.5e}")
    logF = np.log([r["F"] for r in rows])
    out = {"case": "powder_column", "n": n, "contacts": n - 1, "forces_N": [r["F"] for r in rows]}
    for m in MODELS + ("plate",):
        slope = float(np.polyfit(logF, np.log([r[f"R_{m}"] for r in rows]), 1)[0])
        out[f"slope_{m}"] = slope
        out[f"slope_error_pct_{m}"] = 100.0 * (slope / (-1.0 / 3.0) - 1.0)
        out[f"max_R_error_pct_{m}"] = float(max(abs(r[f"R_error_pct_{m}"]) for r in rows))
    out["slope"], out["slope_error_pct"] = out["slope_hertz"], out["slope_error_pct_hertz"]
    out["max_R_error_pct"] = out["max_R_error_pct_hertz"]
    out["plate_r_star_over_r"] = float(np.mean([r["plate_r_star_over_r"] for r in rows]))
    out["max_R_error_pct_plate_vs_yade_wall"] = float(max(abs(r["R_error_pct_plate_vs_yade_wall"]) for r in rows))
    out["rows"] = rows
    for e in engines.values():
        e.remove()
    return out


def plot(out, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    F = np.array(out["forces_N"])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ff = np.logspace(np.log10(F[0]), np.log10(F[-1]), 50)
    ax.loglog(ff, chain_resistance(ff, out["n"]), "k-", label="exact chain, Hertz: slope -1/3")
    ax.loglog(ff, plate_chain_resistance(ff, out["n"]), "k--", label="exact, top sphere to plate (Hertz)")
    for m, mk, what in (("hertz", "o", "hertz radius"), ("geometric", "s", "geometric radius"),
                        ("plate", "^", "to the plate, hertz")):
        ax.loglog(F, [r[f"R_{m}"] for r in out["rows"]], mk, label=f"DEM, {what}: slope {out[f'slope_{m}']:.4f}")
    ax.set_xlabel("F [N]")
    ax.set_ylabel("R [ohm]")
    ax.set_title(f"{out['n']} spheres in a column")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--out", default="out/powder_column")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("n",))
    os.makedirs(args.out, exist_ok=True)
    out = run(args.n)
    out["png"] = plot(out, os.path.join(args.out, f"powder_column_n{args.n}.png"))
    with open(os.path.join(args.out, f"powder_column_n{args.n}.json"), "w") as fh:
        json.dump(out, fh)
    print(f"column of {args.n} spheres: slope {out['slope']:.5f} ({out['slope_error_pct']:+.3f} % from -1/3), R within "
          f"{out['max_R_error_pct']:.4f} % of the exact chain; geometric radius: slope {out['slope_geometric']:.5f}")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
