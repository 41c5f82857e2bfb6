"""ElectricalEngine and SceneReader in the real YADE, each case a fresh ``yade-electro -n -x`` process
(one Omega per process). The scripts print their figures as one JSON line at the end."""
import csv
import io

import pytest

pytestmark = pytest.mark.yade

TIMEOUT = 120

# A bonded hexagonal packing of ~400 spheres (r = 0.5 mm) in a 6 x 6 x 12 mm box, bonded with
# CohFrictMat (cohesion set on the contacts found with a detection factor 1.1 in one step),
# plus a wall (FrictMat) touching the bottom layer, which the reader must leave out.
PACKING = r'''
import json, sys
import numpy as np
from yade import pack, utils

O.materials.append(CohFrictMat(young=1e9, poisson=0.3, density=8000, frictionAngle=0.5,
                               normalCohesion=1e8, shearCohesion=1e8, momentRotationLaw=True, label="steel"))
O.materials.append(FrictMat(young=1e9, poisson=0.3, density=8000, frictionAngle=0.5, label="wallmat"))
r = 0.5e-3
sphere_ids = O.bodies.append(pack.regularHexa(pack.inAlignedBox((0, 0, 0), (6e-3, 6e-3, 12e-3)),
                                              radius=r, gap=0, material="steel"))
zs = np.array([O.bodies[i].state.pos[2] for i in sphere_ids])
zmin, zmax = zs.min(), zs.max()
wall_id = O.bodies.append(utils.wall(zmin - r, axis=2, sense=1, material="wallmat"))
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=1.1, label="bo1"), Bo1_Wall_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=1.1, label="ig2"), Ig2_Wall_Sphere_ScGeom()],
        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True, setCohesionOnNewContacts=False),
         Ip2_FrictMat_FrictMat_FrictPhys()],
        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(), Law2_ScGeom_FrictPhys_CundallStrack()]),
    NewtonIntegrator(damping=0.4, gravity=(0, 0, 0)),
]
O.dt = 0.5 * PWaveTimeStep()
O.step()
bo1.aabbEnlargeFactor = -1
ig2.interactionDetectionFactor = -1

RHO = 0.73e-6
TOP = pack.inAlignedBox((-1, -1, zmax - 0.5 * r), (1, 1, 1))
BOTTOM = pack.inAlignedBox((-1, -1, -1), (1, 1, zmin + 0.5 * r))

from yade_electro import ContactGraph, equivalent_resistance
from yade_electro.laws.factors import conductance
from yade_electro.yade import ElectricalEngine, Electrode, Material, Output, Reader


def independent_graph():
    """The bonded graph read here directly from O (not through SceneReader)."""
    ids = [b.id for b in O.bodies if isinstance(b.shape, Sphere)]
    index = {i: k for k, i in enumerate(ids)}
    pos = [tuple(O.bodies[i].state.pos) for i in ids]
    rad = [O.bodies[i].shape.radius for i in ids]
    edges = [(index[i.id1], index[i.id2]) for i in O.interactions
             if i.isReal and i.id1 in index and i.id2 in index and not i.phys.cohesionBroken]
    return ContactGraph(pos, rad, np.array(edges).reshape(-1, 2), ids)


def core_resistance(g):
    """R_eq of graph g by the core functions, electrodes by centre z, direct solver."""
    z = g.pos[:, 2]
    return equivalent_resistance(g.n_nodes, g.edges, conductance(g, RHO),
                                 np.flatnonzero(z > zmax - 0.5 * r), np.flatnonzero(z < zmin + 0.5 * r),
                                 solver="direct")


def make_engine(**kw):
    e = ElectricalEngine(material=Material(resistivity=RHO),
                         boundaries=[Electrode("top", select=TOP, potential=1.0),
                                     Electrode("bottom", select=BOTTOM, potential=0.0)],
                         **kw)
    O.engines = O.engines + [e.runner]
    return e
'''

RUN_AND_COMPARE = PACKING + r'''
e = make_engine(iterPeriod=2, output=Output(history="history.csv"), reader=Reader(move_tolerance=1e3))
O.run(6, True)
g = e.graph
ref = independent_graph()
sol = e.solution
top_ids = [b.id for b in O.bodies if isinstance(b.shape, Sphere) and b.state.pos[2] > zmax - 0.5 * r]
out = dict(
    n_spheres=len(sphere_ids), n_nodes=g.n_nodes, n_edges=g.n_edges,
    ref_n_nodes=ref.n_nodes, ref_n_edges=ref.n_edges,
    same_ids=sorted(g.ids.tolist()) == sorted(ref.ids.tolist()),
    same_edges=sorted(map(tuple, np.sort(g.ids[g.edges], axis=1).tolist()))
               == sorted(map(tuple, np.sort(ref.ids[ref.edges], axis=1).tolist())),
    wall_interactions=sum(1 for i in O.interactions if i.isReal and wall_id in (i.id1, i.id2)),
    R_eq=e.equivalent_resistance, R_core=core_resistance(ref),
    currents=e.electrode_currents,
    max_abs_potential_diff=max(abs(getattr(O.bodies[i], "potential") - v) for i, v in e.potential_by_id.items()),
    top_potentials=sorted(set(O.bodies[i].potential for i in top_ids)),
    wall_has_potential=hasattr(O.bodies[wall_id], "potential"),
    ignored=dict(e.reader.ignored), full_reads=e.reader.full_reads, calls=e.reader.calls,
    rebuilds=e.model.rebuilds, history_len=len(e.history), iter=O.iter,
    last_iterations=e.history.rows[-1]["iterations"], revision=g.revision,
)
# a new electrode value: same graph and problem, potentials scale
e.set_electrode("top", 2.0)
e.step()
out.update(R_after_set=e.equivalent_resistance, V_top_after_set=e.solution.electrode_potential["top"],
           body0_ratio=O.bodies[sphere_ids[0]].potential / (sol.potential[list(g.ids).index(sphere_ids[0])]),
           rebuilds_after_set=e.model.rebuilds, full_reads_after_set=e.reader.full_reads)
print(json.dumps(out))
'''

