"""Tests of the packing recipe (yade_electro.yade.packing).

The placement and the statistics are numpy/scipy only; the tests marked ``yade`` run the
real YADE (Debian package) in a subprocess ``yade-electro -n -x`` or through the import path.
"""
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from yade_electro.yade import packing as P
from conftest import repo_env  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
YADE_PY = "/usr/lib/x86_64-linux-gnu/yade-double/py"
ROD = P.Cylinder((0, 0, 0), (0, 0, 5e-3), 1e-3)
N = 600


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("packcache")


@pytest.fixture(scope="module")
def rod(cache):
    return P.dense_packing(ROD, n=N, seed=1, cache_dir=cache)


def test_mean_radius_eq1():
    v = np.pi * 1e-6 * 5e-3
    r = P.mean_radius_for_count(v, 5000)
    assert r == pytest.approx((0.63 * v / (4 / 3 * np.pi * 5000)) ** (1 / 3))
    assert 4 / 3 * np.pi * r ** 3 * 5000 / v == pytest.approx(0.63)
    with pytest.raises(ValueError):
        P.mean_radius_for_count(-1.0, 10)
    with pytest.raises(ValueError):
        P.mean_radius_for_count(1.0, 0)


def test_shapes_signed_distance():
    c = ROD
    pts = np.array([[0, 0, 2.5e-3], [0.5e-3, 0, 2.5e-3], [2e-3, 0, 2.5e-3], [0, 0, 6e-3]])
    assert np.allclose(c.sdf(pts), [-1e-3, -0.5e-3, 1e-3, 1e-3])
    assert c.exact_volume == pytest.approx(np.pi * 1e-6 * 5e-3)
    b = P.Box((0, 0, 0), (1, 2, 3))
    assert np.allclose(b.sdf([[0.5, 1, 1.5], [2, 1, 1.5]]), [-0.5, 1.0])
    s = P.Sphere((0, 0, 0), 1.0)
    assert np.allclose(s.sdf([[0, 0, 0], [2, 0, 0]]), [-1, 1])
    notched = b - P.Box((0.4, -1, 1.4), (0.6, 3, 1.6))
    assert notched.sdf([[0.5, 1, 1.5]])[0] > 0          # inside the notch: outside the bar
    assert notched((0.2, 1, 0.5), 0.1) and not notched((0.5, 1, 1.5))
    # gradient is the unit outward normal
    g = c.gradient(np.array([[0.9e-3, 0, 2.5e-3]]))
    assert np.allclose(g, [[1, 0, 0]], atol=1e-6)


def test_container_volume_monte_carlo():
    bar = P.Box((0, 0, 0), (1, 1, 4))
    notched = bar - P.Box((0.25, -1, 1.75), (0.75, 2, 2.25))
    v, method = P.container_volume(notched, n_samples=1_000_000)
    assert method.startswith("monte-carlo")
    assert v == pytest.approx(4 - 0.25, rel=5e-3)
    assert P.container_volume(bar) == (4.0, "exact")
    # fixed seed: reproducible
    assert P.container_volume(notched, n_samples=1_000_000)[0] == v


def test_dense_packing_rod(rod):
    assert rod.centers.shape == (N, 3) and rod.radii.shape == (N,)
    # radii: uniform with 25 % dispersion around the (scaled) eq. 1 radius
    base = rod.radii / rod.radius_scale
    assert base.min() >= 0.875 * rod.r_mean_requested * (1 - 1e-9)
    assert base.max() <= 1.125 * rod.r_mean_requested * (1 + 1e-9)
    assert 0.9 < rod.radius_scale <= 1.0
    # no overlap, inside the container, dense, touching the wall
    assert rod.max_overlap <= 1e-6
    assert np.all(ROD.sdf(rod.centers) + rod.radii <= 1e-9 * rod.r_mean)
    assert rod.volume_fraction > 0.55
    d = rod.distance_to_surface()
    assert np.sum(d - rod.radii < 0.01 * rod.r_mean) > 0.15 * N   # many touch the wall
    assert rod.container_volume == pytest.approx(ROD.exact_volume)
    assert rod.volume_method == "exact"
    assert rod.volume_fraction == pytest.approx(
        np.sum(4 / 3 * np.pi * rod.radii ** 3) / rod.container_volume)


