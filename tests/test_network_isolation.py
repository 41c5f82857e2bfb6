"""No socket listens beyond loopback in the runs the project starts (issue 36, item 6).

Each run goes in a private network namespace of its own (``unshare -n``), where the test polls
the namespace's listening TCP sockets (``/proc/net/tcp``, ``tcp6``) every 50 ms while it runs:
any socket bound to an address other than 127.0.0.1 / ::1 (``0.0.0.0``, ``[::]``: every
interface) fails it. The runs: the install step, a serial ``solver='petsc'`` solve (an MPI
singleton), a serial LIGGGHTS run (an MPI program: a singleton too), and ``mpiexec -n 2`` as
the tests start it (:func:`~yade_electro.core.mpi_network.private_network`: its own namespace,
nothing of it in the test's). Before the fix, the singleton's ``orted`` and the solve's
process listened on ``0.0.0.0`` and ``[::]``.
"""
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

from yade_electro.core.mpi_network import namespaces_available

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

DRIVER = r'''
import os, subprocess, sys, time, json
def listening():
    out = set()
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            rows = open(name).read().splitlines()[1:]
        except OSError:
            continue
        for r in rows:
            f = r.split()
            if f[3] != "0A":
                continue
            addr = f[1].split(":")[0]
            if addr in ("0100007F", "00000000000000000000000001000000"):    # 127.0.0.1, ::1
                continue
            out.add(f"{name[-4:]} {f[1]}")
    return out
cmd = json.loads(sys.argv[1])
proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
seen = set()
while proc.poll() is None:
    seen |= listening()
    time.sleep(0.05)
text = proc.stdout.read()
print(json.dumps({"rc": proc.returncode, "seen": sorted(seen), "tail": text[-1500:]}))
'''

PETSC_SOLVE = textwrap.dedent('''
    import numpy as np, scipy.sparse as sp, time
    from yade_electro.solvers.registry import make_solver
    A = sp.diags([np.full(99, -1.0), np.full(100, 2.1), np.full(99, -1.0)], [-1, 0, 1]).tocsr()
    x, info = make_solver("petsc").solve(A, np.ones(100))
    time.sleep(1.0)
    print("solved", info["iterations"], float(np.linalg.norm(A @ x - 1)))
''')


def _isolated(cmd, timeout=600):
    import json
    wrapper = ["unshare", "-n", "sh", "-c", 'ip link set lo up && exec "$@"', "sh",
               sys.executable, "-c", DRIVER, json.dumps(cmd)]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               PYTHONPATH=os.pathsep.join(p for p in (ROOT, os.environ.get("PYTHONPATH")) if p))
    res = subprocess.run(wrapper, capture_output=True, text=True, timeout=timeout, env=env, cwd=ROOT,
                         stdin=subprocess.DEVNULL)
    assert res.returncode == 0, res.stderr[-2000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


pytestmark = pytest.mark.skipif(namespaces_available() != ["-n"],
                                reason="needs root and unshare -n (a private network namespace)")


def test_the_install_step_listens_on_nothing():
    out = _isolated(["bash", "scripts/install.sh"])
    assert out["rc"] == 0, out["tail"]
    assert out["seen"] == [], out


def test_a_serial_petsc_solve_listens_on_nothing():
    out = _isolated([sys.executable, "-c", PETSC_SOLVE])
    assert out["rc"] == 0 and "solved" in out["tail"], out["tail"]
    assert out["seen"] == [], out


@pytest.mark.skipif(shutil.which("liggghts") is None, reason="no LIGGGHTS")
def test_a_serial_liggghts_run_listens_on_nothing(tmp_path):
    script = textwrap.dedent(f'''
        import time
        from yade_electro import liggghts as L
        d = L.particle_data([[0, 0, 1.9e-3]], 2e-3, 8900.0, box=[[-0.01, 0.01]] * 2 + [[-0.005, 0.01]])
        mat = L.GranularMaterial(young=1e8, poisson=0.3, density=8900.0, conductivity=385.0, specific_heat=172.0)
        deck = L.heat_conduction_deck(d, [mat], 273.15, 1e-6, 4000, 2000, walls=[L.PlaneWall("z", 0.0, temperature=373.15)])
        L.run_heat_conduction(deck, {str(tmp_path / "run")!r}, progress=None)
        print("ran")
    ''')
    out = _isolated([sys.executable, "-c", script])
    assert out["rc"] == 0 and "ran" in out["tail"], out["tail"]
    assert out["seen"] == [], out


@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="no mpiexec")
def test_mpiexec_as_the_project_starts_it_listens_on_nothing_outside_its_namespace():
    from yade_electro.core.mpi_network import private_network
    rank = ("import sys, time; sys.path.insert(0, '" + ROOT + "'); from yade_electro.solvers.petsc import import_petsc; "
            "P = import_petsc(); time.sleep(1.5); print('rank', P.COMM_WORLD.getRank(), 'of', P.COMM_WORLD.getSize())")
    out = _isolated(private_network(["mpiexec", "--oversubscribe", "-n", "2", sys.executable, "-c", rank]))
    assert out["rc"] == 0 and "of 2" in out["tail"], out["tail"]
    assert out["seen"] == [], out


def test_open_mpi_that_cannot_start_is_said_in_python():
    """Item 15: where Open MPI cannot start (here: no network interface up, and settings that
    need its daemon), solver='petsc' raises SolverError with Open MPI's own words instead of the
    whole process aborting inside MPI_Init with no Python error."""
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from yade_electro.solvers.petsc import import_petsc\n"
            "try:\n    import_petsc()\n    print('STARTED')\n"
            "except Exception as exc:\n    print('RAISED', type(exc).__name__, exc)\n") % ROOT
    env = dict(os.environ, OMPI_MCA_ess_singleton_isolated="0", OMPI_MCA_btl="tcp,self")
    res = subprocess.run(["unshare", "-n", sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                         env=env, stdin=subprocess.DEVNULL)
    assert res.returncode == 0, res.stderr[-2000:]
    assert "RAISED SolverError" in res.stdout and "Open MPI cannot start" in res.stdout, res.stdout[-2000:]
    assert "Unable to start a daemon" in res.stdout
