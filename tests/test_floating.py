"""The one policy for parts of a network that reach no fixed value, for current and heat alike
(yade_electro.network.floating): with nothing put in, a floating part keeps a reference level
(0 V; its mean temperature) with one warning; with something put in, there is no steady state
and the solve raises, saying so."""
import numpy as np
import pytest

from yade_electro import BoundaryConditionError, Electrode, ThermalError, solve_potential
from yade_electro.network import FixedTemperature, HeatSolver

# a chain 0-1-2 between the fixed values, and a pair 3-4 joined to nothing
EDGES = [[0, 1], [1, 2], [3, 4]]


def heat(**kw):
    return HeatSolver(np.array([1.0, 1.0, 1.0, 2.0, 1.0]), EDGES, [1.0, 1.0, 1.0], [0.0, 0.0, 0.0, 300.0, 330.0],
                      conditions=[FixedTemperature("cold", [0], 300.0), FixedTemperature("hot", [2], 400.0)], **kw)


def test_a_floating_part_keeps_its_mean_temperature_in_a_steady_solve():
    hs = heat()
    with pytest.warns(UserWarning, match=r"2 element\(s\) in 1 part\(s\) are connected to no fixed temperature "
                                         r"and no convection: they carry nothing to the rest and keep their mean"):
        out = hs.steady()
    # the chain: the linear profile between the fixed values; the pair: its heat kept, 2*300 + 330 = 3 * 310
    np.testing.assert_allclose(out.temperature, [300.0, 350.0, 400.0, 310.0, 310.0], rtol=1e-12)
    np.testing.assert_array_equal(out.floating, [False, False, False, True, True])
    assert out.balance_error < 1e-12


def test_a_floating_part_that_receives_heat_has_no_steady_state():
    hs = heat()
    with pytest.raises(ThermalError, match=r"2 element\(s\) in 1 part\(s\) reach no fixed temperature and no "
                                           r"convection but receive heat .* has nowhere to go"):
        hs.steady(sources=np.array([0.0, 0.0, 0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(hs.temperature, [300.0, 0.0, 400.0, 300.0, 330.0])   # nothing changed


def test_a_floating_part_integrates_in_time_without_a_word(recwarn):
    hs = heat()
    hs.advance(0.1, sources=np.array([0.0, 0.0, 0.0, 1.0, 0.0]))
    assert not [w for w in recwarn if "connected to no" in str(w.message)]
    assert 2.0 * hs.temperature[3] + hs.temperature[4] == pytest.approx(3 * 310.0 + 0.1, rel=1e-12)


def test_current_follows_the_same_policy():
    with pytest.warns(UserWarning, match=r"2 element\(s\) in 1 part\(s\) are connected to no electrode: they "
                                         r"carry nothing to the rest and keep a potential of 0 V"):
        sol = solve_potential(5, EDGES, [1.0, 1.0, 1.0], [Electrode("a", [0], potential=1.0),
                                                           Electrode("b", [2], potential=0.0)])
    np.testing.assert_array_equal(sol.floating, [False, False, False, True, True])
    with pytest.raises(BoundaryConditionError, match="no return path"):
        solve_potential(5, EDGES, [1.0, 1.0, 1.0], [Electrode("a", [0], potential=1.0),
                                                     Electrode("b", [2], potential=0.0),
                                                     Electrode("c", [3], current=1.0)])



def test_a_node_joined_only_by_edges_of_zero_conductance_floats():
    """A contact that opened stays in the structure with conductance 0: the node it held joins
    nothing, so a steady solve keeps its temperature (the floating policy) instead of failing
    on a zero diagonal."""
    C = np.array([1.0, 1.0, 1.0, 1.0])
    hs = HeatSolver(C, [[0, 1], [1, 2], [1, 3]], [1.0, 1.0, 1.0], [300.0, 300.0, 300.0, 345.0],
                    conditions=[FixedTemperature("cold", [0], 300.0), FixedTemperature("hot", [2], 400.0)])
    hs.update_values(conductance=[1.0, 1.0, 0.0])          # node 3's only contact (to node 1) opened
    with pytest.warns(UserWarning, match=r"1 element\(s\) in 1 part\(s\)"):
        st = hs.steady()
    assert st.temperature[3] == 345.0 and st.floating.tolist() == [False, False, False, True]
    assert st.temperature[1] == pytest.approx(350.0, rel=1e-12)
