"""The finite-element reference (yade_electro.fem) against closed forms, and its convergence.

Coarse meshes only: the whole file runs in well under a minute on 2 cores. The finer
reference values quoted in docs/fem.md come from ``python3 -m yade_electro.fem``.
"""
import math

import numpy as np
import pytest

skfem = pytest.importorskip("skfem")

from yade_electro.core.errors import BoundaryConditionError, MaterialError, ThermalError  # noqa: E402
from yade_electro import fem  # noqa: E402
from yade_electro.fem import (STEEL_304L, box_mesh, coax_mesh, converged,  # noqa: E402
                              joule_heating, notched_bar, plate_potential, richardson, rod_mesh,
                              solve_potential, steady_temperature)

RHO = STEEL_304L.resistivity
LAM = STEEL_304L.conductivity
RHO_C = STEEL_304L.rho_c
T0 = 293.15


def _has_gmsh():
    try:
        import gmsh  # noqa: F401
    except ImportError:
        return False
    return True


needs_gmsh = pytest.mark.skipif(not _has_gmsh(), reason="gmsh Python API (python3-gmsh) missing")


def _order(h, err):
    return np.log(err[:-1] / err[1:]) / np.log(np.asarray(h[:-1]) / np.asarray(h[1:]))


# --------------------------------------------------------------------------- bar: exact
@pytest.mark.parametrize("order", [1, 2])
def test_bar_resistance_is_rho_L_over_A(order):
    lx, ly, lz = 10e-3, 2e-3, 1e-3
    sol = solve_potential(box_mesh(lx, ly, lz, 0.5e-3), RHO, {"end0": 1.0, "end1": 0.0},
                          order=order)
    r_th = fem.bar_resistance(RHO, lx, ly * lz)
    assert abs(sol.equivalent_resistance("end0", "end1") / r_th - 1) < 1e-10
    assert abs(sol.currents["end0"] + sol.currents["end1"]) < 1e-10 * sol.currents["end0"]
    assert abs(sol.joule_power() - 1.0 / r_th) < 1e-10 / r_th
    s, v = sol.profile((0, 1e-3, 0.5e-3), (lx, 1e-3, 0.5e-3), 11)
    assert np.allclose(v, 1.0 - s / lx, atol=1e-12)


def test_box_axis_and_imposed_current():
    sol = solve_potential(box_mesh(1e-3, 1e-3, 4e-3, n=(2, 2, 8), axis=2), RHO,
                          {"end1": 2.0, "end0": 0.0})
    assert abs(sol.equivalent_resistance("end1", "end0") / (RHO * 4e-3 / 1e-6) - 1) < 1e-10
    res = joule_heating(box_mesh(4e-3, 1e-3, 1e-3, 0.5e-3), RHO, LAM, RHO_C,
                        {"end1": 1.0, "end0": 0.0}, t_end=1e-3, dt=1e-3, current=100.0)
    r = RHO * 4e-3 / 1e-6
    assert np.allclose(res.current, 100.0) and np.allclose(res.voltage, 100.0 * r)


# --------------------------------------------------------------------------- rod: polygon
@needs_gmsh
def test_rod_resistance_converges_second_order():
    radius, length = 1e-3, 5e-3
    r_th = RHO * length / (math.pi * radius ** 2)
    hs = (0.4e-3, 0.2e-3, 0.1e-3)
    err = []
    for h in hs:
        mesh = rod_mesh(radius, length, h, layers=2)
        sol = solve_potential(mesh, RHO, {"end0": 1.0, "end1": 0.0})
        r_eq = sol.equivalent_resistance("end0", "end1")
        # exact for the meshed (polygonal) section: the only error is the polygon
        tri = mesh.p[:, mesh.facets[:, mesh.boundaries["end0"]]]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0],
                                             axis=0), axis=0).sum()
        assert abs(r_eq * area / (RHO * length) - 1) < 1e-10
        err.append(r_eq / r_th - 1)
    err = np.asarray(err)
    assert np.all(err > 0) and np.all(np.diff(err) < 0)
    p = _order(hs, err)
    assert np.all((p > 1.7) & (p < 2.4)), p
    assert err[-1] < 3e-3
    conv = fem.rod_reference(radius, length, hs=hs)["R_eq"]
    assert conv.monotone and abs(conv.extrapolated - r_th) < conv.gci
    assert abs(conv.extrapolated / r_th - 1) < 3e-4


