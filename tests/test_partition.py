"""The partitioned network: each rank's rows (numpy, one process) and the collective solves
under a real ``mpiexec`` with 1, 2 and 3 ranks against the serial solvers."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from lattice import cubic_lattice
from yade_electro.core.mpi_network import private_network
from yade_electro.core.errors import GraphError
from yade_electro.network.partition import LocalNetwork, OwnedRows, split_network

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def _serial_reduced(n, edges, c, fixed, value, diag):
    L = sp.coo_matrix((np.r_[c, c, -c, -c], (np.r_[edges[:, 0], edges[:, 1], edges[:, 0], edges[:, 1]],
                                             np.r_[edges[:, 0], edges[:, 1], edges[:, 1], edges[:, 0]])),
                      shape=(n, n)).tocsr() + sp.diags(diag)
    free = np.flatnonzero(~fixed)
    return L[free][:, free].toarray(), -(L[free][:, np.flatnonzero(fixed)] @ value[fixed])


@pytest.mark.parametrize("native", [True, False])
def test_stacked_rows_of_every_rank_are_the_serial_reduced_matrix(native, monkeypatch):
    if not native:                                      # the pattern without the compiled helper
        import yade_electro.native as N
        monkeypatch.setattr(N, "csr_pattern", lambda *a: None)
    g = cubic_lattice((4, 3, 9), r=1.0)
    edges = g.edges
    n = g.n_nodes
    rng = np.random.default_rng(0)
    c = rng.uniform(0.5, 2.0, edges.shape[0])
    diag = rng.uniform(0, 0.1, n)
    fixed = np.zeros(n, bool)
    fixed[:12] = fixed[-12:] = True
    value = np.where(np.arange(n) < 12, 1.0, 0.0)
    owner = rng.integers(0, 3, n)                       # a scattered split, the hardest case
    # global numbers: owned free nodes of rank 0, then rank 1, then rank 2
    order = np.concatenate([np.flatnonzero((owner == r) & ~fixed) for r in range(3)])
    number = np.full(n, -1)
    number[order] = np.arange(order.shape[0])
    A_rows, r_rows = [], []
    for rank in range(3):
        share, held = split_network(n, edges, owner, rank)
        local_nodes = np.concatenate([np.flatnonzero(owner == rank), share.ghost_key])
        rows = OwnedRows(share, number[local_nodes])
        data = rows.values(c[held], diag[np.flatnonzero(owner == rank)])
        A_rows.append(sp.csr_matrix((data, rows.indices, rows.indptr), shape=(rows.n_rows, order.shape[0])))
        r_rows.append(rows.fixed_rhs(c[held], value[local_nodes]))
    A = sp.vstack(A_rows).toarray()
    A_ser, r_ser = _serial_reduced(n, edges, c, fixed, value, diag)
    # serial rows are in node order of the free nodes; ours in global-number order
    free = np.flatnonzero(~fixed)
    perm = np.searchsorted(free, order)                 # serial row of each global number
    np.testing.assert_allclose(A, A_ser[np.ix_(perm, perm)], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(np.concatenate(r_rows), r_ser[perm], rtol=1e-14)


def test_local_network_refuses_bad_shares():
    with pytest.raises(GraphError, match="joins two ghosts"):
        LocalNetwork([0, 1], [5, 6], [1, 1], [[0, 1], [2, 3]])
    with pytest.raises(GraphError, match="repeats"):
        LocalNetwork([0, 1], [5], [1], [[0, 1], [1, 0]])
    with pytest.raises(GraphError, match="key repeats"):
        LocalNetwork([0, 1], [1], [1], [[0, 2]])
    with pytest.raises(GraphError, match="ghost_owner"):
        LocalNetwork([0, 1], [5], [1, 2], [[0, 2]])


def _mpiexec(args, n, timeout=600):
    env = dict(os.environ, **MPI_ENV)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, env.get("PYTHONPATH")) if p)
    cmd = private_network(["mpiexec", "--oversubscribe", "-n", str(n)] + list(args))     # off the network
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("ranks", [2, 3])
def test_partitioned_solves_match_the_serial_ones(ranks):
    pytest.importorskip("mpi4py")
    res = _mpiexec([sys.executable, os.path.join(ROOT, "tests", "mpi_partition_check.py")], ranks)
    rows = [json.loads(line) for line in res.stdout.splitlines() if line.startswith("{")]
    assert res.returncode == 0 and rows, res.stdout[-2000:] + res.stderr[-3000:]
    out = rows[-1]
    assert out["ranks"] == ranks
    for pc in ("deflation", "hypre", "gamg"):
        r = out[pc]
        assert r["max_dphi_V"] < 1e-10 and r["R_rel_diff"] < 1e-10 and r["I_a_rel_diff"] < 1e-10, (pc, r)
        assert abs(r["I_sum"]) < 1e-10 and r["max_dP_rel"] < 1e-9, (pc, r)
        assert r["floating_ok"] and r["floating_warned"] == out["serial_floating_warned"], (pc, r)
    assert out["changed"]["max_dphi_V"] < 1e-9, out["changed"]
    auto = out["auto"]                 # deflation, GAMG, BoomerAMG twice each, then the fastest
    assert auto["max_dphi_V"] < 1e-9 and auto["chosen"] in ("deflation", "gamg", "hypre"), auto
    assert auto["preconditioners"][:6] == ["deflation", "deflation", "gamg", "gamg", "hypre", "hypre"], auto
    assert auto["preconditioners"][6:] == [auto["chosen"]] * 2, auto
    assert out["heat_auto"]["max_dT_K"] < 1e-9, out["heat_auto"]
    assert out["heat_auto"]["chosen"] in ("deflation", "gamg", "hypre"), out["heat_auto"]
    for theta in ("0", "0.5", "1"):
        h = out[f"heat_theta_{theta}"]
        assert h["max_dT_K"] < 1e-9 and h["content_rel_diff"] < 1e-10, (theta, h)
        w = out[f"wall_theta_{theta}"]          # an isothermal wall's links, values changing
        assert w["max_dT_K"] < 1e-9 and w["heat_rel_diff"] < 1e-10 and w["flow_rel_diff"] < 1e-10, (theta, w)
    lk = out["links"]                           # a wall electrode: links' values, then their nodes change
    assert lk["phi"] < 1e-10 and lk["I"] < 1e-10 and lk["P"] < 1e-9 and lk["R_rel_diff"] < 1e-10, lk


@pytest.mark.parametrize("ranks", [2, 3])
def test_voronoi_shares_of_regions_are_the_whole_tessellations(ranks):
    """Each rank tessellates only its region (its slab and a halo of hops + 3 diameters):
    the factors, cell volumes and conducting pairs of its owned elements are the whole
    packing's, before and after bonds break (crack facets)."""
    from scipy.spatial import cKDTree
    from yade_electro.core.graph import ContactGraph
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.laws.factors import make_law
    from yade_electro.physics.shares import carve_region_share
    rng = np.random.default_rng(5)
    R, L, h = 1e-3, 4e-3, 0.2e-3
    cyl = Cylinder((0, 0, 0), (0, 0, L), R)
    g0 = cubic_lattice((11, 11, 21), r=0.5 * h)          # a jittered lattice cut to the cylinder
    p = g0.pos - g0.pos.mean(axis=0) + np.array([0, 0, L / 2]) + rng.uniform(-0.15, 0.15, g0.pos.shape) * h
    p = p[(np.hypot(p[:, 0], p[:, 1]) < R - 0.3 * h) & (p[:, 2] > 0.3 * h) & (p[:, 2] < L - 0.3 * h)]
    rad = rng.uniform(0.45, 0.55, p.shape[0]) * h
    bonds = cKDTree(p).query_pairs(1.2 * h, output_type="ndarray")
    ids = np.arange(p.shape[0]) * 3 + 7                   # body ids are not node indices
    whole = ContactGraph(p, rad, bonds, ids=ids)
    broken = bonds[rng.random(bonds.shape[0]) > 0.9]      # 10 % of the bonds break
    left = bonds[~np.isin(bonds[:, 0] * p.shape[0] + bonds[:, 1], broken[:, 0] * p.shape[0] + broken[:, 1])]
    serial = make_law("voronoi", container=cyl)
    ref = {}
    for stage, b in (("intact", bonds), ("cracked", left)):
        g = whole.with_edges(b)
        pairs = serial.network(g)
        ref[stage] = dict(zip(map(tuple, np.sort(ids[pairs], axis=1).tolist()), serial.factor(g, pairs)))
    vol = dict(zip(ids.tolist(), serial.cell_volumes(whole)))
    z = p[:, 2]
    owner = np.minimum((z / L * ranks).astype(int), ranks - 1)
    halo = (3 + 2 + 1) * 2 * rad.max()
    for r in range(ranks):
        own = owner == r
        d, _ = cKDTree(p[own]).query(p, distance_upper_bound=halo)
        keep = np.flatnonzero(np.isfinite(d))
        local = np.full(p.shape[0], -1)
        local[keep] = np.arange(keep.size)
        law = make_law("voronoi", container=cyl, radius_range=(rad.min(), rad.max()))
        for stage, b in (("intact", bonds), ("cracked", left)):
            inside = b[(local[b[:, 0]] >= 0) & (local[b[:, 1]] >= 0)]
            region = ContactGraph(p[keep], rad[keep], local[inside], ids=ids[keep])
            share = carve_region_share(region, owner[keep], r, law)
            got = dict(zip(map(tuple, np.sort(share.graph.ids[share.network.edges], axis=1).tolist()), share.factor))
            mine = set(ids[own].tolist())
            want = {k: v for k, v in ref[stage].items() if k[0] in mine or k[1] in mine}
            assert set(got) == set(want), (r, stage, len(set(got) ^ set(want)))
            scale = float(np.median(list(want.values())))      # tiny clipped faces: their error is the scale's
            assert max(abs(got[k] - want[k]) for k in want) < 1e-11 * scale
            assert np.allclose(share.volume, [vol[i] for i in share.owned_ids.tolist()], rtol=1e-10, atol=0)
        assert law.tessellations == 1                    # faces of the first configuration, kept


