"""Joule heating of a notched bar (paper 000, section 3.3, figures 10, 12, 13 and 14).

A rectangular bar with a notch on each side at mid-length (a current constriction) is held
at 1 V between its end faces and heats adiabatically for 0.01 s; its equivalent
resistance, the temperature in the notch and the potential and temperature profiles
along the bar are compared with a finite-element reference (``yade_electro.fem``) on the
same geometry, mesh-converged with an error estimate.

Geometry (our choice; the paper gives no dimensions)
----------------------------------------------------
Paper 000 uses 5,000 / 10,000 / 20,000 / 40,000 elements of mean radius 59 / 47 / 37 /
30 um. By eq. 1, r = (0.63 V / (4/3 pi N))^(1/3), these give a solid volume of 6.8-7.2
mm^3 (6.83, 6.90, 6.74, 7.18). It also says that a slab of thickness 4 r_mean across the
notch holds 100 elements at 5,000 and 362 at 40,000; a slab of section A holds
0.63 A 4r / (4/3 pi r^3) = 1.89 A / (pi r^2) elements, so A = 0.58 mm^2 (5,000) and
0.54 mm^2 (40,000). We take

    bar 6 mm (x) x 1.1 mm (y) x 1.1 mm (z); two rectangular notches through the thickness
    at mid-length, 0.6 mm long (x) and 0.3 mm deep (y), one from each side;
    ligament 0.5 mm x 1.1 mm = 0.55 mm^2, V = 6.864 mm^3.

Eq. 1 then gives 59.1 / 46.9 / 37.2 / 29.6 um and the slab rule 95 / 150 / 239 / 378
elements (paper: 59 / 47 / 37 / 30 um, 100 ... 362). The DEM container is the exact shape
``Box(bar) - Box(notch 1) - Box(notch 2)`` (also the Voronoi law's container); the FEM
reference uses ``NotchedBarGeometry(6e-3, 1.1e-3, 1.1e-3, 0.6e-3, 0.3e-3, 'rect', 'both')``.

Electrodes and heating
----------------------
* electrodes (as in the rod case): ``end0`` = every element whose sphere comes within
  ``gap * r_mean`` of the face x = 0 (x_i - r_i <= gap r_mean, gap = 0.1), at 0 V;
  ``end1`` likewise at x = L, at 1 V;
* material 304L with constant properties (rho_e 0.73e-6 ohm m, 7900 kg/m^3, 500 J/kg/K,
  15 W/m/K), T0 = 293.15 K, eta = 1, adiabatic (no thermal boundary condition), 1 V for
  t = 0.01 s (the paper's rod heating; the ligament heats by ~300 K, so 304L stays solid);
* DEM: ``ElectroThermalEngine``, backward Euler, ``nsteps`` = 100 thermal steps of 1e-4 s;
  capacities: 'continuum' uses the paper's rho c V_i / fv_i; 'voronoi' uses rho c V_cell
  with the bounded Voronoi cell volumes (``yade_electro.geometry.voronoi.voronoi_cell_volumes``)
  when that function exists, else the fv capacities (the JSON says which: ``capacity``);
  a cell it returns with a non-positive volume keeps its element's fv capacity (counted in
  ``n_bad_cells``);
* FEM: P1, one layer, Crank-Nicolson, h = 0.1, 0.05, 0.025 mm (half of it within one notch
  width of the notch), 50 / 100 / 200 steps; Richardson extrapolation and GCI (the error
  estimate quoted next to each FEM value).

What is compared
----------------
* ``R_eq`` (DEM between the electrode super-nodes; FEM between the end faces);
* notch temperature: the mean temperature of the DEM elements whose centres lie in the
  slab |x - L/2| <= 2 r_mean (paper: "a domain slab with thickness 4 r_mean") against the
  FEM volume average over the same slab; also the mean over the whole notch region
  |x - L/2| <= 0.3 mm against the FEM notch-subdomain average. Temperature errors are
  errors of the temperature *rise* T - T0 (stricter than errors of T in K);
* the potential gradient across the same slab (paper figure 13, "+14.5 %" for its DEM):
  (mean V of the right half of the slab - mean V of its left half) / (2 r_mean), DEM
  elements and FEM volume averages alike;
* profiles (paper figures 13 and 14): DEM element potentials and temperatures averaged in
  ``nbins`` slabs along x against the FEM slab averages on the same slabs.
Elements left without any bond (rattlers, 0 or 1 per packing: ``n_floating``) carry no
current and no heat and are left out of every DEM average.

As for the plate, the DEM electrodes are the element layers whose centres sit ~r_mean
inside the end faces; the FEM with the electrodes moved r_mean inwards (a bar of length
L - 2 r_mean, same notch) is reported too (``*_offset``): it is what the network should
converge to at a given r_mean.

Run
---
    yade-electro -n -x cases/notched_joule.py --n 5000 --law voronoi
    yade-electro -n -x cases/notched_joule.py --sweep                       # 5k..40k x both laws
    yade-electro batch cases/notched_joule.table cases/notched_joule.py

Writes CSV/PNG to ``--out`` (default out/notched_joule/) and ends by printing one line of
JSON. Importable (``run_notched``, ``fem_reference``) by the tests.
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import sys
import time

import numpy as np

# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_NAME = "notched_joule.py"
_SCRIPT = __file__ if __file__.endswith(_NAME) else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith(_NAME) else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)
from caselib import apply_batch_table, collect_runs, public, sweep_runs  # noqa: E402

LENGTH = 6e-3          # m, x (electrodes at x = 0 and x = L)
WIDTH = 1.1e-3         # m, y (notches from y = 0 and y = WIDTH)
THICKNESS = 1.1e-3     # m, z
NOTCH_WIDTH = 0.6e-3   # m, along x
NOTCH_DEPTH = 0.3e-3   # m, along y, each side
RHO_E = 0.73e-6        # ohm m
DENSITY, SPECIFIC_HEAT, CONDUCTIVITY = 7900.0, 500.0, 15.0   # 304L
T0 = 293.15            # K
VOLTAGE, T_END = 1.0, 0.01
SIZES = (5000, 10000, 20000, 40000)
LAWS = ("continuum", "voronoi", "voronoi-surface")
#: a "law" of the sweep: the conductance law, with "-surface" for electrodes on the end faces
#: themselves (surface electrodes, see yade_electro.geometry.boundary) instead of element layers
FEM_HS = (0.1e-3, 0.05e-3, 0.025e-3)
#: Paper 000 figure 12 / text: (N, r_mean [um]); errors [%]: resistance 9.2 (5k) -> 6.7 (40k),
#: notch temperature ~12 (5k), 5.8 (10k), "around 7" (20k, 40k)
PAPER_R_MEAN = {5000: 59, 10000: 47, 20000: 37, 40000: 30}
PAPER_R_ERROR = {5000: 9.2, 40000: 6.7}
PAPER_T_ERROR = {5000: 12.0, 10000: 5.8, 20000: 7.0, 40000: 7.0}


def notch_region():
    c = 0.5 * LENGTH
    return c - 0.5 * NOTCH_WIDTH, c + 0.5 * NOTCH_WIDTH


def bar_shape():
    """The exact container: the bar minus the two notches (a ``packing.Shape``)."""
    from yade_electro.yade import packing as P
    a, b = notch_region()
    L, B, Z, D = LENGTH, WIDTH, THICKNESS, NOTCH_DEPTH
    return (P.Box((0, 0, 0), (L, B, Z)) - P.Box((a, -B, -Z), (b, D, 2 * Z))
            - P.Box((a, B - D, -Z), (b, 2 * B, 2 * Z)))


def bar_geometry(offset: float = 0.0):
    """FEM geometry; ``offset`` > 0 shortens the bar by 2 offset (electrodes moved inwards)."""
    from yade_electro.fem import NotchedBarGeometry
    return NotchedBarGeometry(length=LENGTH - 2 * offset, width=WIDTH, thickness=THICKNESS,
                              notch_width=NOTCH_WIDTH, notch_depth=NOTCH_DEPTH, kind="rect",
                              sides="both")


def end_layers(x, r, r_mean, gap=0.1):
    """Masks (end0, end1) of the electrode layers (see module doc)."""
    return (x - r) <= gap * r_mean, (LENGTH - x - r) <= gap * r_mean


def hold_on_rollers(bodies, x0, end0):
    """Hold the end layer ``end0`` of the bar on rollers (in x) and remove the rigid-body modes:
    the element nearest the section's centre held in x, y, z, the one farthest from it across
    the width in x, z. ``bodies`` and ``x0`` (reference positions [m]) are in the same order.
    Returns the indices of the two pinned elements."""
    k_a = int(np.flatnonzero(end0)[np.argmin(np.sum((x0[end0, 1:] - [0.5 * WIDTH, 0.5 * THICKNESS]) ** 2, 1))])
    k_b = int(np.flatnonzero(end0)[np.argmax(np.abs(x0[end0, 1] - x0[k_a, 1]))])
    for k in np.flatnonzero(end0):
        bodies[k].state.blockedDOFs = "x"
    bodies[k_a].state.blockedDOFs = "xyz"
    bodies[k_b].state.blockedDOFs = "xz"
    return k_a, k_b


def bin_edges(nbins):
    return np.linspace(0.0, LENGTH, int(nbins) + 1)


def slab_mean(x, values, edges):
    """Mean of ``values`` of the elements whose x lies in each slab (nan if empty)."""
    idx = np.digitize(x, edges) - 1
    ok = (idx >= 0) & (idx < len(edges) - 1)
    num = np.bincount(idx[ok], values[ok], minlength=len(edges) - 1)
    cnt = np.bincount(idx[ok], minlength=len(edges) - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return num / cnt, cnt


# --------------------------------------------------------------------------- FEM
@functools.lru_cache(maxsize=32)
def _fem_run(h, offset, half_widths, nbins, voltage, t_end):
    """One FEM Joule-heating run (cached): scalars and profiles on the nominal x axis."""
    from yade_electro import fem
    g = bar_geometry(offset)
    nsteps = max(10, int(round(20 * 0.25e-3 / h)))
    mesh = fem.notched_bar_mesh(g, h, 0.5, 1)
    m = fem.STEEL_304L
    res = fem.joule_heating(mesh, m.resistivity, m.conductivity, m.rho_c,
                            {"end1": voltage, "end0": 0.0}, t_end=t_end, dt=t_end / nsteps,
                            theta=0.5, T0=T0, probes=[g.notch_centre])
    c = 0.5 * g.length
    out = {"R_eq": float(res.resistance[0]), "T_centre": float(res.probe_temperatures[-1, 0]),
           "T_notch": res.subdomain_average("notch"), "T_max": float(np.max(res.T)),
           "energy_balance_error": float(res.energy_balance_error), "ndofs": int(res.basis.N)}
    sol = res.potential
    for hw in half_widths:
        out[f"T_slab_{hw:.6e}"] = float(res.slab_average(0, [c - hw, c + hw])[0])
        left, right = fem.slab_average(sol.basis, sol.u, 0, [c - hw, c, c + hw])
        out[f"dVdx_slab_{hw:.6e}"] = float((right - left) / hw)
    # profiles on the nominal bins, shifted into the (possibly shorter) FEM bar
    edges = bin_edges(nbins) - offset
    out["V_profile"] = fem.slab_average(sol.basis, sol.u, 0, edges)
    out["T_profile"] = res.slab_average(0, edges)
    return out


def fem_reference(half_widths=(), offset=0.0, hs=FEM_HS, nbins=60, voltage=VOLTAGE, t_end=T_END):
    """Mesh-converged FEM figures.

    Returns
    -------
    dict
        name -> ``Convergence`` for ``R_eq``, ``T_centre`` (ligament centre), ``T_notch``
        (notch-region average), ``T_slab_<hw>`` (average over |x - L/2| <= hw for each
        half-width in ``half_widths``), plus ``profiles`` (finest mesh: ``V_profile``,
        ``T_profile`` on the nominal slabs, and ``*_diff``: |finest - previous mesh|).
    """
    from yade_electro import fem
    hw = tuple(float(f"{h:.6e}") for h in half_widths)
    runs = [_fem_run(float(h), float(offset), hw, int(nbins), float(voltage), float(t_end)) for h in hs]
    keys = (["R_eq", "T_centre", "T_notch", "T_max"] + [f"T_slab_{h:.6e}" for h in hw]
            + [f"dVdx_slab_{h:.6e}" for h in hw])
    ref = {k: fem.richardson(list(hs), [r[k] for r in runs]) for k in keys}
    ref["profiles"] = {"x": 0.5 * (bin_edges(nbins)[1:] + bin_edges(nbins)[:-1]),
                       "V_profile": runs[-1]["V_profile"], "T_profile": runs[-1]["T_profile"],
                       "V_profile_diff": np.abs(runs[-1]["V_profile"] - runs[-2]["V_profile"]),
                       "T_profile_diff": np.abs(runs[-1]["T_profile"] - runs[-2]["T_profile"])}
    ref["energy_balance_error"] = runs[-1]["energy_balance_error"]
    ref["ndofs"] = runs[-1]["ndofs"]
    return ref


def slab_key(half_width, name="T_slab"):
    return f"{name}_{float(f'{half_width:.6e}'):.6e}"


# --------------------------------------------------------------------------- DEM
def capacity_record(law, model):
    """What the capacities are: ``"fv"`` (paper: rho c V_i / fv_i) or, with 'voronoi', the
    law's bounded cell volumes (``"voronoi_cells"``, rho c V_cell, the model's default; a
    non-positive cell volume would be refused by the model, so ``n_bad_cells`` is 0)."""
    if law != "voronoi":
        return {"capacity": "fv", "n_bad_cells": 0}
    return {"capacity": "voronoi_cells", "n_bad_cells": 0,
            "cell_volume_sum": float(np.sum(model.capacity) / (DENSITY * SPECIFIC_HEAT))}


def run_notched(n=5000, seed=1, law="continuum", voltage=VOLTAGE, t_end=T_END, nsteps=100,
                gap=0.1, nbins=60, solver="cg", cache_dir=None, history=None, elements_csv=None):
    """Build (or load) the bonded notched bar in YADE, heat it with the electro-thermal
    engine, and return the DEM figures. Resets YADE's scene first."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade_electro.yade import ElectroThermalEngine, Integrator, Law, Material, Output, electrodes_from_dict
    from yade_electro.yade import packing as P

    O = yade.Omega()
    O.reset()
    t0 = time.perf_counter()
    shape = bar_shape()
    packing = P.dense_packing(shape, n=n, seed=seed, cache_dir=cache_dir)
    t_pack = time.perf_counter() - t0
    ids = np.asarray(P.add_bonded_packing(packing))
    r_mean = float(np.mean(packing.radii))
    end0, end1 = end_layers(packing.centers[:, 0], packing.radii, r_mean, gap)
    label, surface = law, law.endswith("-surface")
    law = law[:-len("-surface")] if surface else law
    law_params = {"container": shape} if law == "voronoi" else None
    if surface:
        box = P.Box((0, 0, 0), (LENGTH, WIDTH, THICKNESS))
        electrodes = {"end1": dict(surface=box.face("x+"), potential=voltage),
                      "end0": dict(surface=box.face("x-"), potential=0.0)}
    else:
        electrodes = {"end1": dict(select=ids[end1], potential=voltage), "end0": dict(select=ids[end0], potential=0.0)}
    engine = ElectroThermalEngine(
        material=Material(resistivity=RHO_E, density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY, beta=0.0),
        boundaries=electrodes_from_dict(electrodes),
        temperature=T0,
        law=Law(law, **(law_params or {})),
        integrator=Integrator(theta="backward-euler", dt=t_end / nsteps, eta=1.0),
        output=Output(history=history),
        solver=solver,
        iterPeriod=1,
        label="notched")
    O.engines = O.engines + [engine.runner]
    t1 = time.perf_counter()
    O.run(int(nsteps), True)
    t_run = time.perf_counter() - t1
    model = engine.coupled
    capacity = capacity_record(law, model)
    g = engine.graph
    pos, V, T = g.pos, engine.potential.copy(), engine.temperature.copy()
    sol = engine.solution
    live = ~np.asarray(sol.floating[:g.n_nodes], dtype=bool)   # unbonded elements carry nothing: left out
    c = 0.5 * LENGTH
    a, b = notch_region()
    slab = live & (np.abs(pos[:, 0] - c) <= 2.0 * r_mean)
    notch = live & (pos[:, 0] >= a) & (pos[:, 0] <= b)
    edges = bin_edges(nbins)
    Vp, cnt = slab_mean(pos[live, 0], V[live], edges)
    Tp, _ = slab_mean(pos[live, 0], T[live], edges)
    # potential gradient across the slab: (mean V of its right half - left half) / (2 r_mean)
    left = slab & (pos[:, 0] < c)
    right = slab & (pos[:, 0] >= c)
    dVdx = float((np.mean(V[right]) - np.mean(V[left])) / (2.0 * r_mean))
    out = {"case": "notched_joule", "n": int(g.n_nodes), "n_target": int(n), "seed": int(seed),
           "law": label, "electrodes": "surface" if surface else "layers", "capacity": capacity["capacity"],
           "r_mean": r_mean,
           "cell_volume_sum": capacity.get("cell_volume_sum"), "n_bad_cells": capacity["n_bad_cells"],
           "container_volume": float(packing.container_volume),
           "r_mean_eq1": float(packing.r_mean_requested),
           "volume_fraction": float(packing.volume_fraction),
           "n_end0": int(end0.sum()) if not surface else int(engine.model.surfaces["end0"].saved.ids.size),
           "n_end1": int(end1.sum()) if not surface else int(engine.model.surfaces["end1"].saved.ids.size),
           "n_slab": int(slab.sum()), "n_notch": int(notch.sum()), "n_floating": int((~live).sum()),
           "R_eq": float(engine.equivalent_resistance),
           "T_slab": float(np.mean(T[slab])), "T_notch": float(np.mean(T[notch])),
           "dVdx_slab": dVdx, "T_max": float(np.max(T)), "t_thermal": float(model.time), "nsteps": int(nsteps),
           "heat_content_J": float(model.heat_content()), "joule_energy_J": float(model.joule_energy),
           "current_imbalance": float(sol.current_imbalance), "residual": float(sol.residual),
           "t_packing_s": t_pack, "t_run_s": t_run,
           "_x": 0.5 * (edges[1:] + edges[:-1]), "_V_profile": Vp, "_T_profile": Tp,
           "_bin_count": cnt, "_pos": pos, "_V": V, "_T": T}
    if elements_csv is not None:
        np.savetxt(elements_csv, np.column_stack([g.ids, pos, g.radius, V, T]), delimiter=",",
                   header="body_id,x,y,z,radius,potential,temperature", comments="",
                   fmt=["%d"] + ["%.9e"] * 6)
    engine.remove()
    return out


