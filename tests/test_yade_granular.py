"""The granular mode in the real YADE (each test a fresh ``yade-electro -n -x`` process): a
bed falling onto a wall with contacts changing at every call (energy conserved with an
adiabatic wall, wall heat = heat stored with an isothermal one), beds with no contact,
particles leaving, bad set-ups refused in the script, and the drum and container cases at
small sizes."""
import os
import sys

import pytest

pytestmark = pytest.mark.yade

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "cases"))

BED = r'''
import json
import numpy as np
from yade import pack, utils
from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Material, Reader, Wall
mat = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5))
floor = O.bodies.append(utils.wall(0, axis=2, sense=1, material=mat))
sp = pack.SpherePack()
sp.makeCloud((0, 0, GAP), (0.012, 0.012, 0.03), rMean=1e-3, rRelFuzz=0.2, seed=1)
ids = sp.toSimulation(material=mat)
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]),
             NewtonIntegrator(gravity=(0, 0, GRAVITY), damping=0.3)]
O.dt = 0.5 * utils.PWaveTimeStep()
hot = {i: 373.15 for i in ids if O.bodies[i].state.pos[2] > 0.015}
e = HeatEngine(
    material=Material(density=8900, specific_heat=172, conductivity=385),
    boundaries=[Wall("floor", bodies=floor, temperature=WALL_T)],
    temperature=InitialTemperature(273.15, by_id=hot),
    law=LAW,
    integrator=Integrator(theta=THETA),
    reader=Reader(bonds="contacts", overlap=OVERLAP),
    iterPeriod=10)
O.engines = O.engines + [e.runner]
heat_init = e.coupled.summary()["heat_content"]
rows = []
for k in range(CHUNKS):
    O.run(2000, True)
    if ERASE and k == 1:                # the hottest particle leaves the domain
        O.bodies.erase(max(e.temperature_by_id, key=e.temperature_by_id.get))
    rows.append(e.coupled.summary())
r = rows[-1]
T = e.temperature
print(json.dumps({"heat_init": heat_init, "heat": r["heat_content"], "wall_heat": r.get("wall_heat:floor"),
                  "boundary": r["boundary_heat"], "particle_heat": r["particle_heat"],
                  "heat0": rows[0]["heat_content"], "finite": bool(np.all(np.isfinite(T))), "n": int(T.size),
                  "T_min": float(T.min()), "T_max": float(T.max()), "builds": e.reader.list_builds,
                  "calls": e.reader.calls, "full_reads": e.reader.full_reads,
                  "contacts": [int(np.sum(e.coupled.heat.conductance > 0))],
                  "wall_contacts": r.get("wall_contacts:floor"),
                  "C_T": float(np.sum(e.coupled.capacity * (T - 273.15))),
                  "state_temp_ok": bool(abs(O.bodies[ids[-1]].state.temp - e.temperature_by_id[ids[-1]]) < 1e-12)}))
'''


def _bed(run_yade_script, tmp_path, wall_t="None", law="'contact'", theta="'explicit'", erase=False, gap="0.001",
         gravity="-9.81", chunks=6, overlap=False):
    src = (BED.replace("WALL_T", wall_t).replace("LAW", law).replace("THETA", theta).replace("ERASE", repr(erase))
           .replace("GAP", gap).replace("GRAVITY", gravity).replace("CHUNKS", str(chunks))
           .replace("OVERLAP", repr(overlap)))
    return run_yade_script(src, timeout=300, cwd=tmp_path, check=True).result


def test_falling_bed_conserves_energy_with_an_adiabatic_wall(run_yade_script, tmp_path):
    out = _bed(run_yade_script, tmp_path)
    assert out["finite"] and out["builds"] > 3 and out["full_reads"] == 1     # contacts changed, no full read
    assert out["contacts"][0] > 20                     # the bed landed (it spreads on the open floor)
    # adiabatic: the capacity-weighted temperature sum does not move (1e-9 relative)
    initial = out["heat_init"]
    assert initial > 0 and abs(out["heat"] - initial) <= 1e-9 * abs(initial)
    assert out["wall_heat"] is None and out["boundary"] == 0.0
    assert 273.15 < out["T_min"] and out["T_max"] < 373.15 and out["state_temp_ok"]


@pytest.mark.parametrize("theta", ["'explicit'", "'backward-euler'"])
def test_isothermal_wall_heat_is_the_heat_stored(run_yade_script, tmp_path, theta):
    out = _bed(run_yade_script, tmp_path, wall_t="473.15", theta=theta)
    assert out["wall_contacts"] > 10 and out["wall_heat"] > 0
    # the heat stored since the start is what the wall gave (1e-9)
    assert out["heat"] - out["heat_init"] == pytest.approx(out["wall_heat"], rel=1e-9)
    assert out["boundary"] == pytest.approx(out["wall_heat"], rel=1e-12)


def test_a_bed_without_contacts_keeps_its_temperatures(run_yade_script, tmp_path):
    # no gravity, a loose cloud: no sphere touches another or the wall
    out = _bed(run_yade_script, tmp_path, wall_t="473.15", gap="0.004", gravity="0", chunks=2)
    assert out["finite"] and out["contacts"] == [0] and out["wall_contacts"] == 0
    assert out["heat"] == out["heat_init"] and out["wall_heat"] == 0.0


