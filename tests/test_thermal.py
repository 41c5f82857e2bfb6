"""Heat capacities, Joule sources, thermal boundary conditions, the theta integrators and the
electro-thermal coupling, checked against exact answers:

* energy conservation (adiabatic Joule heating: heat gained = Joule energy);
* two equal elements: the discrete decay factors of forward Euler, Crank-Nicolson and
  backward Euler, and the continuous exp(-2 G t / C);
* linear steady state of a conducting chain between two fixed temperatures;
* stability: backward Euler at 100x the explicit limit, explicit at 1.01x (raise or sub-cycle);
* uniform Joule heating of a lattice bar: dT = P t / sum C;
* convection of a single element: exponential cooling at rate h A / C;
* rho_e(T): the single-resistor ODE at fixed voltage and at fixed current;
* bad input and non-finite values (ThermalError, state preserved).
"""
import math
import warnings

import numpy as np
import pytest

from yade_electro import ContactGraph, MaterialError, ThermalError, solve_potential
from yade_electro.laws.factors import conductance
from yade_electro import Material
from yade_electro.physics.coupled import ElectroThermalModel
from yade_electro.physics.integrator import Integrator
from yade_electro.physics.electrical import ElectricalModel
from yade_electro.core.history import History
from yade_electro.core.errors import BoundaryConditionError
from yade_electro.network.kirchhoff import Electrode
from yade_electro.laws.transmission import edge_transmission_surface, volume_fraction
from yade_electro.network.heat_conditions import Convection, FixedTemperature, HeatFlux
from yade_electro.network.transient import HeatSolver
from yade_electro.laws.transmission import exposed_area
from yade_electro.network.theta import theta_of
from yade_electro.physics.thermal import (diffusion_time_step, edge_joule_power, electrical_power, heat_capacity,
                                          heat_solver_on_graph, joule_sources, thermal_conductance)
from yade_electro.network.theta import stable_time_step

from lattice import cubic_lattice, end_selectors, node_class

# 304L steel (paper 000, table II)
R, RHO_E = 0.5e-3, 0.73e-6
DENSITY, SPECIFIC_HEAT, LAMBDA = 7900.0, 500.0, 15.0
SHAPE = (3, 3, 8)
Z_TOP = 2 * R * (SHAPE[2] - 1)

bottom, top = end_selectors(SHAPE, R)


def rod():
    return cubic_lattice(SHAPE, r=R)


def electrical(potential=1e-3, current=None, beta_graph=None, **kw):
    a = dict(select=top, potential=potential) if current is None else dict(select=top, current=current)
    return ElectricalModel(RHO_E, {"top": a, "bottom": dict(select=bottom, potential=0.0)}, solver="direct", **kw)


def chain(n, G=2.0, C=3.0):
    """A chain of n nodes with uniform conductance G [W/K] and capacity C [J/K]."""
    edges = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    return np.full(n, C), edges, np.full(n - 1, G)


def pair(r=R, rho0=RHO_E):
    """Two bonded elements (one resistor)."""
    return ContactGraph([[0, 0, 0], [2 * r, 0, 0]], [r, r], [[0, 1]])


# ---------------------------------------------------------------------------------------------
# building blocks
# ---------------------------------------------------------------------------------------------
def test_heat_capacity_is_eq13_and_options():
    g = rod()
    C = heat_capacity(g, DENSITY, SPECIFIC_HEAT)
    np.testing.assert_allclose(C, DENSITY * SPECIFIC_HEAT * 4 / 3 * np.pi * R ** 3 / volume_fraction(g), rtol=1e-14)
    # interior element: the cube of side 2r (fv(6) = pi/6)
    interior = np.flatnonzero(node_class(SHAPE) == 0)
    np.testing.assert_allclose(C[interior], DENSITY * SPECIFIC_HEAT * (2 * R) ** 3, rtol=1e-12)
    np.testing.assert_allclose(heat_capacity(g, DENSITY, SPECIFIC_HEAT, volume_fraction=1.0),
                               DENSITY * SPECIFIC_HEAT * g.volume, rtol=1e-14)
    cells = np.full(g.n_nodes, 8 * R ** 3)
    np.testing.assert_allclose(heat_capacity(g, DENSITY, SPECIFIC_HEAT, cell_volume=cells),
                               DENSITY * SPECIFIC_HEAT * cells, rtol=1e-14)
    with pytest.raises(ValueError):
        heat_capacity(g, DENSITY, SPECIFIC_HEAT, volume_fraction=1.0, cell_volume=cells)


