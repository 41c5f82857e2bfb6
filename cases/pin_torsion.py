"""Pin torsion (paper 000, section 4): the rise of the electrical resistance detects the cracks
while YADE twists a bonded cast-iron pin until it breaks.

The pin
-------
The rod of section 3.1: radius r = 1 mm, length h = 5 mm, about 5,000 elements (the paper
writes "d = 1 mm" but calls it the same domain as section 3.1; with r = 1 mm the elastic
solution gives first yield at theta_y = tau_y h / (G r) = 0.0416 rad, the paper's 0.043 rad,
while d = 1 mm would give 0.083 rad: r = 1 mm is used). Grey cast iron ASTM 40 (paper Table
IV): G = 48.062 GPa, 7060 kg/m^3, rho_e = 0.11e-6 ohm m, shear yield stress tau_y = 400 MPa.

Mechanics (YADE)
----------------
Brittle-elastic cohesive bonds: ``CohFrictMat`` with ``momentRotationLaw`` and ``fragile``
(``Law2_ScGeom6D_CohFrictPhys_CohesionMoment``). Why: it is the closest YADE law to the
paper's cohesive beams (André et al.: each bond carries normal and shear forces and bending
and twisting moments), and it is the law our bonded packings already use, bonds stress-free
at the start (``unp``). A bond breaks when its tension exceeds ``normalCohesion r^2`` or its
shear force ``shearCohesion r^2 + F_n tan phi`` (r = min(r1, r2); one strength sigma_b for
both), or when its bending moment exceeds sigma_b r^3 / 4 or its twisting moment sigma_b r^3 / 2
(the moment strengths of later YADE versions, missing in 2023.02a and applied every 50 steps
by :class:`yade_electro.yade.bond_strength.MomentStrength`: without them, ligaments held by
their moments alone never break and the pin never separates). A broken bond in tension is
erased, one broken otherwise stays as a frictional contact (tan phi = 0.3). JCFpm would count
its cracks for free but carries no moments; our engine finds CohFrictMat breaks itself with
``bond_check='flags'`` (3 ms a call at 5,000 elements).

The grips are the elements whose centre is within one mean radius of an end face
(:class:`yade_electro.yade.torsion_rig.TorsionRig`): the bottom one clamped, the top one
turned about the axis at the paper's rate, the shear strain rate r dtheta/dt / h = 75 1/s
(dtheta/dt = 375 rad/s), after a linear start over the first 0.005 rad. The bonds that touch
a grip do not break (the grips stand for the shoulders of a real specimen). The twisted length
h_free is the distance between the grips' mean planes (4.86 mm at 5,000 elements); the elastic
reference is T = G J theta / h_free with J = pi r^4 / 2, and theta_y = tau_y h_free / (G r).

Calibration (``--calibrate``; its result is kept in ``cases/pin_torsion.calibration.json``)
-------------------------------------------------------------------------------------------
One quasi-static elastic twist to theta_y with unbreakable bonds (a trial bond modulus
E_0 = 200 GPa, ks/kn = 0.25, alphaKr = alphaKtw = 2): twisted in 3,000 steps, then held with
heavy damping until the torque is steady. Everything in the bonded model scales with E at a
fixed displacement field, so

* bond modulus E_b = E_0 (G J / h_free) / (T / theta)  (the torque-angle slope matches G J / h_free);
* bond strength sigma_b = (E_b / E_0) max over bonds of max(-F_n / r^2, (|F_s| - F_n tan phi) / r^2,
  4 |M_b| / r^3, 2 |M_t| / r^3) at theta_y (the first bond reaches its strength at theta_y; grip
  bonds left out).

Nothing electrical is calibrated. The Poisson ratio of the pin is not calibrated (torsion
does not see it).

Electrical engines
------------------
Both laws run in the same simulation (the same mechanics for both): ``voronoi`` (crack rule
``facets``, surface electrodes on the end faces) and ``continuum`` (paper 000, electrodes the
end element layers z - r <= 0.1 r_mean), 1 V against ground, every ``--every`` steps (default
100: 1.85e-4 rad between calls at the paper's rate, about 220 calls up to theta_y and 150 from
the first break to separation), ``bond_check='flags'`` (every bond's flag read at every call: no break is missed or
seen late). R_eq is inf once no bonded path joins the electrodes (never nan).

Outputs (``--out``, default out/pin_torsion)
-------------------------------------------
``pin_n<N>_s<seed>.csv`` (one row per record: theta, torque, tau/tau_y, energies, broken
bonds, R and R/R0 per law), ``.png`` (paper figure 16: torque and tau/tau_y, R/R0, broken
bonds against theta), VTK snapshots (meshio) ``vtk/pin_<stage>_elements.vtu`` (potential of each law,
displacement, broken bonds per element) and ``_bonds.vtu`` (every initial bond, ``broken`` = 1
once broken) at the stages ``before`` (last record before the first break), ``onset`` (first
record with R/R0 >= 1.01) and ``separation`` (last record before R = inf, or the last record).
Ends with one JSON line (``case``, ``law``, ``n``, ``elastic_torque_error_pct``,
``theta_first_break``, ``R_ratio_at``, ``theta_separation``, ``wall_s``, ``engine_share``, ...).

Run
---
    yade-electro -n -x cases/pin_torsion.py                          # 5,000 elements, both laws
    yade-electro -n -x cases/pin_torsion.py --rate-factor 0.5        # half the twist rate
    yade-electro -n -x cases/pin_torsion.py --calibrate --n 5000     # redo the calibration
    yade-electro batch cases/pin_torsion.table cases/pin_torsion.py  # a parameter study
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("pin_torsion.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("pin_torsion.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from yade_electro.post.torsion import (crack_summary, elastic_slope, elastic_torque, polar_moment,  # noqa: E402
                                  ratio_at, yield_angle)

RADIUS = 1e-3            # m
LENGTH = 5e-3            # m
SHEAR_MODULUS = 48.062e9  # Pa
DENSITY = 7060.0         # kg/m^3
RESISTIVITY = 0.11e-6    # ohm m
SHEAR_YIELD = 400e6      # Pa
STRAIN_RATE = 75.0       # 1/s, paper 000 section 4: r dtheta/dt / h
KS_KN = 0.25             # CohFrictMat "poisson": ks / kn
FRICTION = math.atan(0.3)  # rad, crack lips in contact
TRIAL_YOUNG = 200e9      # Pa, calibration's trial bond modulus
UNBREAKABLE = 1e300      # Pa, strength of the grip bonds and of the calibration run
LAWS = ("voronoi", "continuum")
ANGLES = (0.05, 0.06, 0.07)
RAMP_ANGLE = 0.005       # rad, the twist rate starts linearly over this angle
STRENGTH_EVERY = 50      # steps between two checks of the bonds' moment strength
CALIBRATION_FILE = os.path.join(HERE, "pin_torsion.calibration.json")


def paper_rate() -> float:
    """Twist rate [rad/s] of the paper's shear strain rate: 75 h / r = 375 rad/s."""
    return STRAIN_RATE * LENGTH / RADIUS