@pytest.mark.parametrize("overlap", [False, True], ids=["plain", "overlap"])
def test_a_particle_leaving_the_bed(run_yade_script, tmp_path, overlap):
    out = _bed(run_yade_script, tmp_path, wall_t="473.15", erase=True, overlap=overlap)
    assert out["finite"] and out["full_reads"] == 2          # the erased body was seen once
    assert out["wall_heat"] > 0 and out["particle_heat"] < 0  # the hot particle took its heat away
    # the balance closes with the heat it took: stored = given by the wall + carried by particles
    assert out["heat"] - out["heat_init"] == pytest.approx(out["wall_heat"] + out["particle_heat"], rel=1e-9)


OUTCOME = r'''
def outcome(make):
    """'accepted', or 'ExceptionType: message' of what make() raised."""
    try:
        make()
        return "accepted"
    except Exception as exc:
        return f"{type(exc).__name__}: {exc}"
'''


BAD = OUTCOME + r'''
import json
from yade import pack, utils
from yade_electro.yade import ElectricalEngine, HeatEngine, Electrode, Material, Reader, Wall
mat = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5))
floor = O.bodies.append(utils.wall(0, axis=2, sense=1, material=mat))
s = O.bodies.append([utils.sphere((0, 0, 1e-3), 1e-3, material=mat), utils.sphere((0, 0, 3e-3), 1e-3, material=mat)])
out = {}
M = Material(density=8900, specific_heat=172, conductivity=385)
granular, bonded = Reader(bonds="contacts"), Reader(bonds="cohesive")
cases = {
    "wall_on_sphere": lambda: dict(reader=granular, boundaries=[Wall("w", bodies=s[0], temperature=300.0)]),
    "wall_missing": lambda: dict(reader=granular, boundaries=[Wall("w", bodies=99, temperature=300.0)]),
    "wall_bad_key": lambda: dict(reader=granular, boundaries=[Wall("w", bodies=floor, temp=300.0)]),
    "contact_law_bonded": lambda: dict(reader=bonded, law="contact"),
    "solid_law_granular": lambda: dict(reader=granular, law="continuum"),
    "walls_bonded": lambda: dict(reader=bonded, law="continuum",
                                 boundaries=[Wall("w", bodies=floor, temperature=300.0)]),
    "bad_skin": lambda: dict(reader=Reader(bonds="contacts", skin=-1.0)),
    "overlap_bonded": lambda: dict(reader=Reader(bonds="cohesive", overlap=True), law="continuum"),
    "overlap_not_bool": lambda: dict(reader=Reader(bonds="contacts", overlap="yes")),
}
for name, kw in cases.items():
    out[name] = outcome(lambda: HeatEngine(material=M, temperature=273.15, label="bad_" + name, **kw()))
for name, reader, law in (("wall_electrode_no_contact", granular, "auto"),
                          ("wall_electrode_bonded", bonded, "continuum")):
    out[name] = outcome(lambda: ElectricalEngine(
        material=Material(resistivity=1e-7),
        boundaries=[Electrode("plate", wall=floor, potential=0.0), Electrode("top", select=[s[1]], potential=1.0)],
        reader=reader, law=law, label="bad_" + name))
from yade_electro.yade import ElectroThermalEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
out["overlap_electrodes"] = outcome(lambda: ElectroThermalEngine(
    material=Material(resistivity=1e-7, density=8900, specific_heat=172, conductivity=385),
    boundaries=[Electrode("a", select=[s[0]], potential=0.0), Electrode("b", select=[s[1]], potential=1.0)],
    temperature=273.15,
    law="contact",
    reader=Reader(bonds="contacts", overlap=True),
    label="bad_overlap_electrodes"))
print(json.dumps(out))
'''


def test_bad_granular_setups_are_refused_in_the_script(run_yade_script, tmp_path):
    out = run_yade_script(BAD, timeout=120, cwd=tmp_path, check=True).result
    assert "is a Sphere, not a wall" in out["wall_on_sphere"]
    for name in ("overlap_bonded", "overlap_electrodes"):
        assert out[name].startswith("ValueError: overlap=True is for heat-only engines in the granular mode"), name
    assert out["overlap_not_bool"].startswith("ValueError: Reader overlap must be True or False")
    assert "no body 99" in out["wall_missing"]
    assert "unexpected keyword argument 'temp'" in out["wall_bad_key"]
    assert out["contact_law_bonded"].startswith("ValueError") and "bonds='contacts'" in out["contact_law_bonded"]
    assert out["solid_law_granular"].startswith("ValueError") and "law='contact'" in out["solid_law_granular"]
    assert "granular mode only" in out["walls_bonded"]
    assert "skin must be finite and > 0" in out["bad_skin"]
    assert "touches no particle" in out["wall_electrode_no_contact"]
    assert "granular mode only" in out["wall_electrode_bonded"]


