"""The live core: structure kept while values change, solver work reused, R_eq a property of the
network whatever the excitation, histories that say what they overwrite and survive a lost
file, and the checks of bad input (no YADE here)."""
import os
import warnings

import numpy as np
import pytest

from yade_electro import BoundaryConditionError, ContactGraph, Electrode, MaterialError
from yade_electro.laws.factors import conductance
from yade_electro.laws.law import Law
from yade_electro.physics.electrical import ElectricalModel, ElectrodeSpec
from yade_electro.core.history import History
from yade_electro.core.materials import Material
from yade_electro.network.conduction import ConductionProblem, solve_potential
from yade_electro.core.selection import check_selector

from lattice import cubic_lattice, end_selectors

R, RHO = 0.5e-3, 0.73e-6
SHAPE = (4, 4, 12)
bottom, top = end_selectors(SHAPE, R)


def rod():
    return cubic_lattice(SHAPE, r=R)


def two(g, va=1.0, vb=0.0, **kw):
    return [Electrode("top", np.flatnonzero(top(g.pos, None)), potential=va, **kw),
            Electrode("bottom", np.flatnonzero(bottom(g.pos, None)), potential=vb)]


def reference_R(g, c):
    sol = solve_potential(g.n_nodes, g.edges, c, two(g), solver="direct")
    return (sol.electrode_potential["top"] - sol.electrode_potential["bottom"]) / sol.electrode_current["top"]


# -- R_eq does not depend on the excitation ---------------------------------------------------
@pytest.mark.parametrize("va, vb", [(1.0, 0.0), (1.0, 1.0), (0.0, 0.0), (1.0, 1.0 - 1e-9), (-3.0, 2.0)])
def test_equivalent_resistance_is_the_networks(va, vb):
    g = rod()
    c = conductance(g, RHO)
    R0 = reference_R(g, c)
    for solver in ("cg", "cg-deflated", "direct"):
        sol = solve_potential(g.n_nodes, g.edges, c, two(g, va, vb), solver=solver)
        assert sol.equivalent_resistance("top", "bottom") == pytest.approx(R0, rel=1e-9), solver
        assert np.isfinite(sol.equivalent_resistance("top", "bottom"))
        # and the currents are those of the excitation
        assert sol.electrode_current["top"] == pytest.approx((va - vb) / R0, rel=1e-8, abs=1e-12 / R0)


def test_equivalent_resistance_with_an_imposed_current_and_with_three_electrodes():
    g = rod()
    c = conductance(g, RHO)
    R0 = reference_R(g, c)
    el = [Electrode("top", np.flatnonzero(top(g.pos, None)), current=0.0),
          Electrode("bottom", np.flatnonzero(bottom(g.pos, None)), potential=0.0)]
    sol = solve_potential(g.n_nodes, g.edges, c, el)
    assert sol.equivalent_resistance("top", "bottom") == pytest.approx(R0, rel=1e-9)   # 0 A fed
    mid = np.flatnonzero(np.isclose(g.pos[:, 2], 2 * R * 5))
    three = two(g) + [Electrode("mid", mid, potential=0.3)]
    sol = solve_potential(g.n_nodes, g.edges, c, three)
    open_mid = solve_potential(g.n_nodes, g.edges, c, two(g) + [Electrode("mid", mid, current=0.0)])
    R_open = (open_mid.electrode_potential["top"] - 0.0) / open_mid.electrode_current["top"]
    assert sol.equivalent_resistance("top", "bottom") == pytest.approx(R_open, rel=1e-9)
    # the matrix is a Laplacian on the electrodes: symmetric, rows summing to 0
    S = sol.conductance_matrix
    np.testing.assert_allclose(S, S.T, rtol=0, atol=1e-12 * np.abs(S).max())
    np.testing.assert_allclose(S.sum(axis=1), 0.0, atol=1e-12 * np.abs(S).max())


