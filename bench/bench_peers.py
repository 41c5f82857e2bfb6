"""Our default solver against the library solvers a user would pick instead, on one process and
partitioned over the ranks of mpiexec.

    /usr/bin/python3 bench/bench_peers.py [--sizes 20000,100000,1000000] [--systems lattice,bed,voronoi]
                                          [--repeat 2] [--ranks 1,2,3] [--out results.jsonl]

Systems (the reduced systems the engines solve: the end layers held at 1 V and 0 V, eliminated):

``lattice``
    bench_scale's jittered lattice rod (m x m x 4m, 5 % jitter), continuum law.
``bed``
    A contact-law bed: the same lattice of spheres with radii 1.10-1.30 R, so each contact's
    overlap, hence conductance, differs (contact law; the few contacts the jitter opens, about
    0.3 %, are left out).
``voronoi``
    A dense random rod (``dense_packing`` in a 1:1:4 box, kept in ``--cache-dir``, bonded where
    the gap is under 10 % of the radii's sum) with the voronoi law (only the sizes up to ``--voronoi-max``: the packing of 1M takes ~26 min).

Serial part (this process, OpenBLAS on one thread, the solvers interleaved in blocks, best of
``--repeat``): ours (``cg-deflated``, given the unknowns' positions as the engines give them),
PETSc CG + BoomerAMG (hypre's 3-D options), PETSc CG + GAMG, PyAMG SA-CG (``cg-amg``) and
Eigen's CG (compiled driver of bench_scale, diagonal preconditioner); each cold, then a re-solve
after a +-1 % change of every conductance (setup kept where the solver keeps one, warm start).
Tolerance 1e-10 on the unpreconditioned residual. One JSON line per system and size.

Partitioned part (``--ranks``): ``mpiexec -n P`` runs of this script (``--worker``), each rank
owning a z slab of the same system, our deflation (ICC smoother, the default, and
``deflation_jacobi`` for reference), BoomerAMG and GAMG as the preconditioner of the partitioned
CG (:mod:`yade_electro.solvers.partitioned`); cold and re-solve, rank 0 prints one JSON line
per system, size and P. The last lines extrapolate our iteration count to 10M and 100M unknowns
(a power law through the measured counts) and name the size at which AMG's (flat) count would
make it faster, from the measured time per iteration of each: serially (``ranks`` 0) and for
each rank count. ``--parts serial`` or ``--parts partitioned`` runs one part only.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))

RTOL = 1e-10
SERIAL = ("ours", "boomeramg", "gamg", "pyamg", "eigen")


def log(msg):
    print(f"[bench_peers] {msg}", file=sys.stderr, flush=True)


# -- the systems ------------------------------------------------------------------------------
def system(kind: str, n: int, cache_dir=None):
    """(graph, edges, conductances [S], top nodes, bottom nodes, spacing [m]) of a system."""
    from bench_scale import RADIUS, RHO, jittered_rod
    from yade_electro.laws.factors import conductance, make_law
    if kind == "lattice":
        g, top, bottom = jittered_rod(n)
        return g, g.edges, conductance(g, RHO, "continuum"), top, bottom, 2.0 * RADIUS
    if kind == "bed":
        from yade_electro.core.graph import ContactGraph
        g, top, bottom = jittered_rod(n)
        rad = RADIUS * np.random.default_rng(5).uniform(1.10, 1.30, g.n_nodes)
        g = ContactGraph(g.pos, rad, g.edges)
        a = make_law("contact").factor(g, g.edges)
        g = g.with_edges(g.edges[a > 0])                 # the few contacts the jitter opened
        return g, g.edges, a[a > 0] / RHO, top, bottom, 2.0 * RADIUS
    if kind == "voronoi":
        from yade_electro.geometry.shapes import Box
        from yade_electro.packing import dense_packing
        side = (n / 4.0 * (4.0 / 3.0) * np.pi / 0.64) ** (1.0 / 3.0) * RADIUS
        box = Box((0, 0, 0), (side, side, 4 * side))
        p = dense_packing(box, n=n, seed=1, cache_dir=cache_dir)
        from scipy.spatial import cKDTree
        from yade_electro.core.graph import ContactGraph
        pairs = cKDTree(p.centers).query_pairs(2.2 * float(p.radii.max()), output_type="ndarray")
        d = np.linalg.norm(p.centers[pairs[:, 0]] - p.centers[pairs[:, 1]], axis=1)
        bonded = pairs[d < 1.1 * (p.radii[pairs[:, 0]] + p.radii[pairs[:, 1]])]   # bonds (add_bonded_packing: 1.04)
        g = ContactGraph(p.centers, p.radii, bonded)
        law = make_law("voronoi", container=box)
        edges = law.network(g)
        c = law.factor(g, edges) / RHO
        z, r = p.centers[:, 2], p.radii
        top = np.flatnonzero(z + r >= 4 * side - 0.1 * r.mean())
        bottom = np.flatnonzero(z - r <= 0.1 * r.mean())
        return g, edges, c, top, bottom, 2.0 * float(r.mean())
    raise ValueError(f"unknown system {kind!r}")


def reduced(g, edges, c, top, bottom):
    from yade_electro.network.condensation import ReducedSystem
    rs = ReducedSystem(g.n_nodes, edges, [top, bottom])
    Kuu, Kud = rs.assemble(c)
    return rs, Kuu, Kud, -(Kud @ np.array([1.0, 0.0])), g.pos[rs.unknown_nodes]


def _solver(name, nu, coords, spacing):
    from yade_electro.solvers.registry import make_solver
    if name == "ours":
        s = make_solver("cg-deflated", nu, rtol=RTOL)
        s.set_geometry(coords, spacing)
        return s
    if name in ("boomeramg", "gamg"):
        from yade_electro.solvers.petsc import PETScSolver, import_petsc
        return PETScSolver(rtol=RTOL, preconditioner="hypre" if name == "boomeramg" else "gamg",
                           comm=import_petsc().COMM_SELF)
    return make_solver("cg-amg", nu, rtol=RTOL)


def run_eigen(exe, path):
    """bench_scale's Eigen driver, its JSON read with nan/inf; a run that did not reach the
    tolerance counts as failed (time inf)."""
    import re
    out = subprocess.run([exe, path], check=True, capture_output=True, text=True,
                         env=dict(os.environ, OMP_NUM_THREADS="1")).stdout.strip().splitlines()[-1]
    row = json.loads(re.sub(r"-?\bnan\b", "NaN", re.sub(r"-inf\b", "-Infinity", re.sub(r"(?<![-\w])inf\b", "Infinity", out))))
    if not (row.get("eigen_residual", np.inf) <= 10 * RTOL):
        row["eigen_ms"] = np.inf
    return row


def serial_block(kind, n, repeat, exe, tmp, cache_dir):
    from bench_scale import write_system
    t = time.perf_counter()
    g, edges, c, top, bottom, spacing = system(kind, n, cache_dir)
    rs, Kuu, Kud, b, coords = reduced(g, edges, c, top, bottom)
    nu = Kuu.shape[0]
    log(f"{kind} {n}: {nu} unknowns ({time.perf_counter() - t:.1f} s to build)")
    path = os.path.join(tmp, "system.bin")
    write_system(path, Kuu, b)
    cold = {k: np.inf for k in SERIAL}
    again = {k: np.inf for k in SERIAL if k != "eigen"}
    its, its2 = {}, {}
    rng = np.random.default_rng(2)
    for block in range(repeat):
        e = run_eigen(exe, path)
        cold["eigen"] = min(cold["eigen"], e["eigen_ms"] / 1e3)
        its["eigen"] = e["eigen_iterations"]
        c2 = c * (1.0 + 0.01 * rng.uniform(-1.0, 1.0, c.size))
        for name in SERIAL[:-1]:
            rs.assemble(c)
            s = _solver(name, nu, coords, spacing)
            t = time.perf_counter()
            x, info = s.solve(Kuu, b)
            cold[name] = min(cold[name], time.perf_counter() - t)
            its[name] = info["iterations"]
            rs.assemble(c2)                      # the same Kuu object, values in place
            b2 = -(Kud @ np.array([1.0, 0.0]))
            t = time.perf_counter()
            s.update(Kuu)
            x, info = s.solve(Kuu, b2, x0=x)
            again[name] = min(again[name], time.perf_counter() - t)
            its2[name] = info["iterations"]
        log(f"  block {block + 1}/{repeat}: " + ", ".join(f"{k} {cold[k]:.3f} s" for k in SERIAL))
    others = [k for k in SERIAL if k != "ours"]
    fastest = min(others, key=lambda k: cold[k])
    fastest2 = min([k for k in others if k != "eigen"], key=lambda k: again[k])
    return {"bench": "peers", "part": "serial", "system": kind, "n": int(g.n_nodes), "unknowns": int(nu),
            "cold_s": cold, "iterations": its, "resolve_s": again, "resolve_iterations": its2,
            "fastest_other": fastest, "ratio_ours_to_fastest": cold["ours"] / cold[fastest],
            "fastest_other_resolve": fastest2, "resolve_ratio_ours_to_fastest": again["ours"] / again[fastest2],
            "loadavg": os.getloadavg()[0], "threads": os.environ.get("OPENBLAS_NUM_THREADS"), "repeat": repeat}


# -- partitioned --------------------------------------------------------------------------------
def worker(kinds, sizes, repeat, cache_dir):
    """One rank of ``mpiexec -n P``: its slab of each system, solved by the partitioned CG."""
    from yade_electro.network.partition import OwnedRows, split_network
    from yade_electro.solvers.partitioned import GhostExchange, PartitionedSystem, mpi_comm, number_unknowns
    comm = mpi_comm()
    rank, size = comm.Get_rank(), comm.Get_size()
    for kind in kinds:
        for n in sizes:
            g, edges, c, top, bottom, spacing = system(kind, n, cache_dir)
            z = g.pos[:, 2]
            bounds = np.sort(z)[(np.arange(1, size) * g.n_nodes) // size]
            owner = np.searchsorted(bounds, z, side="right")
            share, held = split_network(g.n_nodes, edges, owner, rank)
            own = np.flatnonzero(owner == rank)
            fixed_value = np.full(g.n_nodes, np.nan)
            fixed_value[top], fixed_value[bottom] = 1.0, 0.0
            ex = GhostExchange(share, comm)
            unknown, n_global = number_unknowns(ex, ~np.isnan(fixed_value[own]))
            rows = OwnedRows(share, unknown)
            local_nodes = np.concatenate([own, share.ghost_key])
            v = np.nan_to_num(fixed_value[local_nodes])
            row = {"bench": "peers", "part": "partitioned", "system": kind, "n": int(g.n_nodes), "ranks": size,
                   "unknowns": int(n_global)}
            c2 = c * (1.0 + 0.01 * np.random.default_rng(2).uniform(-1.0, 1.0, c.size))
            for name in ("deflation", "deflation_jacobi", "hypre", "gamg"):
                pc = name.split("_")[0]
                best, best2, it, it2 = np.inf, np.inf, 0, 0
                for _ in range(repeat):
                    comm.Barrier()
                    t = time.perf_counter()
                    ps = PartitionedSystem(rows, n_global, comm, preconditioner=pc, rtol=RTOL,
                                           coords=g.pos[own][rows.free_owned], spacing=spacing,
                                           smoother="jacobi" if name.endswith("jacobi") else "icc")
                    ps.set_values(rows.values(c[held]), ex)
                    x, info = ps.solve(rows.fixed_rhs(c[held], v))
                    comm.Barrier()
                    best, it = min(best, time.perf_counter() - t), info["iterations"]
                    t = time.perf_counter()
                    ps.set_values(rows.values(c2[held]), ex)
                    x, info = ps.solve(rows.fixed_rhs(c2[held], v), x0=x)
                    comm.Barrier()
                    best2, it2 = min(best2, time.perf_counter() - t), info["iterations"]
                    ps.destroy()                         # petsc4py 3.18 frees parallel objects only so
                row[name] = {"cold_s": best, "iterations": it, "resolve_s": best2, "resolve_iterations": it2}
            row["loadavg"] = os.getloadavg()[0]
            if rank == 0:
                print(json.dumps(row), flush=True)


def run_ranks(ranks, kinds, sizes, repeat, cache_dir):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    from yade_electro.core.mpi_network import private_network
    cmd = ["mpiexec", "--oversubscribe", "-n", str(ranks), sys.executable, os.path.abspath(__file__), "--worker",
           "--systems", ",".join(kinds), "--sizes", ",".join(map(str, sizes)), "--repeat", str(repeat)]
    if cache_dir:
        cmd += ["--cache-dir", cache_dir]
    res = subprocess.run(private_network(cmd), env=env, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if res.returncode != 0:
        raise RuntimeError(f"mpiexec -n {ranks} failed: {res.stderr[-3000:]}")
    return [json.loads(line) for line in res.stdout.splitlines() if line.startswith("{")]


def _crossing(kind, n, it, unknowns, t_ours_cold, amg, t_amg_cold, **extra):
    """Our iteration count as a power of the size through the two largest of (n, it),
    extrapolated to 10M and 100M; AMG's count taken flat; times per iteration per unknown from
    the largest size. The two largest only: the regime nearest the extrapolation. (The
    partitioned coarse space's cap grows with the size up to 8,000 clusters, reached at 800k
    unknowns: between 100k and 1M the cap grows and the fit flattens the growth that follows
    above 1M, where it stays; the guide says how much.)"""
    p, a = np.polyfit(np.log(n[-2:]), np.log(it[-2:]), 1)
    t_ours = t_ours_cold / (it[-1] * unknowns)
    t_amg_it = t_amg_cold / unknowns                   # per unknown, for its (flat) count
    est = {}
    for N in (1e7, 1e8):
        its_N = float(np.exp(a) * N ** p)
        est[f"{N:.0e}"] = {"ours_iterations": its_N, "ours_s": t_ours * its_N * N, "amg_s": t_amg_it * N}
    # ours: t_ours * exp(a) N^(1+p); AMG: t_amg_it * N -> equal at N^p = t_amg_it / (t_ours exp(a))
    cross = float((t_amg_it / (t_ours * np.exp(a))) ** (1.0 / p)) if p > 0 else float("inf")
    return dict({"bench": "peers", "part": "extrapolation", "system": kind, "iteration_exponent": float(p),
                 "amg": amg, "estimates": est, "amg_wins_above_unknowns": cross}, **extra)


def extrapolate(rows):
    """The serial rows' extrapolation (see :func:`_crossing`), and that of the partitioned
    rows of each rank count (our deflation with the smoother the engines take for the system,
    Jacobi for the voronoi rod and ICC for the others, against the faster of BoomerAMG and GAMG
    cold)."""
    out = []
    for kind in sorted({r["system"] for r in rows if r["part"] == "serial"}):
        rr = sorted((r for r in rows if r["part"] == "serial" and r["system"] == kind), key=lambda r: r["unknowns"])
        if len(rr) < 2:
            continue
        big = rr[-1]
        amg = min(("boomeramg", "gamg", "pyamg"), key=lambda k: big["cold_s"][k])
        out.append(_crossing(kind, np.array([r["unknowns"] for r in rr], float),
                             np.array([r["iterations"]["ours"] for r in rr], float), big["unknowns"],
                             big["cold_s"]["ours"], amg, big["cold_s"][amg], ranks=0))
    for kind, P in sorted({(r["system"], r["ranks"]) for r in rows if r["part"] == "partitioned"}):
        rr = sorted((r for r in rows if r["part"] == "partitioned" and r["system"] == kind and r["ranks"] == P),
                    key=lambda r: r["unknowns"])
        if len(rr) < 2:
            continue
        big = rr[-1]
        amg = min(("hypre", "gamg"), key=lambda k: big[k]["cold_s"])
        ours = "deflation_jacobi" if kind == "voronoi" else "deflation"
        out.append(_crossing(kind, np.array([r["unknowns"] for r in rr], float),
                             np.array([r[ours]["iterations"] for r in rr], float), big["unknowns"],
                             big[ours]["cold_s"], amg, big[amg]["cold_s"], ranks=P, ours=ours))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="20000,100000,1000000")
    ap.add_argument("--systems", default="lattice,bed,voronoi")
    ap.add_argument("--voronoi-max", type=int, default=100000)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--ranks", default="1,2,3", help="mpiexec rank counts of the partitioned part ('' for none)")
    ap.add_argument("--cache-dir", default=os.path.join(tempfile.gettempdir(), "yade_electro_bench_packings"))
    ap.add_argument("--out", default=None, help="also append the JSON lines to this file")
    ap.add_argument("--parts", default="serial,partitioned", help="which parts to run")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",") if s]
    kinds = [k for k in args.systems.split(",") if k]
    if args.worker:
        return worker(kinds, sizes, args.repeat, args.cache_dir)
    from bench_scale import eigen_driver
    exe = eigen_driver() if "serial" in args.parts.split(",") else None
    rows = []

    def emit(row):
        print(json.dumps(row), flush=True)
        if args.out:
            with open(args.out, "a") as fh:
                fh.write(json.dumps(row) + "\n")
    parts = args.parts.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        for kind in (kinds if "serial" in parts else []):
            for n in sizes:
                if kind == "voronoi" and n > args.voronoi_max:
                    continue
                row = serial_block(kind, n, args.repeat, exe, tmp, args.cache_dir)
                rows.append(row)
                emit(row)
    for p in [int(r) for r in args.ranks.split(",") if r and "partitioned" in parts]:
        for kind in kinds:
            ks = [n for n in sizes if kind != "voronoi" or n <= args.voronoi_max]
            for row in run_ranks(p, [kind], ks, args.repeat, args.cache_dir):
                rows.append(row)
                emit(row)
    for row in extrapolate(rows):
        emit(row)


if __name__ == "__main__":
    main()
