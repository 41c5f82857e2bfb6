"""ElectricalModel (electrodes by selector, kept problem, summary), select_nodes and the CSV
History, on lattices where the answer is known."""
import csv

import numpy as np
import pytest

from yade_electro import BoundaryConditionError, MaterialError, equivalent_resistance
from yade_electro.laws.factors import conductance
from yade_electro.physics.electrical import ElectricalModel, ElectrodeSpec
from yade_electro.core.selection import select_nodes
from yade_electro.core.history import History
from yade_electro.solvers.cg import CGSolver

from lattice import cubic_lattice, end_selectors

R, RHO = 0.5e-3, 0.73e-6
SHAPE = (3, 3, 8)
LAYER = SHAPE[0] * SHAPE[1]
Z_TOP = 2 * R * (SHAPE[2] - 1)

bottom, top = end_selectors(SHAPE, R)


def rod():
    return cubic_lattice(SHAPE, r=R)


def reference_resistance(graph, rho=RHO):
    """The core computation on the same graph: end layers at 1 V / 0 V, direct solver."""
    return equivalent_resistance(graph.n_nodes, graph.edges, conductance(graph, rho),
                                 np.flatnonzero(top(graph.pos, None)), np.flatnonzero(bottom(graph.pos, None)),
                                 solver="direct")


def model(**kw):
    electrodes = kw.pop("electrodes", {"top": dict(select=top, potential=1.0),
                                       "bottom": dict(select=bottom, potential=0.0)})
    return ElectricalModel(kw.pop("resistivity", RHO), electrodes, **kw)


# -- results ------------------------------------------------------------------------------------
@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_model_matches_the_core_computation(solver):
    g = rod()
    m = model(solver=solver)
    sol = m.solve(g)
    R_ref = reference_resistance(g)
    assert m.measure == ("top", "bottom")
    assert m.equivalent_resistance == pytest.approx(R_ref, rel=1e-9)
    assert sol.electrode_current["top"] == pytest.approx(1.0 / R_ref, rel=1e-9)
    assert m.graph is g and m.rebuilds == 1
    np.testing.assert_array_equal(m.conductance, conductance(g, RHO))
    row = m.summary()
    assert row["R_eq"] == m.equivalent_resistance
    assert (row["V_top"], row["V_bottom"]) == (1.0, 0.0)
    assert row["I_top"] == pytest.approx(-row["I_bottom"], rel=1e-9)
    assert row["joule_power"] == pytest.approx(1.0 * row["I_top"], rel=1e-9)     # V I = sum w^2 / c
    assert (row["n_nodes"], row["n_edges"], row["n_floating"]) == (g.n_nodes, g.n_edges, 0)
    assert row["residual"] <= 1e-10 and row["current_imbalance"] <= 1e-9
    assert set(row) == {"R_eq", "V_top", "I_top", "V_bottom", "I_bottom", "joule_power", "n_nodes", "n_edges",
                        "n_floating", "residual", "current_imbalance", "iterations", "solve_time"}


def test_selectors_ids_mask_and_callable_agree():
    g = cubic_lattice(SHAPE, r=R, ids=np.arange(SHAPE[0] * SHAPE[1] * SHAPE[2]) * 3 + 100)
    top_mask, bottom_mask = top(g.pos, g.radius), bottom(g.pos, g.radius)
    results = []
    for sel_top, sel_bottom in [(top, bottom), (top_mask, bottom_mask),
                                (g.ids[top_mask].tolist(), g.ids[bottom_mask])]:
        m = model(electrodes={"top": dict(select=sel_top, potential=1.0),
                              "bottom": dict(select=sel_bottom, potential=0.0)}, solver="direct")
        m.solve(g)
        np.testing.assert_array_equal(m.problem.electrodes[0].nodes, np.flatnonzero(top_mask))
        results.append(m.equivalent_resistance)
    assert results[0] == results[1] == results[2]
    np.testing.assert_array_equal(select_nodes(g, g.ids[[5, 2]]), [5, 2])