# -- structure kept, values updated in place -------------------------------------------------
@pytest.mark.parametrize("solver", ["cg", "cg-deflated", "cg-amg", "direct"])
def test_value_updates_keep_the_structure_and_the_setup(solver):
    g = rod()
    c = conductance(g, RHO)
    p = ConductionProblem(g.n_nodes, g.edges, c, two(g), solver=solver, coords=g.pos)
    p.solve()
    Kuu = p.system.Kuu
    rng = np.random.default_rng(0)
    c2 = c * (1 + 0.01 * rng.standard_normal(c.size))
    assert p.update_conductance(c2) == "values"
    sol = p.solve()
    assert p.system.Kuu is Kuu and p.structure_builds == 1
    if solver in ("cg", "cg-deflated", "cg-amg"):
        assert p.solver.n_setups == 1 and p.solver.n_updates == 1
    ref = solve_potential(g.n_nodes, g.edges, c2, two(g), solver="direct")
    np.testing.assert_allclose(sol.potential, ref.potential, rtol=0, atol=1e-8)
    assert sol.equivalent_resistance("top", "bottom") == pytest.approx(ref.equivalent_resistance("top", "bottom"),
                                                                       rel=1e-9)


def test_broken_edges_keep_the_structure_until_the_network_splits():
    g = rod()
    c = conductance(g, RHO)
    p = ConductionProblem(g.n_nodes, g.edges, c, two(g), coords=g.pos)
    R0 = p.solve().equivalent_resistance("top", "bottom")
    # one bond lost (between two middle layers): same structure, R up
    z = g.pos[:, 2]
    k = np.flatnonzero(np.isclose(z[g.edges[:, 0]], 2 * R * 5) & np.isclose(z[g.edges[:, 1]], 2 * R * 6))[0]
    keep = np.arange(g.n_edges) != k
    assert p.update_edges(g.edges[keep], c[keep]) == "values"
    R1 = p.solve().equivalent_resistance("top", "bottom")
    assert R1 > R0 and p.structure_builds == 1
    # a whole section cut: the parts change, the structure is rebuilt, R is infinite
    cut = np.isclose(z[g.edges[:, 0]], 2 * R * 5) != np.isclose(z[g.edges[:, 1]], 2 * R * 5)
    cut &= np.maximum(z[g.edges[:, 0]], z[g.edges[:, 1]]) > 2 * R * 5.5
    assert p.update_edges(g.edges[~cut], c[~cut]) == "structure"
    sol = p.solve()
    assert sol.equivalent_resistance("top", "bottom") == np.inf
    assert np.all(np.isfinite(sol.potential)) and np.all(np.isfinite(sol.branch_current))


def test_model_follows_moves_and_resistivity_without_rebuilding():
    from yade_electro.geometry.shapes import Box
    g = rod()
    box = Box((-R, -R, -R), 2 * R * np.array(SHAPE) - R)
    m = ElectricalModel(RHO, {"top": dict(select=top, potential=1.0), "bottom": dict(select=bottom, potential=0.0)},
                        solver="cg-deflated", law=Law("voronoi", container=box))
    m.solve(g)
    # a stretch along z by 1e-3: the faces keep their areas (reference tessellation), the axial
    # lengths grow, and the uniform axial current gives R up by the strain exactly
    g2 = ContactGraph(g.pos * [1, 1, 1.001], g.radius, g.edges, g.ids)
    R0 = m.equivalent_resistance
    m.solve(g2)
    assert m.rebuilds == 1 and m.updates["geometry"] == 1
    assert m.equivalent_resistance == pytest.approx(1.001 * R0, rel=1e-9)
    # rho_e up 10 % on every element: a value update, R scales
    m.set_resistivity(np.full(g.n_nodes, 1.1 * RHO))
    m.solve()
    assert m.rebuilds == 1 and m.updates["resistivity"] == 1
    assert m.equivalent_resistance == pytest.approx(1.1 * 1.001 * R0, rel=1e-9)


def test_membership_is_fixed_by_id_unless_reselect():
    g = rod()
    z0 = 2 * R * (SHAPE[2] - 1)

    def upper(pos, radius):
        return pos[:, 2] > z0 - 0.5 * R
    spec = {"top": dict(select=upper, potential=1.0), "bottom": dict(select=bottom, potential=0.0)}
    m = ElectricalModel(RHO, spec)
    m.solve(g)
    ids0 = m.memberships["top"].ids.copy()
    # the rod shrinks: by position nothing would be "upper" any more, by id the electrode stays
    g2 = ContactGraph(g.pos * [1, 1, 0.9], g.radius, g.edges, g.ids)
    m.solve(g2)
    np.testing.assert_array_equal(m.memberships["top"].ids, ids0)
    re = ElectricalModel(RHO, spec, reselect=True)
    re.solve(g)
    with pytest.raises(BoundaryConditionError, match="selects no element"):
        re.solve(g2.with_edges(g2.edges[1:]))      # a new structure re-selects by position