@pytest.mark.parametrize("bad", [dict(density=0.0), dict(density=-1.0), dict(specific_heat=0.0),
                                 dict(specific_heat=np.nan), dict(cell_volume="neg")])
def test_heat_capacity_rejects_non_positive(bad):
    g = rod()
    kw = dict(density=DENSITY, specific_heat=SPECIFIC_HEAT)
    kw.update(bad)
    if kw.get("cell_volume") == "neg":
        kw["cell_volume"] = -np.ones(g.n_nodes)
    with pytest.raises(MaterialError):
        heat_capacity(g, **kw)


def test_thermal_conductance_is_eq16_and_rejects_bad_conductivity():
    g = rod()
    G = thermal_conductance(g, LAMBDA)
    np.testing.assert_allclose(G, LAMBDA * edge_transmission_surface(g) / g.length, rtol=1e-14)
    np.testing.assert_allclose(G, conductance(g, 1.0 / LAMBDA), rtol=1e-14)
    for bad in (0.0, -15.0, np.inf, np.nan):
        with pytest.raises(MaterialError, match="conductivity"):
            thermal_conductance(g, bad)


def test_joule_sources_split_and_total_equals_electrode_power():
    # one resistor: each end gets half of eta V^2 / R
    p = joule_sources([[0, 1]], [2.0], [4.0], 2, eta=0.5)
    np.testing.assert_allclose(p, [0.25, 0.25], rtol=1e-15)
    g = rod()
    c = conductance(g, RHO_E)
    sol = solve_potential(g.n_nodes, g.edges, c,
                          [Electrode("top", np.flatnonzero(top(g.pos, None)), potential=0.3),
                           Electrode("bottom", np.flatnonzero(bottom(g.pos, None)), potential=-0.2)], solver="direct")
    for eta in (1.0, 0.7):
        q = joule_sources(g.edges, sol.branch_current, c, g.n_nodes, eta)
        assert q.sum() == pytest.approx(eta * electrical_power(sol), rel=1e-9)
        assert q.sum() == pytest.approx(eta * 0.5 ** 2 / sol.equivalent_resistance("top", "bottom"), rel=1e-9)
    with pytest.raises(ValueError, match="eta"):
        edge_joule_power([1.0], [1.0], eta=1.5)


def test_exposed_area_default_and_time_step_figures():
    g = rod()
    a = exposed_area(g)
    cls = node_class(SHAPE)
    np.testing.assert_allclose(a[cls >= 2], np.pi * R ** 2)     # lattice edges and corners (e > 0.4)
    np.testing.assert_array_equal(a[cls <= 1], 0.0)             # faces (e = 0.4) and interior
    C = heat_capacity(g, DENSITY, SPECIFIC_HEAT)
    G = thermal_conductance(g, LAMBDA)
    dtc = stable_time_step(C, g.edges, G)
    diag = np.bincount(g.edges[:, 0], G, g.n_nodes) + np.bincount(g.edges[:, 1], G, g.n_nodes)
    assert dtc == pytest.approx(np.min(C / diag), rel=1e-14)
    assert diffusion_time_step(g, LAMBDA, DENSITY, SPECIFIC_HEAT) == pytest.approx(
        (2 * R) ** 2 / (2 * LAMBDA / (DENSITY * SPECIFIC_HEAT)), rel=1e-12)
    assert theta_of("crank-nicolson") == 0.5 and theta_of(1) == 1.0
    with pytest.raises(ValueError):
        theta_of(1.5)
    with pytest.raises(ValueError):
        theta_of("leapfrog")