def test_dense_packing_is_cached_and_reproducible(rod, cache):
    again = P.dense_packing(ROD, n=N, seed=1, cache_dir=cache)
    assert again.from_cache
    assert np.array_equal(again.centers, rod.centers) and np.array_equal(again.radii, rod.radii)
    assert again.volume_fraction == rod.volume_fraction
    other = P.dense_packing(ROD, n=N, seed=2, cache_dir=cache)
    assert not other.from_cache and not np.array_equal(other.centers, rod.centers)


def test_compiled_pair_forces_are_the_numpy_ones_to_the_last_bit(monkeypatch):
    """The jamming's compiled sphere-sphere forces (native/soft_spheres.cpp) give the same bits
    as the numpy form, so the packings (and every figure made from them) do not change."""
    from scipy.spatial import cKDTree
    import yade_electro.native as native
    from yade_electro.packing import jamming
    rng = np.random.default_rng(0)
    x = rng.random((2000, 3)) * 9.0
    rho = 0.9 + 0.2 * rng.random(2000)
    pairs = cKDTree(x).query_pairs(2.6, output_type="ndarray")
    for s in (0.7, 1.0, 1.1):
        a = jamming.pair_forces_numpy(x, rho, s, pairs)
        b = native.soft_sphere_forces(x, rho, s, pairs)
        assert a[1].size > 0
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and a[2] == b[2]
    assert native.soft_sphere_forces(x, rho, 0.01, pairs)[1].size == 0         # no overlap at all
    fast = P.dense_packing(ROD, n=400, seed=5, cache_dir=False)

    monkeypatch.setattr(native, "soft_sphere_forces", jamming.pair_forces_numpy)   # the numpy reference
    slow = P.dense_packing(ROD, n=400, seed=5, cache_dir=False)
    assert np.array_equal(fast.centers, slow.centers) and np.array_equal(fast.radii, slow.radii)


def test_compiled_fire_steps_agree_with_numpy():
    """The compiled FIRE steps of large packings (native/fire_steps.cpp) against the numpy
    forms to rounding: the Verlet list (the same pairs as cKDTree, sorted by the first
    sphere), the pair forces and energy on one and two threads, the power and the move."""
    from scipy.spatial import cKDTree
    import yade_electro.native as native
    from yade_electro.packing import jamming
    rng = np.random.default_rng(1)
    n = 30000                                            # > 100,000 pairs: the two-thread path
    x = np.ascontiguousarray(rng.random((n, 3)) * [20.0, 20.0, 60.0])
    x = np.ascontiguousarray(x[jamming.morton_order(x)])
    rho = 0.9 + 0.2 * rng.random(n)
    fire = native.FireSteps(threads=1)
    pairs = fire.pairs_within(x, 2.6)
    ref = cKDTree(x).query_pairs(2.6, output_type="ndarray")
    assert pairs.shape == ref.shape and pairs.shape[0] > 100000
    assert np.array_equal(np.sort(pairs[:, 0] * n + pairs[:, 1]), np.sort(ref[:, 0] * n + ref[:, 1]))
    assert np.all(np.diff(pairs[:, 0]) >= 0) and np.all(pairs[:, 0] < pairs[:, 1])
    F_np, ov, mx = jamming.pair_forces_numpy(x, rho, 1.0, pairs)
    for threads in (1, 2):
        fire.threads = threads
        F = np.empty_like(x)
        energy, mx_c, m = fire.pair_forces(x, rho, 1.0, pairs, F)
        assert m == ov.size > 1000 and mx_c == mx
        assert np.allclose(F, F_np, rtol=0, atol=1e-12 * np.abs(F_np).max())
        assert energy == pytest.approx(0.5 * float(ov @ ov), rel=1e-12)
    v = rng.standard_normal((n, 3))
    fmax, P, vn, fn = fire.power(F_np, v)
    assert fmax == pytest.approx(np.sqrt(np.max(np.einsum("ij,ij->i", F_np, F_np))), rel=1e-14)
    assert P == pytest.approx(np.einsum("ij,ij->", F_np, v), rel=1e-10)
    assert (vn, fn) == pytest.approx((np.linalg.norm(v), np.linalg.norm(F_np)), rel=1e-12)
    x2, v2 = x.copy(), v.copy()
    fire.move(x2, v2, F_np, 0.9, 0.3, 0.1)
    w = 0.9 * v + 0.3 * F_np + 0.1 * F_np
    assert np.allclose(v2, w, rtol=1e-14, atol=0) and np.allclose(x2, x + 0.1 * w, rtol=1e-14, atol=0)
    assert fire.max_move(x2, x) == pytest.approx(np.max(np.linalg.norm(x2 - x, axis=1)), rel=1e-14)