def test_electrode_specs_and_measure():
    g = rod()
    specs = [ElectrodeSpec("mid", lambda p, r: np.isclose(p[:, 2], 2 * R * 3), potential=0.25),
             ElectrodeSpec("top", top, potential=1.0), ElectrodeSpec("bottom", bottom, potential=0.0)]
    m = ElectricalModel(RHO, specs, solver="direct", measure=("top", "bottom"))
    sol = m.solve(g)
    # R_eq(top, bottom) is the network's: the middle electrode left open (a floating perfect
    # conductor), whatever it is held at; the same as with the middle fed 0 A
    open_mid = ElectricalModel(RHO, [ElectrodeSpec("mid", specs[0].select, current=0.0)] + specs[1:], solver="direct",
                               measure=("top", "bottom"))
    s_open = open_mid.solve(g)
    R_open = (s_open.electrode_potential["top"] - s_open.electrode_potential["bottom"]) / s_open.electrode_current["top"]
    assert m.equivalent_resistance == pytest.approx(R_open, rel=1e-12)
    assert open_mid.equivalent_resistance == pytest.approx(R_open, rel=1e-12)
    assert m.equivalent_resistance == pytest.approx(reference_resistance(g), rel=1e-6)   # the tied layer barely matters
    # the currents are those of the excitation (mid held at 0.25 V takes current too)
    assert sol.electrode_current["mid"] != 0.0
    assert abs(sum(sol.electrode_current.values())) <= 1e-12 * max(map(abs, sol.electrode_current.values()))
    assert ElectricalModel(RHO, specs).measure == ("mid", "top")
    assert ElectricalModel(RHO, specs[:1]).measure is None


def test_imposed_current_through_the_model():
    g = rod()
    I = 3.0e-3
    m = model(electrodes={"top": dict(select=top, current=I), "bottom": dict(select=bottom, potential=0.0)},
              solver="direct")
    sol = m.solve(g)
    assert sol.electrode_potential["top"] == pytest.approx(I * reference_resistance(g), rel=1e-10)
    assert m.equivalent_resistance == pytest.approx(reference_resistance(g), rel=1e-10)


# -- what is kept between solves ------------------------------------------------------------------
def test_same_graph_keeps_the_problem_and_the_setup():
    g = rod()
    m = model(solver="cg")
    s1 = m.solve(g)
    problem = m.problem
    assert m.solve(g) is s1                          # nothing changed: the same solution
    assert m.problem is problem and m.rebuilds == 1 and problem.basis_solves == 1
    # new electrode values: same problem, no linear solve, linear response
    s3 = m.solve(g, {"top": 2.0})
    assert m.rebuilds == 1 and problem.basis_solves == 1 and problem.solver.n_setups == 1
    assert s3.electrode_potential["top"] == 2.0
    np.testing.assert_allclose(s3.potential, 2 * s1.potential, rtol=0, atol=1e-9)


def test_broken_bonds_keep_the_structure():
    g = rod()
    m = model(solver="direct")
    m.solve(g)
    R0 = m.equivalent_resistance
    # cut every bond between layers 3 and 4: the rod is open
    z = g.pos[:, 2]
    cut = np.isclose(z[g.edges[:, 0]], 2 * R * 3) & np.isclose(z[g.edges[:, 1]], 2 * R * 4)
    assert cut.sum() == LAYER
    broken = g.subgraph(~cut)
    assert broken.revision == g.revision + 1
    sol = m.solve(broken)
    assert m.rebuilds == 1 and m.bond_graph is broken and m.updates["topology"] == 1
    assert np.count_nonzero(m.conductance) == broken.n_edges
    assert m.equivalent_resistance == np.inf
    assert np.all(np.isfinite(sol.potential)) and not np.any(np.isnan(sol.branch_current))
    row = m.summary()
    assert row["R_eq"] == np.inf and abs(row["joule_power"]) < 1e-20   # rounding only
    # back to an intact graph
    m.solve(g.with_edges(g.edges))
    assert m.rebuilds == 1 and m.equivalent_resistance == pytest.approx(R0, rel=1e-12)
    # a bond that was never there is a new structure
    extra = np.vstack([g.edges, [[0, g.n_nodes - 1]]])
    m.solve(g.with_edges(extra))
    assert m.rebuilds == 2


def test_set_resistivity_updates_values_and_scales():
    g = rod()
    m = model(solver="direct")
    m.solve(g)
    R0 = m.equivalent_resistance
    m.set_resistivity(2 * RHO)
    m.solve(g)
    assert m.rebuilds == 1 and m.updates["resistivity"] == 1
    assert m.equivalent_resistance == pytest.approx(2 * R0, rel=1e-12)
    # per-node resistivity: uniform values give the scalar answer
    m.set_resistivity(np.full(g.n_nodes, RHO))
    m.solve(g)
    assert m.equivalent_resistance == pytest.approx(R0, rel=1e-12)


