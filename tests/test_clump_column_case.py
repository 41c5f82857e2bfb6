"""Clumps in the granular heat engine, on real YADE: cases/clump_column.py (lumped and resolved
against their closed forms), and the clumps the engine refuses when it is built."""


def test_clump_column_matches_its_closed_forms(run_yade_script):
    res = run_yade_script("cases/clump_column.py", check=True, timeout=600)
    out = res.result
    r, lu = out["resolved"], out["lumped"]
    assert r["steady_error_K"] < 1e-9 and lu["steady_error_K"] < 1e-9, out
    assert r["steady_K"] == [100.0, 160.0, 220.0, 280.0, 340.0, 400.0]
    assert r["transient_error_pct"] < 0.05 and lu["transient_error_pct"] < 0.05, out   # Crank-Nicolson, dt = 0.25 s
    assert lu["members_equal"] and lu["steady_K"][2:5] == [250.0, 250.0, 250.0]
    # the clump body carries its members' capacity-weighted mean
    assert 100.0 < r["clump_T_last_K"][0] < 160.0 and lu["clump_T_last_K"][0] == 100.0
    assert out["lumped_vs_resolved_pct"] > 1.0                  # the clumps' own conduction


BAD_CLUMPS = """
from yade_electro.yade import HeatEngine, Material, Reader
from yade_electro.core.errors import GraphError
O.bodies.appendClumped([sphere((0, 0, 0), 1e-3), box((0, 0, 2e-3), (1e-3, 1e-3, 1e-3))])
O.bodies.append(sphere((0, 0, -2e-3), 1e-3))
try:
    HeatEngine(material=Material(density=2600, specific_heat=800, conductivity=2.0), law="contact",
               reader=Reader(bonds="contacts"), temperature=300.0)
except GraphError as exc:
    print("REFUSED", exc)
O.reset()
O.bodies.appendClumped([sphere((0, 0, 0), 1e-3), sphere((1.5e-3, 0, 0), 1e-3)])
O.bodies[0].state.mass = 0.0                 # a member with no mass (set after the clump was made)
try:
    HeatEngine(material=Material(density=2600, specific_heat=800, conductivity=2.0), law="contact",
               reader=Reader(bonds="contacts"), temperature=300.0)
except GraphError as exc:
    print("REFUSED", exc)
for kw in (dict(bonds="contacts", clumps="merged"),):
    try:
        Reader(**kw)
    except ValueError as exc:
        print("REFUSED", exc)
"""


def test_clumps_the_engine_refuses_when_built(run_yade_script):
    res = run_yade_script(BAD_CLUMPS, check=True, timeout=300)
    lines = [ln for ln in res.stdout.splitlines() if ln.startswith("REFUSED")]
    assert len(lines) == 3, res.stdout[-2000:]
    assert "is a Box, not a sphere" in lines[0] and "appendClumped" in lines[0]
    assert "has no mass" in lines[1] and "density > 0" in lines[1]
    assert "'lumped' (one temperature per clump) or 'resolved'" in lines[2]


FALLING_CLUMPS = """
import json
import numpy as np
from yade_electro.yade import HeatEngine, Integrator, Material, Reader, Wall
mode = "%s"
O.materials.append(FrictMat(young=1e6, poisson=0.3, frictionAngle=0.4, density=2600, label="m"))
floor = O.bodies.append(box((0, 0, -0.5e-3), (6e-3, 6e-3, 0.5e-3), fixed=True, material="m"))
rng = np.random.default_rng(1)
for k in range(12):                       # dumbbells and triplets, dropped in a loose column
    x, y, z = rng.uniform(-3e-3, 3e-3), rng.uniform(-3e-3, 3e-3), 1.2e-3 + 2.2e-3 * k
    n = 2 + k %% 2
    O.bodies.appendClumped([sphere((x + 1.5e-3 * j * 0.6, y, z), 0.6e-3, material="m") for j in range(n)])
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]),
             NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.4)]
O.dt = 0.5 * PWaveTimeStep()
eng = HeatEngine(material=Material(density=2600, specific_heat=800, conductivity=2.0), law="contact",
                 reader=Reader(bonds="contacts", clumps=mode),
                 boundaries=[Wall("floor", bodies=[floor], temperature=400.0)], temperature=300.0,
                 integrator=Integrator(dt=0.05), iterPeriod=200)
O.engines = O.engines + [eng.runner]
O.run(20000, True)
rows = eng.history.rows
last = rows[-1]
members = [b for b in O.bodies if b.isClumpMember]
clumps = [b for b in O.bodies if b.isClump]
spread = max(np.ptp([O.bodies[m].state.temp for m in c.shape.members.keys()]) for c in clumps)
ledger = last["heat_content"] - (last["boundary_heat"] + last["particle_heat"])   # the wall's heat is boundary heat
print(json.dumps({"rows": len(rows), "contacts": last["wall_contacts:floor"], "T_max": last["T_max"],
                  "wall_heat": last["wall_heat:floor"], "ledger_error": abs(ledger) / abs(last["heat_content"]),
                  "members": len(members), "clump_temps": all(hasattr(c.state, "temp") for c in clumps),
                  "member_spread_K": float(spread)}))
"""


def test_falling_clumps_conduct_lumped_and_resolved(run_yade_script):
    """Clumps dropped on a hot floor (an isothermal wall): they settle, touch, heat up; the
    energy ledger closes; lumped clumps have one temperature, resolved ones do not."""
    out = {}
    for mode in ("lumped", "resolved"):
        out[mode] = run_yade_script(FALLING_CLUMPS % mode, check=True, timeout=600).result
        r = out[mode]
        assert r["rows"] >= 90 and r["contacts"] >= 2 and r["members"] == 30 and r["clump_temps"], r
        assert 300.0 < r["T_max"] <= 400.0 and r["wall_heat"] > 0 and r["ledger_error"] < 1e-9, r
    assert out["lumped"]["member_spread_K"] == 0.0 and out["resolved"]["member_spread_K"] > 0.01, out