class _OneRank:
    """A communicator of one rank (what chosen_ids and the model's checks call)."""

    def allgather(self, x):
        return [x]

    def Get_rank(self):
        return 0

    def Get_size(self):
        return 1


def test_selections_on_a_region_are_joined_and_checked():
    from yade_electro.core.errors import BoundaryConditionError
    from yade_electro.core.graph import ContactGraph
    from yade_electro.core.selection import Membership
    from yade_electro.yade.distributed import chosen_ids
    g = cubic_lattice((3, 3, 4), r=1.0)
    g = ContactGraph(g.pos, g.radius, g.edges, ids=np.arange(g.n_nodes) * 2 + 10)
    kept = Membership("top", [10, 12])
    by_place = Membership("low", lambda p, r: p[:, 2] < 1.0)
    out = chosen_ids(g, {"top": kept, "low": by_place}, comm=_OneRank())
    assert out["top"].tolist() == [10, 12] and kept.ids.tolist() == [10, 12]      # kept by id
    assert by_place.ids.tolist() == out["low"].tolist() and out["low"].size == 9
    with pytest.raises(BoundaryConditionError, match="ids not in the packing: \\[11\\]"):
        chosen_ids(g, {"a": Membership("a", [10, 11])}, comm=_OneRank())
    with pytest.raises(BoundaryConditionError, match="boolean mask cannot select in a distributed run"):
        chosen_ids(g, {"a": Membership("a", np.ones(g.n_nodes, bool))}, comm=_OneRank())
    with pytest.raises(BoundaryConditionError, match="selects no element"):
        chosen_ids(g, {"a": Membership("a", lambda p, r: p[:, 2] > 1e9)}, comm=_OneRank())


def test_the_voronoi_law_distributed_refuses_convection_without_an_area():
    from yade_electro.core.errors import BoundaryConditionError
    from yade_electro.core.materials import Material
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.physics.distributed import DistributedElectroThermal, Exchange
    mat = Material(density=1.0, specific_heat=1.0, conductivity=1.0)
    with pytest.raises(BoundaryConditionError, match="needs a scalar area"):
        DistributedElectroThermal(mat, "voronoi", {"container": Cylinder((0, 0, 0), (0, 0, 1), 1.0)},
                                  convection=[Exchange("air", [1], 10.0, 300.0)], temperature=300.0,
                                  comm=_OneRank())
