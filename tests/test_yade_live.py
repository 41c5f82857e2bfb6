"""Live runs in real YADE: save / load (same and new process) continuing exactly, several
engines, every setup error raised in the script, cheap change detection, and no open port."""
import csv

import numpy as np
import pytest

ROD = r'''
import json, sys, os
import numpy as np
from yade import pack, utils
from yade_electro.yade import ElectroThermalEngine, ElectricalEngine, attach, Electrode, Material, Integrator, Output, Reader
from yade_electro.yade import packing as P
from yade_electro.yade import FixedTemperature, Convection
L, RAD = 2e-3, 0.5e-3
shape = pack.inCylinder((0, 0, 0), (0, 0, L), RAD)
def stretch():
    # the rod strains as it heats: positions a function of the iteration (YADE's own
    # save/load does not restore its dynamics bit for bit, so they are set, not integrated)
    f = 1.0 + 1e-4 * O.iter / 300.0
    for b in O.bodies:
        p = b.state.refPos
        b.state.pos = (p[0], p[1], p[2] * f)
def build(n=400):
    O.reset()
    pk = P.dense_packing(shape, n=n, seed=3)
    ids = np.asarray(P.add_bonded_packing(pk))
    r = float(np.mean(pk.radii))
    z = pk.centers[:, 2]
    top, bottom = ids[z > L - 1.5 * r], ids[z < 1.5 * r]
    utils.setRefSe3()
    for e in O.engines:
        if type(e).__name__ == "NewtonIntegrator":
            e.dead = True
    O.engines = O.engines + [PyRunner(command="stretch()", iterPeriod=1, label="stretcher")]
    return ids, top, bottom
def thermal(top, bottom, history=None):
    e = ElectroThermalEngine(
        material=Material(resistivity=7.3e-7, density=7900.0, specific_heat=500.0, conductivity=16.2, beta=1e-3,
                          reference_temperature=300.0),
        boundaries=[Electrode("top", select=top, potential=0.2), Electrode("bottom", select=bottom, potential=0.0),
                    Convection("air", shape, h=50.0, t_inf=300.0)],
        temperature=300.0, integrator=Integrator(theta="backward-euler", dt=2e-4),
        reader=Reader(geometry_every=1, move_tolerance=0.0), output=Output(history=history), iterPeriod=5)
    O.engines = O.engines + [e.runner]
    return e
def figures(e):
    return dict(T={str(k): v for k, v in e.temperature_by_id.items()}, time=e.coupled.time,
                rows=len(e.history), last=e.history.rows[-1], iter=O.iter,
                body_T={str(i): O.bodies[int(i)].state.temp for i in e.body_ids[:50]})
'''

UNINTERRUPTED = ROD + r'''
ids, top, bottom = build()
e = thermal(top, bottom, history="h.csv")
O.run(300, True)
print(json.dumps(figures(e)))
'''

SAVE = ROD + r'''
ids, top, bottom = build()
e = thermal(top, bottom, history="h.csv")
O.run(150, True)
O.save("scene.yade.gz")
print(json.dumps(figures(e)))
'''

LOAD_NEW_PROCESS = ROD + r'''
O.load("scene.yade.gz")
e = attach("electrothermal")            # the one line after O.load
O.run(150, True)
print(json.dumps(figures(e)))
'''

LOAD_SAME_PROCESS = ROD + r'''
ids, top, bottom = build()
e = thermal(top, bottom, history="h.csv")
O.run(150, True)
O.save("scene.yade.gz")
O.run(50, True)                         # the run goes on, then the user goes back to the save
rows_before = len(e.history)
O.load("scene.yade.gz")
O.run(150, True)                        # the saved PyRunner finds the engine and re-attaches it
out = figures(e)
out["rows_before_load"] = rows_before
out["sidecar"] = os.path.exists("h.csv.after-save.csv")
print(json.dumps(out))
'''


def _csv_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _compare(a, b, rel=1e-9):
    ta = np.array([a["T"][k] for k in sorted(a["T"])])
    tb = np.array([b["T"][k] for k in sorted(a["T"])])
    assert sorted(a["T"]) == sorted(b["T"])
    dT = ta - 300.0
    assert np.max(np.abs(tb - ta)) <= rel * np.max(np.abs(dT)), np.max(np.abs(tb - ta))
    assert b["time"] == pytest.approx(a["time"], rel=1e-12)
    for k in ("R_eq", "joule_energy", "heat_content", "convection_heat", "T_mean"):
        assert b["last"][k] == pytest.approx(a["last"][k], rel=rel), k