# ---------------------------------------------------------------------------------------------
# energy conservation
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", ["explicit", 0.25, "crank-nicolson", "backward-euler"])
def test_adiabatic_joule_energy_equals_heat_gained(theta):
    g = rod()
    C = heat_capacity(g, DENSITY, SPECIFIC_HEAT)
    G = thermal_conductance(g, LAMBDA)
    c = conductance(g, RHO_E)
    sol = solve_potential(g.n_nodes, g.edges, c,
                          [Electrode("top", np.flatnonzero(top(g.pos, None)), potential=1e-3),
                           Electrode("bottom", np.flatnonzero(bottom(g.pos, None)), potential=0.0)], solver="direct")
    q = joule_sources(g.edges, sol.branch_current, c, g.n_nodes)
    T0 = 293.15 + np.linspace(0.0, 5.0, g.n_nodes)       # not uniform: conduction acts too
    hs = HeatSolver(C, g.edges, G, T0, theta=theta)
    dt = 7.3 * hs.critical_time_step                      # sub-cycled when explicit
    joule = 0.0
    for k in range(12):
        step = hs.advance(dt, q)
        joule += q.sum() * dt
        assert step.balance_error < 1e-9
    gained = np.sum(C * (hs.temperature - T0))
    assert gained == pytest.approx(joule, rel=1e-9)
    assert hs.energy["source"] == pytest.approx(joule, rel=1e-12)
    assert hs.time == pytest.approx(12 * dt, rel=1e-14)
    if theta_of(theta) < 0.5:
        assert step.n_substeps == math.ceil(dt / hs.allowed_time_step()) > 1


def test_energy_balance_with_every_boundary_condition():
    C, edges, G = chain(12)
    n = C.size
    for theta in (0.0, 0.5, 1.0):
        hs = HeatSolver(C, edges, G, 300.0, theta=theta,
                        conditions=[FixedTemperature("cold", [0], 280.0), HeatFlux("heater", [5, 6], power=3.0), HeatFlux("sun", [9], flux=100.0, area=0.01), Convection("air", np.arange(7, 12), h=20.0, t_inf=310.0, area=0.05)])
        src = np.linspace(0.0, 1.0, n)
        T_start = hs.temperature
        for _ in range(7):
            step = hs.advance(2.5, src)
            assert step.balance_error < 1e-9
        e = hs.energy
        gained = np.sum(C * (hs.temperature - T_start))
        assert gained == pytest.approx(e["source"] + e["flux"] + e["convection"] + e["boundary"], rel=1e-10)
        assert e["flux"] == pytest.approx((3.0 + 100.0 * 0.01) * 7 * 2.5, rel=1e-14)
        assert e["absorbed"] == pytest.approx(src[0] * 7 * 2.5, rel=1e-14)
        assert hs.temperature[0] == 280.0


# ---------------------------------------------------------------------------------------------
# two equal elements
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta, factor", [
    (0.0, lambda a: 1 - 2 * a),
    (0.5, lambda a: (1 - a) / (1 + a)),
    (1.0, lambda a: 1 / (1 + 2 * a)),
])
def test_two_elements_discrete_decay(theta, factor):
    C, G = 5.0, 2.0
    hs = HeatSolver([C, C], [[0, 1]], [G], [400.0, 300.0], theta=theta)
    assert hs.critical_time_step == pytest.approx(C / G)
    dt = 0.4 * C / G
    a = G * dt / C
    for n in range(1, 31):
        hs.advance(dt)
        T = hs.temperature
        assert T.mean() == pytest.approx(350.0, rel=1e-14)
        assert T[0] - T[1] == pytest.approx(100.0 * factor(a) ** n, rel=1e-9, abs=1e-11)
        assert hs.steps == n and hs.substeps == n


def test_two_elements_converge_to_exponential():
    C, G = 5.0, 2.0
    t_end = 2.0
    hs = HeatSolver([C, C], [[0, 1]], [G], [400.0, 300.0], theta="crank-nicolson")
    for _ in range(2000):
        hs.advance(t_end / 2000)
    T = hs.temperature
    assert T[0] - T[1] == pytest.approx(100.0 * math.exp(-2 * G * t_end / C), rel=1e-6)
    assert T[0] + T[1] == pytest.approx(700.0, rel=1e-12)


# ---------------------------------------------------------------------------------------------
# steady state and stability
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("solver", ["direct", "cg"])
def test_chain_steady_state_is_linear(solver):
    n = 21
    C, edges, G = chain(n)
    hs = HeatSolver(C, edges, G, 300.0, theta=1.0, solver=solver,
                    conditions=[FixedTemperature("hot", [0], 400.0), FixedTemperature("cold", [n - 1], 300.0)])
    for _ in range(3):
        hs.advance(1e16)
    np.testing.assert_allclose(hs.temperature, np.linspace(400.0, 300.0, n), rtol=0, atol=1e-10)
    # steady: heat in at the hot end = heat out at the cold end
    step = hs.advance(1.0)
    assert abs(step.boundary_energy) < 1e-9 * G[0] * 100.0 / (n - 1)