BREAK_BONDS = PACKING + r'''
e = make_engine(iterPeriod=1000, reader=Reader(move_tolerance=1e3, bond_check="flags"))   # every bond every call
e.step()
out = dict(R0=e.equivalent_resistance, I0=e.electrode_currents["top"], rev0=e.graph.revision, reads0=e.reader.full_reads,
           edges0=e.graph.n_edges)

# (1) erase one bond in the middle: detected at the next call, R_eq grows
zmid = 0.5 * (zmin + zmax)
crossing = [i for i in O.interactions if i.isReal and wall_id not in (i.id1, i.id2)
            and (O.bodies[i.id1].state.pos[2] - zmid) * (O.bodies[i.id2].state.pos[2] - zmid) < 0]
O.interactions.erase(crossing[0].id1, crossing[0].id2)
e.step()
out.update(R1=e.equivalent_resistance, rev1=e.graph.revision, reads1=e.reader.full_reads,
           edges1=e.graph.n_edges, R1_core=core_resistance(independent_graph()))

# (2) break every remaining bond crossing the mid-plane (cohesionBroken: the interactions stay
# real, the count of real interactions does not change): the rod is cut
for i in crossing[1:]:
    i.phys.cohesionBroken = True
e.step()
sol = e.solution
pots = [O.bodies[i].potential for i in sphere_ids]
above = [O.bodies[i].potential for i in sphere_ids if O.bodies[i].state.pos[2] > zmid]
below = [O.bodies[i].potential for i in sphere_ids if O.bodies[i].state.pos[2] < zmid]
out.update(n_crossing=len(crossing), R2=e.equivalent_resistance, rev2=e.graph.revision,
           reads2=e.reader.full_reads, edges2=e.graph.n_edges, currents2=e.electrode_currents,
           all_finite=bool(np.all(np.isfinite(sol.potential)) and np.all(np.isfinite(sol.branch_current))),
           above=[min(above), max(above)], below=[min(below), max(below)],
           n_floating=int(sol.floating.sum()))

# (3) nothing changed: no new read, no rebuild
rebuilds = e.model.rebuilds
e.step()
out.update(reads3=e.reader.full_reads, rebuilds_delta=e.model.rebuilds - rebuilds,
           R3=e.equivalent_resistance, history_R=e.history.column("R_eq").tolist(),
           history_rev=e.history.column("graph_revision").tolist())
print(json.dumps(out))
'''

NO_SPHERES = r'''
import json
from yade import pack, utils
from yade_electro.yade import ElectricalEngine, Electrode, Material
O.bodies.append(utils.wall(0, axis=2))
O.bodies.append(utils.box((0, 0, 1), (1, 1, 1)))
out = {}
try:
    ElectricalEngine(
        material=Material(resistivity=1e-6),
        boundaries=[
            Electrode("a", select=pack.inAlignedBox((-9, -9, -9), (9, 9, 9)), potential=1.0),
            Electrode("b", select=[1], potential=0.0)])
except Exception as exc:
    out["build"] = [type(exc).__name__, str(exc)]
print(json.dumps(out))
'''

SELECTS_NOTHING = r'''
import json
from yade import pack, utils
from yade_electro.yade import ElectricalEngine, Electrode, Material
for k in range(5):
    O.bodies.append(utils.sphere((0, 0, 2e-3 * k), 1e-3))
out = {}
try:
    # the scene has spheres already, so the engine checks its electrodes when it is built
    e = ElectricalEngine(
        material=Material(resistivity=1e-6),
        boundaries=[
            Electrode("top", select=pack.inAlignedBox((-1, -1, 5), (1, 1, 6)), potential=1.0),
            Electrode("bottom", select=pack.inAlignedBox((-1, -1, -1), (1, 1, 1e-4)), potential=0.0)])
    e.step()
except Exception as exc:
    out["step"] = [type(exc).__name__, [c.__name__ for c in type(exc).__mro__], str(exc)]
print(json.dumps(out))
'''


def run(run_yade_script, source):
    res = run_yade_script(source, timeout=TIMEOUT, check=True)
    assert res.result is not None, "no JSON line in the output:\n%s\n%s" % (res.stdout[-3000:], res.stderr[-3000:])
    return res


