"""Distributed engines on real YADE under a real mpiexec: cases/distributed.py with 3 ranks
(plain mpiexec: 3 ranks own slabs; yade.mpy: a master and 2 workers), each case against a
serial reference (the rod, the pin torsion test with bonds breaking, the bed; the bed in
yade.mpy); and the errors a distributed run gives when the engine is built."""
import json
import os
import re
import subprocess

import pytest

from yade_electro.core.mpi_network import private_network

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def _mpiexec(args, n, timeout=900):
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, env.get("PYTHONPATH")) if p)
    cmd = private_network(["mpiexec", "--oversubscribe", "-n", str(n)] + list(args))     # off the network
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def test_distributed_case_matches_serial_with_two_workers(yade_exe):
    res = _mpiexec(yade_exe + ["-n", "-x", os.path.join(ROOT, "cases", "distributed.py"), "--quick"], 3)
    rows = [json.loads(line) for line in res.stdout.splitlines() if line.startswith('{"ranks"')]
    assert res.returncode == 0 and len(rows) == 1, res.stdout[-2000:] + res.stderr[-4000:]
    out = rows[0]
    assert out["workers"] == {"plain_mpiexec": 3, "yade_mpy": 2}
    for case in ("rod", "rod_continuum", "rod_surface_voronoi", "rod_surface_continuum", "rod_cells", "pin",
                 "pin_voronoi", "bed", "walls", "heat", "mpy"):
        assert out[case]["max_rel_diff"] < 1e-8, (case, out[case])
    walls = out["walls"]                                   # the floor: an electrode and an isothermal wall
    assert walls["wall_contacts_equal"] and walls["wall_contacts_serial_distributed"][0] > 10, walls
    assert walls["wall_heat_J"]["floor_heat"] < 0 and walls["electrode_currents_A"]["floor"] < 0, walls
    assert abs(walls["I_left"] - 3.0) < 1e-9 and walls["V_left"] > 0, walls   # fed 3 A: its potential found
    for law in ("voronoi", "continuum"):                   # faces chosen on each rank's region, top fed 200 A
        rod = out[f"rod_surface_{law}"]
        assert abs(rod["I_top"] - 200.0) < 1e-6 and rod["fed_potential_rel_diff"] < 1e-8 and rod["T_rise_K"] > 1, rod
    assert out["rod"]["elements"] > 900 and out["rod"]["owned"] < out["rod"]["elements"]
    assert out["bed"]["T_rise_K"] > 1.0 and out["rod"]["T_rise_K"] > 10.0 and out["rod_cells"]["T_rise_K"] > 10.0
    assert out["mpy"]["calls"] >= 5 and out["max_rel_diff"] < 1e-8
    sub = out["heat"]["substeps_serial_distributed"]
    assert sub[0] == sub[1] > 1                            # forward Euler split the same way
    for pin in ("pin", "pin_voronoi"):                     # bonds broke, the shares were rebuilt
        assert out[pin]["compared_calls"] >= 5 and out[pin]["R_ratio_last_finite"] > 1.05, out[pin]


def test_walls_held_by_the_master_in_yade_mpy(yade_exe):
    """The floor is the master's body (subdomain 0); each worker joins its own spheres on it to
    the floor electrode and the isothermal wall: the answer is a serial solve's on the workers'
    geometry, and the workers count every sphere on the floor."""
    res = _mpiexec(yade_exe + ["-n", "-x", os.path.join(ROOT, "cases", "distributed.py"), "--quick",
                               "--cases", "mpy-walls"], 3)
    rows = [json.loads(line) for line in res.stdout.splitlines() if line.startswith('{"ranks"')]
    assert res.returncode == 0 and len(rows) == 1, res.stdout[-2000:] + res.stderr[-4000:]
    out = rows[0]["mpy_walls"]
    assert out["workers"] == 2 and out["max_rel_diff"] < 1e-8, out
    assert out["floor_contacts"] == out["floor_contacts_engine"] > 10 and out["floor_heat_J"] < 0, out


BAD_SCRIPT = """
import numpy as np
from yade import pack
from yade_electro.core.mpi_network import private_network
from yade_electro.yade import ElectricalEngine, Electrode, Material
from yade_electro.core.errors import BoundaryConditionError
for i in range(4):
    for j in range(4):
        for k in range(8):
            O.bodies.append(sphere((i, j, k), 0.51))
ids = np.arange(len(O.bodies))
z = np.array([b.state.pos[2] for b in O.bodies])
from yade_electro.yade import Reader
kw = dict(material=Material(resistivity=1e-6), reader=Reader(bonds="contacts"), law="contact", solver="petsc")
try:
    ElectricalEngine(boundaries=[Electrode("a", select=ids[z < 0.5], current=1.0),
                                 Electrode("b", select=ids[z > 6.5], current=-1.0)], **kw)
except BoundaryConditionError as exc:
    print("REFUSED", exc, flush=True)
"""


def _refused_on_both_ranks(yade_exe, tmp_path, text) -> str:
    """Run a script that prints REFUSED and the error under mpiexec -n 2; its stdout, once both
    ranks refused."""
    script = tmp_path / "refused.py"
    script.write_text(text)
    res = _mpiexec(yade_exe + ["-n", "-x", str(script)], 2, timeout=300)
    # the two ranks share stdout, and mpiexec may join their lines ("REFUSEDREFUSED ..."): count the marks
    assert res.returncode == 0 and res.stdout.count("REFUSED") == 2, res.stdout[-2000:] + res.stderr[-3000:]
    return res.stdout


def test_distributed_refuses_what_it_does_not_do_when_built(yade_exe, tmp_path):
    out = _refused_on_both_ranks(yade_exe, tmp_path, BAD_SCRIPT)
    assert out.count("has an imposed current: hold one at a potential") == 2, out


