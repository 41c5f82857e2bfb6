"""Thermal cracking of a notched cast-iron bar heated by a current (issue 34, item 5).

The notched bar of ``cases/notched_joule.py`` (6 x 1.1 x 1.1 mm, two 0.6 x 0.3 mm notches at
mid-length, ligament 0.5 mm), with brittle bonds (``CohFrictMat``, ``fragile``, normal and
shear cohesion ``--strength``), goes through a resistance-heating cycle:

1. **heating**, ``--t-heat`` of current at ``--voltage`` between the two end layers, which are
   the copper grips: held at T0 (``FixedTemperature``), the end x = 0 on rollers, the end
   x = L free, so the bar expands freely (``ThermalExpansion(mode='bonds')``);
2. **gripped hot**: the end layer x = L is then held in x where it is;
3. **cooling** through the grips, with the current down to ``--sense`` volts (a measuring
   current: 1/625 of the heating power at the defaults) so that R(t) is still measured. The
   bar contracts against the grips; the tension, highest across the ligament, breaks bonds
   there until the bar separates (R_eq infinite) or ``--t-cool`` has passed.

All three engines run in the YADE loop: ``ElectroThermalEngine`` (voronoi law, a broken bond
conducts neither current nor heat: crack facets), ``ThermalExpansion`` and YADE's cohesive law,
which breaks the bonds. The heat runs on its own clock (``Integrator(dt=...)``, one thermal
step per call); after each call YADE relaxes ``--steps`` mechanical steps, and more with the
engines idle, until the relaxation is quasi-static (see :func:`run`). rho_e does not depend on
T (``beta = 0``), so R(t) shows the cracks alone.

Figures, per call (the CSV): thermal time, phase, voltage, current, R_eq and the temperatures
(T_max, the ligament slab's mean, the mean) of the call; then, after the relaxation that follows
it, broken bonds (in the ligament slab and elsewhere, read in the scene), the grip's force and
that force over the ligament's 0.5 x 1.1 mm section, the ligament slab's and the bar's mean
Love-Weber sigma_xx, the free elements' mean |force| over the bonds' mean |normal force| (how
quasi-static the relaxation is; YADE's unbalancedForce counts the grips' reactions), and the
energy ledger. The JSON line has the onset (first broken bond: time, temperatures), the
ligament's sigma_xx at the last call before it, the separation, R/R0, and two balances:

* ``ledger_error``: heat content - (Joule heat - absorbed heat + boundary heat) over the
  Joule heat, at the end (the heat solver's own conservation);
* ``electrical_work_error``: sum of V I dt over the calls against the Joule heat (what the
  electrodes put in against what the elements dissipated).

Then (unless ``--no-pull``) the same bar is pulled at T0 by its grip at a constant speed
(strain 4e-4 over 20,000 steps): ``mechanical_strength_Pa``, the grip's peak force over the
ligament section, and ``thermal_over_mechanical``, the bracket of the thermal run's ligament
strength over it: the ligament's sigma_xx at the last call before the onset (the crack starts
within the relaxation that follows) and the peak sigma_xx of the run.

VTK (``--out/vtk``): elements (temperature, potential, displacement, Love-Weber stress, broken
bonds per element) and every initial bond (``broken`` = 1 once broken) at the end of heating,
at the onset and at the end: the crack pattern.

Run::

    yade-electro -n -x cases/thermal_cracking.py                  # 5,000 elements
    yade-electro -n -x cases/thermal_cracking.py --quick          # 1,500 elements (the CI test)
    yade-electro -n -x cases/thermal_cracking.py --voltage 0.1    # below the threshold: no crack
    yade-electro -n -x cases/thermal_cracking.py --clamped --voltage 0.5 --t-heat 0.3 --t-cool 0 --no-pull

With ``--clamped`` both grips hold the bar from the start: the heating itself loads it in
compression and the bonds break while the current flows (``T_ligament_at_grip_K`` is then the
end of heating; ``min_ligament_sxx_Pa`` the largest compression).

Ends with one JSON line.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time

import numpy as np

_NAME = "thermal_cracking.py"
HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith(_NAME) else __file__))
for d in (HERE, os.path.dirname(HERE)):
    if d not in sys.path:
        sys.path.insert(0, d)

import notched_joule as NJ  # noqa: E402

# grey cast iron (ASM handbook ranges: rho_e 0.7-1.1 uOhm m, lambda 40-55 W/(m K), alpha 1.0-1.2e-5 1/K)
RHO_E = 1.0e-6          # ohm m
CONDUCTIVITY = 46.0     # W/(m K)
DENSITY = 7150.0        # kg/m^3
SPECIFIC_HEAT = 490.0   # J/(kg K)
ALPHA = 1.05e-5         # 1/K
T0 = 293.0              # K
STRENGTH = 2.0e8        # Pa, the bonds' normal and shear cohesion
LIGAMENT_AREA = (NJ.WIDTH - 2 * NJ.NOTCH_DEPTH) * NJ.THICKNESS   # m^2


def _say(msg):
    sys.stderr.write(f"[thermal_cracking] {msg}\n")
    sys.stderr.flush()


def cast_iron(strength):
    """The bonds: 304L's elastic constants with brittle cohesion ``strength`` [Pa]."""
    from yade_electro.yade.bonding import steel_304L
    return steel_304L(density=DENSITY, normalCohesion=float(strength), shearCohesion=float(strength),
                      fragile=True, label="cast_iron")


