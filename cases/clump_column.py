"""A column of 6 equal spheres joined in clumps of 2 and 3 (issue 35): lumped and resolved
clumps in the granular heat engine against their closed forms.

Six spheres, r = 1 mm, in a vertical line with centres 1.9 r apart (an overlap of 0.1 r at
each of the 5 joints): spheres 0-1 are one clump, 2-3-4 another, 5 is alone
(``O.bodies.appendClumped``), all at rest. Glass-like: k = 2 W/(m K), rho = 2600 kg/m^3,
c = 800 J/(kg K). Sphere 5 (top) is held at 400 K and sphere 0 (bottom) at 100 K; the others
start at 100 K. Every joint, inside a clump (the lens of two members) or between two
particles (a contact), conducts H = 2 k a with a = sqrt(r^2 - (0.95 r)^2) (the contact law).

* **resolved** (``Reader(clumps='resolved')``): six temperatures; each member's capacity is its
  share of its clump's volume (its sphere less half of each lens it shares with a member:
  V_lens = pi (4 r + d) (2 r - d)^2 / 12 for equal spheres d apart). Steady closed form: the
  five equal joints in series, T_k = 100 + 300 k / 5 K. Transient closed form: the exact
  solution of the 4 free nodes' ODE C dT/dt = -K T + b (matrix exponential, scipy), against
  the engine's Crank-Nicolson steps.
* **lumped** (``Reader(clumps='lumped')``): one temperature per clump. Holding sphere 0 holds its
  clump; the joints inside clumps drop out; the free clump {2, 3, 4} (capacity of its three
  members) sees one contact to each side: steady 250 K, transient
  T = 250 - 150 exp(-2 H t / C_clump).

The figures: the steady errors (K) and the transient errors (per cent of the 300 K span) of
each mode, and how far lumped is from resolved on the middle clump's mean temperature over the
history (``lumped_vs_resolved_pct``): the clumps' own conduction, which the lumped model
leaves out. YADE's own ThermalEngine is not run beside them: in YADE 2023.02a it needs a
FlowEngine (it crashes without one), which a column of six spheres cannot have.

Run
---
    yade-electro -n -x cases/clump_column.py

Ends with one JSON line: ``{"case": "clump_column", "resolved": {...}, "lumped": {...},
"max_error_pct": ..., "lumped_vs_resolved_pct": ...}``.
"""
from __future__ import annotations

import json
import math
import os
import sys

import numpy as np

