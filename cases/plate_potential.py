"""Thick plate in a non-uniform field (paper 000, section 3.2, figures 8 and 9).

A plate grounded on its bottom edge with a 1 V potential source of 6 mm diameter through
its thickness at its centre; the potentials at two control points are compared with a
finite-element reference (``yade_electro.fem``, mesh-converged, with its error estimate).

Geometry (our choice; the paper gives only the 6 mm source)
-----------------------------------------------------------
Paper 000 uses 5,000 / 10,000 / 20,000 elements of mean radius 408 / 323 / 257 um. By its
eq. 1, r = (0.63 V / (4/3 pi N))^(1/3), these three pairs all give a solid volume
V = 2.26e-6 m^3 (2.258, 2.241, 2.247e-6). Figure 8 shows a square plate, thick, with the
source at its centre. We take

    25 mm (x) x 25 mm (y) x 3.8 mm (z), minus the 6 mm hole at (12.5, 12.5) mm,

i.e. V = (25^2 - pi 3^2) x 3.8 mm^3 = 2.268e-6 m^3: eq. 1 then gives 408.6 / 324.3 /
257.4 um for the three counts (the paper's 408 / 323 / 257). The container is the exact
shape ``Box((0,0,0), (25,25,3.8) mm) - Cylinder(hole axis, 3 mm)`` (the same ``Shape`` is
the Voronoi law's container), and the FEM reference is computed on the same plate
(``PlateGeometry(25e-3, 25e-3, 3.8e-3, 6e-3)``).

Control points (``PlateGeometry.control_points``), at mid-thickness z = 1.9 mm:
``mid`` (12.5, 4.75) mm, halfway between the ground y = 0 and the near edge of the source
(y = 9.5 mm); ``corner`` (0, 25) mm, the top-left corner.

Electrodes (precise definition)
-------------------------------
* ground: every element whose sphere comes within ``gap * r_mean`` of the bottom face,
  y_i - r_i <= gap r_mean (gap = 0.1, as in the rod case), held at 0 V;
* source: every element whose sphere comes within ``gap * r_mean`` of the hole surface,
  rho_i - r_i - 3 mm <= gap r_mean with rho_i the distance of the centre to the hole axis,
  held at 1 V.
These are the elements touching the two faces. Their centres sit about r_mean inside the
solid, so the DEM's equipotential surfaces are the plane y ~ r_mean and the cylinder of
radius ~ 3 mm + r_mean, not the faces themselves (the rod's L - 2 r_mean). Two FEM
references are therefore reported:

* ``nominal``: electrodes on the faces (the paper's comparison, the primary figure);
* ``offset``: the same plate with the electrodes moved r_mean into the solid (ground at
  y = r_mean, source of radius 3 mm + r_mean; the solid between an electrode face and its
  offset surface is equipotential in the DEM and is left out), which is what the DEM
  network should converge to for a given r_mean. It shows how much of the error is the
  electrode-layer offset.

Estimator of the DEM potential at a control point
-------------------------------------------------
The exact field does not vary through the thickness. The DEM value at a control point p
is the linear least-squares fit V ~ a + g . (x - p) of the potentials of the elements whose
centre lies within ``fit_radius`` r_mean (default 2.5) of the line through p along z
(all z), evaluated at p (= a): ``fit_radius`` = 2.5 for ``mid`` (a full disc, about 40
elements) and ``corner_fit_radius`` = 4 for ``corner``, where only the quarter disc inside
the solid holds elements (about 20-25 elements). Near the insulated corner the exact field
is V0 + a (x^2 - y'^2) + ..., y' = H - y (zero normal derivative on both faces), whose
quadratic part averages out over the symmetric quarter disc, so the one-sided linear fit
is not biased at second order. A fit with fewer than 6 elements raises. Elements left
without any bond (``n_floating``, none in our plates) are left out.

Run
---
    yade-electro -n -x cases/plate_potential.py --n 5000 --law voronoi      # one packing, one law
    yade-electro -n -x cases/plate_potential.py --sweep                      # 5k, 10k, 20k x both laws
    yade-electro batch cases/plate_potential.table cases/plate_potential.py  # the same through yade-batch

Writes CSV/PNG to ``--out`` (default out/plate_potential/) and ends by printing one line of
JSON. Importable (``run_plate``, ``fem_reference``, ``control_point_value``) by the tests.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_NAME = "plate_potential.py"
_SCRIPT = __file__ if __file__.endswith(_NAME) else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith(_NAME) else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)
from caselib import apply_batch_table, collect_runs, public, sweep_runs  # noqa: E402

WIDTH = 25e-3          # m, x
HEIGHT = 25e-3         # m, y (ground at y = 0)
THICKNESS = 3.8e-3     # m, z
SOURCE_DIAMETER = 6e-3  # m (paper 000)
RHO_304L = 0.73e-6     # ohm m (the potentials do not depend on it)
SIZES = (5000, 10000, 20000)
LAWS = ("continuum", "voronoi", "voronoi-surface")
#: a "law" of the sweep: the conductance law, with "-surface" for electrodes on the hole and
#: the bottom face themselves (surface electrodes) instead of element layers
#: Paper 000 section 3.2: (N, r_mean [um]); errors "<= 4.2 %, mainly around 2 %" (figure 9)
PAPER = {5000: 408, 10000: 323, 20000: 257}
PAPER_MAX_ERROR_PCT = 4.2
#: FEM mesh sizes of the convergence study (P2, one layer, h/2 at the hole)
FEM_HS = (2e-3, 1e-3, 0.5e-3)


def plate_shape():
    """The exact container: box minus the source hole (a ``packing.Shape``)."""
    from yade_electro.yade import packing as P
    cx, cy = WIDTH / 2, HEIGHT / 2
    return (P.Box((0, 0, 0), (WIDTH, HEIGHT, THICKNESS))
            - P.Cylinder((cx, cy, -THICKNESS), (cx, cy, 2 * THICKNESS), SOURCE_DIAMETER / 2))


def plate_geometry(offset: float = 0.0):
    """FEM geometry; ``offset`` > 0 moves both electrodes ``offset`` into the solid (the
    plate then spans y in [offset, HEIGHT], shifted down by ``offset``)."""
    from yade_electro.fem import PlateGeometry
    return PlateGeometry(width=WIDTH, height=HEIGHT - offset, thickness=THICKNESS,
                         source_diameter=SOURCE_DIAMETER + 2 * offset,
                         source_centre=(WIDTH / 2, HEIGHT / 2 - offset))


def control_points() -> dict:
    """The two control points [m] of the nominal plate."""
    return {k: tuple(v) for k, v in plate_geometry().control_points().items()}


def hole_surface(tol=0.3 * SOURCE_DIAMETER / 2):
    """The source hole's surface as a surface selector: boundary faces within ``tol`` [m] of
    the hole's cylinder whose outward normal points into the hole (a concave wall is met by
    tangent planes, whose faces lie up to s^2 / (2 R) inside it, s their size)."""
    from yade_electro.geometry.surfaces import SurfaceSelector
    c = np.array([WIDTH / 2, HEIGHT / 2])
    R = SOURCE_DIAMETER / 2

    def on_hole(points, normals):
        d = points[:, :2] - c
        rho = np.hypot(d[:, 0], d[:, 1])
        inward = -np.einsum("ij,ij->i", d, normals[:, :2]) / np.maximum(rho, 1e-300)
        return (np.abs(rho - R) <= tol) & (inward > 0.5)
    return SurfaceSelector(on_hole, "the source hole's surface")


def electrode_layers(pos, r, r_mean, gap=0.1):
    """Masks (ground, source) of the electrode layers (see module doc)."""
    ground = (pos[:, 1] - r) <= gap * r_mean
    rho = np.hypot(pos[:, 0] - WIDTH / 2, pos[:, 1] - HEIGHT / 2)
    source = (rho - r - SOURCE_DIAMETER / 2) <= gap * r_mean
    return ground, source


def control_point_value(pos, potential, point, r_mean, fit_radius=2.5, min_points=6):
    """Linear least-squares fit of element potentials around the line through ``point``
    along z, evaluated at ``point`` (see module doc; ``yade_electro.post.probes.probe``).
    Returns (value, n_used)."""
    from yade_electro.post.probes import probe
    out = probe(pos, potential, point, fit_radius * r_mean, axis=(0, 0, 1), min_points=min_points)
    return float(out.value[0]), int(out.n_used[0])


def fem_reference(offset: float = 0.0, hs=FEM_HS, voltage=1.0) -> dict:
    """Mesh-converged FEM potentials at the control points (and R_eq).

    Returns name -> ``Convergence`` for ``mid``, ``corner``, ``R_eq`` (richardson over
    ``hs``). With ``offset``, the control points are shifted with the plate."""
    from yade_electro import fem
    g = plate_geometry(offset)
    pts = {k: (v[0], v[1] - offset, v[2]) for k, v in control_points().items()}

    def run(h):
        out = fem.plate_potential(g, h, voltage, points=pts, order=2)
        out.pop("ndofs")
        return out
    return fem.converged(run, hs)


def fem_field_at(points, offset: float = 0.0, h=FEM_HS[-1], voltage=1.0):
    """FEM potential (finest mesh, P2) at arbitrary points [m] of the nominal plate (points
    of the offset plate outside its electrodes are clipped to the electrode value)."""
    from yade_electro import fem
    g = plate_geometry(offset)
    sol = fem.solve_potential(fem.plate_mesh(g, h, layers=1), RHO_304L,
                              {"source": voltage, "bottom": 0.0}, order=2)
    x = np.array(points, dtype=float).copy()
    x[:, 1] -= offset
    x[:, 2] = 0.5 * THICKNESS
    rho = np.hypot(x[:, 0] - g.centre[0], x[:, 1] - g.centre[1])
    in_src = rho <= 0.5 * g.source_diameter
    below = x[:, 1] <= 0.0
    ok = ~(in_src | below)
    v = np.empty(len(x))
    v[ok] = sol.probe(x[ok])
    v[in_src], v[below] = voltage, 0.0
    return v


def run_plate(n=5000, seed=1, law="continuum", voltage=1.0, gap=0.1, fit_radius=2.5,
              corner_fit_radius=4.0, solver="cg", cache_dir=None, elements_csv=None):
    """Build (or load) the bonded plate in YADE, solve the potentials with the electrical
    engine, and return the DEM figures (control-point values, counts, timings). Resets
    YADE's scene first."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade_electro.yade import ElectricalEngine, Law, Material, electrodes_from_dict
    from yade_electro.yade import packing as P

    O = yade.Omega()
    O.reset()
    t0 = time.perf_counter()
    shape = plate_shape()
    packing = P.dense_packing(shape, n=n, seed=seed, cache_dir=cache_dir)
    t_pack = time.perf_counter() - t0
    ids = np.asarray(P.add_bonded_packing(packing))
    r_mean = float(np.mean(packing.radii))
    ground, source = electrode_layers(packing.centers, packing.radii, r_mean, gap)
    label, surface = law, law.endswith("-surface")
    law = law[:-len("-surface")] if surface else law
    law_params = {"container": shape} if law == "voronoi" else None
    if surface:
        electrodes = {"source": dict(surface=hole_surface(), potential=voltage),
                      "ground": dict(surface=P.Box((0, 0, 0), (WIDTH, HEIGHT, THICKNESS)).face("y-"), potential=0.0)}
    else:
        electrodes = {"source": dict(select=ids[source], potential=voltage), "ground": dict(select=ids[ground], potential=0.0)}
    engine = ElectricalEngine(
        material=Material(resistivity=RHO_304L),
        boundaries=electrodes_from_dict(electrodes),
        law=Law(law, **(law_params or {})),
        solver=solver,
        iterPeriod=1,
        label="plate")
    O.engines = O.engines + [engine.runner]
    t1 = time.perf_counter()
    O.step()
    t_solve = time.perf_counter() - t1
    g, sol = engine.graph, engine.solution
    pos, pot = g.pos, engine.potential
    live = ~np.asarray(sol.floating[:g.n_nodes], dtype=bool)   # unbonded elements: no potential, left out
    out = {"case": "plate_potential", "n": int(g.n_nodes), "n_target": int(n), "seed": int(seed),
           "law": label, "electrodes": "surface" if surface else "layers", "r_mean": r_mean, "r_mean_eq1": float(packing.r_mean_requested),
           "volume_fraction": float(packing.volume_fraction),
           "n_ground": int(ground.sum()), "n_source": int(source.sum()), "n_floating": int((~live).sum()),
           "R_eq": float(engine.equivalent_resistance),
           "current_imbalance": float(sol.current_imbalance), "residual": float(sol.residual),
           "t_packing_s": t_pack, "t_solve_s": t_solve}
    for name, p in control_points().items():
        radius = corner_fit_radius if name == "corner" else fit_radius
        v, k = control_point_value(pos[live], pot[live], p, r_mean, radius)
        out[f"V_{name}"], out[f"n_fit_{name}"] = v, k
    if elements_csv is not None:
        np.savetxt(elements_csv, np.column_stack([g.ids, pos, g.radius, pot]), delimiter=",",
                   header="body_id,x,y,z,radius,potential", comments="",
                   fmt=["%d"] + ["%.9e"] * 5)
    out["_pos"], out["_potential"] = pos, pot
    engine.remove()
    return out


