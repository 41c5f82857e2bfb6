"""Script text shared by the tests that run YADE scripts (``run_yade_script``)."""

#: a bonded rod in a fresh scene: ``rod`` (R = 0.5 mm, L = 2 mm, the container) and ``build()``,
#: which resets the scene and bonds 400 elements of ``dense_packing`` (seed 3) with YADE's
#: integrator dead; ``P`` is ``yade_electro.yade.packing``
BONDED_ROD = r'''
from yade_electro.yade import packing as P
L, RAD = 2e-3, 0.5e-3
rod = P.Cylinder((0, 0, 0), (0, 0, L), RAD)
def build():
    O.reset()
    P.add_bonded_packing(P.dense_packing(rod, n=400, seed=3))
    for e in O.engines:
        if type(e).__name__ == "NewtonIntegrator":
            e.dead = True
'''