def test_save_and_load_in_a_new_process_continues_exactly(run_yade_script, tmp_path):
    ref_dir, run_dir = tmp_path / "ref", tmp_path / "run"
    ref_dir.mkdir(), run_dir.mkdir()
    ref = run_yade_script(UNINTERRUPTED, cwd=ref_dir, check=True).result
    saved = run_yade_script(SAVE, cwd=run_dir, check=True).result
    res = run_yade_script(LOAD_NEW_PROCESS, cwd=run_dir, check=True)
    out = res.result
    assert ref["T"] and max(v for v in ref["T"].values()) > 300.1          # it heated
    assert saved["rows"] < out["rows"] == ref["rows"]
    _compare(ref, out)
    # temperatures on the bodies are the engine's
    for k, v in out["body_T"].items():
        assert v == out["T"][k]
    # the history CSV was appended, not truncated, and equals the uninterrupted one
    a, b = _csv_rows(ref_dir / "h.csv"), _csv_rows(run_dir / "h.csv")
    assert len(a) == len(b) == ref["rows"]
    for ra, rb in zip(a, b):
        assert int(ra["iter"]) == int(rb["iter"])
        assert float(rb["T_max"]) == pytest.approx(float(ra["T_max"]), rel=1e-9)


def test_load_in_the_same_process_reattaches(run_yade_script, tmp_path):
    ref_dir, run_dir = tmp_path / "ref", tmp_path / "run"
    ref_dir.mkdir(), run_dir.mkdir()
    ref = run_yade_script(UNINTERRUPTED, cwd=ref_dir, check=True).result
    res = run_yade_script(LOAD_SAME_PROCESS, cwd=run_dir, check=True)
    out = res.result
    _compare(ref, out)
    assert out["rows"] == ref["rows"] and out["rows_before_load"] == ref["rows"] - 30 + 10
    assert out["sidecar"]                 # the rows written after the save are kept aside
    assert "continuing from the state it saved" in res.stderr


SEVERAL = r'''
import json, warnings
import numpy as np
from yade import pack
from yade_electro.yade import ElectricalEngine, ENGINES, Electrode, Material, Output, Reader, electrodes_from_dict
from yade_electro.yade import packing as P
pk = P.dense_packing(pack.inCylinder((0, 0, 0), (0, 0, 2e-3), 0.5e-3), n=300, seed=2)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
el = lambda v: {"top": dict(select=ids[z > z.max() - 1e-4], potential=v), "bottom": dict(select=ids[z < z.min() + 1e-4], potential=0.0)}
out = {}
a = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict(el(1.0)),
    output=Output(history="a.csv"))
b = ElectricalEngine(
    material=Material(resistivity=2e-6),
    boundaries=electrodes_from_dict(el(1.0)),
    output=Output(history="b.csv", write_back="potential_b"))
out["labels"] = [a.label, b.label]
for kw, key in ((dict(label="electro", output=Output(history="c.csv")), "explicit_taken"),
                (dict(output=Output(history="a.csv"), label="third"), "shared_history")):
    try:
        ElectricalEngine(material=Material(resistivity=1e-6), boundaries=electrodes_from_dict(el(1.0)), **kw)
    except Exception as exc:
        out[key] = [type(exc).__name__, str(exc)]
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    c = ElectricalEngine(
        material=Material(resistivity=3e-6),
        boundaries=electrodes_from_dict(el(1.0)),
        output=Output(history="c.csv"),
        label="third")
    out["shared_attribute_warning"] = [str(x.message) for x in w if "both write" in str(x.message)]
O.engines = O.engines + [a.runner, b.runner, c.runner]
O.run(4, True)
out["rows"] = [len(a.history), len(b.history), len(c.history)]
out["R"] = [a.equivalent_resistance, b.equivalent_resistance, c.equivalent_resistance]
out["registry"] = sorted(ENGINES)
print(json.dumps(out))
'''


def test_several_engines(run_yade_script):
    out = run_yade_script(SEVERAL, check=True).result
    assert out["labels"] == ["electro", "electro_2"]
    assert out["explicit_taken"][0] == "ValueError" and "already running" in out["explicit_taken"][1]
    assert out["shared_history"][0] == "ValueError" and "already writes the history file" in out["shared_history"][1]
    assert len(out["shared_attribute_warning"]) == 1 and "b.potential" in out["shared_attribute_warning"][0]
    assert all(n >= 3 for n in out["rows"])                  # each engine ran its own model
    Ra, Rb, Rc = out["R"]
    assert Rb == pytest.approx(2 * Ra, rel=1e-9) and Rc == pytest.approx(3 * Ra, rel=1e-9)
    assert out["registry"] == ["electro", "electro_2", "third"]