def test_spatial_order_of_large_packings(monkeypatch):
    """From SPATIAL_ORDER_FROM spheres on, the jamming works in Morton order (sorted pairs,
    wall terms on the wall's candidates only) and returns the spheres in their own order: the
    same algorithm with other rounding (FIRE is chaotic: the paths part after a while), so
    about the same FIRE steps, a packing without overlaps inside the container, and the
    same volume fraction to the bisection's resolution."""
    from yade_electro.packing import jamming
    x = np.random.default_rng(3).random((5000, 3)) * [1.0, 2.0, 0.5]
    order = jamming.morton_order(x)
    assert np.array_equal(np.sort(order), np.arange(5000))
    # consecutive points in the order are close: far closer than in the random order
    step = np.linalg.norm(np.diff(x[order], axis=0), axis=1)
    assert np.median(step) < 0.2 * np.median(np.linalg.norm(np.diff(x, axis=0), axis=1))
    plain = P.dense_packing(ROD, n=600, seed=4, cache_dir=False)
    monkeypatch.setattr(jamming, "SPATIAL_ORDER_FROM", 1)
    spatial = P.dense_packing(ROD, n=600, seed=4, cache_dir=False)
    assert spatial.params["spatial_order"] and "spatial_order" not in plain.params
    assert abs(spatial.params["fire_steps"] / plain.params["fire_steps"] - 1) < 0.2
    # ds_min = 2.5e-4 on the radius scale: 7.5e-4 on the fraction, relative
    assert abs(spatial.volume_fraction / plain.volume_fraction - 1) < 2e-3
    assert spatial.max_overlap <= 0.0
    assert np.all(ROD.sdf(spatial.centers) + spatial.radii <= 1e-12)
    # the spheres keep their own radii (the order was put back)
    assert np.allclose(spatial.radii / spatial.radius_scale, plain.radii / plain.radius_scale, rtol=1e-9)


def test_r_mean_mode_and_errors(cache):
    box = P.Box((0, 0, 0), (1e-3, 1e-3, 1e-3))
    r = 0.1e-3
    pk = P.dense_packing(box, r_mean=r, seed=3, cache_dir=False)
    assert pk.n == round(0.63 * 1e-9 / (4 / 3 * np.pi * r ** 3))
    assert pk.r_mean_requested == r and pk.r_mean <= r * 1.01
    assert pk.max_overlap <= 1e-6
    with pytest.raises(ValueError, match="exactly one"):
        P.dense_packing(box, n=10, r_mean=r)
    with pytest.raises(ValueError, match="exactly one"):
        P.dense_packing(box)
    with pytest.raises(ValueError, match="unknown option"):
        P.dense_packing(box, n=10, tolerance=1)
    with pytest.raises(ValueError, match="dispersion"):
        P.dense_packing(box, n=10, dispersion=3, cache_dir=False)


def test_notched_bar_packing():
    bar = P.Box((0, 0, 0), (1e-3, 1e-3, 3e-3))
    notch = P.Box((0.4e-3, -1e-3, 1.4e-3), (0.6e-3, 2e-3, 1.6e-3))
    shape = bar - notch
    pk = P.dense_packing(shape, n=400, seed=1, cache_dir=False)
    assert pk.max_overlap <= 1e-6
    assert np.all(shape.sdf(pk.centers) + pk.radii <= 1e-9 * pk.r_mean)
    assert pk.volume_method.startswith("monte-carlo")
    assert pk.volume_fraction > 0.5


