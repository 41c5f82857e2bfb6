"""Resolved grains at any pose (numpy, scikit-fem and gmsh; no YADE): paper 003's two particles
as two posed copies of one grain template, pressed together, against the finite-element answer."""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases"))

from yade_electro.network.grains import grain_contact, grain_network, rigid_pose  # noqa: E402
from yade_electro.packing.grains import grain_template  # noqa: E402
from yade_electro.network.transient import HeatSolver  # noqa: E402


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def test_rigid_pose_recovers_the_motion():
    x = np.random.default_rng(1).normal(size=(50, 3))
    R, t = rotation((1, -2, 0.5), 1.1), np.array([0.3, -1.0, 2.0])
    R2, t2 = rigid_pose(x, x @ R.T + t)
    assert np.allclose(R2, R, atol=1e-12) and np.allclose(t2, t, atol=1e-12)


def test_two_posed_grains_follow_the_finite_element_answer():
    pytest.importorskip("gmsh")
    import two_grains as tg
    from yade_electro.fem.two_discs import two_discs_transient
    from yade_electro.geometry.shapes import Box, Cylinder, Intersection
    g = tg.geometry()
    shape = Intersection(Cylinder((0, 0, 0), (0, 0, g.w), g.r),
                         Box((-2 * g.r, -2 * g.r, -g.w), (0.5 * g.d, 2 * g.r, 2 * g.w)))
    tmpl = grain_template(shape, 1000, seed=1)
    flip = np.diag([-1.0, -1.0, 1.0])                 # B: A turned half round about z, its chord facing A's
    delta = 0.02 * tmpl.radii.mean()                  # pressed together by 2 % of a radius
    tau, t = tg.times(g)
    fem = two_discs_transient(g, tg.K_LOW, tg.RHO_C, tg.R_C, tg.T_A0, tg.T_B0, t, h=0.025, dt=tau / 100)["mean_B"]
    results = []
    for Q in (np.eye(3), rotation((1, 2, 3), 0.7)):  # the pair as built, and turned as a whole
        poses = [(Q, np.zeros(3)), (Q @ flip, Q @ np.array([g.d - delta, 0, 0]))]
        e, G, C, first, contacts = grain_network([tmpl, tmpl], poses, tg.K_LOW, tg.RHO_C, tg.R_C)
        assert list(contacts) == [(0, 1)] and contacts[(0, 1)] == pytest.approx(g.contact_area, rel=0.02)
        heat = HeatSolver(C, e, G, np.repeat([tg.T_A0, tg.T_B0], tmpl.n), theta="backward-euler", solver="direct")
        mean_B = []
        for tn in t:
            while heat.time < tn - 1e-9 * tn:
                heat.advance(min((t[1] - t[0]) / 10, tn - heat.time))
            mean_B.append(C[tmpl.n:] @ heat.temperature[tmpl.n:] / C[tmpl.n:].sum())
        results.append(np.array(mean_B))
        assert tg.error_pct(mean_B, fem) < 1.0
    assert np.max(np.abs(results[0] - results[1])) < 0.2          # K: the same physics at any pose
    # moved apart, they no longer touch
    far = grain_contact(tmpl, (np.eye(3), np.zeros(3)), tmpl, (flip, np.array([g.d + 0.01, 0, 0])), tg.R_C, 1.0)
    assert far[0].shape == (0, 2) and far[2] == 0.0
