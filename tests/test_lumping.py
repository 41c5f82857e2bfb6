"""Clumps as lumps (numpy only): the lumped heat solver is the heat solver of the network
aggregated by hand; the members' volumes sum to the union of the clump's spheres."""
import numpy as np
import pytest

from yade_electro.network.boundary import FixedValue
from yade_electro.network.heat_conditions import Convection, FixedTemperature
from yade_electro.network.lumping import LumpedHeatSolver, Lumping, lens_volume, member_volumes
from yade_electro.network.transient import HeatSolver

# a chain of 7 members: clumps {0, 1}, {2, 3, 4}, then 5 and 6 alone; plus a cross edge 1-3
LABELS = np.array([10, 10, 20, 20, 20, -1, -1])
EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [1, 3]])
G = np.array([3.0, 1.0, 5.0, 4.0, 2.0, 1.5, 0.5])
C = np.array([1.0, 2.0, 1.0, 1.5, 0.5, 1.0, 2.0])
T0 = np.array([300.0, 310.0, 320.0, 330.0, 340.0, 350.0, 360.0])
# by hand: lumps A = {0, 1}, B = {2, 3, 4}, c = {5}, d = {6}; edges A-B (1 + 0.5), B-c (2), c-d (1.5)
EDGES_L = np.array([[0, 1], [1, 2], [2, 3]])
G_L = np.array([1.5, 2.0, 1.5])
C_L = np.array([3.0, 3.0, 1.0, 2.0])
T_L = np.array([(300 * 1 + 310 * 2) / 3, (320 * 1 + 330 * 1.5 + 340 * 0.5) / 3, 350.0, 360.0])


def test_lumping_groups_edges_and_sums():
    lump = Lumping.of(LABELS)
    assert lump.n_lumps == 4 and lump.group.tolist() == [0, 0, 1, 1, 1, 2, 3]
    e, slot = lump.edges(EDGES)
    assert e.tolist() == EDGES_L.tolist() and slot.tolist() == [-1, 0, -1, -1, 1, 2, 0]
    assert np.allclose(lump.sum(C), C_L) and np.allclose(lump.mean(T0, C), T_L)
    nodes, s = lump.node_sums([1, 0, 4, 6], [1.0, 2.0, 3.0, 4.0])
    assert nodes.tolist() == [0, 1, 3] and s.tolist() == [3.0, 3.0, 4.0]


@pytest.mark.parametrize("theta", [0.0, 0.5, 1.0])
def test_lumped_solver_is_the_solver_of_the_aggregated_network(theta):
    """Transient steps with sources, a fixed temperature on a member (its whole clump is
    held), convection and a linked fixed temperature whose links change: every member's
    temperature is its lump's in the hand-aggregated solver, to rounding."""
    conds = [FixedTemperature("cold", nodes=[6], temperature=280.0),
             Convection("air", nodes=[2, 5], h=1.0, t_inf=290.0, area=0.25),
             FixedValue("wall", nodes=np.zeros(0, np.int64), value=400.0)]
    src = np.array([0.5, 0.0, 1.0, 0.0, 0.0, 0.2, 0.0])
    lumped = LumpedHeatSolver(Lumping.of(LABELS), C, EDGES, G, T0, conditions=conds, theta=theta, solver="direct",
                              nodes_of={"cold": np.array([6]), "air": np.array([2, 5]), "wall": np.zeros(0, np.int64)},
                              link_of={"wall": np.zeros(0)})
    ref = HeatSolver(C_L, EDGES_L, G_L, T_L, theta=theta, solver="direct",
                     conditions=[FixedTemperature("cold", nodes=[3], temperature=280.0),
                                 Convection("air", nodes=[1, 2], h=1.0, t_inf=290.0, area=0.25),
                                 FixedValue("wall", nodes=np.zeros(0, np.int64), value=400.0)],
                     nodes_of={"wall": np.zeros(0, np.int64)}, link_of={"wall": np.zeros(0)})
    dt = 0.2 if theta else 0.5 * ref.critical_time_step
    for k in range(4):
        lumped.set_links("wall", [0, 1, 4], [0.1 * k, 0.2, 0.3])      # two members of lump A: summed
        ref.set_links("wall", [0, 1], [0.1 * k + 0.2, 0.3])
        lumped.advance(dt, src)
        ref.advance(dt, Lumping.of(LABELS).sum(src))
    assert np.allclose(lumped.temperature, ref.temperature[Lumping.of(LABELS).group], rtol=0, atol=1e-12)
    assert lumped.link_energy["wall"] == pytest.approx(ref.link_energy["wall"], rel=1e-13)
    assert lumped.energy == pytest.approx(ref.energy, rel=1e-13)
    assert lumped.time == pytest.approx(4 * dt)
    st = lumped.steady(src)                     # steady, spread to the members
    assert np.allclose(st.temperature, ref.steady(Lumping.of(LABELS).sum(src)).temperature[[0, 0, 1, 1, 1, 2, 3]])


def test_lumped_solver_takes_members_temperatures_and_new_edges():
    lumped = LumpedHeatSolver(Lumping.of(LABELS), C, EDGES, G, T0, solver="direct")
    T = T0.copy()
    T[:2] = [100.0, 400.0]
    lumped.set_temperature(T)                   # lump A: its capacity-weighted mean
    assert lumped.temperature[0] == lumped.temperature[1] == pytest.approx((100 + 800) / 3)
    assert lumped.update_edges(EDGES[:-1], G[:-1]) == "values"     # the cross edge broke: same lump edges
    assert lumped.update_edges(EDGES[[0, 1, 2, 3, 5]], G[[0, 1, 2, 3, 5]]) == "values"   # B-c gone: a subset
    G2 = G[[0, 1, 2, 3, 5]] * 2.0                        # new values on the kept subset: B-c stays at 0
    lumped.update_values(G2)
    ref = HeatSolver(C_L, EDGES_L, [2 * 1.0, 0.0, 2 * 1.5], lumped.lumped.temperature, solver="direct")
    lumped.advance(0.3)
    ref.advance(0.3)
    assert np.allclose(lumped.temperature, ref.temperature[[0, 0, 1, 1, 1, 2, 3]], rtol=0, atol=1e-12)
    assert lumped.update_edges(np.vstack([EDGES, [[0, 6]]]), np.append(G, 1.0)) == "structure"   # A-d: new
    assert lumped.n == 7 and lumped.capacity.tolist() == C.tolist()


def test_lens_and_member_volumes():
    r, d = 1.0, 1.2
    v_lens = np.pi * (4 * r + d) * (2 * r - d) ** 2 / 12             # two equal spheres
    assert lens_volume(r, r, d) == pytest.approx(v_lens, rel=1e-14)
    assert lens_volume(1.0, 0.3, 0.5) == pytest.approx(4 / 3 * np.pi * 0.3 ** 3)   # inside
    assert lens_volume(1.0, 1.0, 2.5) == 0.0
    pos = np.array([[0, 0, 0], [d, 0, 0], [5, 0, 0], [5 + d, 0, 0]], float)
    v = member_volumes(pos, np.ones(4), [7, 7, -1, -1])  # a clump of 2, and 2 spheres that are not one
    sphere = 4 / 3 * np.pi
    assert v[0] == v[1] == pytest.approx(sphere - v_lens / 2) and v[2] == v[3] == pytest.approx(sphere)
    assert v[0] + v[1] == pytest.approx(2 * sphere - v_lens)            # the union
