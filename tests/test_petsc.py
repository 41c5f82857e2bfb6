"""solver='petsc' (PETSc CG + GAMG through petsc4py): exact answers, the same potentials as the
serial solvers, kept setup, a clear error without petsc4py, and real runs on 2 MPI ranks
(standalone and inside YADE), plus the refusal inside yade.mpy's domain decomposition."""
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from lattice import cubic_lattice

from yade_electro.core.mpi_network import private_network
from yade_electro import Electrode, SolverError
from yade_electro.network.conduction import ConductionProblem
from yade_electro.solvers.registry import check_solver_name, make_solver, solver_names

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: OpenMPI refuses to start as root without these (CI runs as root)
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def _rod(shape=(4, 4, 12)):
    g = cubic_lattice(shape, r=1e-4)
    layer = shape[0] * shape[1]
    return g, np.arange(layer), np.arange(g.n_nodes - layer, g.n_nodes)


def _json_rows(text):
    """Every JSON object printed in ``text``: the ranks share one stdout, and mpiexec can join
    two ranks' lines before either newline arrives."""
    dec, rows, k = json.JSONDecoder(), [], text.find("{")
    while k >= 0:
        try:
            obj, end = dec.raw_decode(text, k)
            rows.append(obj)
        except json.JSONDecodeError:        # a brace in other output
            end = k + 1
        k = text.find("{", end)
    return rows


def _mpiexec(args, n, timeout=600, extra_env=None):
    env = dict(os.environ, **MPI_ENV, **(extra_env or {}))
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, env.get("PYTHONPATH")) if p)
    cmd = private_network(["mpiexec", "--oversubscribe", "-n", str(n)] + list(args))     # off the network
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def test_petsc_is_a_solver_name():
    assert "petsc" in solver_names()
    check_solver_name("petsc")


def test_petsc_uniform_rod_is_exact_and_matches_cg():
    # uniform bars between two end layers: the potential is linear in the layer index
    g, bottom, top = _rod()
    c = np.full(len(g.edges), 2.5)
    el = [Electrode("top", top, potential=1.0), Electrode("bottom", bottom, potential=0.0)]
    sols = {s: ConductionProblem(g.n_nodes, g.edges, c, el, solver=s).solve() for s in ("petsc", "cg")}
    k = np.arange(g.n_nodes) // 16
    assert np.max(np.abs(sols["petsc"].potential - k / 11.0)) < 1e-9
    assert np.max(np.abs(sols["petsc"].potential - sols["cg"].potential)) < 1e-8
    # 16 parallel chains of 11 bars
    assert sols["petsc"].equivalent_resistance("top", "bottom") == pytest.approx(11 / (16 * 2.5), rel=1e-9)
    assert sols["petsc"].info["solver"] == "petsc"


def test_petsc_update_keeps_setup_and_warm_starts():
    import scipy.sparse as sp
    rng = np.random.default_rng(3)
    n = 2000
    A = sp.random(n, n, density=3e-3, random_state=4)
    A = A + A.T
    A = (sp.diags(np.asarray(abs(A).sum(axis=1)).ravel() + 1e-3) - A).tocsr()   # SPD M-matrix
    b = rng.normal(size=n)
    s = make_solver("petsc")
    x, info = s.solve(A, b)
    assert info["setup"] and np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)
    A.data *= 1.0 + 1e-3 * rng.uniform(-1, 1, A.nnz)
    A = (A + A.T) * 0.5
    A2 = A.tocsr()
    s2 = make_solver("petsc")
    x_cold, cold = s2.solve(A2, b)
    A2.data *= 1.001                     # the same matrix object, new values
    s2.update(A2)
    x_warm, warm = s2.solve(A2, b, x0=x_cold / 1.001 * 0.999)
    assert not warm["setup"] and s2.n_setups == 1 and s2.n_updates == 1
    assert np.linalg.norm(A2 @ x_warm - b) <= 1e-9 * np.linalg.norm(b)
    assert warm["iterations"] < cold["iterations"]
    ref, _ = make_solver("direct").solve(A2, b)
    assert np.max(np.abs(x_warm - ref)) <= 1e-8 * np.max(np.abs(ref))