def test_solver_object_is_kept_across_rebuilds():
    g = rod()
    solver = CGSolver(rtol=1e-12)
    m = model(solver=solver)
    m.solve(g)
    m.solve(g.with_edges(np.vstack([g.edges, [[0, g.n_nodes - 1]]])))
    assert m.problem.solver is solver and m.rebuilds == 2
    m.solve(g.with_edges(g.edges))
    assert m.equivalent_resistance == pytest.approx(reference_resistance(g), rel=1e-10)


def test_floating_cluster_in_the_model():
    g = rod()
    # detach node (0, 0, 3), on a side edge of the rod, by removing its 4 bonds
    node = 3 * LAYER + 0
    keep = ~np.any(g.edges == node, axis=1)
    assert (~keep).sum() == 4
    with pytest.warns(UserWarning, match=r"1 element\(s\) in 1 part\(s\) are connected to no electrode"):
        sol = model(solver="direct").solve(g.subgraph(keep))
    assert sol.floating.sum() == 1 and sol.floating[node] and sol.potential[node] == 0.0


# -- bad input ------------------------------------------------------------------------------
@pytest.mark.parametrize("rho", [0.0, -1.0, np.nan])
def test_bad_resistivity(rho):
    with pytest.raises(MaterialError, match="resistivity must be finite and > 0"):
        model(resistivity=rho)
    with pytest.raises(MaterialError, match="resistivity must be finite and > 0"):
        model().set_resistivity(rho)


def test_electrode_selecting_nothing():
    m = model(electrodes={"top": dict(select=lambda p, r: p[:, 2] > 1.0, potential=1.0),
                          "bottom": dict(select=bottom, potential=0.0)})
    with pytest.raises(BoundaryConditionError, match="electrode 'top' selects no element"):
        m.solve(rod())
    for empty in ([], np.zeros(rod().n_nodes, dtype=bool)):
        with pytest.raises(BoundaryConditionError, match="electrode 'e' selects no element"):
            select_nodes(rod(), empty, "e")


def test_bad_selectors():
    g = rod()
    with pytest.raises(BoundaryConditionError, match=r"electrode 'e': ids not in the graph: \[9999\]"):
        select_nodes(g, [0, 9999], "e")
    with pytest.raises(BoundaryConditionError, match=r"electrode 'e': mask has shape \(3,\), the graph has 72"):
        select_nodes(g, np.array([True, False, True]), "e")
    with pytest.raises(BoundaryConditionError, match=r"electrode 'e': the selector returned shape \(\)"):
        select_nodes(g, lambda p, r: True, "e")


def test_same_body_in_two_electrodes():
    m = model(electrodes={"top": dict(select=top, potential=1.0),
                          "all": dict(select=lambda p, r: np.ones(len(p), bool), potential=0.0)})
    with pytest.raises(BoundaryConditionError, match="belong to both electrodes 'top' and 'all'"):
        m.solve(rod())


def test_model_construction_errors():
    with pytest.raises(BoundaryConditionError, match="at least one electrode"):
        ElectricalModel(RHO, {})
    with pytest.raises(BoundaryConditionError, match="names must be unique"):
        ElectricalModel(RHO, [ElectrodeSpec("a", top, potential=1.0), ElectrodeSpec("a", bottom, potential=0.0)])
    with pytest.raises(BoundaryConditionError, match=r"measure=\('top', 'side'\) must name two different electrodes"):
        model(measure=("top", "side"))
    with pytest.raises(BoundaryConditionError, match=r"electrode 'top': give a dict\(select=..."):
        ElectricalModel(RHO, {"top": 1.0})
    with pytest.raises(RuntimeError, match="no solution yet"):
        model().equivalent_resistance
    with pytest.raises(RuntimeError, match="no solution yet"):
        model().summary()


def test_unknown_law_and_solver():
    # the names are checked when the model is built
    with pytest.raises(KeyError, match="unknown conductance law 'ohm'; known laws: .*continuum"):
        model(law="ohm")
    with pytest.raises(ValueError, match="unknown solver 'lu'; known: auto, cg, cg-amg, cg-deflated, cg-jacobi, direct"):
        model(solver="lu")


# -- History ---------------------------------------------------------------------------------
def read_csv(path):
    with open(path, newline="") as fh:
        return list(csv.reader(fh))


