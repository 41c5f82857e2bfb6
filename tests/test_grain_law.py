"""The 'grains' conductance law alone (numpy): resolved grains read from a graph of their
elements give the network grain_network makes from their poses; a rigid motion changes no
conductance; links follow the grains as they move (FactorNetwork); a pressure law takes the
normal forces; bad input is refused with the body or grain named."""
import numpy as np
import pytest

from yade_electro.core.errors import BoundaryConditionError, GraphError
from yade_electro.core.graph import ContactGraph
from yade_electro.core.materials import in_series, thermal_conductance_of
from yade_electro.geometry.shapes import Box
from yade_electro.laws import FactorNetwork, Law
from yade_electro.network.grain_contact import mikic_resistance
from yade_electro.network.grain_law import GrainLaw, GrainSet
from yade_electro.network.grains import grain_network
from yade_electro.packing.grains import grain_template

K, RHO_C, R_C = 2.0, 1e6, 1e-3


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    Kx = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * Kx + (1 - np.cos(angle)) * Kx @ Kx


@pytest.fixture(scope="module")
def template():
    return grain_template(Box((-5e-3, -5e-3, -2e-3), (5e-3, 5e-3, 2e-3)), 150, seed=2)


def graph_of(template, poses, ids_from=0, skin=0.3):
    pos = np.concatenate([template.placed(R, t) for R, t in poses])
    r = np.tile(template.radii, len(poses))
    from scipy.spatial import cKDTree
    pairs = cKDTree(pos).query_pairs(2 * (1 + skin) * r.max(), output_type="ndarray")
    return ContactGraph(pos, r, pairs, ids_from + np.arange(pos.shape[0]))


def stacked(template, Q=np.eye(3), shift=np.zeros(3), press=0.02):
    h = 4e-3 - press * template.radii.mean()
    return [(Q, shift), (Q @ rotation((0, 0, 1), 0.3), shift + Q @ np.array([0, 0, h]))]


def grain_set(template, k=2, ids_from=0):
    gs = GrainSet()
    for j in range(k):
        gs.add(template, ids_from + j * template.n + np.arange(template.n))
    return gs


def thermal(law, graph):
    net = FactorNetwork(law)
    net.update(graph)
    G = thermal_conductance_of(net.factor, K, net.edges)
    return net, in_series(G, law.thermal_series(graph, net.edges))


def as_dict(edges, G):
    e = np.sort(edges, axis=1)
    return {(int(a), int(b)): float(g) for (a, b), g in zip(e, G) if g > 0}


def test_the_law_gives_grain_networks_conductances_and_capacities(template):
    poses = stacked(template)
    gs = grain_set(template, ids_from=10)
    graph = graph_of(template, poses, ids_from=10)
    law = Law("grains", grains=gs, contact_resistance=R_C, samples=20_000).make()
    assert isinstance(law, GrainLaw)
    net, G = thermal(law, graph)
    e, Gn, C, first, contacts = grain_network([template, template], poses, K, RHO_C, R_C, samples=20_000)
    mine, ref = as_dict(net.edges, G), as_dict(e, Gn)
    assert mine.keys() == ref.keys()
    assert max(abs(mine[k] - ref[k]) / ref[k] for k in ref) < 1e-12
    assert law.contacts.keys() == contacts.keys() == {(0, 1)}
    assert law.contacts[(0, 1)] == pytest.approx(contacts[(0, 1)], rel=1e-12)
    assert np.allclose(RHO_C * law.cell_volumes(graph), C, rtol=1e-12)


def test_a_rigid_motion_changes_no_conductance(template):
    gs = grain_set(template)
    net0, G0 = thermal(GrainLaw(gs, R_C), graph_of(template, stacked(template)))
    Q, t = rotation((1, 2, 3), 1.2), np.array([0.3, -0.1, 2.0])
    net1, G1 = thermal(GrainLaw(gs, R_C), graph_of(template, stacked(template, Q, t)))
    a, b = as_dict(net0.edges, G0), as_dict(net1.edges, G1)
    assert a.keys() == b.keys()
    assert max(abs(a[k] - b[k]) / a[k] for k in a) < 1e-9