SETUP_ERRORS = r'''
import json
import numpy as np
from yade import pack
from yade_electro.yade import (ElectricalEngine, ElectroThermalEngine, Electrode, Material, Integrator, Output,
                               electrodes_from_dict, FixedTemperature, Convection)
from yade_electro.yade import packing as P
pk = P.dense_packing(pack.inCylinder((0, 0, 0), (0, 0, 2e-3), 0.5e-3), n=300, seed=2)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
EL = {"top": dict(select=ids[z > z.max() - 1e-4], potential=1.0), "bottom": dict(select=ids[z < z.min() + 1e-4], potential=0.0)}
nowhere = pack.inAlignedBox((1, 1, 1), (2, 2, 2))
M = dict(resistivity=1e-6, density=7900.0, specific_heat=500.0, conductivity=16.0)
def heating(material=None, boundaries=(), integrator=None):
    return ElectroThermalEngine(material=Material(**{**M, **(material or {})}),
                                boundaries=electrodes_from_dict(EL) + list(boundaries), temperature=300.0,
                                integrator=integrator or Integrator())
cases = {   # made when the case runs (a boundary condition checks itself when made)
  "density 0": lambda: heating(dict(density=0.0)), "density negative": lambda: heating(dict(density=-1.0)),
  "density NaN": lambda: heating(dict(density=float("nan"))), "density string": lambda: heating(dict(density="7900")),
  "conductivity string": lambda: heating(dict(conductivity="x")),
  "specific_heat 0": lambda: heating(dict(specific_heat=0.0)),
  "theta": lambda: heating(integrator=Integrator(theta="rk4")),
  "theta number": lambda: heating(integrator=Integrator(theta=2.0)),
  "fixed selects nothing": lambda: heating(boundaries=[FixedTemperature("hot", nowhere, 400.0)]),
  "fixed overlap": lambda: heating(boundaries=[FixedTemperature("a", ids[:20], 400.0),
                                               FixedTemperature("b", ids[10:30], 300.0)]),
  "convection bad area": lambda: heating(boundaries=[Convection("air", ids[:5], h=10.0, t_inf=300.0, area=-1.0)]),
  "flux not a BC": lambda: heating(boundaries=["hot"]),
  "thermal_dt": lambda: heating(integrator=Integrator(dt=-1.0)),
  "old keyword": lambda: ElectricalEngine(resistivity=1e-6, electrodes=EL),
  "positional": lambda: ElectroThermalEngine(1e-6, EL, 7900.0, 500.0, 16.0, 300.0),
  "electrodes as a dict": lambda: ElectricalEngine(material=Material(resistivity=1e-6), boundaries=EL),
}
out = {}
def record(name, fn):
    try:
        fn()
        out[name] = None
    except Exception as exc:
        out[name] = [type(exc).__name__, [c.__name__ for c in type(exc).__mro__], str(exc)]
for name, make in cases.items():
    record(name, make)
record("iterPeriod 0", lambda: ElectricalEngine(material=Material(resistivity=1e-6), boundaries=electrodes_from_dict(EL), iterPeriod=0))
record("iterPeriod float", lambda: ElectricalEngine(material=Material(resistivity=1e-6), boundaries=electrodes_from_dict(EL), iterPeriod=2.5))
record("label", lambda: ElectricalEngine(material=Material(resistivity=1e-6), boundaries=electrodes_from_dict(EL), label="my engine"))
record("write_back read-only", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict(EL),
    output=Output(write_back="id")))
record("write_back YADE's", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict(EL),
    output=Output(write_back="dynamic")))
record("write_back not a name", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict(EL),
    output=Output(write_back="a.b")))
record("selector float", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict({**EL, "top": dict(select=3.7, potential=1.0)})))
record("selector floats", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict({**EL, "top": dict(select=[1.5, 2.7], potential=1.0)})))
record("value string", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict({**EL, "top": dict(select=EL["top"]["select"], potential="1V")})))
record("value NaN", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict({**EL, "top": dict(select=EL["top"]["select"], current=float("nan"))})))
record("resistivity string", lambda: ElectricalEngine(material=Material(resistivity="1e-6"), boundaries=electrodes_from_dict(EL)))
record("electrode selects nothing", lambda: ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=electrodes_from_dict({**EL, "top": dict(select=nowhere, potential=1.0)})))
print(json.dumps(out))
'''

