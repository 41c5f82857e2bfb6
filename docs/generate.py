"""Write the docs' generated tables (``docs/_generated/*.md``) from the results the cases and the
benches printed (``docs/results``): every figure in a validation or benchmark table comes from
a file a script wrote, none is typed by hand.

Run by ``make docs`` before Sphinx; ``python3 docs/generate.py`` alone to look at them.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
OUT = HERE / "_generated"


def read_csv(name):
    with open(RESULTS / name, newline="") as fh:
        return list(csv.DictReader(fh))


def read_jsonl(name):
    return [json.loads(line) for line in (RESULTS / name).read_text().splitlines() if line.strip().startswith("{")]


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def fmt(v, spec):
    if spec == "s":
        return str(v)
    x = num(v)
    if math.isnan(x):
        return "-"
    if math.isinf(x):
        return "inf"
    return format(x, spec)


def table(rows, columns, source):
    """A markdown table of ``rows`` (dicts) by ``columns`` [(header, key or function, format)],
    with its source file named under it."""
    head = "| " + " | ".join(c[0] for c in columns) + " |"
    lines = [head, "|" + "---|" * len(columns)]
    for r in rows:
        cells = []
        for _, key, spec in columns:
            v = key(r) if callable(key) else r.get(key)
            cells.append(fmt(v, spec))
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    lines.append(f"*Generated from `docs/results/{source}`.*")
    return "\n".join(lines) + "\n"


def mean(xs):
    xs = [num(x) for x in xs]
    return sum(xs) / len(xs)


# ---------------------------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------------------------
def rod_resistance():
    cont, vor = read_csv("rod_resistance_continuum.csv"), read_csv("rod_resistance_voronoi.csv")
    surf = read_csv("rod_resistance_voronoi_surface.csv")
    rows = []
    for n in sorted({int(r["n"]) for r in cont}):
        c = [r for r in cont if int(r["n"]) == n]
        v = [r for r in vor if int(r["n"]) == n]
        s = [r for r in surf if int(r["n"]) == n]
        rows.append({"n": n, "r_mean": 1e6 * num(c[0]["r_mean"]),
                     "continuum": ", ".join(f"{num(r['error_pct']):+.2f}" for r in c),
                     "continuum_mean": mean(r["error_pct"] for r in c),
                     "voronoi": ", ".join(f"{num(r['error_pct']):+.2f}" for r in v),
                     "voronoi_mean": mean(r["error_pct"] for r in v),
                     "surface_mean": mean(r["error_pct"] for r in s) if s else math.nan})
    return table(rows, [("N", "n", ",.0f"), ("r_mean [um]", "r_mean", ".0f"),
                        ("`continuum`, 3 packings [%]", "continuum", "s"), ("mean [%]", "continuum_mean", "+.1f"),
                        ("`voronoi`, element layers [%]", "voronoi", "s"), ("mean [%]", "voronoi_mean", "+.2f"),
                        ("`voronoi`, surface electrodes, mean [%]", "surface_mean", "+.2f")],
                 "rod_resistance_{continuum,voronoi,voronoi_surface}.csv")


def joule_rod():
    rows = [r for r in read_csv("joule_rod.csv") if r["theta"] == "backward-euler"]
    return table(rows, [("law", "law", "s"), ("seed", "seed", ".0f"), ("core vs T(t) [%]", "error_core_pct", "+.2f"),
                        ("rod mean vs energy balance [%]", "error_mean_vs_energy_balance_pct", "+.2f"),
                        ("rod mean vs T(t) [%]", "error_mean_vs_theory_pct", "+.2f")], "joule_rod.csv")


def slab():
    cols = [("integrator", "integrator", "s"), ("step / explicit bound", "dt_over_explicit_bound", ".3g")]
    cols += [(f"Fo {fo}", f"error_Fo_{fo}", ".2g") for fo in ("0.05", "0.1", "0.2", "0.5", "1")]
    return table(read_csv("slab_transient.csv"), cols, "slab_transient.csv")


def plate():
    rows = read_csv("plate_potential.csv")
    return table(rows, [("N", "n", ",.0f"), ("law", "law", "s"), ("V_mid", "V_mid", ".4f"),
                        ("vs FEM [%]", "error_mid_pct", "+.2f"), ("vs offset FEM [%]", "error_mid_offset_pct", "+.2f"),
                        ("V_corner", "V_corner", ".4f"), ("vs FEM [%]", "error_corner_pct", "+.2f"),
                        ("vs offset FEM [%]", "error_corner_offset_pct", "+.2f")], "plate_potential.csv")


def notched():
    rows = read_csv("notched_joule.csv")
    return table(rows, [("N", "n", ",.0f"), ("law", "law", "s"), ("R_eq [mohm]", lambda r: 1e3 * num(r["R_eq"]), ".4f"),
                        ("vs FEM [%]", "error_R_eq_pct", "+.2f"), ("T_slab [K]", "T_slab", ".2f"),
                        ("T_slab FEM [K]", "T_slab_fem", ".2f"), ("rise error [%]", "error_T_slab_pct", "+.2f")],
                 "notched_joule.csv")


def edge_crack():
    rows = read_csv("edge_crack.csv")
    return table(rows, [("N", "n", ",.0f"), ("seed", "seed", ".0f"), ("broken bonds", "broken_bonds", ".0f"),
                        ("`facets` increment", "increment_facets", ".4f"),
                        ("error [%]", "increment_error_pct_facets", "+.2f"),
                        ("leak [%]", lambda r: 100 * num(r["leak_fraction_facets"]), ".1f"),
                        ("`paths` increment", "increment_paths", ".4f"),
                        ("error [%]", "increment_error_pct_paths", "+.2f")], "edge_crack.csv")


# ---------------------------------------------------------------------------------------------
# benchmarks
# ---------------------------------------------------------------------------------------------
def bench_solvers():
    return table(read_jsonl("bench_solvers_latest.jsonl"),
                 [("N", "n", ",.0f"), ("unknowns", "n_unknowns", ",.0f"), ("solver", "solver", "s"),
                  ("cold [ms]", "cold_ms", ".1f"), ("first solve [ms]", "cold_solve_ms", ".1f"),
                  ("re-solve after 1 % [ms]", "resolve_ms", ".1f"), ("iterations cold", "cold_iterations", ".0f"),
                  ("re-solve", "resolve_iterations", ".0f"), ("re-solve / cold", "resolve_ratio", ".2f")],
                 "bench_solvers_latest.jsonl")


def bench_live():
    rows = read_jsonl("bench_live_5k_latest.jsonl") + read_jsonl("bench_live_20k_latest.jsonl")
    rows = [r for r in rows if r.get("bench") == "live"]
    return table(rows, [("N", "n", ",.0f"), ("engine", "engine", "s"), ("law", "law", "s"), ("period", "period", ".0f"),
                        ("wall ratio", "ratio", ".3f"), ("from calls", "ratio_from_calls", ".3f"),
                        ("unchanged call [ms]", "unchanged_ms", ".2f"),
                        ("median call that found moves [ms]", "geometry_median_ms", ".1f"),
                        ("largest call [ms]", "max_call_ms", ".1f"), ("bond-break call [ms]", "bond_break_call_ms", ".0f"),
                        ("YADE step [ms]", "mech_step_ms", ".1f")],
                 "bench_live_{5k,20k}_latest.jsonl")


def bench_coupled():
    d = read_jsonl("bench_coupled_latest.jsonl")[0]
    return table(d["results"], [("N", "n", ",.0f"), ("backward Euler, constant rho [ms]", "be_unchanged_ms", ".2f"),
                                ("backward Euler, rho_e(T) [ms]", "be_rho_T_ms", ".2f"),
                                ("rho_T step ratio", "rho_T_step_ratio", ".2f"),
                                ("explicit, constant rho [ms]", "explicit_unchanged_ms", ".2f"),
                                ("first step [ms]", "be_unchanged_first_ms", ".0f")], "bench_coupled_latest.jsonl")


def bench_granular():
    rows = read_jsonl("bench_granular_latest.jsonl")
    rows = [r for r in rows if r.get("block_timer")][-4:]
    return table(rows, [("period", "period", ".0f"), ("overlap", "overlap", "s"),
                        ("engine share, median of pairs", lambda r: 100 * r["engine_share"], ".1f"),
                        ("share of the sums [%]", lambda r: 100 * r["engine_share_of_sums"], ".1f"),
                        ("a bare pause as long [%]", lambda r: 100 * r.get("pause_share", math.nan), ".1f"),
                        ("in-call [ms]", "call_ms", ".2f"), ("YADE step [ms]", "yade_step_ms", ".2f")],
                 "bench_granular_latest.jsonl (the last four rows)")


def bench_pin():
    return table(read_jsonl("bench_pin_latest.jsonl"),
                 [("law", "law", "s"), ("period", "period", ".0f"),
                  ("engine share [%]", lambda r: 100 * r["engine_share"], ".2f"), ("wall ratio", "ratio", ".3f")],
                 "bench_pin_latest.jsonl")


def bench_scale():
    rows = read_jsonl("scale/bench_scale_run9.jsonl")
    return table(rows, [("N", "n", ",.0f"), ("pipeline [s]", "pipeline_s", ".3g"),
                        ("cold solve [ms]", "cold_solve_ms", ".4g"), ("iterations", "iterations", ".0f"),
                        ("Eigen CG [ms]", "eigen_ms", ".4g"), ("Eigen iterations", "eigen_iterations", ".0f"),
                        ("ours / Eigen", "ratio_vs_eigen", ".2f"), ("peak memory [MB]", "peak_rss_mb", ".0f")],
                 "scale/bench_scale_run9.jsonl")


def bench_scale_voronoi():
    rows = read_jsonl("scale/bench_scale_voronoi_run3.jsonl")
    return table(rows, [("N", "n", ",.0f"), ("pipeline [s]", "pipeline_s", ".3g"),
                        ("tessellation [s]", lambda r: r["stages_s"]["tessellation"], ".3g"),
                        ("solve [s]", lambda r: r["stages_s"]["solve"], ".3g"),
                        ("R vs nominal", "R_rel_diff", ".1e"), ("peak memory [MB]", "peak_rss_mb", ".0f")],
                 "scale/bench_scale_voronoi_run3.jsonl")


def bench_size_spread():
    return table(read_jsonl("bench_size_spread_latest.jsonl"),
                 [("spheres", "n", ",.0f"), ("largest / smallest radius", "ratio", ".0f"),
                  ("by size classes [ms]", "classes_ms", ".1f"), ("one reach [ms]", "single_reach_ms", ".0f"),
                  ("speed-up", "speedup", ".0f"), ("same pairs", "same_pairs", "s")],
                 "bench_size_spread_latest.jsonl")


FIGURES = {
    "validation_granular": [
        ("two_spheres.json", "max_error_pct", "two copper spheres against the closed form, largest error [% of 100 K]",
         ".2g", "< 0.1"),
        ("powder_column_n10.json", "slope_error_pct_hertz",
         "pressed chain of 10 spheres, slope of log R against log F against -1/3 [%]", ".2g", "< 1"),
        ("powder_column_n10.json", "slope_error_pct_plate", "the same, top sphere to the plate electrode [%]", ".2g",
         "< 1"),
        ("powder_column_n10.json", "max_R_check_error_pct",
         "random bed pressed between plates: R against the network from YADE's forces [%]", ".2g", ""),
        ("falling_bed/falling_bed_n2000.json", "energy_drift", "falling bed: largest drift of the stored heat",
         ".1e", "< 1e-9"),
        ("falling_bed/falling_bed_n2000.json", "ratio", "falling bed: k_eff of the network over the affine estimate",
         ".3f", ""),
        ("container_heating/container_heating_n2000.json", "balance_rel",
         "container heated through its wall: wall heat against heat stored", ".1e", "< 1e-6"),
        ("container_heating/container_heating_n2000.json", "t90_centre_s",
         "container: the bed centre at 90 % of the wall temperature [s]", ".0f", ""),
        ("cross_engine_heat/cross_engine_heat_all.json", "max_rel_diff_pct",
         "the same heat problem in YADE and LIGGGHTS, largest difference [% of the range]", ".3f", "< 0.5"),
    ],
    "validation_pin": [
        ("pin_torsion_n5000_s1.json", "elastic_torque_error_pct", "elastic torque against G J theta / h [%]", "+.3f",
         "within 5"),
        ("pin_torsion_n5000_s1.json", "theta_first_break_vs_yield_pct", "first broken bond against theta_y [%]",
         "+.2f", "within 20"),
        ("pin_torsion_n5000_s1.json", "theta_separation", "separation (R = inf, both laws) [rad]", ".4f",
         "infinite once broken"),
        ("pin_torsion_n5000_s1.json", "max_tau_ratio", "peak torque as tau / tau_y", ".2f", ""),
        ("pin_torsion_n5000_s1.json", "kinetic_to_elastic_max", "kinetic / elastic energy before the first break",
         ".1e", "quasi-static"),
        ("pin_torsion_n5000_s1.json", "engine_share", "both engines' share of the wall time, every 100 steps",
         ".3f", "< 0.10"),
    ],
}


def figures(rows):
    lines = ["| figure | value | target |", "|---|---|---|"]
    sources = []
    for name, key, label, spec, target in rows:
        d = json.loads((RESULTS / name).read_text())
        lines.append(f"| {label} | {fmt(d.get(key), spec)} | {target} |")
        if name not in sources:
            sources.append(name)
    return "\n".join(lines) + "\n\n*Generated from " + ", ".join(f"`docs/results/{n}`" for n in sources) + ".*\n"


def cross_packing():
    d = json.loads((RESULTS / "cross_engine_packing/cross_engine_packing_n5000.json").read_text())
    keys = ("n", "bed_height_m", "volume_fraction", "volume_fraction_core", "volume_fraction_wall", "coordination",
            "coordination_core", "overlap_mean", "overlap_median", "k_eff_over_k")
    lines = ["| figure | LIGGGHTS | YADE | YADE / LIGGGHTS - 1 |", "|---|---|---|---|"]
    for k in keys:
        lines.append(f"| {k} | {fmt(d['liggghts'][k], '.5g')} | {fmt(d['yade'][k], '.5g')} | "
                     f"{100 * d['relative_difference'][k]:+.1f} % |")
    lines.append(f"| overlaps, Kolmogorov-Smirnov | D = {d['ks_statistic']:.3f} | p = {d['ks_pvalue']:.2g} | "
                 f"{'differ' if d['overlaps_differ'] else 'do not differ'} at 5 % |")
    return "\n".join(lines) + "\n\n*Generated from `docs/results/cross_engine_packing/cross_engine_packing_n5000.json`.*\n"


TABLES = {
    "validation_granular": lambda: figures(FIGURES["validation_granular"]),
    "validation_pin": lambda: figures(FIGURES["validation_pin"]),
    "validation_cross_packing": cross_packing,
    "validation_rod": rod_resistance, "validation_joule_rod": joule_rod, "validation_slab": slab,
    "validation_plate": plate, "validation_notched": notched, "validation_edge_crack": edge_crack,
    "bench_solvers": bench_solvers, "bench_live": bench_live, "bench_coupled": bench_coupled,
    "bench_granular": bench_granular, "bench_pin": bench_pin, "bench_scale": bench_scale,
    "bench_scale_voronoi": bench_scale_voronoi, "bench_size_spread": bench_size_spread,
}


def main():
    OUT.mkdir(exist_ok=True)
    for name, fn in TABLES.items():
        (OUT / f"{name}.md").write_text(fn())
    print(f"[docs] {len(TABLES)} tables written to {OUT}")


if __name__ == "__main__":
    main()