# -- bad input --------------------------------------------------------------------------------
@pytest.mark.parametrize("bad", [3.7, [1.5, 2.7], "top", None, {"a": 1}, [[1, 2]], [1, "x"]])
def test_selectors_that_are_not_ids_masks_or_callables(bad):
    with pytest.raises(BoundaryConditionError):
        check_selector(bad, "electrode 'e'")
    with pytest.raises(BoundaryConditionError):
        ElectrodeSpec("e", bad, potential=1.0)


def test_integer_valued_float_ids_are_ids():
    check_selector([3.0, 4.0], "x")
    check_selector(np.arange(3), "x")
    check_selector(np.zeros(4, bool), "x")


@pytest.mark.parametrize("value", ["1", None, np.nan, np.inf, 1j, True])
def test_electrode_values_must_be_real_numbers(value):
    with pytest.raises(BoundaryConditionError, match="electrode 'e'"):
        ElectrodeSpec("e", [0], potential=value)
    m = ElectricalModel(RHO, {"e": dict(select=[0], potential=1.0)})
    with pytest.raises(BoundaryConditionError):
        m.set_electrode("e", value)


@pytest.mark.parametrize("field", ["resistivity", "density", "specific_heat", "conductivity"])
@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, "7900", None])
def test_material_values(field, bad):
    kw = dict(resistivity=1.0, density=1.0, specific_heat=1.0, conductivity=1.0)
    kw[field] = bad
    if bad is None and field != "resistivity":
        Material(**kw)                             # None: not given (heat-only / electrical-only)
        return
    if bad is None:
        kw["resistivity"] = None
        with pytest.raises(MaterialError, match="needs resistivity"):
            Material(**kw).require_electrical()
        return
    with pytest.raises(MaterialError, match=field):
        Material(**kw)


def test_beta_needs_a_reference_temperature():
    with pytest.raises(MaterialError, match="reference_temperature"):
        Material(resistivity=1.0, beta=1e-3)
    m = Material(resistivity=2.0, beta=1e-3, reference_temperature=300.0)
    assert m.resistivity_at(np.array([300.0, 400.0])) == pytest.approx([2.0, 2.2])


# -- history ------------------------------------------------------------------------------------
def test_history_says_it_overwrites_and_appends_on_request(tmp_path):
    path = tmp_path / "h.csv"
    h = History(str(path))
    h.append({"a": 1.0, "b": 2})
    with pytest.warns(UserWarning, match="exists and is replaced"):
        History(str(path))
    h = History(str(path))
    h.append({"a": 1.0, "b": 2})
    a = History(str(path), mode="a")
    assert a.rows == [{"a": 1.0, "b": 2}]
    a.append({"a": 3.0, "b": 4})
    assert path.read_text().splitlines() == ["a,b", "1.0,2", "3.0,4"]
    with pytest.raises(FileExistsError, match="exists"):
        History(str(path), mode="x")
    with pytest.raises(ValueError, match="history mode"):
        History(str(path), mode="r")


def test_a_lost_history_file_warns_and_is_written_again(tmp_path):
    d = tmp_path / "out"
    path = d / "h.csv"
    h = History(str(path))
    h.append({"i": 0})
    # the directory is removed under the running simulation
    os.remove(path)
    os.rmdir(d)
    blocker = tmp_path / "out"
    blocker.write_text("a file where the directory was")           # the directory cannot come back
    with pytest.warns(RuntimeWarning, match="cannot write the history file"):
        h.append({"i": 1})
    with warnings.catch_warnings():
        warnings.simplefilter("error")                              # warned once only
        h.append({"i": 2})
    assert [r["i"] for r in h.rows] == [0, 1, 2]
    blocker.unlink()                                                # the disk is back
    h.append({"i": 3})
    assert path.read_text().splitlines() == ["i", "0", "1", "2", "3"]