def test_history_writes_the_csv_row_by_row(tmp_path):
    path = tmp_path / "out" / "deep" / "history.csv"          # directories are created
    h = History(str(path))
    assert path.exists() and path.read_text() == ""
    rows = [{"iter": 0, "R_eq": 1.0 / 3.0, "I": -2.5e-7},
            {"iter": 10, "R_eq": float("inf"), "I": 0.1},
            {"I": np.float64(1e-300), "iter": 20, "R_eq": 12.0}]      # key order does not matter
    for k, row in enumerate(rows):
        h.append(row)
        lines = read_csv(path)
        assert lines[0] == ["iter", "R_eq", "I"]
        assert len(lines) == k + 2 and len(h) == k + 1
        last = lines[-1]
        assert int(last[0]) == row["iter"]
        assert float(last[1]) == row["R_eq"] and float(last[2]) == row["I"]   # exact round trip
    np.testing.assert_array_equal(h.column("iter"), [0, 10, 20])
    df = h.to_dataframe()
    assert list(df.columns) == ["iter", "R_eq", "I"] and len(df) == 3
    assert df["R_eq"].iloc[0] == 1.0 / 3.0 and np.isinf(df["R_eq"].iloc[1])
    h.append({"iter": 30, "R_eq": 1.0})                       # a row without I: nan there
    lines = read_csv(path)
    assert len(lines) == 5 and lines[-1] == ["30", "1.0", "nan"]
    h.append({"iter": 40, "R_eq": 2.0, "I": 0.5, "steps": 3})  # a new key: a wider header, the file again
    lines = read_csv(path)
    assert lines[0] == ["iter", "R_eq", "I", "steps"] and len(lines) == 6
    assert lines[1][3] == "nan" and lines[-1] == ["40", "2.0", "0.5", "3"]
    assert np.isnan(h.column("steps")[0]) and h.column("steps")[-1] == 3


def test_history_starts_a_fresh_file_and_can_stay_in_memory(tmp_path):
    path = tmp_path / "h.csv"
    path.write_text("old,content\n1,2\n")
    h = History(str(path))
    assert path.read_text() == ""
    h.append({"a": 1.5})
    assert read_csv(path) == [["a"], ["1.5"]]
    mem = History()
    mem.append({"a": 1.0})
    assert len(mem) == 1 and mem.to_dataframe()["a"].tolist() == [1.0]
    assert History().to_dataframe().empty


def test_model_summary_goes_into_a_history(tmp_path):
    g = rod()
    m = model(solver="direct")
    h = History(str(tmp_path / "h.csv"))
    for v in (1.0, 2.0):
        m.solve(g, {"top": v})
        h.append(m.summary())
    lines = read_csv(tmp_path / "h.csv")
    assert len(lines) == 3 and lines[0][0] == "R_eq"
    df = h.to_dataframe()
    assert df["V_top"].tolist() == [1.0, 2.0]
    assert df["R_eq"].iloc[0] == pytest.approx(df["R_eq"].iloc[1], rel=1e-12)


def test_plot_history_from_csv_and_history(tmp_path):
    from yade_electro.core.history import History
    from yade_electro.post.plotting import plot_history
    h = History(str(tmp_path / "h.csv"))
    for k in range(4):
        h.append({"iter": k, "time": 1e-3 * k, "R_eq": 1e-3, "current": 1e3, "joule_power": 1e3,
                  "joule_energy": 1.0 * k, "heat_content": 1.0 * k, "T_mean": 293.15 + k, "T_max": 294.0 + k,
                  "T_min": 293.15})
    for src in (str(tmp_path / "h.csv"), h, h.to_dataframe()):
        out = plot_history(src, str(tmp_path / "h.png"))
        assert (tmp_path / "h.png").stat().st_size > 1000 and out.endswith("h.png")
    with pytest.raises(ValueError, match="no rows"):
        plot_history(History(), str(tmp_path / "x.png"))


def test_overlap_warns_when_yade_leaves_no_core_free():
    from yade_electro.yade.overlap import overlap_competes
    assert overlap_competes(1, 2) is None and overlap_competes(3, 8) is None
    said = overlap_competes(2, 2)
    assert said.startswith("overlap=True: YADE runs 2 thread(s) on 2 core(s)") and "yade -j 1" in said
    assert overlap_competes(4, 2) is not None and overlap_competes(1, 1).endswith("With one core, use overlap=False")