PERIODIC = OUTCOME + r"""
import json, math
import numpy as np
from yade import utils
from yade_electro.yade import ElectricalEngine, HeatEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
n, a, r = 6, 0.004, 0.00201               # a simple-cubic bed, 0.02 mm overlaps, 3 n^3 contacts
L = n * a
mat = O.materials.append(FrictMat(young=1.0, poisson=0.3, density=7850, frictionAngle=0.5))
ids = [O.bodies.append(utils.sphere(((i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a), r, material=mat))
       for i in range(n) for j in range(n) for k in range(n)]
x0 = np.array([O.bodies[i].state.pos[0] for i in ids])
out = {}
# built on a box, then the cell made periodic: the engine's next call takes the images
O.engines = [ForceResetter(), NewtonIntegrator(gravity=(0, 0, 0))]
O.dt = 1e-4
T0, dT = 300.0, 10.0
mode = np.cos(2 * math.pi * x0 / L)
init = {int(i): T0 + dT * c for i, c in zip(ids, mode)}
eng = HeatEngine(
    material=Material(density=7850, specific_heat=470, conductivity=50),
    temperature=InitialTemperature(T0, by_id=init),
    law="contact",
    integrator=Integrator(theta="backward-euler", time_scale=100.0),
    reader=Reader(bonds="contacts"),
    iterPeriod=1,
    label="heat")
O.engines = O.engines + [eng.runner]
O.run(1, True)
out["box_contacts"] = int(np.sum(eng.contact_heat_flow()[1] > 0))
O.periodic = True
O.cell.setBox(L, L, L)
for i in ids:
    O.bodies[i].state.vel = (0.3, 0.2, 0.1)     # the bed drifts through the cell's faces
t_start = eng.coupled.time
A_start = 2.0 / len(ids) * np.sum((eng.temperature - T0) * mode)
O.run(200, True)
T = np.array([eng.temperature_by_id[int(i)] for i in ids])
A = 2.0 / len(ids) * np.sum((T - T0) * mode)
m = 7850 * 4 / 3 * math.pi * r ** 3 * 470
G = 2 * 50 * math.sqrt(r ** 2 - (a / 2) ** 2)             # H = 2 k a, the lens of the overlap
lam = 2 * G / m * (1 - math.cos(2 * math.pi / n))        # the mode's rate on the periodic lattice
h = O.dt * 100
steps = round((eng.coupled.time - t_start) / h)
out.update(A_rel=A / (A_start * (1 + lam * h) ** -steps) - 1, mode_dev=float(np.max(np.abs(T - T0 - A * mode))),
           steps=steps, contacts=int(np.sum(eng.contact_heat_flow()[1] > 0)), crossed=float(max(
               O.bodies[i].state.pos[0] for i in ids)) > L)
import meshio
vtk = meshio.read(eng.write_vtk("bed")["contacts"])
seg = vtk.points[vtk.cells_dict["line"]]
out["vtk_lines"] = len(seg)
out["vtk_longest"] = float(np.max(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)))
out["vtk_extra_points"] = len(vtk.points) - len(ids)
# a deforming, shearing cell: the contacts against the nearest images of YADE's own cell
O.cell.velGrad = Matrix3(0.5, 0, 0, 0, 0, 0, 0.2, 0, 0)
agree = []
for k in range(20):
    O.run(10, True)
    Hm = np.array([[O.cell.hSize[p, q] for q in range(3)] for p in range(3)])
    S = np.array([O.cell.wrap(O.bodies[i].state.pos) for i in ids]) @ np.linalg.inv(Hm).T
    dS = S[None] - S[:, None]
    dS -= np.round(dS)
    brute = int(np.sum(np.triu(np.linalg.norm(dS @ Hm.T, axis=2) < 2 * r, 1)))
    agree.append((int(np.sum(eng.contact_heat_flow()[1] > 0)), brute))
out["deforming"] = agree
O.engines = O.engines[:2]
for name, make in {
        "electrical_bonded": lambda: ElectricalEngine(
            material=Material(resistivity=1e-7),
            boundaries=[
                Electrode("a", select=ids[:36], potential=1.0),
                Electrode("b", select=ids[-36:], potential=0.0)],
            label="e1"),
        "electrical_contacts": lambda: ElectricalEngine(
            material=Material(resistivity=1e-7),
            boundaries=[
                Electrode("a", select=ids[:36], potential=1.0),
                Electrode("b", select=ids[-36:], potential=0.0)],
            law="contact",
            reader=Reader(bonds="contacts"),
            label="e2"),
        "heat_bonded": lambda: HeatEngine(material=Material(density=7850, specific_heat=470, conductivity=50), temperature=T0, label="h1"),
        "heat_walls": lambda: HeatEngine(
            material=Material(density=7850, specific_heat=470, conductivity=50),
            boundaries=[Wall("w", bodies=[O.bodies.append(utils.wall(0, axis=2))], temperature=T0)],
            temperature=T0,
            reader=Reader(bonds="contacts"),
            label="h2")}.items():
    out[name] = outcome(make)
print(json.dumps(out))
"""