def test_target_method_keeps_eq1_radii():
    pk = P.dense_packing(P.Box((0, 0, 0), (1e-3, 1e-3, 1e-3)), n=300, seed=1, method="target",
                         cache_dir=False)
    assert pk.radius_scale == 1.0
    assert pk.volume_fraction > 0.62          # 0.63 * (1 + (0.25^2)/4) by construction
    assert 0 < pk.max_overlap < 0.3


def test_bonds_and_statistics(rod):
    k = P.DEFAULT_DETECTION_FACTOR
    edges = P.bond_pairs(rod.centers, rod.radii, k)
    d = np.linalg.norm(rod.centers[edges[:, 0]] - rod.centers[edges[:, 1]], axis=1)
    assert np.all(d < k * (rod.radii[edges[:, 0]] + rod.radii[edges[:, 1]]))
    assert np.all(edges[:, 0] < edges[:, 1])
    st = P.packing_statistics(rod.centers, rod.radii, edges, rod.container_volume,
                              rod.distance_to_surface)
    assert st["n"] == N and st["n_bonds"] == len(edges)
    assert st["mean_coordination"] == pytest.approx(2 * len(edges) / N)
    assert sum(st["coordination_histogram"]) == N
    assert 5.0 < st["mean_coordination"] < 8.0
    assert st["isolated"] == 0
    assert st["e_below_0.4_core"] > st["e_below_0.4_surface"]
    assert st["max_overlap"] <= 1e-6
    # eccentricity agrees with the core's definition (surfaces.eccentricity on a ContactGraph)
    from yade_electro.core.graph import ContactGraph
    from yade_electro.laws.transmission import eccentricity
    e = eccentricity(ContactGraph(rod.centers, rod.radii, edges))
    assert st["e_below_0.4"] == pytest.approx(np.mean(e < 0.4))
    # coordination grows with the detection factor; calibration hits the target
    z = [2 * len(P.bond_pairs(rod.centers, rod.radii, kk)) / N for kk in (1.01, 1.03, 1.06)]
    assert z[0] < z[1] < z[2]
    k67 = P.detection_factor_for_coordination(rod.centers, rod.radii, 6.7)
    assert 2 * len(P.bond_pairs(rod.centers, rod.radii, k67)) / N >= 6.7
    assert 2 * len(P.bond_pairs(rod.centers, rod.radii, k67 - 1e-3)) / N < 6.7


# ------------------------------------------------------------------------------------------
# Real YADE
# ------------------------------------------------------------------------------------------