def test_engine_on_a_bonded_packing(run_yade_script, tmp_path):
    out = run(run_yade_script, RUN_AND_COMPARE).result
    assert 300 <= out["n_spheres"] <= 1000
    # the graph is the spheres and their cohesive bonds, the wall is left out cleanly
    assert out["n_nodes"] == out["ref_n_nodes"] == out["n_spheres"]
    assert out["n_edges"] == out["ref_n_edges"] > 2 * out["n_spheres"]
    assert out["same_ids"] and out["same_edges"]
    assert out["wall_interactions"] > 0
    assert out["ignored"] == {"Wall": 1}
    assert not out["wall_has_potential"]
    # R_eq as the core computes it on the same graph (engine: CG, core: direct)
    assert out["R_eq"] == pytest.approx(out["R_core"], rel=1e-8)
    assert 0 < out["R_eq"] < float("inf")
    # potentials written on the bodies; the top electrode at exactly 1 V
    assert out["max_abs_potential_diff"] == 0.0
    assert out["top_potentials"] == [1.0]
    # current conservation
    I_top, I_bottom = out["currents"]["top"], out["currents"]["bottom"]
    assert I_top == pytest.approx(1.0 / out["R_eq"], rel=1e-12)
    assert abs(I_top + I_bottom) <= 1e-9 * I_top
    # nothing changed during the run: one full read, one build, the second solve did no iteration
    assert out["full_reads"] == 1 and out["rebuilds"] == 1 and out["revision"] == 0
    # one read when the engine is built (to raise setup errors in the script), then one per call
    assert out["calls"] == out["history_len"] + 1 and out["history_len"] >= 2
    assert out["last_iterations"] == 0
    # the history CSV has one row per call (and one more for the set_electrode step below)
    rows = list(csv.DictReader(io.StringIO((tmp_path / "history.csv").read_text())))
    assert len(rows) == out["history_len"] + 1
    assert float(rows[-1]["V_top"]) == 2.0
    rows = rows[:-1]
    assert [float(r["R_eq"]) for r in rows] == [out["R_eq"]] * len(rows)
    assert all(int(r["graph_revision"]) == 0 and int(r["n_nodes"]) == out["n_nodes"] for r in rows)
    assert int(rows[-1]["iter"]) <= out["iter"]
    # set_electrode: the next solve uses the new value on the same problem
    assert out["V_top_after_set"] == 2.0
    assert out["R_after_set"] == pytest.approx(out["R_eq"], rel=1e-8)
    assert out["body0_ratio"] == pytest.approx(2.0, rel=1e-8)
    assert out["rebuilds_after_set"] == 1 and out["full_reads_after_set"] == 1


def test_breaking_bonds_is_detected(run_yade_script):
    out = run(run_yade_script, BREAK_BONDS).result
    assert 0 < out["R0"] < float("inf") and out["rev0"] == 0 and out["reads0"] == 1
    # one bond erased: a new read and revision at the next call, one edge less, R_eq up
    assert out["reads1"] == 2 and out["rev1"] == 1 and out["edges1"] == out["edges0"] - 1
    assert out["R1"] > out["R0"]
    assert out["R1"] == pytest.approx(out["R1_core"], rel=1e-8)
    # every crossing bond broken (flag only): detected, R_eq infinite, nothing NaN
    assert out["n_crossing"] > 10
    assert out["reads2"] == 3 and out["rev2"] == 2
    assert out["edges2"] == out["edges0"] - out["n_crossing"]
    assert out["R2"] == float("inf")
    # no current flows (CG, started from the previous solution: zero to its tolerance)
    assert all(abs(i) <= 1e-9 * out["I0"] for i in out["currents2"].values())
    assert out["all_finite"] and out["n_floating"] == 0
    # each half at its electrode's potential
    assert out["above"] == pytest.approx([1.0, 1.0], abs=1e-9)
    assert out["below"] == pytest.approx([0.0, 0.0], abs=1e-9)
    # and then nothing changes: no new read, no rebuild
    assert out["reads3"] == 3 and out["rebuilds_delta"] == 0 and out["R3"] == float("inf")
    assert out["history_rev"] == [0, 1, 2, 2]
    assert out["history_R"][:2] == [out["R0"], out["R1"]] and out["history_R"][2:] == [float("inf")] * 2


def test_scene_without_spheres_raises_graph_error(run_yade_script):
    """Refused when the engine is built, in the user's script, with the real exception."""
    res = run(run_yade_script, NO_SPHERES)
    name, message = res.result["build"]
    assert name == "GraphError"
    assert "no spherical bodies" in message and "add spheres" in message
    assert "'Wall': 1" in message and "'Box': 1" in message


def test_electrode_predicate_selecting_nothing(run_yade_script):
    res = run(run_yade_script, SELECTS_NOTHING)
    name, mro, message = res.result["step"]
    assert name == "BoundaryConditionError" and "ValueError" in mro
    assert "electrode 'top' selects no element" in message
    assert "selection is by element centre" in message