def test_periodic_cells_conduct_across_their_faces(run_yade_script, tmp_path):
    # heat in a periodic simple-cubic bed drifting through the cell's faces: a cosine mode
    # decays by the exact backward-Euler factor of the lattice's rate (every contact, through
    # every face); in a stretching, shearing cell the contacts are those of the nearest images
    out = run_yade_script(PERIODIC, timeout=300, cwd=tmp_path, check=True).result
    assert out["box_contacts"] == 540 and out["contacts"] == 648 and out["crossed"]     # 3 n^2 (n - 1), 3 n^3
    assert out["steps"] == 200 and abs(out["A_rel"]) < 1e-9 and out["mode_dev"] < 1e-9
    # VTK: each contact drawn to the neighbour's image (the centres' distance a), none across
    # the cell; those crossing a face (3 n^2 of them) get their own end point
    assert out["vtk_lines"] == 648 and out["vtk_longest"] == pytest.approx(0.004, rel=1e-9)
    assert out["vtk_extra_points"] == 3 * 36
    counts = [c for c, _ in out["deforming"]]
    assert all(c == b for c, b in out["deforming"]) and counts[0] == 648 and counts[-1] == 432
    # refused: the bonded reader, electrodes and walls in a periodic cell
    for key in ("electrical_bonded", "electrical_contacts", "heat_bonded"):
        assert out[key].startswith("GraphError") and "periodic cell" in out[key], out[key]
    assert out["heat_walls"].startswith("GraphError") and "walls (['w']) in a periodic cell" in out["heat_walls"]


CLUMPS = r"""
import json
from yade import utils
from yade_electro.yade import HeatEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
mat = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=7850, frictionAngle=0.5))
s = O.bodies.append([utils.sphere((0, 0, 0), 1e-3, material=mat), utils.sphere((1.9e-3, 0, 0), 1e-3, material=mat)])
O.bodies.appendClumped([utils.sphere((3.8e-3, 0, 0), 1e-3, material=mat),
                        utils.sphere((5.5e-3, 0, 0), 1e-3, material=mat)])
e = HeatEngine(
    material=Material(density=7850, specific_heat=470, conductivity=50),
    temperature=300.0,
    reader=Reader(bonds="contacts"),
    label="heat")
from yade_electro.yade.scene import SceneReader
bonded = SceneReader(O)
bonded.read()
print(json.dumps({"nodes": int(e.reader.graph.n_nodes), "clump_bodies": e.reader.ignored["clump body"],
                  "bonded_nodes": int(bonded.graph.n_nodes), "bonded_left_out": bonded.ignored["clump"]}))
"""


def test_clumps_conduct_in_a_bed_and_are_left_out_of_a_bonded_solid(run_yade_script, tmp_path):
    """A granular bed takes clump members as elements (lumped by default); a bonded solid's
    reader leaves clumps out, and says so."""
    res = run_yade_script(CLUMPS, timeout=120, cwd=tmp_path, check=True)
    assert res.result == {"nodes": 4, "clump_bodies": 1, "bonded_nodes": 2, "bonded_left_out": 3}
    assert "3 clump(s) and clump member(s) are left out" in res.stderr and "clumps='lumped'" in res.stderr


def test_drum_case_small(run_yade_script, tmp_path):
    res = run_yade_script(os.path.join(ROOT, "cases", "rotating_drum.py"), "--n", "200", "--duration", "0.2",
                          "--sample", "0.05", "--baffles", "--out", str(tmp_path), timeout=600, check=True).result
    assert res["case"] == "rotating_drum" and res["wall"] == "baffles" and res["n"] > 150
    assert res["balance_rel"] < 1e-9 and res["wall_heat_J"] > 0
    assert -0.5 < res["final_lacey"] < 1.2
    assert os.path.exists(res["png"])


def test_container_case_small(run_yade_script, tmp_path):
    res = run_yade_script(os.path.join(ROOT, "cases", "container_heating.py"), "--n", "150", "--settle", "0.4",
                          "--dt", "5", "--out", str(tmp_path), timeout=600, check=True).result
    assert res["case"] == "container_heating" and res["n"] == 150
    assert res["balance_rel"] < 1e-6 and res["t90_centre_s"] is not None
    assert res["wall_contacts"]["side"] > 0 and res["wall_contacts"]["bottom"] > 0
    assert all(os.path.exists(p) for p in res["vtk"])


def test_lacey_index_limits():
    import numpy as np
    import rotating_drum as drum
    rng = np.random.default_rng(0)
    pos = rng.uniform(0, 0.1, (4000, 3))
    segregated = pos[:, 0] < 0.048           # on a cell boundary (cells of 4 diameters, 16 mm)
    assert drum.lacey_index(pos, segregated) < 0.05
    mixed = rng.random(4000) < 0.5
    assert drum.lacey_index(pos, mixed) == pytest.approx(1.0, abs=0.15)


SAVED_BED = r'''
import json
import numpy as np
from yade import pack, utils
from yade_electro.yade import HeatEngine, attach, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
def build():
    mat = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5))
    floor = O.bodies.append(utils.wall(0, axis=2, sense=1, material=mat))
    sp = pack.SpherePack()
    sp.makeCloud((0, 0, 0.001), (0.006, 0.006, 0.02), rMean=1e-3, rRelFuzz=0.2, seed=2)
    ids = sp.toSimulation(material=mat)
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                                 [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
                 NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.3)]
    O.dt = 0.5 * utils.PWaveTimeStep()
    O.run(4000, True)
    e = HeatEngine(
        material=Material(density=8900, specific_heat=172, conductivity=385),
        boundaries=[Wall("floor", bodies=floor, temperature=373.15)],
        temperature=273.15,
        law="contact",
        integrator=Integrator(theta="backward-euler", dt=1e-3),
        reader=Reader(bonds="contacts"),
        output=Output(history="h.csv"),
        iterPeriod=10)
    O.engines = O.engines + [e.runner]
    return e
def figures(e):
    last = e.history.rows[-1]
    return dict(T={str(k): v for k, v in e.temperature_by_id.items()}, rows=len(e.history),
                wall_heat=last["wall_heat:floor"], heat=last["heat_content"], time=e.coupled.time)
'''