# --------------------------------------------------------------------------- non-uniform fields
@needs_gmsh
def test_coax_resistance_converges():
    r1, r2, length = 1e-3, 3e-3, 1e-3
    r_th = fem.coax_resistance(RHO, r1, r2, length)
    hs = (0.4e-3, 0.2e-3, 0.1e-3)
    err = []
    for h in hs:
        sol = solve_potential(coax_mesh(r1, r2, length, h, layers=1), RHO,
                              {"inner": 1.0, "outer": 0.0}, order=2)
        err.append(abs(sol.equivalent_resistance("inner", "outer") / r_th - 1))
    p = _order(hs, np.asarray(err))
    assert np.all(p > 1.6), p
    assert err[-1] < 1.5e-3


def test_steady_joule_parabola_converges():
    length = 5e-3
    j = 1.0 / (RHO * length)
    x = np.linspace(0.0, length, 41)
    pts = np.vstack([x, np.full_like(x, 0.3e-3), np.full_like(x, 0.7e-3)])
    hs = (0.5e-3, 0.25e-3, 0.125e-3)
    err = []
    for h in hs:
        sol = solve_potential(box_mesh(length, 1e-3, 1e-3, h), RHO, {"end0": 1.0, "end1": 0.0})
        T = steady_temperature(sol, LAM, fixed_T={"end0": T0, "end1": T0})
        tp = fem.probe_matrix(sol.basis, pts) @ T
        err.append(np.max(np.abs(tp - fem.joule_parabola(x, length, j, RHO, LAM, T0))))
    p = _order(hs, np.asarray(err))
    assert np.all(p > 1.8), p
    rise = j * j * RHO * length ** 2 / (8 * LAM)
    assert err[-1] < 1e-3 * rise


# --------------------------------------------------------------------------- Joule heating
@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_adiabatic_joule_heating_of_a_bar_is_exact(theta):
    length = 5e-3
    res = joule_heating(box_mesh(length, 1e-3, 1e-3, 0.5e-3), RHO, LAM, RHO_C,
                        {"end1": 1.0, "end0": 0.0}, t_end=0.01, dt=1e-3, theta=theta, T0=T0,
                        probes=[[2.5e-3, 0.5e-3, 0.5e-3], [0.0, 0.0, 0.0], [length, 1e-3, 1e-3]])
    t_th = fem.adiabatic_joule_temperature(res.times, 1.0, length, RHO, RHO_C, T0)
    rise = t_th[-1] - T0
    assert np.max(np.abs(res.probe_temperatures - t_th[:, None])) < 1e-10 * rise
    assert abs(res.mean_temperatures[-1] - t_th[-1]) < 1e-10 * rise
    assert res.energy_balance_error < 1e-9
    assert abs(res.joule_energy / (0.01 / (RHO * length / 1e-6)) - 1) < 1e-10


def test_energy_balance_with_losses_and_temperature_dependent_rho():
    mesh = box_mesh(5e-3, 1e-3, 1e-3, 0.5e-3)
    res = joule_heating(mesh, RHO, LAM, RHO_C, {"end1": 1.0, "end0": 0.0}, t_end=0.01,
                        dt=1e-3, theta=0.5, T0=T0, beta=1e-3, fixed_T={"end0": T0},
                        convection={"surface": (1e4, 300.0)})
    assert res.energy_balance_error < 1e-9
    assert res.boundary_heat["end0"] < 0 and res.heat_gained > 0
    assert res.resistance[-1] > res.resistance[0]      # rho grows with T
    const = joule_heating(mesh, RHO, LAM, RHO_C, {"end1": 1.0, "end0": 0.0}, t_end=0.01,
                          dt=1e-3, T0=T0)
    assert res.joule_energy < const.joule_energy        # at fixed V, higher R -> less power