def compare(row, ref, ref_off=None):
    """Add FEM values, their error estimates and the DEM errors [%] to ``row``."""
    hw = 2.0 * row["r_mean"]
    pairs = [("R_eq", "R_eq", None), ("T_slab", slab_key(hw), T0), ("T_notch", "T_notch", T0),
             ("dVdx_slab", slab_key(hw, "dVdx_slab"), None)]
    for suffix, r in (("", ref), ("_offset", ref_off)):
        if r is None:
            continue
        for name, key, base in pairs:
            conv = r[key]
            row[f"{name}_fem{suffix}"], row[f"{name}_fem{suffix}_gci"] = conv.extrapolated, conv.gci
            b = 0.0 if base is None else base
            row[f"error_{name}{suffix}_pct"] = 100.0 * ((row[name] - b) / (conv.extrapolated - b) - 1.0)
    row["T_centre_fem"], row["T_max_fem"] = ref["T_centre"].extrapolated, ref["T_max"].extrapolated
    p = ref["profiles"]
    row["_V_profile_fem"], row["_T_profile_fem"] = p["V_profile"], p["T_profile"]
    if ref_off is not None:
        row["_V_profile_fem_offset"] = ref_off["profiles"]["V_profile"]
        row["_T_profile_fem_offset"] = ref_off["profiles"]["T_profile"]
    ok = np.isfinite(row["_V_profile"]) & np.isfinite(p["V_profile"])
    row["profile_V_rms"] = float(np.sqrt(np.mean((row["_V_profile"][ok] - p["V_profile"][ok]) ** 2)))
    row["profile_T_rms"] = float(np.sqrt(np.mean((row["_T_profile"][ok] - p["T_profile"][ok]) ** 2)))
    row["profile_T_max_abs"] = float(np.max(np.abs(row["_T_profile"][ok] - p["T_profile"][ok])))
    row["fem_energy_balance_error"] = float(ref["energy_balance_error"])
    return row