def saved_and_continued(run_yade_script, tmp_path, scene, before, after, between=""):
    """The figures of ``scene`` (``build()`` and ``figures(e)``, engine labelled 'heat') run
    ``before`` steps, then ``between`` (script lines), then ``after`` steps: uninterrupted, and
    saved after ``between`` then loaded in a new process, re-attached and continued. Returns
    (uninterrupted, continued, their temperatures by sorted body id)."""
    import numpy as np
    ref_dir, run_dir = tmp_path / "ref", tmp_path / "run"
    ref_dir.mkdir(), run_dir.mkdir()
    start = f"e = build()\nO.run({before}, True)\n" + between
    ref = run_yade_script(scene + start + f"O.run({after}, True)\nprint(json.dumps(figures(e)))\n",
                          cwd=ref_dir, check=True).result
    run_yade_script(scene + start + "O.save('bed.yade.gz')\nprint('{}')\n", cwd=run_dir, check=True)
    out = run_yade_script(scene + f"O.load('bed.yade.gz')\ne = attach('heat')\nO.run({after}, True)\n"
                          "print(json.dumps(figures(e)))\n", cwd=run_dir, check=True).result
    keys = sorted(ref["T"])
    return ref, out, np.array([ref["T"][k] for k in keys]), np.array([out["T"][k] for k in keys])


def test_granular_save_and_load_continues(run_yade_script, tmp_path):
    import numpy as np
    ref, out, ta, tb = saved_and_continued(run_yade_script, tmp_path, SAVED_BED, 1000, 1000)
    assert out["rows"] == ref["rows"] and out["time"] == pytest.approx(ref["time"], rel=1e-12)
    assert np.max(np.abs(tb - ta)) <= 1e-9 * np.max(np.abs(ta - 273.15))
    assert out["wall_heat"] == pytest.approx(ref["wall_heat"], rel=1e-9) and ref["wall_heat"] > 0
    assert out["heat"] == pytest.approx(out["wall_heat"], rel=1e-9)


assert SAVED_BED.count('reader=Reader(bonds="contacts")') == 1
OVERLAPPED_BED = SAVED_BED.replace('reader=Reader(bonds="contacts")', 'reader=Reader(bonds="contacts", overlap=True)')


def test_overlapped_calls_give_the_same_bed_one_call_later(run_yade_script, tmp_path):
    # overlap=True: the same temperatures, heat and history as the plain engine; the bodies
    # hold the call before last until the engine publishes the last one (sync, or a result)
    import numpy as np
    script = r"""
e = build()
ids = e.body_ids          # (asking the engine for a result publishes: read the bodies' own)
T_bodies = lambda: np.array([O.bodies[int(i)].state.temp for i in ids])
O.run(1000, True)
before = T_bodies()
f = figures(e)
print(json.dumps(dict(f, before=before.tolist(), after=T_bodies().tolist(), published=e.sync() is None,
                      T_engine=e.temperature.tolist())))
"""
    plain = run_yade_script(SAVED_BED + script, timeout=300, cwd=tmp_path, check=True).result
    over = run_yade_script(OVERLAPPED_BED + script, timeout=300, cwd=tmp_path, check=True).result
    assert over["rows"] == plain["rows"] == 100 and over["time"] == plain["time"]
    assert np.max(np.abs(np.array(over["T_engine"]) - plain["T_engine"])) <= 1e-12 * 100
    assert over["wall_heat"] == pytest.approx(plain["wall_heat"], rel=1e-12) and plain["wall_heat"] > 0
    assert over["heat"] == pytest.approx(over["wall_heat"], rel=1e-9)
    assert plain["before"] == plain["after"] == plain["T_engine"]
    assert over["after"] == over["T_engine"] and over["published"]       # figures() published it
    assert np.max(np.abs(np.array(over["before"]) - over["T_engine"])) > 1e-6     # one call behind


def test_an_overlapped_call_that_fails_is_raised_at_the_next_call(run_yade_script, tmp_path):
    script = r"""
e = build()
O.run(100, True)
def broken(graph, dt):
    raise ZeroDivisionError("broken on purpose")
e.coupled.step = broken
start = O.iter
try:
    O.run(30, True)
    caught = None
except Exception as exc:
    caught = type(exc).__name__
print(json.dumps(dict(caught=caught, error=f"{type(e.error).__name__}: {e.error}", steps=O.iter - start,
                      then=e.sync())))
"""
    out = run_yade_script(OVERLAPPED_BED + script, timeout=300, cwd=tmp_path, check=True).result
    assert out["caught"] == "RuntimeError" and out["error"] == "ZeroDivisionError: broken on purpose"
    assert out["steps"] <= 11 and out["then"] is None       # stopped at the next call; nothing left pending


