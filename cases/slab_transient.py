"""Transient conduction in a 1D slab (paper 003, "FEM and FDEM perfect contact conduction
validation"): the thermal integrators against the analytic series.

Set-up (paper 003): a slab 0 <= x <= L = 1 m, initially at T_i = 0, insulated at x = 0 and
held at T_D = 1 at x = L from t = 0 (degC in the paper; only differences matter), no heat
source. The paper's material table (its Table 1) is not in our copy of the text; we take
lambda = 1 W/(m K), rho = 100 kg/m^3, c = 1 J/(kg K), i.e. alpha = 0.01 m^2/s, so that the
paper's output times 10, 50 and 100 s are Fo = alpha t / L^2 = 0.1, 0.5 and 1.0. Everything
is reported in Fourier numbers, so the choice does not matter.

Analytic solution (Carslaw & Jaeger; paper 003 prints the eigenvalues as ``n - pi/2``, a
typo for ``(n - 1/2) pi``):

    (T - T_D) / (T_i - T_D) = sum_n 4 sin(l_n) / (2 l_n + sin 2 l_n) cos(l_n x / L) exp(-l_n^2 Fo)
                            = sum_n 2 (-1)^(n+1) / l_n cos(l_n x / L) exp(-l_n^2 Fo),
    l_n = (n - 1/2) pi

(:func:`yade_electro.fem.closed_forms.slab_temperature`, 400 terms).

The DEM slab, and why a lattice
-------------------------------
A simple-cubic column of touching spheres, ``layers + 1`` layers along x of 2 x 2 elements
(spacing h = 2 r = L / (layers + 1/2)), in the box container 0 <= x <= (layers + 1) h. The
first layer touches the insulated wall x = 0 (nothing to impose: no bond crosses it); the
last layer is the fixed-temperature set and its centres sit on x = L, as electrodes sit on
element centres in paper 000's rod (the analytic slab is the part between the wall and
these centres). Conductances come from the 'voronoi' law and capacities from the bounded
Voronoi cells (:func:`yade_electro.geometry.voronoi.voronoi_cell_volumes`): every cell is the cube
h^3 and every bond conducts lambda h, so the DEM is exactly the cell-centred finite-volume
scheme of the 1D equation (second order in h) and the comparison measures the time
integrators, not the packing. A random packed bar would add the packing's own
conductivity and capacity errors (those are the rod cases' subject) and has no exact 1D
node positions. The 2 x 2 section (rather than a chain of single elements) makes it a true
3D lattice with lateral bonds: they carry no heat in this 1D problem, but they set the
explicit stability limit, which is the point of the stability part below.

What is reported
----------------
* The max error over the free elements, |T - T_exact| / |T_D - T_i|, at Fo = 0.05, 0.1,
  0.2, 0.5, 1.0, for: the semi-discrete solution (exact in time, matrix exponential: the
  spatial error alone); explicit (theta = 0) at its stable step; explicit sub-cycled
  (asked for 100 x the stable step); Crank-Nicolson and backward Euler at 1, 10 and 100 x the
  explicit limit (steps shortened to land on the output times).
* The largest stable step: explicit: the HeatSolver bound min C_i / sum_j G_ij (the maximum
  principle), the true limit 2 / lambda_max(C^-1 M) and paper 000's l_min^2 / (2 alpha).
  With sub-cycling off, the HeatSolver refuses any step above its bound (ThermalError, shown);
  growth and decay around the true limit are shown with plain forward-Euler loops on the
  same matrices, with the initial temperatures perturbed by 1e-10 (a perfectly symmetric
  lattice would leave the unstable lateral modes at round-off). theta >= 1/2: no limit;
  shown at 100 x and 1000 x (Crank-Nicolson stays bounded but overshoots; backward Euler
  keeps the maximum principle).

Run (no YADE needed; also ``yade-electro -n -x cases/slab_transient.py``)::

    python3 cases/slab_transient.py [--layers 20] [--out out/slab_transient]

Writes slab_transient.csv (errors), slab_transient_stability.csv, slab_transient.png and
ends with one JSON line. Importable (``slab_model``, ``run_integrator``, ``stability``).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("slab_transient.py") else (sys.argv[0] if sys.argv and sys.argv[0].endswith("slab_transient.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))

from yade_electro.core.errors import ThermalError  # noqa: E402
from yade_electro.fem.closed_forms import slab_temperature  # noqa: E402
from yade_electro.core.graph import ContactGraph  # noqa: E402
from yade_electro.network.heat_conditions import FixedTemperature  # noqa: E402
from yade_electro.network.transient import HeatSolver  # noqa: E402
from yade_electro.physics.thermal import diffusion_time_step  # noqa: E402
from yade_electro.geometry.voronoi import voronoi_cell_volumes  # noqa: E402

LENGTH = 1.0            # m (paper 003)
T_INITIAL = 0.0         # paper 003: 0 degC
T_WALL = 1.0            # paper 003: 1 degC at x = L
CONDUCTIVITY = 1.0      # W/(m K)   (our choice, see the module doc)
DENSITY = 100.0         # kg/m^3
SPECIFIC_HEAT = 1.0     # J/(kg K)
ALPHA = CONDUCTIVITY / (DENSITY * SPECIFIC_HEAT)
FOURIER = (0.05, 0.1, 0.2, 0.5, 1.0)
#: integrators: (name, theta, step as a multiple of the explicit limit, subcycle)
INTEGRATORS = (("explicit", 0.0, 1.0, False), ("explicit sub-cycled", 0.0, 100.0, True),
               ("crank-nicolson", 0.5, 1.0, False), ("crank-nicolson", 0.5, 10.0, False),
               ("crank-nicolson", 0.5, 100.0, False),
               ("backward-euler", 1.0, 1.0, False), ("backward-euler", 1.0, 10.0, False),
               ("backward-euler", 1.0, 100.0, False))


class SlabModel:
    """The DEM slab: graph, container, fixed layer, capacities, conductances, positions."""

    def __init__(self, layers=20, cross=2, length=LENGTH, conductivity=CONDUCTIVITY, density=DENSITY,
                 specific_heat=SPECIFIC_HEAT):
        from yade_electro.geometry.shapes import Box  # numpy only (no YADE import)
        from yade_electro.laws.factors import conductance
        self.layers, self.cross, self.length = int(layers), int(cross), float(length)
        self.h = h = length / (layers + 0.5)
        nx, ny, nz = layers + 1, cross, cross
        k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
        ijk = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
        idx = np.arange(ijk.shape[0])
        edges = []
        for axis, n_axis in enumerate((nx, ny, nz)):
            has = ijk[:, axis] < n_axis - 1
            edges.append(np.stack([idx[has], idx[has] + (1, nx, nx * ny)[axis]], axis=1))
        pos = (ijk + 0.5) * h
        self.graph = ContactGraph(pos, np.full(pos.shape[0], 0.5 * h), np.concatenate(edges))
        self.container = Box((0, 0, 0), (nx * h, ny * h, nz * h))
        self.layer = ijk[:, 0]
        self.fixed = self.layer == layers
        self.x = pos[:, 0]
        self.material = dict(density=density, specific_heat=specific_heat, conductivity=conductivity)
        self.alpha = conductivity / (density * specific_heat)
        self.cell_volume = voronoi_cell_volumes(pos, self.graph.radius, self.container)
        self.G = conductance(self.graph, 1.0 / conductivity, "voronoi", container=self.container)
        # the lattice is the exact cell-centred finite-volume scheme: check it
        self.fv_exact = max(float(np.max(np.abs(self.cell_volume / h ** 3 - 1))),
                            float(np.max(np.abs(self.G / (conductivity * h) - 1))))

    def solver(self, theta, subcycle=True, safety=0.9, temperature=T_INITIAL, **kw) -> HeatSolver:
        return HeatSolver(density_times(self) * self.cell_volume, self.graph.edges, self.G, temperature,
                          conditions=[FixedTemperature("x=L", self.fixed, T_WALL)], theta=theta, subcycle=subcycle,
                          safety=safety, **kw)

    def exact(self, fo):
        """Analytic temperatures at the free elements at Fourier number ``fo``."""
        t = fo * self.length ** 2 / self.alpha
        return slab_temperature(self.x[~self.fixed], t, self.length, self.alpha, T_INITIAL, T_WALL)

    def error(self, T, fo) -> float:
        """max |T - T_exact| / |T_D - T_i| over the free elements."""
        return float(np.max(np.abs(np.asarray(T)[~self.fixed] - self.exact(fo))) / abs(T_WALL - T_INITIAL))

    def limits(self) -> dict:
        """Explicit step limits [s]: ``bound`` = min C_i / sum G (HeatSolver), ``true`` = 2 /
        lambda_max of C^-1 M on the free nodes, ``paper`` = l_min^2 / (2 alpha)."""
        from yade_electro.network.kirchhoff import laplacian
        heat = self.solver(0.0)
        u = ~self.fixed
        K = laplacian(self.graph.edges, self.G, self.graph.n_nodes).tocsr()[u][:, u].toarray()
        c = heat.capacity[u]
        lam = np.linalg.eigvalsh(K / np.sqrt(np.outer(c, c)))
        m = self.material
        return {"bound": heat.critical_time_step, "true": 2.0 / float(lam.max()),
                "paper": diffusion_time_step(self.graph, m["conductivity"], m["density"], m["specific_heat"]),
                "lambda_max": float(lam.max()), "_K": K, "_c": c}


def density_times(model: SlabModel) -> float:
    return model.material["density"] * model.material["specific_heat"]


def fo_to_time(model, fo):
    return fo * model.length ** 2 / model.alpha


def semi_discrete(model: SlabModel, fourier=FOURIER) -> dict:
    """Errors of the semi-discrete solution (exact in time): the spatial error alone."""
    from scipy.linalg import expm
    lim = model.limits()
    K, c = lim["_K"], lim["_c"]
    A = -K / c[:, None]
    out = {}
    for fo in fourier:
        Tu = T_WALL + expm(A * fo_to_time(model, fo)) @ np.full(c.size, T_INITIAL - T_WALL)
        T = np.full(model.graph.n_nodes, T_WALL)
        T[~model.fixed] = Tu
        out[fo] = model.error(T, fo)
    return out


def run_integrator(model: SlabModel, theta, step_ratio, subcycle=False, fourier=FOURIER, dt_limit=None):
    """March from output to output with steps of at most ``step_ratio x dt_limit`` (default
    the explicit bound), shortened to land on each Fo. Returns (errors {Fo: err}, info)."""
    if dt_limit is None:
        dt_limit = model.solver(0.0).critical_time_step
    # the explicit scheme at its bound: use safety 1 (and no sub-cycling) so the step asked
    # for is the step taken
    heat = model.solver(theta, subcycle=subcycle, safety=1.0 if theta == 0 and not subcycle else 0.9)
    dt_max = step_ratio * dt_limit
    errors, profiles, t_prev, n_steps, n_sub, overshoot = {}, {}, 0.0, 0, 0, 0.0
    for fo in fourier:
        t = fo_to_time(model, fo)
        k = max(1, int(math.ceil((t - t_prev) / dt_max * (1 - 1e-12))))
        h = (t - t_prev) / k
        for _ in range(k):
            step = heat.advance(h)
            n_sub += step.n_substeps
            T = heat.temperature
            overshoot = max(overshoot, float(np.max(T) - T_WALL), float(T_INITIAL - np.min(T)))
        n_steps += k
        t_prev = t
        errors[fo] = model.error(heat.temperature, fo)
        profiles[fo] = heat.temperature.copy()
    return errors, {"steps": n_steps, "substeps": n_sub, "dt_max": dt_max, "overshoot": overshoot,
                    "profiles": profiles}


def forward_euler_growth(model: SlabModel, dt, n_steps=2000, noise=1e-10, seed=0):
    """Plain forward Euler (no guard) on the model's matrices, T_i perturbed by ``noise``:
    the max deviation from the analytic solution every 10 steps (array)."""
    lim = model.limits()
    K, c = lim["_K"], lim["_c"]
    from yade_electro.network.kirchhoff import laplacian
    u = ~model.fixed
    Kf = laplacian(model.graph.edges, model.G, model.graph.n_nodes).tocsr()
    kd = -(Kf[u][:, ~u] @ np.full(int((~u).sum()), T_WALL))     # heat from the fixed layer [W/K x K]
    rng = np.random.default_rng(seed)
    Tu = np.full(c.size, T_INITIAL) + noise * rng.standard_normal(c.size)
    dev = []
    xs = model.x[u]
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(1, n_steps + 1):
            Tu = Tu + dt / c * (kd - K @ Tu)
            if k % 10 == 0:
                ex = slab_temperature(xs, k * dt, model.length, model.alpha, T_INITIAL, T_WALL)
                dev.append(float(np.max(np.abs(Tu - ex))))
    return np.array(dev)


def stability(model: SlabModel, n_steps=2000) -> dict:
    """Explicit limits and the growth/decay demonstration (see the module doc)."""
    lim = model.limits()
    out = {k: lim[k] for k in ("bound", "true", "paper")}
    out["true_over_bound"] = lim["true"] / lim["bound"]
    out["paper_over_true"] = lim["paper"] / lim["true"]
    heat = model.solver(0.0, subcycle=False, safety=1.0)
    try:
        heat.advance(1.01 * lim["bound"])
        out["guard"] = "accepted"
    except ThermalError as exc:
        out["guard"] = f"ThermalError: {str(exc)[:90]}..."
    runs = {}
    for label, ratio in (("0.98 x true", 0.98), ("1.02 x true", 1.02)):
        dev = forward_euler_growth(model, ratio * lim["true"], n_steps)
        runs[label] = dev
    dev = forward_euler_growth(model, lim["paper"], n_steps=min(n_steps, 400))
    runs["paper l^2/(2 alpha)"] = dev
    dev0 = forward_euler_growth(model, lim["paper"], n_steps=min(n_steps, 400), noise=0.0)
    runs["paper, no perturbation"] = dev0
    out["final_deviation"] = {k: (float(v[-1]) if np.isfinite(v[-1]) else float("inf")) for k, v in runs.items()}
    out["series"] = runs
    # theta >= 1/2 far above the limit
    big = {}
    for name, theta in (("crank-nicolson", 0.5), ("backward-euler", 1.0)):
        for ratio in (100.0, 1000.0):
            err, info = run_integrator(model, theta, ratio, fourier=(1.0,), dt_limit=lim["bound"])
            big[f"{name} {ratio:g}x"] = {"error_Fo1": err[1.0], "overshoot": info["overshoot"],
                                         "steps": info["steps"]}
    out["implicit_far_above"] = big
    return out


def plot(model, results, stab, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    ax = axes[0]
    xs = np.linspace(0, model.length, 200)
    first = model.graph.pos[:, 1] < model.h        # one element per layer (the section is uniform)
    first &= model.graph.pos[:, 2] < model.h
    be = results["backward-euler 100x"]["profiles"]
    ex = results["explicit 1x"]["profiles"]
    for k, fo in enumerate(FOURIER):
        col = f"C{k}"
        ax.plot(xs, slab_temperature(xs, fo_to_time(model, fo), model.length, model.alpha, T_INITIAL, T_WALL),
                "-", color=col, lw=1, label=f"Fo = {fo:g}")
        sel = first
        ax.plot(model.x[sel], ex[fo][sel], "o", mfc="none", color=col, ms=4)
        ax.plot(model.x[sel], be[fo][sel], "x", color=col, ms=4)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("(T - T_i) / (T_D - T_i)")
    ax.set_title(f"slab, {model.layers} free layers (h = {model.h:.4g} m)\nlines: series, o explicit, "
                 "x backward Euler 100x")
    ax.legend(fontsize=7)
    ax = axes[1]
    for name, r in results.items():
        ax.semilogy(FOURIER, [max(r["errors"][fo], 1e-16) for fo in FOURIER], "o-" if "explicit" in name else
                    ("s--" if "crank" in name else "^:"), label=name, ms=4)
    ax.set_xlabel("Fourier number")
    ax.set_ylabel("max |T - T_exact| / |T_D - T_i|")
    ax.set_title("error against the analytic series")
    ax.set_ylim(1e-5, 3)
    ax.legend(fontsize=6, ncol=2, loc="lower left")
    ax = axes[2]
    for name, dev in stab["series"].items():
        steps = 10 * np.arange(1, len(dev) + 1)
        d = np.where(np.isfinite(dev), dev, np.nan)
        ax.semilogy(steps, np.clip(d, 1e-17, 1e30), label=name)
    ax.set_xlabel("forward-Euler steps")
    ax.set_ylabel("max |T - T_exact|")
    ax.set_title(f"forward Euler: true limit {stab['true']:.3g} s, bound {stab['bound']:.3g} s,\n"
                 f"paper l^2/(2 alpha) {stab['paper']:.3g} s (T_i perturbed by 1e-10)", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run_case(layers=20, out_dir="out/slab_transient", n_steps=2000, write=True):
    """Everything: errors table, limits, stability demo. Returns the JSON summary dict."""
    model = SlabModel(layers)
    lim = model.limits()
    results = {"semi-discrete": {"errors": semi_discrete(model), "steps": 0, "substeps": 0, "dt_max": 0.0,
                                 "overshoot": 0.0}}
    for name, theta, ratio, sub in INTEGRATORS:
        err, info = run_integrator(model, theta, ratio, subcycle=sub, dt_limit=lim["bound"])
        key = f"{name} {ratio:g}x" if name != "explicit sub-cycled" else "explicit sub-cycled (100x asked)"
        results[key] = dict(errors=err, **info)
    stab = stability(model, n_steps)
    summary = {
        "case": "slab_transient", "layers": model.layers, "h": model.h, "alpha": model.alpha, "length": model.length,
        "n_elements": int(model.graph.n_nodes), "finite_volume_exactness": model.fv_exact,
        "dt_explicit_bound": lim["bound"], "dt_explicit_true": lim["true"], "dt_paper": lim["paper"],
        "paper_over_true": stab["paper_over_true"], "guard_above_bound": stab["guard"],
        "forward_euler_final_deviation": stab["final_deviation"],
        "implicit_far_above": stab["implicit_far_above"],
        "errors": {name: {f"{fo:g}": r["errors"][fo] for fo in FOURIER} for name, r in results.items()},
        "max_error": {name: max(r["errors"].values()) for name, r in results.items()},
        "steps": {name: r["steps"] for name, r in results.items()},
        "overshoot": {name: r["overshoot"] for name, r in results.items()},
    }
    if write:
        os.makedirs(out_dir, exist_ok=True)
        import csv
        with open(os.path.join(out_dir, "slab_transient.csv"), "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["integrator", "dt_max_s", "dt_over_explicit_bound", "steps", "substeps", "overshoot"]
                       + [f"error_Fo_{fo:g}" for fo in FOURIER])
            for name, r in results.items():
                w.writerow([name, f"{r['dt_max']:.6g}", f"{r['dt_max'] / lim['bound']:.4g}", r["steps"], r["substeps"],
                            f"{r['overshoot']:.3e}"] + [f"{r['errors'][fo]:.4e}" for fo in FOURIER])
        with open(os.path.join(out_dir, "slab_transient_stability.csv"), "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["run", "step"] + ["max_deviation"])
            for name, dev in stab["series"].items():
                for k, d in enumerate(dev):
                    w.writerow([name, 10 * (k + 1), f"{d:.6e}"])
        plot(model, results, stab, os.path.join(out_dir, "slab_transient.png"))
    return summary, results, stab


def _params(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--layers", type=int, default=20, help="free element layers (h = L / (layers + 1/2))")
    ap.add_argument("--steps", type=int, default=2000, help="forward-Euler steps of the stability demo")
    ap.add_argument("--out", default="out/slab_transient")
    return ap.parse_args(argv)


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    summary, results, stab = run_case(args.layers, args.out, args.steps)
    print(f"slab L = {LENGTH} m, {args.layers} free layers of 2 x 2 elements, h = {summary['h']:.4g} m, "
          f"alpha = {ALPHA:g} m^2/s; lattice = finite volumes to {summary['finite_volume_exactness']:.1e}")
    print(f"explicit limits: bound min C/sum G = {stab['bound']:.4g} s, true 2/lambda_max = {stab['true']:.4g} s "
          f"({stab['true_over_bound']:.3f} x bound), paper l^2/(2 alpha) = {stab['paper']:.4g} s "
          f"({stab['paper_over_true']:.2f} x true)")
    print(f"{'integrator':34s}{'steps':>7s}{'sub':>7s}" + "".join(f"{'Fo=' + format(fo, 'g'):>11s}" for fo in FOURIER))
    for name, r in results.items():
        print(f"{name:34s}{r['steps']:7d}{r['substeps']:7d}" + "".join(f"{r['errors'][fo]:11.2e}" for fo in FOURIER))
    print("forward Euler, final max deviation:",
          ", ".join(f"{k}: {v:.2e}" for k, v in stab["final_deviation"].items()))
    print("HeatSolver above its bound with subcycle=False:", stab["guard"])
    for k, v in stab["implicit_far_above"].items():
        print(f"{k}: error at Fo=1 {v['error_Fo1']:.2e}, overshoot {v['overshoot']:.2e} ({v['steps']} steps)")
    print(f"wrote {args.out}/slab_transient.csv, slab_transient_stability.csv, slab_transient.png")
    print(json.dumps(summary))
    return summary


if __name__ == "__main__":
    main()