def test_petsc_missing_is_a_clear_error(monkeypatch):
    import yade_electro.solvers.petsc as ps
    monkeypatch.setitem(sys.modules, "petsc4py", None)          # import petsc4py -> ImportError
    monkeypatch.setattr(ps, "DEBIAN_PETSC4PY", "/nonexistent/petsc*/lib")
    with pytest.raises(SolverError, match="apt-get install python3-petsc4py"):
        check_solver_name("petsc")
    with pytest.raises(SolverError, match="solver='cg-deflated'"):
        make_solver("petsc")


STANDALONE = textwrap.dedent("""
    import json, sys
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    from lattice import cubic_lattice
    from yade_electro import Electrode
    from yade_electro.network.conduction import ConductionProblem
    from yade_electro.solvers.petsc import import_petsc
    g = cubic_lattice((10, 10, 40), r=1e-4)
    rng = np.random.default_rng(5)                        # the same values on every rank
    c = rng.uniform(0.5, 2.0, len(g.edges))
    el = [Electrode("top", np.arange(3900, 4000), potential=1.0), Electrode("bottom", np.arange(100), potential=0.0)]
    par = ConductionProblem(g.n_nodes, g.edges, c, el, solver="petsc").solve()
    ser = ConductionProblem(g.n_nodes, g.edges, c, el, solver="cg-deflated", coords=g.pos).solve()
    comm = import_petsc().COMM_WORLD
    print(json.dumps({"rank": comm.getRank(), "size": comm.getSize(),
                      "dphi": float(np.max(np.abs(par.potential - ser.potential))),
                      "R": par.equivalent_resistance("top", "bottom"), "R_ser": ser.equivalent_resistance("top", "bottom")}))
""")


def test_petsc_two_ranks_standalone(tmp_path):
    script = tmp_path / "standalone.py"
    script.write_text(STANDALONE)
    res = _mpiexec([sys.executable, str(script), os.path.join(ROOT, "tests")], 2)
    assert res.returncode == 0, res.stderr[-3000:]
    rows = _json_rows(res.stdout)
    assert sorted(r["rank"] for r in rows) == [0, 1]
    for r in rows:
        assert r["size"] == 2
        assert r["dphi"] < 1e-8
        assert r["R"] == pytest.approx(r["R_ser"], rel=1e-8)
    assert rows[0]["R"] == rows[1]["R"]                    # every rank got the same solution


MPY_SCRIPT = textwrap.dedent("""
    from yade import mpy as mp
    import numpy as np
    from yade_electro.yade import ElectricalEngine, Electrode, Material, Reader
    for i in range(4):
        for j in range(4):
            for k in range(4):
                O.bodies.append(sphere((i, j, k), 0.5))
    O.dt = 1e-5
    O.engines = [e for e in O.engines if type(e).__name__ != "GlobalStiffnessTimeStepper"]
    for b in O.bodies:
        b.subdomain = 1 + int(b.state.pos[0] > 1.5)
    x = np.array([b.state.pos[0] for b in O.bodies])
    ids = np.arange(len(O.bodies))
    eng = ElectricalEngine(
        material=Material(resistivity=1e-6),
        boundaries=[
            Electrode("a", select=ids[x < 0.5], potential=1.0),
            Electrode("b", select=ids[x > 2.5], potential=0.0)],
        law="contact",
        reader=Reader(bonds="contacts"),
        iterPeriod=10)
    O.engines = O.engines + [eng.runner]
    mp.mpirun(20, 3, withMerge=True)
""")


def test_engine_refuses_a_yade_mpy_subdomain(yade_exe, tmp_path):
    script = tmp_path / "mpy_engine.py"
    script.write_text(MPY_SCRIPT)
    res = _mpiexec(yade_exe + ["-n", "-x", str(script)], 3, timeout=300)
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert "subdomain of yade.mpy's decomposition" in out, out[-3000:]
    assert "solver='petsc'" in out