def test_overlapped_bed_saved_and_loaded_continues_exactly(run_yade_script, tmp_path):
    # a save between two calls holds the unpublished call's input: the loaded run replays it
    import numpy as np
    ref, out, ta, tb = saved_and_continued(run_yade_script, tmp_path, OVERLAPPED_BED, 1000, 1000)
    assert out["rows"] == ref["rows"] and out["time"] == pytest.approx(ref["time"], rel=1e-12)
    assert np.max(np.abs(tb - ta)) <= 1e-9 * np.max(np.abs(ta - 273.15))
    assert out["wall_heat"] == pytest.approx(ref["wall_heat"], rel=1e-9) and ref["wall_heat"] > 0
    hist = (tmp_path / "run" / "h.csv").read_text().splitlines()
    assert len(hist) == 1 + ref["rows"] and not (tmp_path / "run" / "h.csv.after-save.csv").exists()


def test_temperatures_set_before_a_save_are_kept(run_yade_script, tmp_path):
    # set_temperatures, then O.save before the engine's next call: the run loaded in a new
    # process applies them at its first call, as the uninterrupted run does
    import numpy as np
    hot = "e.set_temperatures({int(e.body_ids[0]): 500.0, int(e.body_ids[-1]): 450.0})\n"
    ref, out, ta, tb = saved_and_continued(run_yade_script, tmp_path, SAVED_BED, 1000, 1000, between=hot)
    assert np.max(ta) > 380.0                                 # the 500 K particle is still hot
    assert np.max(np.abs(tb - ta)) <= 1e-9 * np.max(np.abs(ta - 273.15))
    assert out["heat"] == pytest.approx(ref["heat"], rel=1e-9)


MATERIALS = OUTCOME + r"""
import json, math
import numpy as np
from yade import utils
from yade_electro.yade import ElectricalEngine, HeatEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
cu = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5, label="cu"))
steel = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=7850, frictionAngle=0.5, label="steel"))
r = 2e-3
a_id = O.bodies.append(utils.sphere((0, 0, 0), r, material=cu))
b_id = O.bodies.append(utils.sphere((3.8e-3, 0, 0), r, material=steel))
far = O.bodies.append(utils.sphere((0.1, 0, 0), r, material=steel))       # alone, hot, erased later
O.dt = 1e-3
out = {}
e = HeatEngine(
    material=Materials(default=Material(density=8900, specific_heat=172, conductivity=385), by_yade_material={"steel": Material(density=7850, specific_heat=470, conductivity=50)}),
    temperature=InitialTemperature(273.15, by_id={a_id: 373.15, far: 473.15}),
    law="contact",
    integrator=Integrator(theta="backward-euler"),
    reader=Reader(bonds="contacts"),
    iterPeriod=1,
    label="heat")
O.engines = [e.runner]
O.run(50, True)
O.bodies.erase(far)
O.run(50, True)
V = 4 / 3 * math.pi * r ** 3
C1, C2 = 8900 * 172 * V, 7850 * 470 * V
a = math.sqrt(r ** 2 - 1.9e-3 ** 2)
H = 2 * (2 * 385 * 50 / (385 + 50)) * a
T = e.temperature_by_id
steps = round(e.coupled.time / 1e-3)
out["heat"] = dict(D=T[a_id] - T[b_id], D_exact=100.0 * (1 + 1e-3 * H * (1 / C1 + 1 / C2)) ** -steps,
                   sum=C1 * T[a_id] + C2 * T[b_id], sum0=C1 * 373.15 + C2 * 273.15, steps=steps,
                   particle_heat=e.history.rows[-1]["particle_heat"], far_heat=-C2 * 200.0)
O.engines = []
el = ElectricalEngine(
    material=Materials(default=Material(resistivity=1e-6), by_yade_material={"steel": Material(resistivity=5e-6)}),
    boundaries=[Electrode("a", select=[a_id], potential=1.0), Electrode("b", select=[b_id], potential=0.0)],
    law="contact",
    reader=Reader(bonds="contacts"),
    label="el")
el.step()
out["R"] = [el.model.equivalent_resistance, 0.5 * (1e-6 + 5e-6) / (2 * a)]
bad = {"label": lambda: {"glass": Material(conductivity=1.0)}, "index": lambda: {7: Material(conductivity=1.0)},
       "property": lambda: {"cu": Material(emissivity=0.5)}, "negative": lambda: {"cu": Material(conductivity=-1.0)},
       "resistivity_heat_only": lambda: {"cu": Material(resistivity=1e-6)}, "not_a_dict": lambda: ["cu"]}
M = Material(density=8900, specific_heat=172, conductivity=385)
for name, m in bad.items():
    out[name] = outcome(lambda: HeatEngine(material=Materials(default=M, by_yade_material=m()), temperature=273.15,
                                           reader=Reader(bonds="contacts"), law="contact", label="bad_" + name))
print(json.dumps(out))
"""