YADE_SCRIPT = textwrap.dedent("""
    import json, sys
    import numpy as np
    sys.path.insert(0, {root!r})
    from yade_electro.yade import packing as P
    from yade import pack
    out = {{}}
    # a YADE predicate is recognised as the exact cylinder
    pred = pack.inCylinder((0, 0, 0), (0, 0, 5e-3), 1e-3)
    shape = P.as_shape(pred)
    out["shape"] = type(shape).__name__
    notched = pack.inAlignedBox((0, 0, 0), (1e-3, 1e-3, 3e-3)) - pack.inAlignedBox((0.4e-3, -1e-3, 1.4e-3), (0.6e-3, 2e-3, 1.6e-3))
    out["notched"] = repr(P.as_shape(notched))
    pk = P.dense_packing(pred, n={n}, seed=1, cache_dir={cache!r})
    k = P.DEFAULT_DETECTION_FACTOR
    ids = P.add_bonded_packing(pk, detection_factor=k)
    ref = {{tuple(sorted(p)) for p in np.asarray(ids)[P.bond_pairs(pk.centers, pk.radii, k)].tolist()}}
    real = [i for i in O.interactions if i.isReal]
    out["n_bodies"] = len(O.bodies)
    out["n_bonds"] = len(real)
    out["same_pairs"] = {{tuple(sorted((i.id1, i.id2))) for i in real}} == ref
    out["phys"] = sorted({{type(i.phys).__name__ for i in real}})
    out["cohesive"] = all(not i.phys.cohesionBroken for i in real)
    out["factors"] = [O.engines[1].boundDispatcher.functors[0].aabbEnlargeFactor,
                      O.engines[2].geomDispatcher.functors[0].interactionDetectionFactor]
    out["engines"] = [type(e).__name__ for e in O.engines]
    out["dt_ok"] = 0 < O.dt < PWaveTimeStep()
    O.run(50, True)
    pos = np.array([O.bodies[i].state.pos for i in ids])
    out["max_disp"] = float(np.abs(pos - pk.centers).max() / pk.r_mean)
    out["n_bonds_after"] = sum(1 for i in O.interactions if i.isReal and not i.phys.cohesionBroken)
    # the bonds are the cohesive law's: pulled apart, a bond across a gap pulls back (tension)
    i0 = max(real, key=lambda i: -i.geom.penetrationDepth)
    b2 = O.bodies[i0.id2]
    b2.state.blockedDOFs = "xyzXYZ"
    b2.state.vel = tuple(1e-3 * i0.geom.normal)
    O.run(3, True)
    out["gap"] = -i0.geom.penetrationDepth
    out["tension"] = -i0.phys.normalForce.dot(i0.geom.normal)
    out["tension_expected"] = i0.phys.kn * (i0.phys.unp - i0.geom.penetrationDepth)
    # JCFpm variant on a fresh scene, every progress line printed
    O.reset()
    import yade_electro.core.progress
    yade_electro.core.progress.PROGRESS_EVERY = 0.0
    ids = P.add_bonded_packing(pk, material=JCFpmMat(young=210e9, poisson=0.3, density=7900, cohesion=5e8, tensileStrength=5e8, frictionAngle=0.4), detection_factor=k)
    real = [i for i in O.interactions if i.isReal]
    out["jcfpm_bonds"] = len(real)
    out["jcfpm_cohesive"] = all(i.phys.isCohesive for i in real)
    O.run(20, True)
    out["jcfpm_bonds_after"] = sum(1 for i in O.interactions if i.isReal and i.phys.isCohesive)
    # a large packing's collider sorts along the longest extent (the rod's axis, z): same bonds
    pairs_x = sorted((min(i.id1, i.id2), max(i.id1, i.id2)) for i in real)
    O.reset()
    yade_electro.core.progress.PROGRESS_EVERY = 10.0
    import yade_electro.yade.bonding as B
    B.SORT_ALONG_LONGEST_FROM = 1
    ids = P.add_bonded_packing(pk, material=JCFpmMat(young=210e9, poisson=0.3, density=7900, cohesion=5e8, tensileStrength=5e8, frictionAngle=0.4), detection_factor=k)
    out["sort_axis"] = [e.sortAxis for e in O.engines if type(e).__name__ == "InsertionSortCollider"]
    out["sorted_z_same_bonds"] = sorted((min(i.id1, i.id2), max(i.id1, i.id2)) for i in O.interactions if i.isReal) == pairs_x
    print("RESULT " + json.dumps(out))
""")