def cast_iron(young, strength):
    """The bonds' CohFrictMat: bond modulus ``young`` [Pa], normal = shear cohesion ``strength`` [Pa]."""
    from yade.wrapper import CohFrictMat
    return CohFrictMat(young=float(young), poisson=KS_KN, density=DENSITY, frictionAngle=FRICTION,
                       isCohesive=True, normalCohesion=float(strength), shearCohesion=float(strength),
                       momentRotationLaw=True, fragile=True, label="cast_iron_astm40")


def build_pin(n, seed, young, strength, rate, ramp_time, check_every=STRENGTH_EVERY, cache_dir=None):
    """Reset YADE's scene and build the bonded pin with its torsion rig; returns a dict
    (packing, ids, rig, container, grip_bonds)."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.yade import packing as P
    from yade_electro.yade.torsion_rig import TorsionRig, get_rig
    O = yade.Omega()
    O.reset()
    old = get_rig("pin")
    if old is not None:
        old.remove()
    cyl = Cylinder((0, 0, 0), (0, 0, LENGTH), RADIUS)
    packing = P.dense_packing(cyl, n=n, seed=seed, cache_dir=cache_dir)
    ids = P.add_bonded_packing(packing, material=cast_iron(young, strength))
    r_mean = float(np.mean(packing.radii))
    rig = TorsionRig(ids, packing.centers[:, 2], (0, 0, 0), (0, 0, 1), LENGTH, grip_depth=r_mean, rate=rate,
                     ramp_time=ramp_time, label="pin")
    grip = set(rig.bottom_ids) | set(rig.top_ids)
    grip_bonds = 0
    for i in O.interactions:
        if i.id1 in grip or i.id2 in grip:
            i.phys.normalAdhesion = i.phys.shearAdhesion = UNBREAKABLE
            grip_bonds += 1
    from yade_electro.yade.bond_strength import MomentStrength, _LIVE
    if "pin_strength" in _LIVE:
        _LIVE["pin_strength"].remove()
    strength_check = MomentStrength(iterPeriod=check_every, exclude=grip, label="pin_strength")
    e = list(O.engines)          # ForceResetter, collider, InteractionLoop, NewtonIntegrator
    O.engines = e[:3] + rig.engines + [e[3], rig.runner, strength_check.runner]
    return dict(O=O, packing=packing, ids=ids, rig=rig, container=cyl, grip=grip, grip_bonds=grip_bonds,
                newton=e[3], r_mean=r_mean, strength_check=strength_check)


def pin_electrodes(pin, law):
    """(electrodes, law_params) of each law's engine on the pin built by :func:`build_pin`:
    ``voronoi``: the end faces as surface electrodes, crack rule ``facets``; ``continuum``: the
    end element layers z - r <= 0.1 r_mean (paper 000). 1 V on top, 0 V at the bottom."""
    cyl = pin["container"]
    if law == "voronoi":
        return ({"top": dict(surface=cyl.face("top"), potential=1.0),
                 "bottom": dict(surface=cyl.face("bottom"), potential=0.0)}, dict(container=cyl, crack="facets"))
    if law == "continuum":
        ids, z, r = np.asarray(pin["ids"]), pin["packing"].centers[:, 2], pin["packing"].radii
        gap = 0.1 * pin["r_mean"]
        return ({"top": dict(select=ids[(LENGTH - z - r) <= gap].tolist(), potential=1.0),
                 "bottom": dict(select=ids[(z - r) <= gap].tolist(), potential=0.0)}, None)
    raise ValueError(f"law must be one of {LAWS}, got {law!r}")


def bond_loads(O, grip):
    """(q, mode): for each bond not touching a grip, its load per unit strength [Pa]: the
    largest of the tension -F_n / r^2, the shear (|F_s| - F_n tan phi) / r^2 (F_n > 0 in
    compression), the bending |M_b| / (r^3 / 4) and the twisting |M_t| / (r^3 / 2) (the limits of
    :mod:`yade_electro.yade.bond_strength`, r = min(r1, r2)), and which of the four it is."""
    tan_phi = math.tan(FRICTION)
    q, mode = [], []
    for i in O.interactions:
        if not i.isReal or i.id1 in grip or i.id2 in grip or i.phys.cohesionBroken:
            continue
        ph = i.phys
        fn = ph.normalForce.dot(i.geom.normal)
        r = min(O.bodies[i.id1].shape.radius, O.bodies[i.id2].shape.radius)
        loads = (-fn / r ** 2, (ph.shearForce.norm() - fn * tan_phi) / r ** 2,
                 ph.moment_bending.norm() / (r ** 3 / 4), ph.moment_twist.norm() / (r ** 3 / 2))
        k = int(np.argmax(loads))
        q.append(loads[k])
        mode.append(("tension", "shear", "bending", "twisting")[k])
    return np.array(q), np.array(mode)


def calibrate(n=5000, seed=1, twist_steps=3000, hold_chunk=500, max_hold=12, cache_dir=None, progress=print):
    """The quasi-static elastic twist of the module doc; returns the calibration dict."""
    t0 = time.perf_counter()
    probe = build_pin(n, seed, TRIAL_YOUNG, UNBREAKABLE, rate=1.0, ramp_time=0.0, cache_dir=cache_dir)
    O, rig = probe["O"], probe["rig"]
    h = rig.free_length
    theta_y = yield_angle(SHEAR_YIELD, SHEAR_MODULUS, RADIUS, h)
    rig.rate = theta_y / (0.9 * twist_steps * O.dt)
    rig.ramp_time = 0.2 * twist_steps * O.dt
    while rig.theta + rig.angular_velocity(O.time) * O.dt < theta_y:
        O.step()
    rig.rotation.angularVelocity = (theta_y - rig.theta) / O.dt       # land on theta_y exactly
    O.step()
    rig.hold()
    probe["newton"].damping = 0.8
    last = None
    for k in range(max_hold):
        O.run(hold_chunk, True)
        rec = rig.record()
        torque = 0.5 * (rec["torque_bottom"] - rec["torque_top"])
        progress(f"calibration hold {k + 1}: theta {rig.theta:.5f} rad, torque {torque:.5f} N m, "
                 f"kinetic/elastic {rec['kinetic'] / rec['elastic']:.2e}")
        if last is not None and abs(torque - last) < 1e-4 * abs(torque) and rec["kinetic"] < 1e-6 * rec["elastic"]:
            break
        last = torque
    stiffness = torque / rig.theta
    target = SHEAR_MODULUS * polar_moment(RADIUS) / h
    young = TRIAL_YOUNG * target / stiffness
    q, mode = bond_loads(O, probe["grip"])
    k_max = int(np.argmax(q))
    strength = float(q[k_max]) * young / TRIAL_YOUNG
    out = {"n": int(len(probe["ids"])), "n_target": int(n), "seed": int(seed), "trial_young": TRIAL_YOUNG,
           "free_length": h, "theta_yield": theta_y, "trial_stiffness": stiffness, "target_stiffness": target,
           "young": young, "strength": strength, "first_bond_mode": str(mode[k_max]),
           "modes_above_half": {m: int(np.sum((mode == m) & (q > 0.5 * q[k_max])))
                                for m in ("tension", "shear", "bending", "twisting")},
           "strength_quantiles": {f"{p:g}": float(np.quantile(q, p / 100) * young / TRIAL_YOUNG)
                                  for p in (50, 90, 99, 99.9)},
           "torque_top_bottom": [rec["torque_top"], rec["torque_bottom"]], "hold_chunks": k + 1,
           "kinetic_to_elastic": rec["kinetic"] / rec["elastic"], "ks_kn": KS_KN, "friction_angle": FRICTION,
           "time_s": time.perf_counter() - t0}
    rig.remove()
    probe["strength_check"].remove()
    return out


def _kept_calibrations(path=CALIBRATION_FILE) -> dict:
    """The calibrations kept in ``path``, by "n<N>_s<seed>" ({} when there is no file)."""
    if not os.path.exists(path):
        return {}
    with open(path) as fh:
        return json.load(fh)


def load_calibration(n, seed, out_dir=None, path=CALIBRATION_FILE, cache_dir=None, progress=print):
    """The calibration for (n, seed): the one kept in ``path`` (``--calibrate`` writes there), else
    ``<out_dir>/calibration_n<N>_s<seed>.json``, else a new one, written to that file (each
    batch job its own file: parallel jobs never write one file)."""
    key = f"n{n}_s{seed}"
    kept = _kept_calibrations(path)
    if key in kept:
        return kept[key]
    own = os.path.join(out_dir or ".", f"calibration_{key}.json")
    if os.path.exists(own):
        with open(own) as fh:
            return json.load(fh)
    progress(f"no calibration for {key} in {path}: calibrating (about 80 s at 5,000 elements), kept in {own}")
    cal = calibrate(n, seed, cache_dir=cache_dir, progress=progress)
    os.makedirs(os.path.dirname(os.path.abspath(own)), exist_ok=True)
    with open(own, "w") as fh:
        json.dump(cal, fh, indent=1)
    return cal


class _Snapshots:
    """Keeps the last record's fields and writes VTK snapshots of chosen records."""

    def __init__(self, out_dir, pairs, reader, ref_pos):
        self.dir = os.path.join(out_dir, "vtk")
        self.pairs, self.reader, self.ref_pos = pairs, reader, ref_pos
        self.last = None
        self.written = {}

    def keep(self, potentials, broken, theta):
        self.last = dict(pos=self.reader.positions(), potentials={k: v.copy() for k, v in potentials.items()},
                         broken=broken.copy(), theta=theta)

    def write(self, stage, snap=None):
        from yade_electro.post.vtk import write_bonds, write_elements
        s = snap or self.last
        if s is None or stage in self.written:
            return
        nb = np.zeros(s["pos"].shape[0])
        np.add.at(nb, self.pairs[s["broken"]].ravel(), 1.0)
        fields = {f"potential_{k}": v for k, v in s["potentials"].items()}
        disp = s["pos"] - self.ref_pos
        fields.update(displacement=np.linalg.norm(disp, axis=1), broken_bonds=nb)
        e = write_elements(os.path.join(self.dir, f"pin_{stage}_elements.vtu"), s["pos"], self.reader.graph.radius,
                           fields)
        b = write_bonds(os.path.join(self.dir, f"pin_{stage}_bonds.vtu"), s["pos"], self.pairs,
                        {"broken": s["broken"].astype(float)})
        self.written[stage] = {"theta": s["theta"], "elements": e, "bonds": b}