MPY_VORONOI_SCRIPT = """
import numpy as np
from yade import mpy as mp
from yade_electro.core.errors import BoundaryConditionError
from yade_electro.yade import ElectricalEngine, Electrode, Material
from yade_electro.yade import packing as P
pk = P.dense_packing(P.Box((0, 0, 0), (1e-3, 1e-3, 3e-3)), n=300, seed=1)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
try:
    ElectricalEngine(material=Material(resistivity=1e-6), law="voronoi", solver="petsc",
                     boundaries=[Electrode("a", select=ids[z < 0.2e-3], potential=1.0),
                                 Electrode("b", select=ids[z > 2.8e-3], potential=0.0)])
except BoundaryConditionError as exc:
    print("REFUSED", exc, flush=True)
"""


def test_voronoi_law_is_refused_with_yade_mpy_when_built(yade_exe, tmp_path):
    out = _refused_on_both_ranks(yade_exe, tmp_path, MPY_VORONOI_SCRIPT)
    assert out.count("imports yade.mpy") == 2 and "law='continuum' under mp.mpirun" in out


MPY_SURFACE_SCRIPT = """
import numpy as np
from yade import mpy as mp
from yade_electro.core.errors import BoundaryConditionError
from yade_electro.yade import ElectricalEngine, Electrode, Law, Material
from yade_electro.yade import packing as P
box = P.Box((0, 0, 0), (1e-3, 1e-3, 3e-3))
pk = P.dense_packing(box, n=300, seed=1)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
try:
    ElectricalEngine(material=Material(resistivity=1e-6), law=Law("continuum", container=box), solver="petsc",
                     boundaries=[Electrode("a", surface=box.face("z-"), potential=1.0),
                                 Electrode("b", select=ids[z > 2.8e-3], potential=0.0)])
except BoundaryConditionError as exc:
    print("REFUSED", exc, flush=True)
"""


def test_surface_electrodes_are_refused_with_yade_mpy_when_built(yade_exe, tmp_path):
    """A surface's half cells need the bounded cells of a rank's elements: yade.mpy's mirrors
    are too thin a halo for them."""
    out = _refused_on_both_ranks(yade_exe, tmp_path, MPY_SURFACE_SCRIPT)
    assert out.count("run distributed under plain mpiexec only") == 2 and "['a']" in out, out


CLUMP_SCRIPT = """
from yade_electro.core.errors import BoundaryConditionError
from yade_electro.yade import HeatEngine, Integrator, Material, Reader
for k in range(6):
    O.bodies.appendClumped([sphere((0, 0, 3.0 * k), 1.0), sphere((1.5, 0, 3.0 * k), 1.0)])
try:
    HeatEngine(material=Material(density=2600, specific_heat=800, conductivity=2.0), law="contact",
               reader=Reader(bonds="contacts"), temperature=300.0, integrator=Integrator(dt=1.0, solver="petsc"))
except BoundaryConditionError as exc:
    print("REFUSED", exc, flush=True)
"""


def test_clumps_are_refused_in_a_distributed_run_when_built(yade_exe, tmp_path):
    out = _refused_on_both_ranks(yade_exe, tmp_path, CLUMP_SCRIPT)
    assert out.count("does not do clumps") == 2, out


FAIL_SCRIPT = """
import numpy as np
from yade_electro.yade import ElectricalEngine, Electrode, Material, Reader
from yade_electro.yade.distributed import world_rank
for i in range(3):
    for j in range(3):
        for k in range(10):
            O.bodies.append(sphere((i, j, k), 0.52))
O.engines = [e for e in O.engines if type(e).__name__ != "GlobalStiffnessTimeStepper"]
O.dt = 1e-6
ids = np.arange(len(O.bodies))
z = np.array([b.state.pos[2] for b in O.bodies])
eng = ElectricalEngine(material=Material(resistivity=1e-6), reader=Reader(bonds="contacts"), law="contact",
                       boundaries=[Electrode("a", select=ids[z < 0.5], potential=1.0),
                                   Electrode("b", select=ids[z > 8.5], potential=0.0)],
                       solver="petsc", iterPeriod=1)
O.engines = O.engines + [eng.runner]
O.run(2, True)
eng.set_electrode("a", 2.0)
O.run(1, True)
import sys      # one write per line: print() writes its pieces apart, and the two ranks' pieces interleaved
sys.stdout.write(f"R_EQ {world_rank()} {eng.equivalent_resistance} {eng.electrode_currents['a']}\\n")
sys.stdout.flush()
if world_rank() == 1:
    O.bodies[int(ids[-1])].shape.radius = -1.0      # this rank's reader now fails; the other waits for it
O.run(2, True)
print("NOT REACHED", flush=True)
"""


def test_a_failing_rank_ends_every_rank(yade_exe, tmp_path):
    script = tmp_path / "fail.py"
    script.write_text(FAIL_SCRIPT)
    res = _mpiexec(yade_exe + ["-n", "-x", str(script)], 2, timeout=300)
    out = res.stdout + res.stderr
    assert res.returncode != 0, out[-3000:]
    assert "NOT REACHED" not in out and "ending all ranks (MPI_Abort)" in out, out[-3000:]
    assert "radius must be finite" in out
    rows = re.findall(r"R_EQ (\d) (\S+) ([-+.\deE]+|inf)", res.stdout)       # the ranks' lines may be joined
    assert len(rows) == 2 and rows[0][1] == rows[1][1]               # the same R_eq on both ranks
    assert float(rows[0][2]) == pytest.approx(2.0 / float(rows[0][1]), rel=1e-8)   # the new potential acts
