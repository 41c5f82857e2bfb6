"""Probes (yade_electro.post.probes): exact for linear fields, documented bias for curved ones."""
import numpy as np
import pytest

from yade_electro.post.probes import (ProbeError, element_gradients, line_probe, plane_probe, probe, region_mean,
                                 section_mean, slab_means)


def _cloud(n=4000, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1, size=(n, 3))


def test_a_linear_field_is_probed_exactly_anywhere():
    pos = _cloud()
    g = np.array([0.3, -1.2, 2.0])
    v = 5.0 + pos @ g
    pts = np.array([[0.5, 0.5, 0.5], [0.02, 0.5, 0.98], [0.0, 0.0, 0.0]])     # inside, at a wall, a corner
    out = probe(pos, v, pts, radius=0.25)
    np.testing.assert_allclose(out.value, 5.0 + pts @ g, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out.gradient, np.broadcast_to(g, (3, 3)), atol=1e-10)
    assert np.all(out.n_used >= 6) and np.all(out.residual < 1e-12)
    # a vector field (two components) and the fit along an axis (no variation along z)
    vv = np.column_stack([v, 2 * v])
    two = probe(pos, vv, pts[:1], radius=0.15)
    np.testing.assert_allclose(two.value[0], [5 + pts[0] @ g, 2 * (5 + pts[0] @ g)], atol=1e-12)
    flat = 1.0 + pos[:, 0] - pos[:, 1]
    ax = probe(pos, flat, [0.5, 0.5, 0.1], radius=0.05, axis=(0, 0, 1))
    assert ax.value[0] == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(ax.gradient[0], [1, -1, 0], atol=1e-10)


def test_a_curved_field_is_biased_as_the_radius_squared_at_a_wall():
    """v = x^2 probed at the wall x = 0 (exact 0) and inside: both biases scale as r^2."""
    pos = _cloud(20000, 1)
    v = pos[:, 0] ** 2
    bias = [float(probe(pos, v, [0.0, 0.5, 0.5], radius=r).value[0]) for r in (0.1, 0.2)]
    assert bias[0] < 0 and bias[1] < 0
    assert bias[1] / bias[0] == pytest.approx(4.0, rel=0.25)
    # inside, the fit is the mean over the ball: v + v'' r^2 / 10 = 0.25 + 0.2^2 / 5
    inside = float(probe(pos, v, [0.5, 0.5, 0.5], radius=0.2).value[0])
    assert inside - 0.25 == pytest.approx(0.2 ** 2 / 5, rel=0.15)


def test_lines_planes_and_means():
    pos = _cloud()
    v = pos[:, 2]
    s, out = line_probe(pos, v, (0.5, 0.5, 0.1), (0.5, 0.5, 0.9), 5, radius=0.15)
    np.testing.assert_allclose(s, np.linspace(0, 0.8, 5))
    np.testing.assert_allclose(out.value, np.linspace(0.1, 0.9, 5), atol=1e-12)
    grid, pl = plane_probe(pos, v, (0.2, 0.2, 0.5), (0.6, 0, 0), (0, 0.6, 0), (3, 4), radius=0.15)
    assert grid.shape == (3, 4, 3)
    np.testing.assert_allclose(pl.value, 0.5, atol=1e-12)
    w = np.ones(len(v))
    assert section_mean(pos, v, (0, 0, 0.5), (0, 0, 1), 0.1, w) == pytest.approx(0.5, abs=0.01)
    assert region_mean(v, w, pos[:, 2] < 0.5) == pytest.approx(0.25, abs=0.02)
    c, means = slab_means(pos, v, (0, 0, 1), np.linspace(0, 1, 11), w)
    np.testing.assert_allclose(means, c, atol=0.01)
    g = element_gradients(pos, np.array([[i, j] for i in range(50) for j in range(50, 60)]), 2 * pos[:, 0])
    np.testing.assert_allclose(g[:60], np.broadcast_to([2, 0, 0], (60, 3)), atol=1e-9)


def test_bad_probes_say_what_to_do():
    pos = _cloud(200)
    with pytest.raises(ProbeError, match="increase radius"):
        probe(pos, pos[:, 0], [0.5, 0.5, 0.5], radius=0.01)
    with pytest.raises(ProbeError, match="outside the packing"):
        probe(pos, pos[:, 0], [5.0, 5.0, 5.0], radius=0.1)
    with pytest.raises(ProbeError, match="one row per element"):
        probe(pos, np.ones(3), [0.5, 0.5, 0.5], radius=0.1)
    with pytest.raises(ProbeError, match="no element"):
        region_mean(pos[:, 0], None, pos[:, 0] > 2)