def write_profiles(row, path):
    cols = {"x": row["_x"], "n_elements": row["_bin_count"], "V_dem": row["_V_profile"],
            "V_fem": row["_V_profile_fem"], "T_dem": row["_T_profile"], "T_fem": row["_T_profile_fem"]}
    if "_V_profile_fem_offset" in row:
        cols["V_fem_offset"] = row["_V_profile_fem_offset"]
        cols["T_fem_offset"] = row["_T_profile_fem_offset"]
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols),
               comments="", fmt="%.9e")


def plot_profiles(row, path):
    """Potential and temperature along the bar, DEM slab means vs FEM (figures 13, 14)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.4))
    x = row["_x"] * 1e3
    pos = row["_pos"]
    a, b = notch_region()
    c, hw = 0.5 * LENGTH, 2 * row["r_mean"]
    for ax, key, unit in ((axs[0], "V", "potential [V]"), (axs[1], "T", "temperature [K]")):
        ax.plot(pos[:, 0] * 1e3, row[f"_{key}"], ".", ms=1, color="0.75", label="DEM elements")
        ax.plot(x, row[f"_{key}_profile_fem"], "k-", lw=1.5, label="FEM (slab averages)")
        if f"_{key}_profile_fem_offset" in row:
            ax.plot(x, row[f"_{key}_profile_fem_offset"], "k:", lw=1,
                    label="FEM, electrodes offset by r_mean")
        ax.plot(x, row[f"_{key}_profile"], "o", ms=4, color="C3", label="DEM (slab averages)")
        ax.axvspan(a * 1e3, b * 1e3, color="C0", alpha=0.08, label="notch")
        ax.axvspan((c - hw) * 1e3, (c + hw) * 1e3, color="C1", alpha=0.2, label="slab 4 r_mean")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel(unit)
    axs[0].set_title(f"{row['n']} elements, {row['law']}: R_eq error {row['error_R_eq_pct']:+.2f} %")
    axs[1].set_title(f"t = {row['t_thermal']:g} s: notch-slab rise error {row['error_T_slab_pct']:+.2f} %")
    axs[0].legend(fontsize=7, markerscale=3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sweep(rows, path):
    """Errors of R_eq and of the notch temperature rise vs element count (figure 12)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, paper, target in ((axs[0], "R_eq", PAPER_R_ERROR, 4.0),
                                   (axs[1], "T_slab", PAPER_T_ERROR, 5.0)):
        for i, (law, mk) in enumerate(zip(LAWS, ("o", "s"))):
            rs = sorted([r for r in rows if r["law"] == law], key=lambda r: r["n"])
            if rs:
                ax.plot([r["n"] for r in rs], [r[f"error_{key}_pct"] for r in rs], mk + "-", color=f"C{i}",
                        label=f"{law} vs FEM")
                if f"error_{key}_offset_pct" in rs[0]:
                    ax.plot([r["n"] for r in rs], [r[f"error_{key}_offset_pct"] for r in rs], mk + ":",
                            color=f"C{i}", mfc="none", label=f"{law} vs FEM, electrodes offset r_mean")
        ax.plot(sorted(paper), [paper[k] for k in sorted(paper)], "^--", color="grey",
                label="paper 000 (|error|)")
        for s in (1, -1):
            ax.axhline(s * target, color="r", ls=":", lw=1)
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xscale("log")
        ax.set_xlabel("number of elements")
    axs[0].set_ylabel("(R_dem - R_fem) / R_fem  [%]")
    axs[1].set_ylabel("notch-slab temperature rise error [%]")
    axs[0].set_title("equivalent resistance (target 4 %)")
    axs[1].set_title("notch temperature after 0.01 s (target 5 %)")
    axs[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


CSV_FIELDS = ["n", "n_target", "seed", "law", "capacity", "n_bad_cells", "cell_volume_sum", "container_volume", "r_mean",
              "r_mean_eq1", "volume_fraction",
              "n_end0", "n_end1", "n_slab", "n_notch", "n_floating",
              "R_eq", "R_eq_fem", "R_eq_fem_gci", "error_R_eq_pct", "R_eq_fem_offset", "error_R_eq_offset_pct",
              "T_slab", "T_slab_fem", "T_slab_fem_gci", "error_T_slab_pct", "T_slab_fem_offset",
              "error_T_slab_offset_pct", "T_notch", "T_notch_fem", "T_notch_fem_gci", "error_T_notch_pct",
              "T_notch_fem_offset", "error_T_notch_offset_pct", "dVdx_slab", "dVdx_slab_fem",
              "dVdx_slab_fem_gci", "error_dVdx_slab_pct", "error_dVdx_slab_offset_pct", "T_max", "T_max_fem", "T_centre_fem",
              "profile_V_rms", "profile_T_rms", "profile_T_max_abs", "nsteps", "current_imbalance",
              "t_packing_s", "t_run_s", "t_fem_s"]


SUMMARY_KEYS = ("n", "n_target", "law", "capacity", "r_mean", "n_slab", "R_eq", "R_eq_fem", "error_R_eq_pct",
                "T_slab", "T_slab_fem", "error_T_slab_pct", "error_R_eq_offset_pct", "error_T_slab_offset_pct")


def run_one(n, seed, law, out_dir, hs=FEM_HS, offset=True, plot=True, nbins=60, **kw):
    """One packing and law: DEM, FEM references, files. Returns the row."""
    os.makedirs(out_dir, exist_ok=True)
    stem = os.path.join(out_dir, f"notched_n{n}_s{seed}_{law}")
    row = run_notched(n, seed, law, nbins=nbins, elements_csv=stem + "_elements.csv",
                      history=stem + "_history.csv", **kw)
    t0 = time.perf_counter()
    hw = (2.0 * row["r_mean"],)
    ref = fem_reference(hw, 0.0, hs, nbins)
    ref_off = fem_reference(hw, row["r_mean"], hs, nbins) if offset else None
    compare(row, ref, ref_off)
    row["t_fem_s"] = time.perf_counter() - t0
    row["fem_h"] = list(hs)
    write_profiles(row, stem + "_profiles.csv")
    if plot:
        plot_profiles(row, stem + ".png")
    with open(stem + ".json", "w") as fh:
        json.dump(public(row), fh)
    return row


def summary_line(row) -> str:
    s = (f"notched bar {row['n']} elements (r_mean {row['r_mean'] * 1e6:.1f} um, {row['n_slab']} in the "
         f"4 r_mean slab), {row['law']} ({row['capacity']} capacities): R_eq {row['R_eq'] * 1e3:.4f} mohm "
         f"(FEM {row['R_eq_fem'] * 1e3:.4f}, {row['error_R_eq_pct']:+.2f} %), notch slab T "
         f"{row['T_slab']:.2f} K (FEM {row['T_slab_fem']:.2f} K, rise {row['error_T_slab_pct']:+.2f} %)")
    if "error_R_eq_offset_pct" in row:
        s += (f"; vs offset-electrode FEM: R {row['error_R_eq_offset_pct']:+.2f} %, "
              f"T {row['error_T_slab_offset_pct']:+.2f} %")
    return s


def sweep(sizes=SIZES, laws=LAWS, seed=1, out_dir="out/notched_joule", hs=FEM_HS, **kw):
    """Every size x law; writes notched_joule.csv and notched_joule.png. Returns the rows."""
    rows = sweep_runs(lambda n, law: run_one(n, seed, law, out_dir, hs, **kw), sizes, laws, out_dir,
                      "notched_joule.csv", CSV_FIELDS, summary_line)
    plot_sweep(rows, os.path.join(out_dir, "notched_joule.png"))
    return rows


def collect(out_dir):
    """Rows of every ``notched_n*_s*_*.json`` in ``out_dir`` (sorted by n, law), written to
    ``notched_joule.csv`` with the sweep plot ``notched_joule.png`` there. Returns the rows."""
    rows = collect_runs(out_dir, "notched_n*_s*_*.json", "notched_joule.csv", CSV_FIELDS, LAWS)
    if rows:
        plot_sweep(rows, os.path.join(out_dir, "notched_joule.png"))
    return rows


def _params(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--law", default="continuum", choices=LAWS)
    ap.add_argument("--gap", type=float, default=0.1, help="electrode layer: x - r <= gap r_mean")
    ap.add_argument("--nsteps", type=int, default=100, help="DEM thermal steps (backward Euler)")
    ap.add_argument("--nbins", type=int, default=60, help="slabs along x for the profiles")
    ap.add_argument("--fem-h", type=lambda s: tuple(float(x) for x in s.split(",")), default=FEM_HS,
                    help="FEM mesh sizes [m], coarsest first (three)")
    ap.add_argument("--no-offset", action="store_true", help="skip the offset-electrode FEM")
    ap.add_argument("--sweep", action="store_true", help="5k, 10k, 20k, 40k x both laws")
    ap.add_argument("--collect", action="store_true",
                    help="only gather the per-run JSON files of --out (e.g. after yade-batch) into "
                         "notched_joule.csv and notched_joule.png")
    ap.add_argument("--sizes", type=lambda s: tuple(int(x) for x in s.split(",")), default=SIZES)
    ap.add_argument("--out", default="out/notched_joule")
    args = ap.parse_args(argv)
    return apply_batch_table(args)      # under yade-batch, the table line gives n, seed, law


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    kw = dict(gap=args.gap, nsteps=args.nsteps, nbins=args.nbins, offset=not args.no_offset)
    if args.collect:
        rows = collect(args.out)
        summary = {"case": "notched_joule", "collected": len(rows), "rows": [
            {k: r.get(k) for k in SUMMARY_KEYS} for r in rows]}
        print(json.dumps(summary))
        return summary
    if args.sweep:
        rows = sweep(args.sizes, LAWS, args.seed, args.out, args.fem_h, **kw)
        summary = {"case": "notched_joule", "rows": [{k: r.get(k) for k in SUMMARY_KEYS} for r in rows]}
        print(json.dumps(summary))
        return summary
    row = run_one(args.n, args.seed, args.law, args.out, args.fem_h, **kw)
    print(summary_line(row))
    stem = os.path.join(args.out, f"notched_n{args.n}_s{args.seed}_{args.law}")
    print(f"wrote {stem}_elements.csv, _history.csv, _profiles.csv, .json, .png")
    out = public(row)
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