def test_add_bonded_packing_in_yade(tmp_path, rod, cache, yade_exe):
    script = tmp_path / "bond.py"
    script.write_text(YADE_SCRIPT.format(root=ROOT, n=N, cache=str(cache)))
    proc = subprocess.run(yade_exe + ["-n", "-x", str(script)], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path, env=repo_env())
    lines = [l for l in proc.stdout.splitlines() if l.startswith("RESULT ")]
    assert lines, f"yade failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    out = json.loads(lines[-1][7:])
    assert out["shape"] == "Cylinder"
    assert out["notched"].startswith("Difference(Box(")
    assert out["n_bodies"] == N
    n_ref = len(P.bond_pairs(rod.centers, rod.radii, P.DEFAULT_DETECTION_FACTOR))
    assert out["n_bonds"] == n_ref and out["same_pairs"]
    assert out["phys"] == ["CohFrictPhys"] and out["cohesive"]
    assert out["factors"] == [1.0, 1.0]
    assert out["engines"] == ["ForceResetter", "InsertionSortCollider", "InteractionLoop",
                              "NewtonIntegrator"]
    assert out["dt_ok"]
    assert out["max_disp"] < 1e-6            # the bonded packing starts stress-free
    assert out["n_bonds_after"] == n_ref
    assert out["gap"] > 0 and out["tension"] > 0
    assert out["tension"] == pytest.approx(out["tension_expected"], rel=1e-6)
    assert out["jcfpm_bonds"] == n_ref and out["jcfpm_cohesive"]
    assert out["jcfpm_bonds_after"] == n_ref
    assert out["sort_axis"] == [2] and out["sorted_z_same_bonds"]
    # the progress lines of the bonding (shown with PROGRESS_EVERY = 0 in the JCFpm run only)
    progress = [l for l in proc.stderr.splitlines() if l.startswith("[bonding]")]
    assert any(f"{N} of {N}" in l and "spheres added" in l for l in progress), proc.stderr[-2000:]
    assert any("bonds set stress-free: done in" in l for l in progress), proc.stderr[-2000:]
    assert any("YADE's bonding step on" in l for l in progress), proc.stderr[-2000:]
    assert sum("spheres added to O.bodies: done" in l for l in progress) == 1   # silent while PROGRESS_EVERY = 10 s


@pytest.mark.yade
def test_yade_predicate_import_path():
    """``as_shape`` on YADE predicates, importing YADE into this interpreter."""
    if not os.path.isdir(YADE_PY) or sys.executable != "/usr/bin/python3":
        pytest.skip("needs /usr/bin/python3 with the Debian yade package")
    sys.path.insert(0, YADE_PY)
    from yade import pack
    box = P.as_shape(pack.inAlignedBox((0, 0, 0), (1, 2, 3)))
    assert isinstance(box, P.Box) and np.allclose(box.hi, [1, 2, 3])
    sph = P.as_shape(pack.inSphere((1, 1, 1), 0.5))
    assert isinstance(sph, P.Sphere) and sph.radius == pytest.approx(0.5)
    cyl = P.as_shape(pack.inCylinder((0, 0, 0), (2, 0, 0), 0.3))
    assert isinstance(cyl, P.Cylinder) and cyl.length == pytest.approx(2)
    # an unrecognised predicate falls back to a sampled signed distance field
    hyp = pack.inHyperboloid((0, 0, 0), (0, 0, 1), 0.5, 0.3)
    g = P.as_shape(hyp, voxel=0.02)
    assert isinstance(g, P.GridShape)
    pts = np.array([[0, 0, 0.5], [0.49, 0, 0.01], [0.45, 0, 0.5], [0, 0, 1.2]])
    expect = np.array([hyp(tuple(p), 0) for p in pts])
    assert np.array_equal(g.sdf(pts) <= 0, expect)


def test_fire_steps_threads_follow_yade_batch_jobs(monkeypatch):
    """The compiled FIRE steps use 2 threads on a 2-core machine, also under plain yade (which
    sets OMP_NUM_THREADS=1 for itself); in a yade-batch job (YADE_BATCH set) the job's
    OMP_NUM_THREADS, so that parallel jobs do not oversubscribe; YADE_ELECTRO_THREADS wins."""
    import yade_electro.native as native
    monkeypatch.setattr(native.os, "cpu_count", lambda: 2)
    for name in ("OMP_NUM_THREADS", "YADE_BATCH", "YADE_ELECTRO_THREADS"):
        monkeypatch.delenv(name, raising=False)
    assert native.default_threads() == 2
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    assert native.default_threads() == 2                  # plain yade's own setting
    monkeypatch.setenv("YADE_BATCH", "")
    assert native.default_threads() == 1 and native.FireSteps().threads == 1
    monkeypatch.setenv("OMP_NUM_THREADS", "8")
    assert native.default_threads() == 2
    monkeypatch.setenv("YADE_ELECTRO_THREADS", "1")
    assert native.default_threads() == 1
    monkeypatch.delenv("YADE_ELECTRO_THREADS")
    monkeypatch.setattr(native.os, "cpu_count", lambda: 1)
    assert native.default_threads() == 1