def test_particles_of_two_materials(run_yade_script, tmp_path):
    # copper and steel spheres in contact (materials= by YADE material label): the temperature
    # difference decays by the exact backward-Euler factor of H (1/C1 + 1/C2), H = 2 k_e a with
    # k_e the harmonic mean; the heat is conserved; a hot steel sphere leaving takes its m c dT;
    # electrically the edge takes the mean resistivity: R = (rho_1 + rho_2) / 2 / (2 a)
    out = run_yade_script(MATERIALS, timeout=120, cwd=tmp_path, check=True).result
    h = out["heat"]
    assert h["steps"] == 99 and h["D"] == pytest.approx(h["D_exact"], rel=1e-9)
    assert h["sum"] == pytest.approx(h["sum0"], rel=1e-12)
    assert h["particle_heat"] == pytest.approx(h["far_heat"], rel=1e-12)
    assert out["R"][0] == pytest.approx(out["R"][1], rel=1e-12)
    assert "no material labelled 'glass'" in out["label"] and "['cu', 'steel']" in out["label"]
    assert "no material 7 in O.materials" in out["index"]
    assert out["property"].startswith("TypeError") and "'emissivity'" in out["property"]   # no such property
    assert "conductivity must be finite and > 0" in out["negative"]
    assert "HeatEngine takes no ['resistivity']" in out["resistivity_heat_only"]
    assert "must be a dict" in out["not_a_dict"]
    for key in ("label", "index", "negative", "resistivity_heat_only", "not_a_dict"):
        assert out[key].startswith("MaterialError"), out[key]


SAVED_PERIODIC = r'''
import json, math
import numpy as np
from yade import utils
from yade_electro.yade import HeatEngine, attach, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
def build():
    n, a, r = 5, 0.004, 0.00201
    O.periodic = True
    O.cell.setBox(n * a, n * a, n * a)
    cu = O.materials.append(FrictMat(young=1.0, poisson=0.3, density=8900, frictionAngle=0.5, label="cu"))
    st = O.materials.append(FrictMat(young=1.0, poisson=0.3, density=7850, frictionAngle=0.5, label="steel"))
    ids = [O.bodies.append(utils.sphere(((i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a), r, material=cu if k % 2 else st))
           for i in range(n) for j in range(n) for k in range(n)]
    for b in ids:
        O.bodies[b].state.vel = (0.3, 0.2, 0.1)
    O.engines = [ForceResetter(), NewtonIntegrator(gravity=(0, 0, 0))]
    O.dt = 1e-4
    init = {b: 300.0 + 10.0 * math.cos(2 * math.pi * O.bodies[b].state.pos[0] / (n * a)) for b in ids}
    e = HeatEngine(
        material=Materials(default=Material(density=8900, specific_heat=172, conductivity=385), by_yade_material={"steel": Material(density=7850, specific_heat=470, conductivity=50)}),
        temperature=InitialTemperature(300.0, by_id=init),
        law="contact",
        integrator=Integrator(theta="backward-euler", time_scale=100.0),
        reader=Reader(bonds="contacts"),
        output=Output(history="h.csv"),
        iterPeriod=1)
    O.engines = O.engines + [e.runner]
    return e
def figures(e):
    return dict(T={str(k): v for k, v in e.temperature_by_id.items()}, rows=len(e.history), time=e.coupled.time,
                heat=e.history.rows[-1]["heat_content"])
'''


@pytest.mark.parametrize("overlap", [False, True], ids=["plain", "overlap"])
def test_periodic_two_material_bed_saves_and_continues(run_yade_script, tmp_path, overlap):
    import numpy as np
    scene = SAVED_PERIODIC.replace('reader=Reader(bonds="contacts")', 'reader=Reader(bonds="contacts", overlap=True)') if overlap \
        else SAVED_PERIODIC
    assert scene.count("overlap=True") == int(overlap)
    ref, out, ta, tb = saved_and_continued(run_yade_script, tmp_path, scene, 100, 100)
    assert out["rows"] == ref["rows"] and out["time"] == pytest.approx(ref["time"], rel=1e-12)
    assert np.max(np.abs(tb - ta)) <= 1e-9 * np.max(np.abs(ta - 300.0))
    assert abs(ref["heat"]) < 1e-9 * 10.0 * 125 * 8900 * 172 * 4 / 3 * np.pi * 0.00201 ** 3   # a cosine: no net heat


POURED = OUTCOME + r"""
import json, math
import numpy as np
from yade import utils
from yade_electro.yade import HeatEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
mat = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5))
r = 2e-3
a = O.bodies.append(utils.sphere((0, 0, 0), r, material=mat))
b = O.bodies.append(utils.sphere((3.8e-3, 0, 0), r, material=mat))
wall = O.bodies.append(utils.wall((0, 0, -1), axis=2, material=mat))
O.dt = 1e-3
e = HeatEngine(
    material=Material(density=8900, specific_heat=172, conductivity=385),
    temperature=InitialTemperature(300.0, by_id={a: 350.0}),
    law="contact",
    integrator=Integrator(theta="backward-euler"),
    reader=Reader(bonds="contacts"),
    iterPeriod=1,
    label="heat")
O.engines = [e.runner]
O.run(20, True)
c = O.bodies.append(utils.sphere((7.6e-3, 0, 0), r, material=mat))      # poured in, touching b
T_a = e.temperature_by_id[a]
e.set_temperatures({c: 400.0, a: 320.0})
O.run(1, True)
row = e.history.rows[-1]
C = 8900 * 172 * 4 / 3 * math.pi * r ** 3
out = {"T_c": e.temperature_by_id[c], "particle_heat": row["particle_heat"], "heat": row["heat_content"],
       "heat0": e.history.rows[0]["heat_content"], "expected": C * (400.0 - 300.0) + C * (320.0 - T_a)}
O.run(20, True)
out["heat_end"] = e.history.rows[-1]["heat_content"]
out["particle_heat_end"] = e.history.rows[-1]["particle_heat"]
errors = {}
for name, t in {"wall": {wall: 300.0}, "missing": {99: 300.0}, "nan": {a: float("nan")}, "list": [a]}.items():
    errors[name] = outcome(lambda: e.set_temperatures(t))
out["errors"] = errors
print(json.dumps(out))
"""