def compare(row, ref_nominal, ref_offset=None):
    """Add FEM values, their error estimates (GCI) and DEM errors [%] to ``row``."""
    for name in ("mid", "corner"):
        c = ref_nominal[name]
        row[f"V_{name}_fem"], row[f"V_{name}_fem_gci"] = c.extrapolated, c.gci
        row[f"error_{name}_pct"] = 100.0 * (row[f"V_{name}"] - c.extrapolated) / c.extrapolated
        if ref_offset is not None:
            o = ref_offset[name]
            row[f"V_{name}_fem_offset"], row[f"V_{name}_fem_offset_gci"] = o.extrapolated, o.gci
            row[f"error_{name}_offset_pct"] = 100.0 * (row[f"V_{name}"] - o.extrapolated) / o.extrapolated
    row["R_eq_fem"] = ref_nominal["R_eq"].extrapolated
    if ref_offset is not None:
        row["R_eq_fem_offset"] = ref_offset["R_eq"].extrapolated
    return row


def field_errors(row, offset_too=True):
    """RMS and max |V_dem - V_fem| over all elements (FEM at the element centres)."""
    pos, pot = row["_pos"], row["_potential"]
    v = fem_field_at(pos)
    row["rms_field_error"] = float(np.sqrt(np.mean((pot - v) ** 2)))
    row["max_field_error"] = float(np.max(np.abs(pot - v)))
    row["_fem_at_elements"] = v
    if offset_too:
        vo = fem_field_at(pos, offset=row["r_mean"])
        row["rms_field_error_offset"] = float(np.sqrt(np.mean((pot - vo) ** 2)))
        row["_fem_offset_at_elements"] = vo
    return row