def test_rod_joule_heating_matches_theory():
    if not _has_gmsh():
        pytest.skip("gmsh missing")
    out = fem.rod_joule_heating(h=0.5e-3)
    assert abs(out["relative_error"]) < 1e-9       # polygon does not matter: uniform field
    assert out["energy_balance_error"] < 1e-9


# --------------------------------------------------------------------------- slab (paper 003)
def test_slab_transient_against_series():
    errs = [fem.slab_conduction(h=h)["max_error"] for h in (1e-3, 0.5e-3, 0.25e-3)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[-1] < 0.02          # K, for a 100 K step
    assert np.all(_order((1e-3, 0.5e-3, 0.25e-3), np.asarray(errs)) > 1.5)


# --------------------------------------------------------------------------- plate, notch
@needs_gmsh
def test_plate_builds_solves_and_converges():
    conv = fem.plate_reference(hs=(4e-3, 2e-3, 1e-3))
    for name, ref in (("mid", 0.39709), ("corner", 0.77017)):   # docs/fem.md, finer meshes
        c = conv[name]
        assert c.monotone and 1.5 < c.order < 2.5
        assert abs(c.extrapolated - ref) < 3e-4
        assert c.gci < 2e-3
    one = plate_potential(h=2e-3, order=1)
    assert abs(one["mid"] - 0.39709) < 2e-3 and 0 < one["mid"] < one["corner"] < 1


@needs_gmsh
def test_notched_bar_builds_solves_and_converges():
    conv = fem.notched_bar_reference(hs=(0.4e-3, 0.2e-3, 0.1e-3))
    r = conv["R_eq"]
    assert r.monotone and abs(r.extrapolated / 2.0987e-3 - 1) < 2e-3
    t = conv["T_notch_centre"]
    assert abs(t.extrapolated - 394.26) < 0.5
    out = notched_bar(h=0.4e-3)
    assert out["energy_balance_error"] < 1e-9
    assert out["V_profile"][0] < 0.05 and out["V_profile"][-1] > 0.95
    imid = len(out["x_bins"]) // 2      # x = L/2 is the edge between bins imid-1 and imid
    assert max(out["T_profile"][imid - 1:imid + 1]) == max(out["T_profile"])
    # the bar without notch would be 10 mm / (2 x 2 mm^2): the notch adds resistance
    assert out["R_eq"] > RHO * 10e-3 / 4e-6


@needs_gmsh
@pytest.mark.parametrize("kind,sides", [("v", "both"), ("circular", "one")])
def test_other_notches_build_and_solve(kind, sides):
    g = fem.NotchedBarGeometry(kind=kind, sides=sides)
    out = notched_bar(g, h=0.4e-3, nsteps=5)
    base = RHO * 10e-3 / 4e-6
    assert base < out["R_eq"] < 1.5 * base
    assert out["T_notch_centre"] > T0


# --------------------------------------------------------------------------- errors, helpers
def test_clear_errors():
    mesh = box_mesh(2e-3, 1e-3, 1e-3, 0.5e-3)
    with pytest.raises(BoundaryConditionError, match="unknown boundary 'nope'.*end0"):
        solve_potential(mesh, RHO, {"nope": 1.0})
    with pytest.raises(BoundaryConditionError, match="touch"):
        solve_potential(mesh, RHO, {"end0": 1.0, "y0": 0.0})
    with pytest.raises(MaterialError, match="positive"):
        solve_potential(mesh, -RHO, {"end0": 1.0, "end1": 0.0})
    with pytest.raises(fem.ProbeError, match="outside"):
        solve_potential(mesh, RHO, {"end0": 1.0, "end1": 0.0}).probe([5e-3, 0, 0])
    with pytest.raises(ThermalError, match="whole number"):
        joule_heating(mesh, RHO, LAM, RHO_C, {"end0": 1.0, "end1": 0.0}, t_end=1e-3, dt=3e-4)
    with pytest.raises(BoundaryConditionError, match="steady"):
        steady_temperature(solve_potential(mesh, RHO, {"end0": 1.0, "end1": 0.0}), LAM)
    with pytest.raises(fem.MeshError, match="ligament"):
        fem.NotchedBarGeometry(notch_depth=1e-3)
    with pytest.raises(ValueError, match="sequence of points"):
        solve_potential(mesh, RHO, {"end0": 1.0, "end1": 0.0}).probe(np.zeros((3, 4)))


def test_richardson_on_a_known_sequence():
    hs = np.array([0.4, 0.2, 0.1])
    c = richardson(hs, 1.0 + 3.0 * hs ** 2)
    assert abs(c.order - 2) < 1e-8 and abs(c.extrapolated - 1) < 1e-12
    assert abs(c.gci - 1.25 * 3 * (0.04 - 0.01) / 3) < 1e-12
    osc = richardson(hs, [1.5, 1.25, 1.3])
    assert not osc.monotone and osc.order == 2.0 and osc.gci == pytest.approx(0.05)
    two = converged(lambda h: {"a": 1 + h, "b": 2 - h * h}, hs)
    assert abs(two["a"].order - 1) < 1e-8 and abs(two["b"].extrapolated - 2) < 1e-12


@needs_gmsh
def test_cracked_bar_is_a_slit_and_approaches_the_closed_form_from_below():
    """The edge crack of the 2 x 2 x 8 mm bar: the slit conducts nothing (a crack through
    90 % of the width raises R far more), and the P1 increments (a lower bound of R: the
    FEM energy is above the true one at fixed potentials) rise towards Johnson's closed
    form 0.1103 as the mesh is refined."""
    exact = fem.edge_crack_increment(2e-3, 8e-3, 1e-3)
    assert exact == pytest.approx(4 * 2 / (math.pi * 8) * math.log(math.sqrt(2)), rel=1e-12)
    coarse = fem.cracked_bar(h=0.5e-3)["increment"]
    finer = fem.cracked_bar(h=0.35e-3)["increment"]
    assert 0.85 * exact < coarse < finer < exact
    deep = fem.cracked_bar(fem.CrackedBarGeometry(crack_depth=1.8e-3), h=0.5e-3)["increment"]
    assert deep > 5 * coarse
    with pytest.raises(ValueError, match="depth < width"):
        fem.edge_crack_increment(2e-3, 8e-3, 2e-3)
    with pytest.raises(fem.MeshError, match="inside the bar"):
        fem.CrackedBarGeometry(crack_depth=3e-3)


def test_thermoelastic_closed_forms():
    """fem.thermoelastic on a box: free expansion strain alpha dT with no stress, the bar held
    at both ends sigma = -E alpha dT, to round-off (P1 and P2)."""
    from yade_electro.fem.meshes import box_mesh
    from yade_electro.fem.thermoelastic import thermal_stress
    m = box_mesh(1e-3, 1e-3, 4e-3, 0.5e-3, axis=2)
    E, nu, a = 200e9, 0.3, 1.2e-5
    T = np.full(m.p.shape[1], 393.0)
    corner = int(np.argmin(np.sum(m.p ** 2, axis=0)))
    other = int(np.argmin((m.p[0] - 1e-3) ** 2 + m.p[1] ** 2 + m.p[2] ** 2))
    pins = ((corner, (0, 1)), (other, (1,)))
    for order in (1, 2):
        free = thermal_stress(m, T, 293.0, E, nu, a, {"end0": (2,)}, pins=pins, order=order)
        assert np.abs(free.stress).max() < 1e-9 * E * a * 100
        np.testing.assert_allclose(free.displacement_at([[0.5e-3, 0.5e-3, 4e-3]])[0, 2], 4e-3 * a * 100, rtol=1e-9)
        held = thermal_stress(m, T, 293.0, E, nu, a, {"end0": (2,), "end1": (2,)}, pins=pins, order=order)
        np.testing.assert_allclose(held.stress[:, 2, 2], -E * a * 100, rtol=1e-9)
        assert held.mean_stress_where(np.ones(held.stress.shape[0], bool))[0, 0] == pytest.approx(0, abs=1e-6 * E * a)
    with pytest.raises(Exception, match="nu"):
        thermal_stress(m, T, 293.0, E, 0.5, a, {"end0": (2,)})