def test_lattice_bar_steady_state_is_linear():
    g = rod()
    z = g.pos[:, 2]
    hs = HeatSolver(np.ones(g.n_nodes), g.edges, np.full(g.n_edges, 0.3), 300.0, theta=1.0, graph=g,
                    conditions=[FixedTemperature("hot", top, 500.0), FixedTemperature("cold", bottom, 300.0)])
    for _ in range(3):
        hs.advance(1e16)
    np.testing.assert_allclose(hs.temperature, 300.0 + 200.0 * z / Z_TOP, rtol=0, atol=1e-10)


def test_backward_euler_stable_at_100x_explicit_limit():
    n = 15
    C, edges, G = chain(n)
    hs = HeatSolver(C, edges, G, 300.0, theta="backward-euler",
                    conditions=[FixedTemperature("hot", [0], 400.0), FixedTemperature("warm", [n - 1], 350.0)])
    dt = 100 * hs.critical_time_step
    prev = hs.temperature
    for _ in range(60):
        step = hs.advance(dt)
        T = hs.temperature
        assert step.n_substeps == 1
        assert np.all(T >= 300.0 - 1e-12) and np.all(T <= 400.0 + 1e-12)
        assert np.all(T >= prev - 1e-12)       # heated from 300 K: no node ever cools (no oscillation)
        prev = T
    np.testing.assert_allclose(T, np.linspace(400.0, 350.0, n), atol=1e-6)


def test_explicit_above_limit_raises_without_subcycling():
    C, G = 5.0, 2.0
    hs = HeatSolver([C, C], [[0, 1]], [G], [400.0, 300.0], theta="explicit", subcycle=False, safety=1.0)
    dt = 1.01 * hs.critical_time_step
    with pytest.raises(ThermalError, match="stable step"):
        hs.advance(dt)
    np.testing.assert_array_equal(hs.temperature, [400.0, 300.0])
    assert hs.time == 0.0 and hs.steps == 0
    hs.advance(0.99 * hs.critical_time_step)            # below the limit: fine


def test_explicit_above_limit_subcycles():
    C, G = 5.0, 2.0
    hs = HeatSolver([C, C], [[0, 1]], [G], [400.0, 300.0], theta="explicit", safety=1.0)
    dt = 1.01 * hs.critical_time_step
    for n in range(1, 21):
        step = hs.advance(dt)
        assert step.n_substeps == 2
        a = G * (dt / 2) / C
        d = hs.temperature[0] - hs.temperature[1]
        assert d == pytest.approx(100.0 * (1 - 2 * a) ** (2 * n), rel=1e-9, abs=1e-11)
        assert 0 <= d < 100.0
    # without sub-cycling the factor would be 1 - 2.02 = -1.02: growing oscillation
    assert abs(1 - 2 * G * dt / C) > 1


# ---------------------------------------------------------------------------------------------
# uniform Joule heating, convection
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", ["explicit", "backward-euler"])
def test_adiabatic_joule_heating_of_a_bar(theta, tmp_path):
    g = rod()
    V = 1e-3
    hist = History(str(tmp_path / "h.csv"))
    m = ElectroThermalModel(electrical(potential=V),
                            Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA), 293.15,
                            integrator=Integrator(theta=theta), history=hist)
    dt = 2e-3
    for _ in range(10):
        row = m.step(g, dt)
    C = m.heat.capacity
    P = V ** 2 / row["R_eq"]
    t = 10 * dt
    assert row["time"] == pytest.approx(t, rel=1e-14)
    assert row["joule_power"] == pytest.approx(P, rel=1e-9)
    assert row["joule_energy"] == pytest.approx(P * t, rel=1e-9)
    assert row["heat_content"] == pytest.approx(P * t, rel=1e-9)
    assert row["T_mean"] - 293.15 == pytest.approx(P * t / C.sum(), rel=1e-9)
    assert row["current"] == pytest.approx(V / row["R_eq"], rel=1e-12)
    assert row["n_potential_solves"] == 1              # constant rho_e: one potential solve
    assert len(hist) == 10 and (tmp_path / "h.csv").read_text().count("\n") == 11
    if theta == "explicit":
        assert row["n_substeps"] == math.ceil(dt / m.heat.allowed_time_step())
    # a new electrode value re-solves once, then the solution is reused again
    m.step(g, dt, values={"top": 2 * V})
    row = m.step(g, dt)
    assert row["n_potential_solves"] == 2
    assert row["joule_power"] == pytest.approx(4 * P, rel=1e-9)