EXPECTED = {
    "density 0": ("MaterialError", "density"), "density negative": ("MaterialError", "density"),
    "density NaN": ("MaterialError", "density"), "density string": ("MaterialError", "density"),
    "conductivity string": ("MaterialError", "conductivity"), "specific_heat 0": ("MaterialError", "specific_heat"),
    "theta": ("ValueError", "unknown integrator"), "theta number": ("ValueError", "theta must be in [0, 1]"),
    "fixed selects nothing": ("BoundaryConditionError", "fixed-temperature boundary condition 'hot' selects no element"),
    "fixed overlap": ("BoundaryConditionError", "fixed-temperature boundary conditions 'a' and 'b'"),
    "convection bad area": ("BoundaryConditionError", "convection boundary condition 'air': areas must be finite"),
    "flux not a BC": ("TypeError", "HeatFlux"),
    "thermal_dt": ("ValueError", "dt must be > 0"),
    "old keyword": ("TypeError", "resistivity -> material=Material(resistivity=...); electrodes -> boundaries=["),
    "positional": ("TypeError", "keyword arguments only"),
    "electrodes as a dict": ("BoundaryConditionError", "boundaries= is a list"),
    "iterPeriod 0": ("ValueError", "iterPeriod must be an integer >= 1"),
    "iterPeriod float": ("ValueError", "iterPeriod must be an integer >= 1"),
    "label": ("ValueError", "label must be a Python identifier"),
    "write_back read-only": ("ValueError", "write_back='id'"),
    "write_back YADE's": ("ValueError", "attribute of YADE's Body"),
    "write_back not a name": ("ValueError", "write_back must be an attribute name"),
    "selector float": ("BoundaryConditionError", "body ids must be integers"),
    "selector floats": ("BoundaryConditionError", "body ids must be integers, got [1.5, 2.7]"),
    "value string": ("BoundaryConditionError", "electrode 'top': value must be a real number"),
    "value NaN": ("BoundaryConditionError", "electrode 'top': value must be finite"),
    "resistivity string": ("MaterialError", "resistivity"),
    "electrode selects nothing": ("BoundaryConditionError", "electrode 'top' selects no element"),
}


def test_every_setup_error_is_raised_in_the_script(run_yade_script):
    out = run_yade_script(SETUP_ERRORS, check=True).result
    for case, (name, text) in EXPECTED.items():
        got = out[case]
        assert got is not None, f"{case}: accepted"
        assert got[0] == name and text in got[2], (case, got)
    # errors of bad values are ValueErrors too (a user's `except ValueError` catches them)
    for case in ("density 0", "fixed selects nothing", "value string"):
        assert "ValueError" in out[case][1]


DETECTION = r'''
import json
import numpy as np
from yade import pack
from yade_electro.yade import ElectricalEngine, Electrode, Material, Output, Reader, electrodes_from_dict
from yade_electro.yade import packing as P
pk = P.dense_packing(pack.inCylinder((0, 0, 0), (0, 0, 2e-3), 0.5e-3), n=300, seed=2)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
extra = O.bodies.append(sphere((5e-3, 5e-3, 5e-3), 1e-4))   # an unbonded sphere far away
e = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=[
        Electrode("top", select=ids[z > z.max() - 1e-4], potential=1.0),
        Electrode("bottom", select=ids[z < z.min() + 1e-4], potential=0.0)],
    reader=Reader(geometry_every=0, sweep_calls=4))
out = {"mode": e.reader.bond_mode}
e.step(); out["reads0"] = e.reader.full_reads
e.step(); out["reads_unchanged"] = e.reader.full_reads
O.bodies[extra].shape.radius = 2e-4                        # a radius change
e.step(); out["after_radius"] = [e.reader.full_reads, e.reader.last_change]
O.bodies.erase(extra)                                     # an unbonded body erased
e.step(); out["after_erase"] = [e.reader.full_reads, e.reader.last_change, int(e.bond_graph.n_nodes)]
r0 = e.model.equivalent_resistance
inner = int(ids[np.argmin(np.abs(z - 1e-3))])
O.bodies[inner].shape.radius *= 1.3                       # a bonded sphere grows: its bonds conduct more
e.step()
fresh = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=[
        Electrode("top", select=ids[z > z.max() - 1e-4], potential=1.0),
        Electrode("bottom", select=ids[z < z.min() + 1e-4], potential=0.0)],
    law=e.model.law_name,
    reader=Reader(geometry_every=0),
    label="fresh")
fresh.step()
out["grown"] = [r0, e.model.equivalent_resistance, fresh.model.equivalent_resistance]
# the continuum law's transmission surfaces go as r^2 (the voronoi law's faces do not see radii)
cont = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=[
        Electrode("top", select=ids[z > z.max() - 1e-4], potential=1.0),
        Electrode("bottom", select=ids[z < z.min() + 1e-4], potential=0.0)],
    law="continuum",
    reader=Reader(geometry_every=0),
    label="cont")
cont.step()
r1 = cont.model.equivalent_resistance
O.bodies[inner].shape.radius *= 1.3
cont.step()
fresh2 = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=[
        Electrode("top", select=ids[z > z.max() - 1e-4], potential=1.0),
        Electrode("bottom", select=ids[z < z.min() + 1e-4], potential=0.0)],
    law="continuum",
    reader=Reader(geometry_every=0),
    label="fresh2")
fresh2.step()
out["grown_continuum"] = [r1, cont.model.equivalent_resistance, fresh2.model.equivalent_resistance]
for lab in ("fresh", "cont", "fresh2"):
    O.engines = [x for x in O.engines if getattr(x, "label", "") != lab]
e.step()                                                  # the second growth seen before the next check
# a bond broken in shear with its spheres still in contact: no counter changes, the sweep finds it
mid = [i for i in O.interactions if i.isReal and abs(O.bodies[i.id1].state.pos[2] - 1e-3) < 2e-4][0]
mid.phys.cohesionBroken = True
calls = 0
while e.reader.last_change != "a bond broke" and calls < 10:
    e.step(); calls += 1
out["sweep_calls_to_find"] = calls
out["check_calls"] = e.reader.bond_check_calls
out["edges"] = int(e.bond_graph.n_edges)
O.bodies[int(ids[0])].shape.radius = -1e-5               # a negative radius: refused
try:
    e.step()
except Exception as exc:
    out["negative_radius"] = [type(exc).__name__, str(exc)]
print(json.dumps(out))
'''


