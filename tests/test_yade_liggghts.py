"""Packings between YADE and LIGGGHTS in the real programs: a YADE scene written as a
LIGGGHTS data file that LIGGGHTS runs, and a packing settled in LIGGGHTS imported into YADE,
loose (YADE finds exactly LIGGGHTS' contacts) and bonded (a solid with cohesive bonds)."""
import pytest

pytestmark = pytest.mark.liggghts

SCENE_TO_LIGGGHTS = r'''
import json, sys
import numpy as np
from yade import utils
from yade_electro import liggghts as L
from yade_electro.yade.spheres import scene_particle_data
steel = O.materials.append(FrictMat(young=2e11, poisson=0.3, density=7800))
glass = O.materials.append(FrictMat(young=6e10, poisson=0.25, density=2500))
ids = O.bodies.append([utils.sphere((0, 0, 0), 1e-3, material=steel), utils.sphere((1.9e-3, 0, 0), 1e-3, material=glass),
                       utils.sphere((0, 1.95e-3, 0), 1e-3, material=steel)])
O.bodies.append(utils.wall(-1e-3, axis=2))                  # not a sphere: left out
data, mats = scene_particle_data()
mats_l = [L.GranularMaterial(young=m.young, poisson=m.poisson, density=m.density, conductivity=k, specific_heat=500.0)
          for m, k in zip(mats, (16.0, 1.0))]
deck = L.heat_conduction_deck(data, mats_l, 300.0, 1e-6, 100, 50, initial_temperature={1: 400.0})
res = L.run_heat_conduction(deck, sys.argv[1], progress=None)
back = L.read_data(res.run.workdir / "particles.data")
print(json.dumps({"ids": data.ids.tolist(), "types": data.types.tolist(), "density": data.density.tolist(),
                  "same_pos": bool(np.array_equal(back.positions, np.array([tuple(O.bodies[i].state.pos) for i in ids]))),
                  "contacts": len(res.contacts[0]), "T_end": res.temperatures[100]["Temp"].tolist()}))
'''


def test_yade_scene_to_a_liggghts_run(run_yade_script, liggghts_exe, tmp_path):
    r = run_yade_script(SCENE_TO_LIGGGHTS, str(tmp_path / "run"), check=True, timeout=300).result
    assert r["ids"] == [1, 2, 3] and r["types"] == [1, 2, 1] and r["density"] == [7800.0, 2500.0, 7800.0]
    assert r["same_pos"] and r["contacts"] == 2
    assert r["T_end"][0] < 400.0 and r["T_end"][1] > 300.0 and r["T_end"][2] > 300.0


LIGGGHTS_TO_YADE = r'''
import json, sys
import numpy as np
from yade_electro import liggghts as L
from yade_electro.geometry.shapes import Cylinder
from yade_electro.yade.spheres import add_spheres, bonded_packing
from yade_electro.yade.bonding import add_bonded_packing
R = 0.006
mat = L.GranularMaterial(young=5e6, poisson=0.3, density=2500.0)
p = L.settle_packing([L.CylinderWall("z", R), L.PlaneWall("z", 0.0)], L.CylinderRegion(R - 1e-3, 1e-3, 0.035), 150,
                     [0.6e-3, 0.8e-3], [0.5, 0.5], mat, [[-R - 1e-3, R + 1e-3]] * 2 + [[-1e-3, 0.04]], 2e-5, sys.argv[1],
                     settle_time=1.0, progress=None)
from yade import utils
ids = add_spheres(p.centers, p.radii, FrictMat(young=5e6, poisson=0.3, density=2500, frictionAngle=0.46))
floor = O.bodies.append(utils.wall(0.0, axis=2, sense=1))
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                             [Law2_ScGeom_FrictPhys_CundallStrack()]), NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.3)]
O.dt = 0.5 * utils.PWaveTimeStep()
O.step()
from yade_electro.packing.beds import contact_pairs
sphere_sphere = sum(1 for i in O.interactions if i.isReal and i.id1 in ids and i.id2 in ids)
loose = {"n": len(ids), "sphere_contacts": sphere_sphere, "overlapping_pairs": len(contact_pairs(p.centers, p.radii)),
         "floor_contacts": sum(1 for i in O.interactions if i.isReal and floor in (i.id1, i.id2)),
         "same_radii": bool(np.allclose([O.bodies[i].shape.radius for i in ids], p.radii, rtol=0, atol=0))}
O.reset()
top = float((p.centers[:, 2] + p.radii).max())
solid = bonded_packing(p.centers, p.radii, Cylinder((0, 0, 0), (0, 0, top), R))
bonded = add_bonded_packing(solid)
n_bonds = sum(1 for i in O.interactions if i.isReal and getattr(i.phys, "cohesionBroken", True) is False)
print(json.dumps({"loose": loose, "bonded_n": len(bonded),
                  "bonds": n_bonds, "phi": solid.volume_fraction}))
'''


def test_liggghts_packing_into_yade(run_yade_script, liggghts_exe, tmp_path):
    r = run_yade_script(LIGGGHTS_TO_YADE, str(tmp_path / "settle"), check=True, timeout=300).result
    loose = r["loose"]
    assert loose["n"] == 150 and loose["same_radii"] and loose["floor_contacts"] > 10
    assert loose["sphere_contacts"] == loose["overlapping_pairs"] > 150     # YADE finds LIGGGHTS' contacts
    assert r["bonded_n"] == 150 and r["bonds"] > 150 and 0.3 < r["phi"] < 0.7