def test_particles_poured_in_hot(run_yade_script, tmp_path):
    # a sphere added during the run takes the temperature set for it (not the engine's
    # default), and the heat this brings, like the one set on an old sphere, is in
    # particle_heat: the balance of the adiabatic bed closes exactly
    out = run_yade_script(POURED, timeout=120, cwd=tmp_path, check=True).result
    assert 390.0 < out["T_c"] < 400.0                         # poured at 400 K, one step of conduction
    assert out["heat"] - out["heat0"] == pytest.approx(out["particle_heat"], rel=1e-12)
    assert out["heat_end"] == pytest.approx(out["heat"], rel=1e-12)       # adiabatic afterwards
    assert out["particle_heat_end"] == out["particle_heat"]
    assert out["particle_heat"] == pytest.approx(out["expected"], rel=1e-12)   # C (400 - 300) + C (320 - T_a)
    for name, text in {"wall": "is not a sphere", "missing": "is not a sphere", "nan": "must be finite",
                       "list": "takes a dict"}.items():
        assert text in out["errors"][name], out["errors"][name]


COMPRESSED = r"""
import json
import numpy as np
from yade import pack, utils
from yade_electro.yade import HeatEngine, Electrode, InitialTemperature, Integrator, Material, Materials, Output, Reader, Wall
O.periodic = True
L = 0.03
O.cell.setBox(L, L, L)
glass = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=2500, frictionAngle=0.5, label="glass"))
cu = O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5, label="cu"))
sp = pack.SpherePack()
sp.makeCloud((0, 0, 0), (L, L, L), rMean=1e-3, rRelFuzz=0.5, periodic=True, seed=3)     # radii over a factor 3
ids = [O.bodies.append(utils.sphere(c, r, material=(cu if i % 3 == 0 else glass))) for i, (c, r) in enumerate(sp)]
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]),
             PeriIsoCompressor(charLen=2e-3, stresses=[-1e4, -1e5], doneHook="O.pause()", globalUpdateInt=20,
                               keepProportions=True),
             NewtonIntegrator(damping=0.4)]
O.dt = 0.5 * utils.PWaveTimeStep()
hot = {i: 400.0 for i in ids if O.bodies[i].state.pos[0] < L / 2}
e = HeatEngine(
    material=Materials(default=Material(density=2500, specific_heat=800, conductivity=1.0), by_yade_material={"cu": Material(density=8900, specific_heat=385, conductivity=385)}),
    temperature=InitialTemperature(300.0, by_id=hot),
    law="contact",
    integrator=Integrator(theta="backward-euler"),
    reader=Reader(bonds="contacts"),
    iterPeriod=20,
    label="heat")
O.engines = O.engines + [e.runner]
O.run(12000, True)
e.step()                                  # the graph of the positions as they are now
Hm = np.array([[O.cell.hSize[p, q] for q in range(3)] for p in range(3)])
P = np.array([O.bodies[i].state.pos for i in ids])
R = np.array([O.bodies[i].shape.radius for i in ids])
S = P @ np.linalg.inv(Hm).T
dS = S[None] - S[:, None]
dS -= np.round(dS)
brute = int(np.sum(np.triu(np.linalg.norm(dS @ Hm.T, axis=2) < R[:, None] + R[None, :], 1)))
rows = e.history.rows
print(json.dumps({"strain": 1 - Hm[0, 0] / L, "builds": e.reader.list_builds, "brute": brute,
                  "ours": int(np.sum(e.contact_heat_flow()[1] > 0)), "heat0": rows[0]["heat_content"],
                  "heat": rows[-1]["heat_content"], "T_max": rows[-1]["T_max"], "T_min": rows[-1]["T_min"]}))
"""


def test_periodic_bed_under_isotropic_compression(run_yade_script, tmp_path):
    # a polydisperse two-material cloud in a periodic cell compressed by YADE's
    # PeriIsoCompressor: the conducting contacts are those of the nearest images (brute force
    # on YADE's cell), the adiabatic bed keeps its heat, and the hot half warms the cold one
    out = run_yade_script(COMPRESSED, timeout=600, cwd=tmp_path, check=True).result
    assert out["strain"] > 0.05 and out["builds"] > 10
    assert out["ours"] == out["brute"] > 0
    assert out["heat"] == pytest.approx(out["heat0"], rel=1e-12)
    assert 300.0 < out["T_min"] + 1e-9 and out["T_max"] <= 400.0