def build(n, seed, strength, cache_dir=None):
    """Reset YADE's scene, add the bonded notched bar (every element at T0) and hold the end
    x = 0 on rollers (its end layer held in x, one element in x, y, z, one in x, z). Returns
    (ids, bodies, reference positions, end layers, mean radius)."""
    from yade import O
    from yade_electro.yade import ensure_thermal_state
    from yade_electro.yade import packing as P
    O.reset()
    pk = P.dense_packing(NJ.bar_shape(), n=n, seed=seed, cache_dir=cache_dir)
    ids = np.asarray(P.add_bonded_packing(pk, material=cast_iron(strength), damping=0.5))
    bodies = [O.bodies[int(i)] for i in ids]
    ensure_thermal_state(bodies)
    for b in bodies:
        b.state.temp = T0
    r_mean = float(pk.radii.mean())
    x0 = pk.centers.copy()
    end0, end1 = NJ.end_layers(x0[:, 0], pk.radii, r_mean, 0.1)
    NJ.hold_on_rollers(bodies, x0, end0)
    return ids, bodies, x0, end0, end1, r_mean


def bond_keys(a, b):
    """One int64 key per bond of body ids ``a`` and ``b`` (either order)."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    return lo.astype(np.int64) << 32 | hi.astype(np.int64)


def cohesive_pairs(ids) -> np.ndarray:
    """(m, 2) body ids of the scene's unbroken cohesive bonds between ``ids`` (YADE's
    ``CohFrictPhys.cohesionBroken`` is False), read now."""
    from yade import O
    inside = set(int(i) for i in ids)
    out = [(i.id1, i.id2) for i in O.interactions
           if i.isReal and not i.phys.cohesionBroken and i.id1 in inside and i.id2 in inside]
    return np.asarray(out, np.int64).reshape(-1, 2)


class InitialBonds:
    """The scene's cohesive bonds between ``ids`` now, and later which of them are broken.

    Attributes
    ----------
    pairs : (m, 2) the bonds as indices into ``ids``
    """

    def __init__(self, ids):
        pair = cohesive_pairs(ids)
        self.ids, self.keys = ids, bond_keys(pair[:, 0], pair[:, 1])
        self.pairs = np.searchsorted(ids, pair)

    def broken(self) -> np.ndarray:
        """Which of the bonds are broken in the scene now (m,)."""
        now = cohesive_pairs(self.ids)
        return ~np.isin(self.keys, bond_keys(now[:, 0], now[:, 1]))


class _Crack(InitialBonds):
    """The initial bonds, which of them are broken (in the scene, now), the ligament's, and the
    VTK snapshots of the crack pattern."""

    def __init__(self, ids, x0, out_dir):
        super().__init__(ids)
        self.x0 = x0
        mid = 0.5 * (x0[self.pairs[:, 0], 0] + x0[self.pairs[:, 1], 0])
        self.in_ligament = np.abs(mid - 0.5 * NJ.LENGTH) <= 0.5 * NJ.NOTCH_WIDTH
        self.dir = os.path.join(out_dir, "vtk") if out_dir else None
        self.written = {}

    def write(self, stage, engine, stress, broken, pos, time_s):
        if self.dir is None or stage in self.written:
            return
        from yade_electro.post.vtk import write_bonds, write_elements
        nb = np.zeros(self.ids.size)
        np.add.at(nb, self.pairs[broken].ravel(), 1.0)
        order = np.searchsorted(engine.body_ids, self.ids)
        fields = {"temperature_K": engine.temperature[order], "potential_V": engine.potential[order],
                  "displacement_m": np.linalg.norm(pos - self.x0, axis=1), "broken_bonds": nb,
                  "s_xx_Pa": stress[:, 0, 0], "s_yy_Pa": stress[:, 1, 1], "s_zz_Pa": stress[:, 2, 2]}
        r = np.asarray(engine.graph.radius)[order]
        os.makedirs(self.dir, exist_ok=True)
        self.written[stage] = {
            "time_s": time_s,
            "elements": write_elements(os.path.join(self.dir, f"cracking_{stage}_elements.vtu"), pos, r, fields),
            "bonds": write_bonds(os.path.join(self.dir, f"cracking_{stage}_bonds.vtu"), pos, self.pairs,
                                 {"broken": broken.astype(float)})}


def pull_strength(n, seed, strength, cache_dir=None, strain=4e-4, steps=20000, every=200):
    """The same bar pulled at T0 (the grip at x = L moved at a constant speed, the end x = 0
    on rollers, no heat): the grip's force over the ligament section [Pa] at its peak, the
    mechanical counterpart of the thermal onset. Resets YADE's scene."""
    from yade import O
    ids, bodies, x0, end0, end1, r_mean = build(n, seed, strength, cache_dir)
    speed = strain * NJ.LENGTH / (steps * O.dt)
    for k in np.flatnonzero(end1):
        bodies[k].state.blockedDOFs = "x"
        bodies[k].state.vel = (speed, 0, 0)
    crack = _Crack(ids, x0, None)
    peak, history = 0.0, []
    for _ in range(steps // every):
        O.run(every, True)
        stress = -float(sum(O.forces.f(int(i))[0] for i in ids[end1])) / LIGAMENT_AREA
        history.append(stress)
        peak = max(peak, stress)
        if peak > 0 and stress < 0.1 * peak and crack.broken().any():
            break
    broken = crack.broken()
    return {"mechanical_strength_Pa": peak, "pull_strain_at_peak": float(np.argmax(history) + 1) * every * speed
            * O.dt / NJ.LENGTH, "pull_broken_bonds": int(broken.sum()),
            "pull_broken_in_ligament": int((broken & crack.in_ligament).sum())}


def run(n=5000, seed=1, voltage=0.25, t_heat=0.5, t_cool=1.5, dt=0.01, steps=300, strength=STRENGTH, sense=0.01,
        tol=0.01, max_extra=10, clamped=False, out_dir="out/thermal_cracking", vtk=True, cache_dir=None):
    """The heating-gripping-cooling cycle (see the module doc); returns the figures and writes
    the CSV (one row per call) and the VTK snapshots. After each call YADE relaxes ``steps``
    steps, and more (the engines idle) until the free elements' mean |force| is below ``tol``
    of the bonds' mean |normal force| (at most ``max_extra`` more chunks). Resets YADE's scene."""
    from yade import O
    from yade_electro.yade import (ElectroThermalEngine, FixedTemperature, Integrator, Material, Output,
                                   ThermalExpansion, electrodes_from_dict)
    t_start = time.time()
    ids, bodies, x0, end0, end1, r_mean = build(n, seed, strength, cache_dir)
    _say(f"{len(ids)} elements, r_mean {r_mean * 1e6:.1f} um, {int(end0.sum())} + {int(end1.sum())} in the grips")
    grips = np.concatenate([ids[end0], ids[end1]])
    engine = ElectroThermalEngine(
        material=Material(resistivity=RHO_E, density=DENSITY, specific_heat=SPECIFIC_HEAT,
                          conductivity=CONDUCTIVITY, beta=0.0),
        boundaries=electrodes_from_dict({"end1": dict(select=ids[end1], potential=voltage),
                                         "end0": dict(select=ids[end0], potential=0.0)})
        + [FixedTemperature("grips", nodes=grips.tolist(), temperature=T0)],
        temperature=T0, integrator=Integrator(theta="backward-euler", dt=dt), output=Output(write_back=None),
        iterPeriod=steps, label="cracking_heat")
    expansion = ThermalExpansion(alpha=ALPHA, mode="bonds", reference_temperature=T0, iterPeriod=steps,
                                 label="cracking_expansion")
    for r in (engine.runner, expansion.runner):
        r.initRun = True                # called at the first step of each chunk of ``steps``, then YADE relaxes
    O.engines = O.engines + [engine.runner, expansion.runner]
    crack = _Crack(ids, x0, out_dir if vtk else None)
    if clamped:                                     # the far grip holds the bar from the start
        for k in np.flatnonzero(end1):
            bodies[k].state.blockedDOFs = "x"
    lig = np.abs(x0[:, 0] - 0.5 * NJ.LENGTH) <= 0.5 * NJ.NOTCH_WIDTH
    inner = np.flatnonzero(~end0 & ~end1)
    volume = expansion.element_volumes()

    def measure(read=None):
        """The scene after a relaxation (``read``: its interactions, if read already):
        positions, stress, broken bonds, the free elements' mean |force| over the bonds' mean
        |normal force| (YADE's unbalancedForce counts the grips' reactions), the grip's force [N]."""
        read = expansion.read_interactions() if read is None else read
        grip = float(sum(O.forces.f(int(i))[0] for i in ids[end1]))
        return read[0], expansion.element_stress(read), crack.broken(), unbalanced(read), grip

    def unbalanced(read=None):
        fn, _ = expansion.bond_forces(read)
        f_free = np.mean([np.linalg.norm(O.forces.f(int(i))) for i in ids[inner]])
        return float(f_free / max(np.abs(fn).mean(), 1e-300))

    order = None
    rows, work, phase, t_grip = [], 0.0, "heating", None
    n_calls = int(round(t_heat / dt)) + int(round(t_cool / dt))
    every = max(1, n_calls // 20)
    for call in range(n_calls):
        if phase == "heating" and engine.coupled.time >= t_heat - 1e-12:
            pos, stress, broken, _, _ = measure()
            crack.write("heated", engine, stress, broken, pos, engine.coupled.time)
            for k in np.flatnonzero(end1):          # the grip closes on the hot bar
                bodies[k].state.blockedDOFs = "x"
                bodies[k].state.vel = (0, 0, 0)
            engine.set_electrode("end1", sense)
            phase, t_grip = "cooling", engine.coupled.time
        O.run(steps, True)                          # the engines' call, then the relaxation
        read, extra = expansion.read_interactions(), 0
        while unbalanced(read) > tol and extra < max_extra:   # until quasi-static: the engines wait meanwhile
            for r in (engine.runner, expansion.runner):
                r.dead = True
            O.run(steps, True)
            for r in (engine.runner, expansion.runner):
                r.dead = False
            read, extra = expansion.read_interactions(), extra + 1
        h = engine.history.rows[-1]
        if order is None:
            order = np.searchsorted(engine.body_ids, ids)
        T = engine.temperature[order]
        pos, stress, broken, ub, grip = measure(read)
        R = float(h["R_eq"])
        work += float(h["voltage"]) * float(h["current"]) * float(h["dt"])
        row = {"call": call, "time_s": float(h["time"]), "phase": phase, "voltage_V": float(h["voltage"]),
               "current_A": float(h["current"]), "R_eq_ohm": R, "T_max_K": float(T.max()),
               "T_ligament_K": float(T[lig].mean()), "T_mean_K": float(h["T_mean"]),
               "broken_bonds": int(broken.sum()), "broken_in_ligament": int((broken & crack.in_ligament).sum()),
               "grip_force_N": grip, "grip_stress_Pa": -grip / LIGAMENT_AREA,
               "ligament_sxx_Pa": float(np.sum(volume[lig] * stress[lig, 0, 0]) / volume[lig].sum()),
               "bar_sxx_Pa": float(np.sum(volume * stress[:, 0, 0]) / volume.sum()),
               "unbalanced": ub, "relax_chunks": 1 + extra, "joule_energy_J": float(h["joule_energy"]),
               "electrical_work_J": work, "heat_content_J": float(h["heat_content"]),
               "absorbed_heat_J": float(h["absorbed_heat"]), "boundary_heat_J": float(h["boundary_heat"])}
        rows.append(row)
        if row["broken_bonds"] and "onset" not in crack.written:
            crack.write("onset", engine, stress, broken, pos, row["time_s"])
        if call % every == 0 or row["broken_bonds"] and len(rows) > 1 and not rows[-2]["broken_bonds"]:
            _say(f"t {row['time_s']:.3f} s {phase}: R {R:.5e} ohm, T_lig {row['T_ligament_K']:.1f} K, "
                 f"ligament sigma_xx {row['ligament_sxx_Pa'] / 1e6:.1f} MPa, broken {row['broken_bonds']}")
        if not np.isfinite(R):
            _say(f"separated at t = {row['time_s']:.3f} s")
            break
    crack.write("end", engine, stress, broken, pos, rows[-1]["time_s"])
    if out_dir:
        os.makedirs(out_dir, exist_ok=True)
        with open(os.path.join(out_dir, f"thermal_cracking_n{n}.csv"), "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        plot(rows, os.path.join(out_dir, f"thermal_cracking_n{n}.png"))
    out = summary(rows, t_grip, len(ids), r_mean, strength, voltage)
    out.update({"vtk": crack.written, "wall_s": round(time.time() - t_start, 1), "steps_per_call": steps,
                "dt_thermal_s": dt})
    engine.remove()
    expansion.remove()
    return out


def plot(rows, path):
    """R/R0, temperatures, the ligament's stress and the broken bonds against the thermal time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = np.array([r["time_s"] for r in rows])
    R = np.array([r["R_eq_ohm"] for r in rows])
    fig, ax = plt.subplots(4, 1, figsize=(6, 8), sharex=True)
    ax[0].plot(t, np.where(np.isfinite(R), R / R[0], np.nan), "k.-")
    ax[0].set_ylabel("R / R0")
    ax[1].plot(t, [r["T_ligament_K"] for r in rows], label="ligament")
    ax[1].plot(t, [r["T_mean_K"] for r in rows], label="mean")
    ax[1].set_ylabel("T [K]")
    ax[1].legend()
    ax[2].plot(t, [r["ligament_sxx_Pa"] / 1e6 for r in rows], label="ligament, Love-Weber")
    ax[2].plot(t, [r["grip_stress_Pa"] / 1e6 for r in rows], "--", label="grip force / ligament section")
    ax[2].set_ylabel("sigma_xx [MPa]")
    ax[2].legend()
    ax[3].plot(t, [r["broken_bonds"] for r in rows], "r.-")
    ax[3].set_ylabel("broken bonds")
    ax[3].set_xlabel("thermal time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def summary(rows, t_grip, n, r_mean, strength, voltage) -> dict:
    """The JSON figures of a run's rows."""
    last = rows[-1]
    heated = [r for r in rows if r["phase"] == "heating"]
    onset = next((r for r in rows if r["broken_bonds"]), None)
    sep = next((r for r in rows if not np.isfinite(r["R_eq_ohm"])), None)
    intact = [r for r in rows if not r["broken_bonds"]]
    R0 = rows[0]["R_eq_ohm"]
    finite = [r["R_eq_ohm"] for r in rows if np.isfinite(r["R_eq_ohm"])]
    joule = last["joule_energy_J"]
    ledger = last["heat_content_J"] - (joule - last["absorbed_heat_J"] + last["boundary_heat_J"])
    return {"case": "thermal_cracking", "elements": n, "r_mean_m": r_mean, "bond_strength_Pa": strength,
            "voltage_V": voltage, "t_grip_s": t_grip,
            "T_ligament_at_grip_K": heated[-1]["T_ligament_K"] if heated else None,
            "T_max_at_grip_K": heated[-1]["T_max_K"] if heated else None,
            "R0_ohm": R0, "R_last_finite_over_R0": finite[-1] / R0,
            "onset": None if onset is None else {k: onset[k] for k in (
                "time_s", "phase", "T_ligament_K", "T_mean_K", "broken_bonds")},
            "peak_ligament_sxx_Pa": max(r["ligament_sxx_Pa"] for r in rows),
            "min_ligament_sxx_Pa": min(r["ligament_sxx_Pa"] for r in rows),
            "ligament_sxx_before_onset_Pa": intact[-1]["ligament_sxx_Pa"] if onset is not None and intact else None,
            "peak_grip_stress_Pa": max(r["grip_stress_Pa"] for r in rows),
            "separated_at_s": None if sep is None else sep["time_s"],
            "broken_bonds": last["broken_bonds"], "broken_in_ligament": last["broken_in_ligament"],
            "joule_energy_J": joule, "electrical_work_J": last["electrical_work_J"],
            "ledger_error": abs(ledger) / joule,
            "electrical_work_error": abs(last["electrical_work_J"] - joule) / joule,
            "max_unbalanced": max(r["unbalanced"] for r in rows), "calls": len(rows),
            "relax_chunks": int(sum(r["relax_chunks"] for r in rows))}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--quick", action="store_true", help="1,500 elements, 0.02 s thermal steps, 200 steps per call")
    ap.add_argument("--voltage", type=float, default=0.25, help="heating voltage [V]")
    ap.add_argument("--sense", type=float, default=0.01, help="measuring voltage while cooling [V]")
    ap.add_argument("--t-heat", type=float, default=0.5, help="heating time [s]")
    ap.add_argument("--t-cool", type=float, default=1.5, help="longest cooling time [s]")
    ap.add_argument("--dt", type=float, default=0.01, help="thermal step [s]")
    ap.add_argument("--steps", type=int, default=300, help="mechanical steps between two calls")
    ap.add_argument("--strength", type=float, default=STRENGTH, help="bond cohesion [Pa]")
    ap.add_argument("--out", default="out/thermal_cracking")
    ap.add_argument("--no-vtk", action="store_true")
    ap.add_argument("--no-pull", action="store_true", help="leave out the mechanical pull of the same bar")
    ap.add_argument("--clamped", action="store_true", help="both grips hold the bar from the start")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    if args.quick:
        args.n, args.dt, args.steps = 1500, 0.02, 200
    out = run(n=args.n, voltage=args.voltage, t_heat=args.t_heat, t_cool=args.t_cool, dt=args.dt, steps=args.steps,
              strength=args.strength, sense=args.sense, clamped=args.clamped, out_dir=args.out, vtk=not args.no_vtk,
              cache_dir=args.cache_dir)
    if not args.no_pull:
        _say("the same bar pulled at T0, for its mechanical strength")
        out.update(pull_strength(args.n, 1, args.strength, cache_dir=args.cache_dir))
        before = out["ligament_sxx_before_onset_Pa"]
        mech = out["mechanical_strength_Pa"]
        # the crack starts within the relaxation after the last intact call: its strength lies
        # between that call's stress and the peak stress reached
        out["thermal_over_mechanical"] = None if before is None else [before / mech, out["peak_ligament_sxx_Pa"] / mech]
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