_SCRIPT = __file__ if __file__.endswith("clump_column.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("clump_column.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

RADIUS = 1e-3                # m
SPACING = 1.9 * RADIUS       # m, centre to centre
CONDUCTIVITY, DENSITY, SPECIFIC_HEAT = 2.0, 2600.0, 800.0     # W/(m K), kg/m^3, J/(kg K)
T_TOP, T_BOTTOM = 400.0, 100.0                                 # K
CLUMPS = ((0, 1), (2, 3, 4))
DT, STEPS = 0.25, 240        # s: the engine's thermal step, and how many (60 s, about 5 decay times)


def joint_conductance() -> float:
    """H = 2 k a [W/K] of every joint (lens or contact)."""
    a = math.sqrt(RADIUS ** 2 - (SPACING / 2) ** 2)
    return 2.0 * CONDUCTIVITY * a


def capacities() -> np.ndarray:
    """Each sphere's capacity [J/K] in the resolved model: its share of its clump's volume."""
    sphere = 4.0 / 3.0 * math.pi * RADIUS ** 3
    lens = math.pi * (4 * RADIUS + SPACING) * (2 * RADIUS - SPACING) ** 2 / 12.0
    lenses = np.array([1, 1, 1, 2, 1, 0])           # the lenses each shares with its own clump
    return DENSITY * SPECIFIC_HEAT * (sphere - 0.5 * lens * lenses)


def resolved_exact(times) -> np.ndarray:
    """(len(times), 6) exact temperatures [K] of the resolved chain (matrix exponential)."""
    from scipy.linalg import expm
    H, C = joint_conductance(), capacities()
    free = np.arange(1, 5)
    K = np.zeros((6, 6))
    for i in range(5):
        K[i, i] += H
        K[i + 1, i + 1] += H
        K[i, i + 1] -= H
        K[i + 1, i] -= H
    held = np.array([T_BOTTOM, T_TOP])
    A = -K[np.ix_(free, free)] / C[free, None]
    b = -(K[np.ix_(free, [0, 5])] @ held) / C[free]
    T_inf = np.linalg.solve(A, -b)
    out = np.empty((len(times), 6))
    out[:, 0], out[:, 5] = T_BOTTOM, T_TOP
    for k, t in enumerate(times):
        out[k, free] = T_inf + expm(A * t) @ (np.full(4, T_BOTTOM) - T_inf)
    return out


def lumped_exact(times) -> np.ndarray:
    """(len(times),) exact temperature [K] of the free clump {2, 3, 4} in the lumped model."""
    C = capacities()[2:5].sum()                   # the clump's volume: its members' shares
    mid = 0.5 * (T_TOP + T_BOTTOM)
    return mid - (mid - T_BOTTOM) * np.exp(-2.0 * joint_conductance() * np.asarray(times) / C)


def run(mode: str) -> dict:
    """Build the column in YADE, run the engine ``STEPS`` steps of ``DT``, then to steady."""
    from yade_electro.yade import FixedTemperature, HeatEngine, Integrator, Material, Reader
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    O = yade.Omega()
    O.reset()
    O.materials.append(yade.FrictMat(young=1e6, density=DENSITY, label="glass"))
    z = [SPACING * k for k in range(6)]
    clumps = [O.bodies.appendClumped([yade.utils.sphere((0, 0, z[i]), RADIUS, fixed=True) for i in members])
              for members in CLUMPS]
    ids = [*clumps[0][1], *clumps[1][1], O.bodies.append(yade.utils.sphere((0, 0, z[5]), RADIUS, fixed=True))]
    for cid, _ in clumps:
        O.bodies[cid].state.blockedDOFs = "xyzXYZ"
    O.engines = [yade.ForceResetter(), yade.NewtonIntegrator(gravity=(0, 0, 0))]
    O.dt = 1e-6
    eng = HeatEngine(material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
                     law="contact", reader=Reader(bonds="contacts", clumps=mode),
                     boundaries=[FixedTemperature("top", nodes=[ids[5]], temperature=T_TOP),
                                 FixedTemperature("bottom", nodes=[ids[0]], temperature=T_BOTTOM)],
                     temperature=T_BOTTOM, integrator=Integrator(theta="crank-nicolson", dt=DT), iterPeriod=1)
    O.engines = O.engines + [eng.runner]
    history = []
    O.run(1, True)                   # the runner's first call comes at the second step
    for _ in range(STEPS):
        O.run(1, True)
        history.append([O.bodies[i].state.temp for i in ids])
    clump_T = [O.bodies[cid].state.temp for cid, _ in clumps]
    eng.steady_state()
    steady = np.array([O.bodies[i].state.temp for i in ids])
    eng.remove()
    return {"history": np.array(history), "steady": steady, "clump_T": clump_T}


def main() -> dict:
    times = DT * np.arange(1, STEPS + 1)
    out = {"case": "clump_column", "joint_conductance_W_per_K": joint_conductance(), "dt_s": DT, "steps": STEPS}
    res = run("resolved")
    exact = resolved_exact(times)
    steady_exact = T_BOTTOM + (T_TOP - T_BOTTOM) * np.arange(6) / 5.0
    out["resolved"] = {
        "steady_K": res["steady"].round(6).tolist(),
        "steady_error_K": float(np.max(np.abs(res["steady"] - steady_exact))),
        "transient_error_pct": float(100 * np.max(np.abs(res["history"] - exact)) / (T_TOP - T_BOTTOM)),
        "clump_T_last_K": res["clump_T"]}
    lum = run("lumped")
    exact_l = lumped_exact(times)
    out["lumped"] = {
        "steady_K": lum["steady"].round(6).tolist(),
        "steady_error_K": float(max(np.max(np.abs(lum["steady"][2:5] - 250.0)),
                                    np.max(np.abs(lum["steady"][:2] - T_BOTTOM)))),
        "transient_error_pct": float(100 * np.max(np.abs(lum["history"][:, 2:5] - exact_l[:, None]))
                                     / (T_TOP - T_BOTTOM)),
        "members_equal": bool(np.all(np.ptp(lum["history"][:, 2:5], axis=1) == 0)),
        "clump_T_last_K": lum["clump_T"]}
    mid_res = (res["history"][:, 2:5] * capacities()[2:5]).sum(axis=1) / capacities()[2:5].sum()
    out["lumped_vs_resolved_pct"] = float(100 * np.mean(np.abs(lum["history"][:, 2] - mid_res) / mid_res))
    out["max_error_pct"] = max(out["resolved"]["transient_error_pct"], out["lumped"]["transient_error_pct"])
    out["yade_thermal_engine"] = "not run: YADE 2023.02a's ThermalEngine needs a FlowEngine"
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