@pytest.mark.parametrize("theta, factor", [
    (0.0, lambda a: 1 - a),
    (0.5, lambda a: (1 - a / 2) / (1 + a / 2)),
    (1.0, lambda a: 1 / (1 + a)),
])
def test_convection_of_one_element(theta, factor):
    C, h, A, T_inf = 4.0, 25.0, 0.01, 300.0
    hs = HeatSolver([C], np.zeros((0, 2)), np.zeros(0), 400.0, theta=theta,
                    conditions=[Convection("air", [0], h=h, t_inf=T_inf, area=A)])
    assert hs.critical_time_step == pytest.approx(C / (h * A))
    dt = 0.2 * C / (h * A)
    a = h * A * dt / C
    for n in range(1, 16):
        step = hs.advance(dt)
        assert hs.temperature[0] - T_inf == pytest.approx(100.0 * factor(a) ** n, rel=1e-12)
        assert step.convection_energy == pytest.approx(step.heat_change, rel=1e-12)


def test_convection_rate_is_hA_over_C():
    C, h, A, T_inf = 4.0, 25.0, 0.01, 300.0
    hs = HeatSolver([C], np.zeros((0, 2)), np.zeros(0), 400.0, theta="crank-nicolson",
                    conditions=[Convection("air", [0], h=h, t_inf=T_inf, area=A)])
    t_end = 2 * C / (h * A)
    for _ in range(1000):
        hs.advance(t_end / 1000)
    assert hs.temperature[0] - T_inf == pytest.approx(100.0 * math.exp(-h * A * t_end / C), rel=1e-5)
    assert hs.energy["convection"] == pytest.approx(C * (hs.temperature[0] - 400.0), rel=1e-12)


def test_default_exposed_area_with_graph():
    g = rod()
    hs = heat_solver_on_graph(g, DENSITY, SPECIFIC_HEAT, LAMBDA, 400.0,
                               conditions=[Convection("air", np.ones(g.n_nodes, bool), h=10.0, t_inf=300.0)])
    np.testing.assert_allclose(hs.h_area, 10.0 * exposed_area(g))
    with pytest.raises(BoundaryConditionError, match="area"):
        HeatSolver(np.ones(3), [[0, 1], [1, 2]], [1.0, 1.0], 300.0,
                   conditions=[Convection("air", [0], h=10.0, t_inf=300.0)])


# ---------------------------------------------------------------------------------------------
# temperature-dependent resistivity: one resistor
# ---------------------------------------------------------------------------------------------
def _resistor_model(beta, iterations, **drive):
    g = pair()
    el = ElectricalModel(RHO_E, {"a": dict(select=[0], **drive), "b": dict(select=[1], potential=0.0)},
                         solver="direct")
    material = Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA, beta=beta,
                        reference_temperature=300.0)
    m = ElectroThermalModel(el, material, 300.0,
                            integrator=Integrator(theta="backward-euler", coupling_iterations=iterations))
    R0 = 1.0 / conductance(g, RHO_E)[0]
    C_tot = heat_capacity(g, DENSITY, SPECIFIC_HEAT).sum()
    return g, m, R0, C_tot


# lagged rho_e: first order (7e-4 here); iterated to the mid-step temperature the scheme is exact
# for this ODE (with backward Euler, (th1 - th0)(1 + beta (th0 + th1) / 2) = V^2 dt / (R0 C) keeps
# th + beta th^2 / 2 on the exact line), so only the fixed-point tolerance is left
@pytest.mark.parametrize("iterations, tol", [(0, 2e-3), (3, 1e-9)])
def test_rho_of_T_at_fixed_voltage(iterations, tol):
    beta, t_end, nsteps = 4e-3, 1.0, 200
    g, m, R0, C_tot = _resistor_model(beta, iterations, potential=1.0)
    # choose V so that theta + beta theta^2 / 2 = 120 K at t_end (theta = 100 K)
    V = math.sqrt(120.0 * R0 * C_tot / t_end)
    powers = []
    for k in range(nsteps):
        th_prev = m.temperature[0] - 300.0 if k else 0.0
        row = m.step(g, t_end / nsteps, values={"a": V} if k == 0 else None)
        powers.append(row["joule_power"])
        assert m.temperature[0] == pytest.approx(m.temperature[1], rel=1e-12)
    assert np.all(np.diff(powers) < 0)                  # hotter -> more resistive -> less power
    th = m.temperature[0] - 300.0
    exact = (-1 + math.sqrt(1 + 2 * beta * V ** 2 * t_end / (R0 * C_tot))) / beta
    assert exact == pytest.approx(100.0, rel=1e-12)
    assert th == pytest.approx(exact, rel=tol)
    # the last solve used rho_e at the start (lagged) or the middle (iterated) of the last step
    assert R0 * (1 + beta * th_prev) * (1 - 1e-12) <= row["R_eq"] <= R0 * (1 + beta * th) * (1 + 1e-12)
    assert row["n_potential_solves"] >= nsteps
    assert row["heat_content"] == pytest.approx(row["joule_energy"], rel=1e-9)


