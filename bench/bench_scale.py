"""Scale: the core pipeline graph -> conductances -> solve -> Joule on jittered lattice rods up
to a million elements, and the linear solve side by side with Eigen's ConjugateGradient.

Each size n is a rod of m x m x 4m spheres (r = 0.5 mm) on a cubic grid of spacing 2r, every
centre moved by a random 5 % of r, bonded to its six grid neighbours; the ends (first and
last layer) are the electrodes at 1 V / 0 V; law ``continuum``, rho_e of 304L. Figures:

* ``stages_s``: graph (positions, edges, ContactGraph), conductances, the cold
  ``ConductionProblem`` solve (structure + solver setup + iterations: what the engine's
  first call costs), Joule heat per edge;
* the linear solve alone, on the reduced system K_uu x = -K_ud u_d of the same problem,
  blocks interleaved (best of ``--repeat``): ``cold_solve_ms`` (the default solver, from
  zero, setup included) against ``eigen_ms`` (Eigen 3.4 ``ConjugateGradient`` with its
  diagonal preconditioner, Lower|Upper, the same relative tolerance 1e-10, compute() + solve(),
  built here with -O3 -march=native from Debian's libeigen3-dev: GranOO's solver);
  ``ratio_vs_eigen`` = cold_solve_ms / eigen_ms; also plain Jacobi CG (``cg_ms``) and CG
  with PyAMG smoothed aggregation (``amg_ms``, setup included);
* ``resolve_ms``: after every conductance changed by a random factor within +-1 % (a rho(T)
  update), the values assembled in place, the solver's setup updated, and the solve
  warm-started from the previous potentials; ``resolve_ratio_vs_eigen`` = resolve_ms /
  eigen_ms (Eigen cold);
* ``peak_rss_mb``: the process's peak resident memory so far (sizes run in increasing order);
* the load average, and the BLAS thread limit (OpenBLAS is held to one thread here, as
  inside YADE; see docs/benchmarks.md).

``--laws voronoi`` (default: both) times the ``voronoi`` law's pipeline instead, each size in
a process of its own: the rod in its box, stages graph / tessellation (bounded Voronoi
cells, faces and the conducting network) / conductances / cold solve / Joule, wall and CPU
time (CPU including the CGAL Delaunay helper, a child process; the face geometry runs on
``YADE_ELECTRO_TESSELLATION_THREADS`` threads, default all cores), peak RSS of the process
and of the helper, and R_eq against rho L / A between the electrode layers.

Run (no YADE needed): ``/usr/bin/python3 bench/bench_scale.py [--sizes 5000,20000,100000]``.
One JSON line per size and law.
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")     # before numpy: YADE's own setting
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

_SCRIPT = __file__ if __file__.endswith("bench_scale.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_scale.py") else __file__)
HERE = Path(os.path.abspath(_SCRIPT)).parent
sys.path.insert(0, str(HERE.parent))

import numpy as np  # noqa: E402

RADIUS = 0.5e-3              # m
RHO = 7.4e-7                 # ohm m (304L)
RTOL = 1e-10


def log(msg):
    print(f"[scale] {msg}", file=sys.stderr, flush=True)


def eigen_driver() -> str:
    """Path of the compiled Eigen CG driver (built once into ~/.cache/yade-electro)."""
    src = HERE / "eigen" / "eigen_cg.cpp"
    cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "yade-electro"
    cache.mkdir(parents=True, exist_ok=True)
    exe = cache / f"eigen_cg_{int(src.stat().st_mtime)}"
    if exe.exists():
        return str(exe)
    cxx = shutil.which("g++")
    if cxx is None or not Path("/usr/include/eigen3/Eigen/Sparse").exists():
        raise SystemExit("bench_scale needs g++ and Eigen (apt-get install g++ libeigen3-dev; `make install` does)")
    log(f"building {exe.name} with g++ -O3 -march=native")
    subprocess.run([cxx, "-O3", "-march=native", "-DNDEBUG", "-I/usr/include/eigen3", str(src), "-o", str(exe)],
                   check=True)
    return str(exe)


def jittered_rod(n, seed=1):
    """(graph, top nodes, bottom nodes) of a rod of about n spheres (m x m x 4m)."""
    from yade_electro.core.graph import ContactGraph
    m = max(3, int(round((n / 4.0) ** (1.0 / 3.0))))
    shape = (m, m, 4 * m)
    k, j, i = np.meshgrid(np.arange(shape[2]), np.arange(shape[1]), np.arange(shape[0]), indexing="ij")
    grid = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    rng = np.random.default_rng(seed)
    pos = grid * (2.0 * RADIUS) + rng.normal(0.0, 0.05 * RADIUS, grid.shape)
    idx = np.arange(grid.shape[0]).reshape(shape[2], shape[1], shape[0])
    edges = np.concatenate([
        np.stack([idx[:, :, :-1].ravel(), idx[:, :, 1:].ravel()], axis=1),
        np.stack([idx[:, :-1, :].ravel(), idx[:, 1:, :].ravel()], axis=1),
        np.stack([idx[:-1, :, :].ravel(), idx[1:, :, :].ravel()], axis=1)])
    g = ContactGraph(pos, np.full(grid.shape[0], RADIUS), edges)
    layer = m * m
    return g, np.arange(grid.shape[0] - layer, grid.shape[0]), np.arange(layer)


def reduced_rod_system(g, top, bottom, c):
    """The reduced system of the rod with ``top`` at 1 V and ``bottom`` at 0 V: (ReducedSystem,
    K_uu, K_ud, b = -K_ud u_d, coordinates of the unknowns)."""
    from yade_electro.network.condensation import ReducedSystem
    rs = ReducedSystem(g.n_nodes, g.edges, [top, bottom])
    Kuu, Kud = rs.assemble(c)
    return rs, Kuu, Kud, -(Kud @ np.array([1.0, 0.0])), g.pos[rs.unknown_nodes]


def write_system(path, A, b, repeat=1):
    A = A.tocsr()
    with open(path, "wb") as fh:
        np.array([A.shape[0], A.nnz], dtype=np.int64).tofile(fh)
        np.array([RTOL], dtype=np.float64).tofile(fh)
        np.array([repeat], dtype=np.int64).tofile(fh)
        A.indptr.astype(np.int64).tofile(fh)
        A.indices.astype(np.int64).tofile(fh)
        A.data.astype(np.float64).tofile(fh)
        np.asarray(b, dtype=np.float64).tofile(fh)


def run_eigen(exe, path):
    out = subprocess.run([exe, path], check=True, capture_output=True, text=True,
                         env=dict(os.environ, OMP_NUM_THREADS="1"))
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_size(n, repeat, exe, tmp):
    from yade_electro.laws.factors import conductance
    from yade_electro.network.conduction import ConductionProblem
    from yade_electro.network.kirchhoff import Electrode
    from yade_electro.solvers.registry import auto_solver_name, make_solver
    row = {"bench": "scale", "law": "continuum"}
    st = {}
    t = time.perf_counter()
    g, top, bottom = jittered_rod(n)
    st["graph"] = time.perf_counter() - t
    row["n"], row["edges"] = int(g.n_nodes), int(len(g.edges))
    log(f"n = {g.n_nodes}: graph {st['graph']:.1f} s")
    t = time.perf_counter()
    c = conductance(g, RHO, "continuum")
    st["conductances"] = time.perf_counter() - t
    log(f"  conductances {st['conductances']:.1f} s")
    t = time.perf_counter()
    el = [Electrode("top", top, potential=1.0), Electrode("bottom", bottom, potential=0.0)]
    prob = ConductionProblem(g.n_nodes, g.edges, c, el, solver="auto", coords=g.pos)
    sol = prob.solve()
    st["solve"] = time.perf_counter() - t
    log(f"  cold ConductionProblem solve {st['solve']:.1f} s")
    t = time.perf_counter()
    dphi = sol.potential[g.edges[:, 0]] - sol.potential[g.edges[:, 1]]
    joule = c * dphi ** 2
    st["joule"] = time.perf_counter() - t
    row["stages_s"] = st
    row["pipeline_s"] = float(sum(st.values()))
    row["R_eq_ohm"] = float(sol.equivalent_resistance("top", "bottom"))
    row["joule_W"] = float(joule.sum())
    # the reduced system, solved by each side
    rs, Kuu, Kud, b, coords = reduced_rod_system(g, top, bottom, c)
    nu = Kuu.shape[0]
    sysfile = os.path.join(tmp, "system.bin")
    write_system(sysfile, Kuu, b)
    name = auto_solver_name(nu)
    best = {"default": np.inf, "cg": np.inf, "amg": np.inf, "eigen": np.inf}
    info = {}
    for k in range(repeat):
        e = run_eigen(exe, sysfile)
        best["eigen"] = min(best["eigen"], e["eigen_ms"])
        info["eigen"] = e
        for key, sname in (("default", name), ("cg", "cg"), ("amg", "cg-amg")):
            s = make_solver(sname, nu)
            s.set_geometry(coords, 2.0 * RADIUS)
            t = time.perf_counter()
            x, inf = s.solve(Kuu, b)
            best[key] = min(best[key], 1e3 * (time.perf_counter() - t))
            info[key] = inf
        log(f"  block {k + 1}/{repeat}: eigen {e['eigen_ms']:.0f} ms, {name} {best['default']:.0f} ms, "
            f"cg {best['cg']:.0f} ms, cg-amg {best['amg']:.0f} ms (best so far)")
    row.update({"solver": name, "cold_solve_ms": best["default"], "iterations": info["default"]["iterations"],
                "cg_ms": best["cg"], "cg_iterations": info["cg"]["iterations"], "eigen_ms": best["eigen"],
                "eigen_iterations": info["eigen"]["eigen_iterations"], "eigen_residual": info["eigen"]["eigen_residual"],
                "amg_ms": best["amg"], "amg_iterations": info["amg"]["iterations"],
                "ratio_vs_eigen": best["default"] / best["eigen"], "cg_ratio_vs_eigen": best["cg"] / best["eigen"],
                "amg_ratio_vs_eigen": best["amg"] / best["eigen"]})
    # re-solve after a +-1 % change of every conductance, setup kept, warm start
    s = make_solver(name, nu)
    s.set_geometry(coords, 2.0 * RADIUS)
    x, _ = s.solve(Kuu, b)
    rng = np.random.default_rng(2)
    times, its = [], []
    for k in range(repeat):
        c2 = c * (1.0 + 0.01 * rng.uniform(-1.0, 1.0, c.size))
        t = time.perf_counter()
        rs.assemble(c2)                      # the same Kuu object, values in place
        b2 = -(Kud @ np.array([1.0, 0.0]))
        s.update(Kuu)
        x, inf = s.solve(Kuu, b2, x0=x)
        times.append(1e3 * (time.perf_counter() - t))
        its.append(inf["iterations"])
    row.update({"resolve_ms": float(min(times)), "resolve_iterations": int(its[int(np.argmin(times))]),
                "resolve_ratio_vs_eigen": float(min(times)) / best["eigen"],
                "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                "loadavg": os.getloadavg()[0], "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
                "repeat": repeat})
    return row


def bench_voronoi(n):
    """The ``voronoi`` law's pipeline on the rod of about n elements in its box: graph,
    tessellation (bounded cells, faces, the conducting network), conductances, the cold
    ConductionProblem solve, Joule heat. Run in a process of its own (peak RSS per size)."""
    from yade_electro.laws.factors import make_law
    from yade_electro.geometry.shapes import Box
    from yade_electro.network.conduction import ConductionProblem
    from yade_electro.network.kirchhoff import Electrode
    from yade_electro.geometry.tessellation import tessellation_threads
    row = {"bench": "scale", "law": "voronoi"}
    st = {}
    cpu0 = time.process_time()
    t = time.perf_counter()
    g, top, bottom = jittered_rod(n)
    st["graph"] = time.perf_counter() - t
    row["n"] = int(g.n_nodes)
    lo, hi = g.pos.min(axis=0) - RADIUS, g.pos.max(axis=0) + RADIUS
    law = make_law("voronoi", container=Box(lo, hi))
    t = time.perf_counter()
    edges = law.network(g)
    st["tessellation"] = time.perf_counter() - t
    log(f"n = {g.n_nodes}: voronoi faces and network {st['tessellation']:.1f} s ({len(edges)} edges)")
    t = time.perf_counter()
    c = law.factor(g, edges) / RHO
    st["conductances"] = time.perf_counter() - t
    t = time.perf_counter()
    el = [Electrode("top", top, potential=1.0), Electrode("bottom", bottom, potential=0.0)]
    sol = ConductionProblem(g.n_nodes, edges, c, el, solver="auto", coords=g.pos).solve()
    st["solve"] = time.perf_counter() - t
    t = time.perf_counter()
    joule = c * (sol.potential[edges[:, 0]] - sol.potential[edges[:, 1]]) ** 2
    st["joule"] = time.perf_counter() - t
    wall = float(sum(st.values()))
    # the nominal resistance between the electrode layers' centres, in the box's cross-section
    length = float(g.pos[top, 2].mean() - g.pos[bottom, 2].mean())
    area = float((hi[0] - lo[0]) * (hi[1] - lo[1]))
    R = float(sol.equivalent_resistance("top", "bottom"))
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)          # the CGAL helper
    row.update({"stages_s": st, "pipeline_s": wall,
                "cpu_s": time.process_time() - cpu0 + kids.ru_utime + kids.ru_stime,
                "helper_peak_rss_mb": kids.ru_maxrss / 1024.0,
                "edges": int(len(edges)), "R_eq_ohm": R, "R_nominal_ohm": RHO * length / area,
                "R_rel_diff": R / (RHO * length / area) - 1.0, "joule_W": float(joule.sum()),
                "tessellation_threads": tessellation_threads(),
                "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                "loadavg": os.getloadavg()[0]})
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="5000,20000,100000,500000,1000000")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--laws", default="continuum,voronoi",
                    help="continuum: pipeline + solver comparison; voronoi: its pipeline, each size in a process of its own")
    ap.add_argument("--voronoi-worker", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    if args.voronoi_worker:
        print(json.dumps(bench_voronoi(args.voronoi_worker)), flush=True)
        return []
    laws = args.laws.split(",")
    rows = []
    sizes = [int(s) for s in args.sizes.split(",")]
    if "continuum" in laws:
        exe = eigen_driver()
        with tempfile.TemporaryDirectory() as tmp:
            for n in sizes:
                row = bench_size(n, args.repeat, exe, tmp)
                rows.append(row)
                print(json.dumps(row), flush=True)
    if "voronoi" in laws:
        for n in sizes:
            out = subprocess.run([sys.executable, os.path.abspath(_SCRIPT), "--voronoi-worker", str(n)],
                                 check=True, stdout=subprocess.PIPE, text=True)
            row = json.loads(out.stdout.strip().splitlines()[-1])
            rows.append(row)
            print(json.dumps(row), flush=True)
    return rows


if __name__ == "__main__":
    main()
