"""The boundary vocabulary of the transport core: the thermal and electrical names are thin
aliases of the physics-blind conditions (the same bits), and each role is checked in one place,
in the words of the physics that names it."""
import numpy as np
import pytest

from yade_electro.network import FixedTemperature, HeatSolver

def test_generic_conditions_give_the_same_bits_as_their_thermal_names():
    from yade_electro.network import (Convection, FixedTemperature, FixedValue, HeatFlux, Injection, Robin,
                                      generic)
    C = np.array([1.0, 2.0, 1.5, 1.0, 3.0])
    edges, G = [[0, 1], [1, 2], [2, 3], [3, 4]], [1.0, 0.5, 2.0, 1.0]
    thermal = [FixedTemperature("cold", [0], 300.0), HeatFlux("in", [2, 3], power=4.0, area=[0, 0, 1.0, 3.0, 0]),
               Convection("air", [4], h=10.0, t_inf=290.0, area=0.05)]
    blind = [FixedValue("cold", [0], 300.0), Injection("in", [2, 3], rate=4.0, area=[0, 0, 1.0, 3.0, 0]),
             Robin("air", [4], coefficient=10.0, ambient=290.0, area=0.05)]
    assert [generic(b) for b in thermal] == blind
    for theta in (0.0, 0.5, 1.0):
        a = HeatSolver(C, edges, G, 310.0, theta=theta, conditions=thermal)
        b = HeatSolver(C, edges, G, 310.0, theta=theta, conditions=blind)
        for _ in range(3):
            sa, sb = a.advance(0.05), b.advance(0.05)
        assert np.array_equal(a.temperature, b.temperature)
        assert sa.boundary_energy == sb.boundary_energy and sa.convection_energy == sb.convection_energy
        assert np.array_equal(a.steady(apply=False).temperature, b.steady(apply=False).temperature)


def test_a_terminal_is_an_electrode():
    from yade_electro.network import ConductionProblem, Electrode, Terminal
    edges, c = [[0, 1], [1, 2], [2, 3]], [1.0, 2.0, 4.0]
    a = ConductionProblem(4, edges, c, [Electrode("hi", [0], potential=2.0), Electrode("lo", [3], current=-1.0)])
    b = ConductionProblem(4, edges, c, [Terminal("hi", [0], value=2.0), Terminal("lo", [3], rate=-1.0)])
    sa, sb = a.solve(), b.solve()
    assert np.array_equal(sa.potential, sb.potential)
    assert sa.equivalent_resistance("hi", "lo") == pytest.approx(1.0 + 0.5 + 0.25, rel=1e-12)
    assert sb.electrode_current == {"hi": pytest.approx(1.0, rel=1e-12), "lo": -1.0}


def test_every_condition_is_checked_by_its_role_in_its_own_words():
    from yade_electro.core.errors import BoundaryConditionError, MaterialError
    from yade_electro.network import (Convection, Electrode, FixedValue, HeatFlux, HeatSource, Injection, Robin,
                                      Source, Terminal)
    cases = [
        (lambda: FixedTemperature("t", [0]), BoundaryConditionError, r"fixed-temperature boundary condition 't': "
                                                                    r"give temperature= \(K\)"),
        (lambda: FixedValue("v", [0]), BoundaryConditionError, r"fixed-value condition 'v': give value="),
        (lambda: HeatFlux("q", [0], power=1.0, flux=2.0), BoundaryConditionError,
         r"heat-flux boundary condition 'q': give exactly one of power= \(W, total\) or flux= \(W/m\^2\)"),
        (lambda: Injection("q", [0]), BoundaryConditionError, r"injection 'q': give exactly one of rate= \(total\) "
                                                              r"or density="),
        (lambda: Convection("c", [0], h=-1.0, t_inf=300.0), MaterialError,
         r"convection boundary condition 'c': h must be >= 0 \(W/\(m\^2 K\)\)"),
        (lambda: Robin("c", [0], coefficient=-1.0, ambient=0.0), MaterialError, r"Robin condition 'c': coefficient "
                                                                                r"must be >= 0, got -1"),
        (lambda: HeatSource("s", power=1.0, density=1.0), BoundaryConditionError,
         r"heat source 's': give exactly one of power= \(W, total\) or density= \(W/m\^3\)"),
        (lambda: Source("s"), BoundaryConditionError, r"source 's': give exactly one of rate="),
        (lambda: Electrode("e", [0]), BoundaryConditionError, r"electrode 'e': give exactly one of potential= "
                                                              r"\(fixed potential, V\) or current= \(imposed current, A\)"),
        (lambda: Terminal("e", [0], value=1.0, rate=1.0), BoundaryConditionError, r"terminal 'e': give exactly one "
                                                                                  r"of value= \(fixed value\)"),
        (lambda: Terminal("e", [], value=1.0), BoundaryConditionError, r"terminal 'e' selects no element"),
        (lambda: FixedValue("v", [0], value=float("nan")), BoundaryConditionError, r"fixed-value condition 'v': value"),
    ]
    for make, err, text in cases:
        with pytest.raises(err, match=text):
            make()