def test_rho_of_T_at_fixed_current():
    beta, t_end, nsteps = 4e-3, 1.0, 200
    g, m, R0, C_tot = _resistor_model(beta, 3, current=1.0)
    # theta(t) = (exp(beta I^2 R0 t / C) - 1) / beta; choose I for theta(t_end) = 100 K
    I = math.sqrt(math.log(1 + beta * 100.0) * C_tot / (beta * R0 * t_end))
    powers = []
    for k in range(nsteps):
        row = m.step(g, t_end / nsteps, values={"a": I} if k == 0 else None)
        powers.append(row["joule_power"])
    assert np.all(np.diff(powers) > 0)                  # hotter -> more resistive -> more power
    assert row["current"] == pytest.approx(I, rel=1e-12)
    assert m.temperature[0] - 300.0 == pytest.approx(100.0, rel=1e-6)   # midpoint rule: O(dt^2)


def test_resistivity_tolerance_limits_resolves():
    g, m, R0, C_tot = _resistor_model(1e-9, 0, potential=1e-3)
    m.resistivity_tol = 1e-3
    for _ in range(5):
        row = m.step(g, 1e-3)
    assert row["n_potential_solves"] == 1


# ---------------------------------------------------------------------------------------------
# graph changes
# ---------------------------------------------------------------------------------------------
def test_temperatures_follow_ids_when_the_graph_changes():
    g = rod()
    m = ElectroThermalModel(electrical(potential=1e-3),
                            Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA), 293.15)
    m.step(g, 1e-3)
    T = m.temperature
    # one bond broken: a new graph, the same elements
    g2 = g.with_edges(g.edges[1:])
    m.step(g2, 1e-12)
    assert m.n_rebuilds == 1 and m.n_potential_solves == 2          # same structure, one edge at g = 0
    np.testing.assert_allclose(m.temperature, T, rtol=1e-9)
    # reordered ids: temperatures go with the ids
    perm = np.arange(g.n_nodes)[::-1]
    inv = np.argsort(perm)
    g3 = ContactGraph(g.pos[perm], g.radius[perm], inv[g.edges], ids=g.ids[perm])
    T2 = m.temperature
    m.step(g3, 1e-12)
    np.testing.assert_allclose(m.temperature, T2[perm], rtol=1e-9)


# ---------------------------------------------------------------------------------------------
# bad input, non-finite values
# ---------------------------------------------------------------------------------------------
def test_bad_capacity_and_conductance_raise_material_error():
    C, edges, G = chain(4)
    for bad in (0.0, -1.0, np.nan):
        C2 = C.copy()
        C2[2] = bad
        with pytest.raises(MaterialError, match="heat capacity"):
            HeatSolver(C2, edges, G, 300.0)
    G2 = G.copy()
    G2[1] = -1.0
    with pytest.raises(MaterialError):
        HeatSolver(C, edges, G2, 300.0)
    with pytest.raises(MaterialError):
        Convection("air", [0], h=-1.0, t_inf=300.0)
    with pytest.raises(MaterialError):
        heat_solver_on_graph(rod(), DENSITY, SPECIFIC_HEAT, 0.0, 300.0)


@pytest.mark.parametrize("dt", [0.0, -1.0, np.nan, np.inf])
def test_bad_time_step_raises_value_error(dt):
    hs = HeatSolver(*chain(4), 300.0)
    with pytest.raises(ValueError, match="dt"):
        hs.advance(dt)