def run_pin(n=5000, seed=1, laws=LAWS, rate_factor=1.0, every=100, theta_max=0.16, calibration=None,
            out_dir="out/pin_torsion", vtk=True, cache_dir=None, progress=print):
    """Twist the pin with the electrical engines running; returns the figures (see the module
    doc) and writes the outputs. Resets YADE's scene."""
    from yade_electro.yade import ElectricalEngine, Law, Material, Output, Reader, electrodes_from_dict
    cal = calibration or load_calibration(n, seed, out_dir, cache_dir=cache_dir, progress=progress)
    rate = paper_rate() * rate_factor
    pin = build_pin(n, seed, cal["young"], cal["strength"], rate=rate, ramp_time=2 * RAMP_ANGLE / rate,
                    cache_dir=cache_dir)
    O, rig, cyl = pin["O"], pin["rig"], pin["container"]
    h = rig.free_length
    theta_y = yield_angle(SHEAR_YIELD, SHEAR_MODULUS, RADIUS, h)
    os.makedirs(out_dir, exist_ok=True)
    tag = f"pin_n{n}_s{seed}" + ("" if rate_factor == 1 else f"_rate{rate_factor:g}")
    engines = {}
    for law in laws:
        electrodes, params = pin_electrodes(pin, law)
        engines[law] = ElectricalEngine(
            material=Material(resistivity=RESISTIVITY),
            boundaries=electrodes_from_dict(electrodes),
            law=Law(law, **{**(params or {}), "container": cyl}),
            reader=Reader(bond_check="flags"),
            output=Output(write_back=None, history=os.path.join(out_dir, f"{tag}_{law}.csv")),
            iterPeriod=every,
            label=f"pin_{law}")
    rows = []
    first = engines[laws[0]]
    state = {}

    def record():
        rec = rig.record()
        row = dict(rec)
        row["torque"] = 0.5 * (rec["torque_bottom"] - rec["torque_top"])
        row["tau_ratio"] = 2 * row["torque"] / (math.pi * RADIUS ** 3) / SHEAR_YIELD
        g = first.bond_graph
        key = np.sort(g.ids[g.edges], axis=1) @ np.array([1, 1 << 32])
        if "keys" not in state:
            state["keys"], state["pairs"] = key, np.searchsorted(g.ids, np.sort(g.ids[g.edges], axis=1))
            if vtk:
                state["snap"] = _Snapshots(out_dir, state["pairs"], first.reader, first.reader.positions())
        broken = ~np.isin(state["keys"], key)
        row["broken_bonds"] = int(broken.sum())
        for law, eng in engines.items():
            R = float(eng.equivalent_resistance)
            state.setdefault(f"R0_{law}", R)
            row[f"R_{law}"] = R
            row[f"R_ratio_{law}"] = R / state[f"R0_{law}"]
        rows.append(row)
        if vtk:
            snap = state["snap"]
            pots = {law: eng.potential for law, eng in engines.items()}
            if row["broken_bonds"] > 0 and "before" not in snap.written:
                snap.write("before")                      # the previous record
            if not math.isfinite(row[f"R_ratio_{laws[0]}"]):
                snap.write("separation")                  # the last record before R = inf
            snap.keep(pots, broken, row["theta"])
            if row[f"R_ratio_{laws[0]}"] >= 1.01 and "onset" not in snap.written:
                snap.write("onset")

    recorder = rig.recorder(record, every)
    O.engines = O.engines + [e.runner for e in engines.values()] + [recorder]
    O.timingEnabled = True
    for e in O.engines:
        if hasattr(e, "execTime"):
            e.execTime = 0
    progress(f"pin {len(pin['ids'])} elements, {pin['grip_bonds']} grip bonds, bond modulus {cal['young'] / 1e9:.1f} GPa, strength {cal['strength'] / 1e6:.0f} MPa, dt {O.dt:.3g} s, "
             f"rate {rate:g} rad/s ({rate * RADIUS / LENGTH:g} 1/s), theta_y {theta_y:.4f} rad, laws {', '.join(laws)}")
    t0 = time.perf_counter()
    chunk = 20 * every
    while rig.theta < theta_max:
        O.run(chunk, True)
        last = rows[-1]
        progress(f"theta {last['theta']:.4f} rad: torque {last['torque']:.4f} N m (tau/tau_y {last['tau_ratio']:.3f}), "
                 f"broken {last['broken_bonds']}, " + ", ".join(f"R/R0 {l} {last[f'R_ratio_{l}']:.4g}" for l in laws)
                 + f"  [{time.perf_counter() - t0:.0f} s]")
        if all(not math.isfinite(last[f"R_ratio_{law}"]) for law in laws):
            break                                         # separated for every law: done
    wall = time.perf_counter() - t0
    shares = {law: e.runner.execTime * 1e-9 / wall for law, e in engines.items()}
    check = pin["strength_check"]
    check_share = check.runner.execTime * 1e-9 / wall
    if vtk:
        state["snap"].write("separation")                 # never separated: the last record
    cols = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    th = cols["theta"]
    fit_hi = 0.8 * theta_y
    slope = elastic_slope(th, cols["torque"], theta_max=fit_hi, theta_min=2 * RAMP_ANGLE)
    ref_slope = SHEAR_MODULUS * polar_moment(RADIUS) / h
    pre = (th > 2 * RAMP_ANGLE) & (cols["broken_bonds"] == 0) & (cols["elastic"] > 0)
    per_law = {}
    for law in laws:
        s = crack_summary(th, cols[f"R_ratio_{law}"], cols["broken_bonds"])
        per_law[law] = {"R_ratio_at": ratio_at(th, cols[f"R_ratio_{law}"], ANGLES), "theta_R_rise": s["theta_R_rise"],
                        "theta_separation": s["theta_separation"], "engine_share": shares[law],
                        "R0": float(cols[f"R_{law}"][0]),
                        "R0_nominal_error_pct": float(100 * (cols[f"R_{law}"][0] /
                                                             (RESISTIVITY * LENGTH / (math.pi * RADIUS ** 2)) - 1))}
    summary = crack_summary(th, cols[f"R_ratio_{laws[0]}"], cols["broken_bonds"])
    out = {"case": "pin_torsion", "law": laws[0], "n": int(len(pin["ids"])), "n_target": int(n), "seed": int(seed),
           "elastic_torque_error_pct": float(100 * (slope / ref_slope - 1)),
           "theta_first_break": summary["theta_first_break"],
           "theta_first_break_vs_yield_pct": (None if summary["theta_first_break"] is None else
                                              float(100 * (summary["theta_first_break"] / theta_y - 1))),
           "R_ratio_at": per_law[laws[0]]["R_ratio_at"], "theta_R_rise": per_law[laws[0]]["theta_R_rise"],
           "theta_separation": summary["theta_separation"], "wall_s": wall,
           "engine_share": float(sum(shares.values())), "engine_share_by_law": shares,
           "laws": per_law, "moment_check_share": check_share, "broken_by_moment": check.broken,
           "theta_yield": theta_y, "theta_yield_nominal": yield_angle(SHEAR_YIELD, SHEAR_MODULUS,
                                                                                        RADIUS, LENGTH),
           "free_length": h, "rate": rate, "rate_factor": rate_factor, "every": every, "steps": int(O.iter),
           "dt": float(O.dt), "bonds": int(state["keys"].size), "grip_bonds": pin["grip_bonds"],
           "broken_final": summary["broken_final"], "broken_at_separation": summary["broken_at_separation"],
           "max_torque": float(np.max(cols["torque"])), "max_tau_ratio": float(np.max(cols["tau_ratio"])),
           "kinetic_to_elastic_max": float(np.max(cols["kinetic"][pre] / cols["elastic"][pre])) if pre.any() else None,
           "calibration": {k: cal[k] for k in ("young", "strength", "first_bond_mode")},
           "vtk": state["snap"].written if vtk else {}, "records": len(rows)}
    import csv
    csv_path = os.path.join(out_dir, f"{tag}.csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    out["csv"] = csv_path
    try:
        out["png"] = plot_pin(cols, laws, theta_y, os.path.join(out_dir, f"{tag}.png"), h, summary["theta_separation"])
    except Exception as exc:          # a plot failure must not lose the figures
        print(f"plot failed: {exc}", flush=True)
    for e in engines.values():
        e.remove()
    rig.remove()
    check.remove()
    return out


def plot_pin(cols, laws, theta_y, path, free_length=LENGTH, theta_separation=None):
    """Paper figure 16: torque (and tau/tau_y), R/R0 of each law and broken bonds against theta
    (the grey line: theta_y; the red one: separation, R = inf from there on)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    th = cols["theta"]
    fig, ax = plt.subplots(3, 1, figsize=(7, 9), sharex=True)
    ax[0].plot(th, cols["torque"], "k-", label="DEM torque")
    ax[0].plot(th, elastic_torque(SHEAR_MODULUS, RADIUS, free_length, th), "k:", label="G J theta / h")
    for a in ax:
        a.axvline(theta_y, color="grey", lw=0.8)
        if theta_separation is not None:
            a.axvline(theta_separation, color="red", lw=0.8, ls="--")
    ax[0].set_ylabel("torque [N m]")
    ax[0].legend(loc="upper left")
    t2 = ax[0].twinx()
    t2.plot(th, 100 * cols["tau_ratio"], alpha=0)
    t2.set_ylabel("tau / tau_y [%]")
    for law in laws:
        r = cols[f"R_ratio_{law}"]
        ax[1].plot(th[np.isfinite(r)], r[np.isfinite(r)], label=law)
    ax[1].set_ylabel("R / R0 (inf after the red line)")
    ax[1].set_yscale("log")
    ax[1].legend(loc="upper left")
    ax[2].plot(th, cols["broken_bonds"], "r-")
    ax[2].set_ylabel("broken bonds")
    ax[2].set_xlabel("twist angle theta [rad]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _params(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--law", default="both", choices=("both",) + LAWS,
                    help="engines to run (both: voronoi first, it is the JSON's 'law')")
    ap.add_argument("--rate-factor", type=float, default=1.0, help="twist rate / the paper's 375 rad/s")
    ap.add_argument("--every", type=int, default=100, help="steps between engine calls")
    ap.add_argument("--theta-max", type=float, default=0.16, help="stop at this twist [rad] (or once separated)")
    ap.add_argument("--calibrate", action="store_true", help="redo the calibration for --n/--seed and keep it")
    ap.add_argument("--no-vtk", action="store_true")
    ap.add_argument("--out", default="out/pin_torsion")
    return ap.parse_args(argv)


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("n", "seed", "law", "rate_factor", "every"))
    if args.calibrate:
        cal = calibrate(args.n, args.seed)
        kept = _kept_calibrations()
        kept[f"n{args.n}_s{args.seed}"] = cal
        with open(CALIBRATION_FILE, "w") as fh:
            json.dump(kept, fh, indent=1)
        print(f"calibration n={cal['n']}: bond modulus {cal['young'] / 1e9:.2f} GPa, strength "
              f"{cal['strength'] / 1e6:.1f} MPa (first bond in {cal['first_bond_mode']}), kept in {CALIBRATION_FILE}")
        print(json.dumps(dict(case="pin_torsion_calibration", **cal)))
        return cal
    laws = LAWS if args.law == "both" else (args.law,)
    row = run_pin(args.n, args.seed, laws, args.rate_factor, args.every, args.theta_max, out_dir=args.out,
                  vtk=not args.no_vtk)
    with open(os.path.join(args.out, os.path.basename(row["csv"]).replace(".csv", ".json")), "w") as fh:
        json.dump(row, fh)
    s = row
    print(f"pin {s['n']} elements: elastic torque {s['elastic_torque_error_pct']:+.2f} % against G J theta / h, "
          f"first break at {s['theta_first_break']} rad (theta_y {s['theta_yield']:.4f}), separation at "
          f"{s['theta_separation']} rad")
    for law, d in s["laws"].items():
        print(f"  {law}: R/R0 at {d['R_ratio_at']}, R +1/10/100 % at {d['theta_R_rise']}, engine share "
              f"{100 * d['engine_share']:.1f} %")
    print(json.dumps(row))
    return row


if __name__ == "__main__":
    main()