def test_cheap_change_detection(run_yade_script):
    out = run_yade_script(DETECTION, check=True).result
    assert out["mode"] in ("flags", "sweep") and out["mode"] == ("flags" if out["check_calls"] == 1 else "sweep")
    assert out["reads0"] == out["reads_unchanged"] == 1
    assert out["after_radius"][0] == 2 and "sphere volume" in out["after_radius"][1]
    assert out["after_erase"][0] == 3 and "sphere volume" in out["after_erase"][1]
    # a grown radius changes the conductances as a fresh engine on the changed scene has them
    # (the default law here is voronoi, whose faces do not depend on radii)
    r0, r_kept, r_fresh = out["grown"]
    assert r_kept == pytest.approx(r_fresh, rel=1e-9)
    r1, r_kept, r_fresh = out["grown_continuum"]
    assert r_kept < r1 and r_kept == pytest.approx(r_fresh, rel=1e-9)
    assert 1 <= out["sweep_calls_to_find"] <= out["check_calls"]      # as the history rows say
    assert out["negative_radius"][0] == "GraphError" and "radius must be finite and > 0" in out["negative_radius"][1]


PORTS = r'''
import json, os
import numpy as np
from yade import pack
from yade_electro.yade import ElectricalEngine, Electrode, Material, Output, Reader, electrodes_from_dict
from yade_electro.yade import packing as P

def listening():
    socks = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            t = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            continue
        if t.startswith("socket:["):
            socks.add(t[8:-1])
    n = 0
    for f in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in open(f).read().splitlines()[1:]:
            p = line.split()
            if p[3] == "0A" and p[9] in socks:
                n += 1
    return n
pk = P.dense_packing(pack.inCylinder((0, 0, 0), (0, 0, 2e-3), 0.5e-3), n=300, seed=2)
ids = np.asarray(P.add_bonded_packing(pk))
z = pk.centers[:, 2]
e = ElectricalEngine(
    material=Material(resistivity=1e-6),
    boundaries=[
        Electrode("top", select=ids[z > z.max() - 1e-4], potential=1.0),
        Electrode("bottom", select=ids[z < z.min() + 1e-4], potential=0.0)])
seen = []
O.engines = O.engines + [e.runner, PyRunner(command="seen.append(listening())", iterPeriod=1)]
O.run(5, True)
print(json.dumps({"listening_during_run": max(seen), "checks": len(seen)}))
'''


def test_no_port_is_listening_during_a_run(run_yade_script):
    res = run_yade_script(PORTS, check=True)
    assert res.result["checks"] >= 4 and res.result["listening_during_run"] == 0
    assert "remote servers" in res.stderr and "auth cookie" not in res.stdout + res.stderr
