"""The slab case (cases/slab_transient.py, paper 003's 1D slab) and the bounded Voronoi cell
volumes it and the Joule rod use. Pure core (no YADE), a few seconds.

Stated bounds (20 free layers, h = L / 20.5; errors are max |T - T_exact| / |T_D - T_i| over
the free elements at Fo = 0.05 ... 1; measured values in brackets):
* the lattice is the exact cell-centred finite-volume scheme: cells h^3, conductances lambda h
  (to 1e-12);
* semi-discrete (exact in time) < 1e-3 (6.5e-4); explicit at its bound and sub-cycled < 2e-3
  (1.45e-3); Crank-Nicolson at 1x and 10x < 1.5e-3 (9.1e-4); backward Euler 1x < 2.5e-3
  (1.8e-3), 100x < 0.15 (0.12);
* Crank-Nicolson at 100x stays bounded (error < 0.1 at Fo = 1) but overshoots; backward Euler
  never leaves [T_i, T_D];
* the explicit limit: the HeatSolver bound min C/sum G is within 1 % below the true 2 /
  lambda_max, paper 000's l^2/(2 alpha) is 2x the true limit; forward Euler decays at 0.98x
  and grows at 1.02x; the HeatSolver refuses a step above its bound without sub-cycling.
"""
import json
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "cases"))
import slab_transient as slab  # noqa: E402

from yade_electro.core.errors import ThermalError  # noqa: E402
from yade_electro.geometry.voronoi import cell_volume_of, voronoi_cell_volumes  # noqa: E402
from yade_electro.geometry.shapes import Box, Cylinder  # noqa: E402


# --------------------------------------------------------------------------- cell volumes
def test_cell_volumes_cubic_lattice_in_box():
    r = 0.5e-3
    shape = (4, 3, 5)
    ijk = np.stack(np.meshgrid(*(np.arange(k) for k in shape), indexing="ij"), -1).reshape(-1, 3)
    pos = (ijk + 0.5) * 2 * r
    box = Box((0, 0, 0), tuple(2 * r * np.array(shape)))
    v, info = voronoi_cell_volumes(pos, np.full(len(pos), r), box, return_info=True)
    np.testing.assert_allclose(v, (2 * r) ** 3, rtol=1e-12)
    assert info["n_clipped"] > 0 and abs(info["relative_excess"]) < 1e-12


def test_cell_volumes_fill_the_container():
    rng = np.random.default_rng(3)
    box = Box((0, 0, 0), (2e-3, 1e-3, 3e-3))
    p = rng.uniform(0, 1, (400, 3)) * [2e-3, 1e-3, 3e-3]
    v, info = voronoi_cell_volumes(p, np.full(len(p), 0.1e-3), box, return_info=True)
    assert np.all(v > 0) and abs(info["relative_excess"]) < 1e-6
    # curved wall: cells bounded by tangent planes, the solid they leave out integrated over
    # them: the volumes fill the cylinder to a few 1e-6 (random points, 800 cells)
    cyl = Cylinder((0, 0, 0), (0, 0, 2e-3), 1e-3)
    q = rng.uniform(-1, 1, (3000, 3)) * [1e-3, 1e-3, 1e-3] + [0, 0, 1e-3]
    q = q[cyl.sdf(q) < -0.02e-3][:800]
    v, info = voronoi_cell_volumes(q, np.full(len(q), 0.05e-3), cyl, return_info=True)
    assert np.all(v > 0) and abs(info["relative_excess"]) < 1e-5, info


def test_cell_volume_of_is_cached_per_element_set():
    graph = slab.SlabModel(4).graph
    f = cell_volume_of(Box((0, 0, 0), (5 * graph.radius[0] * 2, 4 * graph.radius[0], 4 * graph.radius[0])))
    a = f(graph)
    assert f(graph) is a and a.shape == (graph.n_nodes,)


def test_cell_volumes_need_a_container():
    with pytest.raises(ValueError, match="container"):
        voronoi_cell_volumes(np.zeros((4, 3)), np.ones(4), None)


# --------------------------------------------------------------------------- the slab case
@pytest.fixture(scope="module")
def model():
    return slab.SlabModel(20)


def test_lattice_is_the_finite_volume_scheme(model):
    assert model.fv_exact < 1e-12
    assert model.graph.n_nodes == 21 * 4 and model.fixed.sum() == 4
    assert np.allclose(model.x[model.fixed], slab.LENGTH)


def test_analytic_series_limits(model):
    assert np.max(np.abs(model.exact(1e-3) - slab.T_INITIAL)[model.x[~model.fixed] < 0.5]) < 1e-9
    assert np.max(np.abs(model.exact(20.0) - slab.T_WALL)) < 1e-12


def test_semi_discrete_error(model):
    err = slab.semi_discrete(model)
    assert max(err.values()) < 1e-3


@pytest.mark.parametrize("theta, ratio, subcycle, bound", [
    (0.0, 1.0, False, 2e-3), (0.0, 100.0, True, 2e-3), (0.5, 1.0, False, 1.5e-3), (0.5, 10.0, False, 1.5e-3),
    (1.0, 1.0, False, 2.5e-3), (1.0, 100.0, False, 0.15)])
def test_integrator_errors(model, theta, ratio, subcycle, bound):
    err, info = slab.run_integrator(model, theta, ratio, subcycle=subcycle)
    assert max(err.values()) < bound, err
    if theta == 1.0:
        assert info["overshoot"] <= 1e-12          # backward Euler keeps the maximum principle


def test_crank_nicolson_far_above_the_limit_is_bounded_but_overshoots(model):
    err, info = slab.run_integrator(model, 0.5, 100.0)
    assert err[1.0] < 0.1 and info["overshoot"] > 0.01


def test_explicit_limits_and_guard(model):
    lim = model.limits()
    assert lim["bound"] <= lim["true"] < 1.01 * lim["bound"]
    assert lim["paper"] / lim["true"] > 1.9             # paper 000 eq. 14 is 2x too long here
    heat = model.solver(0.0, subcycle=False, safety=1.0)
    heat.advance(0.99 * lim["bound"])
    with pytest.raises(ThermalError, match="above the stable step"):
        heat.advance(1.01 * lim["bound"])


def test_forward_euler_decays_below_and_grows_above_the_true_limit(model):
    true = model.limits()["true"]
    below = slab.forward_euler_growth(model, 0.98 * true, n_steps=1500)
    above = slab.forward_euler_growth(model, 1.02 * true, n_steps=1500)
    assert below[-1] < 1e-3
    assert above[-1] > 1.0 or not np.isfinite(above[-1])


def test_main_writes_files_and_json(tmp_path, capsys):
    summary = slab.main(["--layers", "10", "--steps", "400", "--out", str(tmp_path)])
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert json.loads(line)["case"] == "slab_transient" == summary["case"]
    for name in ("slab_transient.csv", "slab_transient_stability.csv", "slab_transient.png"):
        assert (tmp_path / name).stat().st_size > 0
    rows = (tmp_path / "slab_transient.csv").read_text().splitlines()
    assert len(rows) == 1 + 1 + len(slab.INTEGRATORS)