def test_bad_boundary_conditions():
    C, edges, G = chain(4)
    with pytest.raises(BoundaryConditionError, match="both"):
        HeatSolver(C, edges, G, 300.0, conditions=[FixedTemperature("a", [0, 1], 1.0), FixedTemperature("b", [1], 2.0)])
    with pytest.raises(BoundaryConditionError, match="no element"):
        HeatSolver(C, edges, G, 300.0, conditions=[FixedTemperature("a", [], 1.0)])
    with pytest.raises(BoundaryConditionError, match="exactly one"):
        HeatFlux("q", [0], power=1.0, flux=2.0)
    with pytest.raises(BoundaryConditionError):
        FixedTemperature("a", [0], np.nan)


@pytest.mark.parametrize("theta", ["explicit", "backward-euler"])
def test_non_finite_source_or_temperature_keeps_the_state(theta):
    C, edges, G = chain(5, G=1e-10)
    hs = HeatSolver(C, edges, G, 300.0, theta=theta)
    hs.advance(0.1, np.ones(5))
    before, t, steps, energy = hs.temperature, hs.time, hs.steps, dict(hs.energy)
    src = np.ones(5)
    src[3] = np.nan
    with pytest.raises(ThermalError, match="non-finite heat sources"):
        hs.advance(0.1, src)
    # finite but overflowing sources: the temperatures would be inf
    with pytest.raises(ThermalError, match="non-finite temperatures"):
        hs.advance(1e9, np.full(5, 1e308))
    with pytest.raises(ThermalError):
        hs.set_temperature([300.0, np.inf, 300.0, 300.0, 300.0])
    np.testing.assert_array_equal(hs.temperature, before)
    assert hs.time == t and hs.steps == steps and hs.energy == energy
    hs.advance(0.1, np.ones(5))                         # and it goes on


def test_coupled_model_keeps_its_history_on_thermal_error():
    g = rod()
    m = ElectroThermalModel(electrical(potential=1e-3),
                            Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA), 293.15,
                            history=History())
    m.step(g, 1e-3)
    T, t, e = m.temperature, m.time, m.joule_energy
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with pytest.raises(ThermalError):
            m.step(g, 1e-3, values={"top": 1e200})      # w^2 overflows: infinite Joule power
    np.testing.assert_array_equal(m.temperature, T)
    assert m.time == t and m.joule_energy == e and len(m.history) == 1


def test_solver_setup_is_kept_while_dt_is_unchanged():
    hs = HeatSolver(*chain(30), 300.0, theta=1.0)
    assert hs.advance(1.0).info["setup"] is True
    info = hs.advance(1.0).info
    assert info["setup"] is False and info["update"] is False
    info = hs.advance(0.5).info                     # another dt: the matrix values are refilled in place
    assert info["setup"] is False and info["update"] is True and hs.solver.n_setups == 1


def test_coupled_time_step_figures():
    g = rod()
    m = ElectroThermalModel(electrical(), Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA),
                            293.15, integrator=Integrator(theta="explicit"))
    m.step(g, 1e-4)
    ts = m.time_steps()
    assert ts["allowed"] == pytest.approx(0.9 * ts["critical"])
    assert ts["paper"] == pytest.approx(diffusion_time_step(g, LAMBDA, DENSITY, SPECIFIC_HEAT))
    # the lumped bound is the same order as the paper's figure on a regular lattice
    assert 0.1 < ts["critical"] / ts["paper"] < 10


def test_the_resistivity_is_held_in_one_place():
    """rho_0 is the electrical model's: the coupled model reads it there, a change reaches both,
    and a heat material that says otherwise is refused."""
    el = electrical(potential=1e-3)
    heat = Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=LAMBDA)
    m = ElectroThermalModel(el, heat, 293.15)
    assert m.material.resistivity == el.material.resistivity == RHO_E
    m.set_material(resistivity=2 * RHO_E, conductivity=2 * LAMBDA)
    assert m.material.resistivity == el.material.resistivity == el.resistivity == 2 * RHO_E
    assert m.material.conductivity == 2 * LAMBDA and m.material.beta == 0.0
    with pytest.raises(MaterialError, match="the resistivity belongs to the electrical model"):
        ElectroThermalModel(el, Material(resistivity=3 * RHO_E, density=DENSITY, specific_heat=SPECIFIC_HEAT,
                                         conductivity=LAMBDA), 293.15)