def plot_field(row, path):
    """Element potentials against the FEM at the element centres (parity), and the map."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pos, pot = row["_pos"], row["_potential"]
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.6))
    sc = axs[0].scatter(pos[:, 0] * 1e3, pos[:, 1] * 1e3, c=pot, s=4, cmap="viridis")
    fig.colorbar(sc, ax=axs[0], label="potential [V]")
    for name, p in control_points().items():
        axs[0].plot(p[0] * 1e3, p[1] * 1e3, "r+", ms=12, mew=2)
        axs[0].annotate(name, (p[0] * 1e3, p[1] * 1e3), color="r", xytext=(4, -10),
                        textcoords="offset points")
    axs[0].set_aspect("equal")
    axs[0].set_xlabel("x [mm]")
    axs[0].set_ylabel("y [mm]")
    axs[0].set_title(f"plate, {row['n']} elements, {row['law']}")
    if "_fem_at_elements" in row:
        axs[1].plot(row["_fem_at_elements"], pot, ".", ms=2, alpha=0.4,
                    label=f"nominal electrodes (RMS {row['rms_field_error'] * 1e3:.1f} mV)")
        if "_fem_offset_at_elements" in row:
            axs[1].plot(row["_fem_offset_at_elements"], pot, ".", ms=2, alpha=0.4,
                        label=f"electrodes offset by r_mean (RMS {row['rms_field_error_offset'] * 1e3:.1f} mV)")
        axs[1].plot([0, 1], [0, 1], "k-", lw=0.8)
        axs[1].set_xlabel("FEM potential at the element centre [V]")
        axs[1].set_ylabel("DEM element potential [V]")
        axs[1].legend(markerscale=5, fontsize=8)
        axs[1].set_title(f"mid {row['error_mid_pct']:+.2f} %, corner {row['error_corner_pct']:+.2f} % (vs nominal FEM)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sweep(rows, path):
    """Error at both control points versus element count (paper figure 9)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, ref in zip(axs, ("", "_offset")):
        for law, mk in zip(LAWS, ("o", "s")):
            rs = sorted([r for r in rows if r["law"] == law], key=lambda r: r["n"])
            if not rs or f"error_mid{ref}_pct" not in rs[0]:
                continue
            for name, ls in (("mid", "-"), ("corner", "--")):
                ax.plot([r["n"] for r in rs], [r[f"error_{name}{ref}_pct"] for r in rs], mk + ls,
                        label=f"{law}, {name}")
        for s in (1, -1):
            ax.axhline(s * PAPER_MAX_ERROR_PCT, color="grey", ls=":", lw=1)
            ax.axhline(s * 3.0, color="r", ls=":", lw=1)
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xscale("log")
        ax.set_xlabel("number of elements")
        ax.set_title("vs FEM, electrodes on the faces (paper)" if not ref else
                     "vs FEM, electrodes offset by r_mean")
    axs[0].set_ylabel("(V_dem - V_fem) / V_fem  [%]")
    axs[0].legend(fontsize=8)
    axs[1].text(0.02, 0.02, "grey: paper's max |error| 4.2 %; red: target 3 %",
                transform=axs[1].transAxes, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


CSV_FIELDS = ["n", "n_target", "seed", "law", "r_mean", "r_mean_eq1", "volume_fraction", "n_ground",
              "n_source", "n_floating", "V_mid", "V_mid_fem", "V_mid_fem_gci", "error_mid_pct", "V_mid_fem_offset",
              "V_mid_fem_offset_gci", "error_mid_offset_pct", "V_corner", "V_corner_fem",
              "V_corner_fem_gci", "error_corner_pct", "V_corner_fem_offset", "V_corner_fem_offset_gci",
              "error_corner_offset_pct", "n_fit_mid", "n_fit_corner", "R_eq", "R_eq_fem", "R_eq_fem_offset",
              "rms_field_error", "rms_field_error_offset", "current_imbalance", "t_packing_s", "t_solve_s"]


SUMMARY_KEYS = ("n", "n_target", "law", "r_mean", "V_mid", "V_mid_fem", "error_mid_pct", "V_corner",
                "V_corner_fem", "error_corner_pct", "error_mid_offset_pct", "error_corner_offset_pct")


def run_one(n, seed, law, out_dir, hs=FEM_HS, offset=True, plot=True, **kw):
    """One packing and law: DEM, both FEM references, field errors, files. Returns the row."""
    os.makedirs(out_dir, exist_ok=True)
    stem = os.path.join(out_dir, f"plate_n{n}_s{seed}_{law}")
    row = run_plate(n, seed, law, elements_csv=stem + "_elements.csv", **kw)
    t0 = time.perf_counter()
    ref = fem_reference(0.0, hs)
    ref_off = fem_reference(row["r_mean"], hs) if offset else None
    compare(row, ref, ref_off)
    field_errors(row, offset_too=offset)
    row["t_fem_s"] = time.perf_counter() - t0
    row["fem_h"] = list(hs)
    if plot:
        plot_field(row, stem + ".png")
    with open(stem + ".json", "w") as fh:
        json.dump(public(row), fh)
    return row


def sweep(sizes=SIZES, laws=LAWS, seed=1, out_dir="out/plate_potential", hs=FEM_HS, **kw):
    """Every size x law; writes plate_potential.csv and plate_potential.png. Returns the rows."""
    rows = sweep_runs(lambda n, law: run_one(n, seed, law, out_dir, hs, **kw), sizes, laws, out_dir,
                      "plate_potential.csv", CSV_FIELDS, summary_line)
    plot_sweep(rows, os.path.join(out_dir, "plate_potential.png"))
    return rows


def summary_line(row) -> str:
    s = (f"plate {row['n']} elements (r_mean {row['r_mean'] * 1e6:.0f} um), {row['law']}: "
         f"V_mid {row['V_mid']:.4f} V (FEM {row['V_mid_fem']:.4f}, {row['error_mid_pct']:+.2f} %), "
         f"V_corner {row['V_corner']:.4f} V (FEM {row['V_corner_fem']:.4f}, {row['error_corner_pct']:+.2f} %)")
    if "error_mid_offset_pct" in row:
        s += (f"; vs offset-electrode FEM: {row['error_mid_offset_pct']:+.2f} %, "
              f"{row['error_corner_offset_pct']:+.2f} %")
    return s


def collect(out_dir):
    """Rows of every ``plate_n*_s*_*.json`` in ``out_dir`` (sorted by n, law), written to
    ``plate_potential.csv`` with the sweep plot ``plate_potential.png`` there. Returns the rows."""
    rows = collect_runs(out_dir, "plate_n*_s*_*.json", "plate_potential.csv", CSV_FIELDS, LAWS)
    if rows:
        plot_sweep(rows, os.path.join(out_dir, "plate_potential.png"))
    return rows


def _params(argv):
    """Parameters from the command line, or from a yade-electro batch table line."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--law", default="continuum", choices=LAWS)
    ap.add_argument("--gap", type=float, default=0.1, help="electrode layer: distance <= gap r_mean")
    ap.add_argument("--fit-radius", type=float, default=2.5, help="control-point fit radius / r_mean")
    ap.add_argument("--corner-fit-radius", type=float, default=4.0,
                    help="fit radius / r_mean at the corner point")
    ap.add_argument("--fem-h", type=lambda s: tuple(float(x) for x in s.split(",")), default=FEM_HS,
                    help="FEM mesh sizes [m], coarsest first (three)")
    ap.add_argument("--no-offset", action="store_true", help="skip the offset-electrode FEM")
    ap.add_argument("--sweep", action="store_true", help="5k, 10k, 20k x both laws")
    ap.add_argument("--collect", action="store_true",
                    help="only gather the per-run JSON files of --out (e.g. after yade-batch) into "
                         "plate_potential.csv and plate_potential.png")
    ap.add_argument("--sizes", type=lambda s: tuple(int(x) for x in s.split(",")), default=SIZES)
    ap.add_argument("--out", default="out/plate_potential")
    args = ap.parse_args(argv)
    return apply_batch_table(args)      # under yade-batch, the table line gives n, seed, law


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    kw = dict(gap=args.gap, fit_radius=args.fit_radius, corner_fit_radius=args.corner_fit_radius)
    if args.collect:
        rows = collect(args.out)
        summary = {"case": "plate_potential", "collected": len(rows), "rows": [
            {k: r.get(k) for k in SUMMARY_KEYS} for r in rows]}
        print(json.dumps(summary))
        return summary
    if args.sweep:
        rows = sweep(args.sizes, LAWS, args.seed, args.out, args.fem_h, offset=not args.no_offset, **kw)
        summary = {"case": "plate_potential", "rows": [{k: r.get(k) for k in SUMMARY_KEYS} for r in rows]}
        print(json.dumps(summary))
        return summary
    row = run_one(args.n, args.seed, args.law, args.out, args.fem_h, offset=not args.no_offset, **kw)
    print(summary_line(row))
    stem = os.path.join(args.out, f"plate_n{args.n}_s{args.seed}_{args.law}")
    print(f"wrote {stem}_elements.csv, {stem}.json, {stem}.png")
    out = public(row)
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