def test_links_follow_the_grains_and_contacts_are_reused_while_still(template):
    gs = grain_set(template)
    law = GrainLaw(gs, R_C)
    net = FactorNetwork(law)
    assert net.update(graph_of(template, stacked(template))) == "structure"
    linked = int(np.count_nonzero(law.thermal_series(net.graph, net.edges)))
    assert linked > 0 and law.contact_computations == 1
    # a move far below the reuse tolerance: the contact is not computed again
    tiny = stacked(template, shift=np.array([1e-12, 0, 0]))
    net.update(graph_of(template, tiny))
    assert law.contact_computations == 1
    # pulled apart (the candidate pairs still join them): no link conducts any more
    apart = [stacked(template)[0], (stacked(template)[1][0], stacked(template)[1][1] + np.array([0, 0, 0.5e-3]))]
    net.update(graph_of(template, apart, skin=1.0))
    assert law.contacts == {} and law.contact_computations == 2
    G = thermal_conductance_of(net.factor, K, net.edges)
    first = template.n
    across = (net.edges[:, 0] < first) != (net.edges[:, 1] < first)
    assert np.all(G[across] == 0.0)


def test_a_pressure_law_takes_the_normal_forces(template):
    gs = grain_set(template)
    graph = graph_of(template, stacked(template))
    calls = []

    def force(pairs):
        calls.append(np.array(pairs))
        return np.full(len(pairs), 2.0)                     # N

    def rc(p):
        return mikic_resistance(p, 1e-6, 0.1, 2e9, K)
    law = GrainLaw(gs, rc, normal_force=force)
    net, G = thermal(law, graph)
    P = 2.0 / law.contacts[(0, 1)]
    ref = thermal(GrainLaw(gs, float(rc(P))), graph)[1]
    assert np.allclose(G, ref, rtol=1e-12) and calls[-1].tolist() == [[0, 1]]
    # a contact that carries no force conducts nothing
    law0 = GrainLaw(gs, rc, normal_force=lambda pairs: np.zeros(len(pairs)))
    net0, G0 = thermal(law0, graph)
    across = (net0.edges[:, 0] < template.n) != (net0.edges[:, 1] < template.n)
    assert np.all(G0[across] == 0) and np.all(G0[~across] > 0)
    bad = GrainLaw(gs, rc, normal_force=lambda pairs: np.full(len(pairs), np.nan))
    with pytest.raises(BoundaryConditionError, match="normal_force gave"):
        thermal(bad, graph)
    with pytest.raises(BoundaryConditionError, match=r"contact_resistance\(.* Pa\) of grains \(0, 1\)"):
        thermal(GrainLaw(gs, lambda p: -1.0, normal_force=force), graph)


def test_bad_grains_are_refused_naming_what_is_wrong(template):
    gs = grain_set(template)
    with pytest.raises(ValueError, match="needs grains="):
        GrainLaw(GrainSet(), R_C)
    with pytest.raises(ValueError, match="needs contact_resistance="):
        GrainLaw(gs)
    with pytest.raises(BoundaryConditionError, match="finite and >= 0"):
        GrainLaw(gs, -1.0)
    with pytest.raises(BoundaryConditionError, match="finite and >= 0"):
        GrainLaw(gs, float("inf"))
    with pytest.raises(ValueError, match="needs the grains' normal forces"):
        GrainLaw(gs, lambda p: 1e-3)
    with pytest.raises(ValueError, match="already elements of a grain"):
        gs.add(template, np.arange(template.n))
    with pytest.raises(ValueError, match="has 150 elements, got 3"):
        GrainSet().add(template, [1, 2, 3])
    law = GrainLaw(gs, R_C)
    g = graph_of(template, stacked(template))
    stray = ContactGraph(np.vstack([g.pos, [[1.0, 1.0, 1.0]]]), np.append(g.radius, 1e-3), g.edges,
                         np.append(g.ids, 999))
    with pytest.raises(GraphError, match=r"bodies \[999\] are elements of no grain"):
        law.network(stray)
    keep = np.arange(g.n_nodes - 1)
    part = ContactGraph(g.pos[keep], g.radius[keep], g.edges[np.all(g.edges < keep.size, axis=1)], g.ids[keep])
    with pytest.raises(GraphError, match=r"grain 1: its elements \[299\] are not in the scene's graph"):
        law.network(part)
    bent = g.pos.copy()
    bent[0] += 1e-4
    with pytest.raises(GraphError, match="grain 0 has not moved as a rigid body"):
        law.network(ContactGraph(bent, g.radius, g.edges, g.ids))
