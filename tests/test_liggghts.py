"""The LIGGGHTS adapter: data files, decks, dumps (exact, no LIGGGHTS) and the real LIGGGHTS
3.8.0 on small runs: a two-sphere heat run against the closed form of its own explicit
Euler step, a deck that fails and whose ERROR line reaches the caller, a timeout, a missing
binary and a packing settled in a cylinder."""
import math
from pathlib import Path

import numpy as np
import pytest

from yade_electro import liggghts as L

COPPER = L.GranularMaterial(young=110e9, poisson=0.34, density=8900.0, conductivity=385.0, specific_heat=172.0)


# ------------------------------------------------------------------ no LIGGGHTS
def test_data_file_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(1)
    pos = rng.random((50, 3)) * 0.01
    d = L.particle_data(pos, rng.uniform(1e-4, 2e-4, 50), rng.uniform(2000, 9000, 50),
                        types=rng.integers(1, 4, 50), ids=np.arange(50) + 7)
    back = L.read_data(L.write_data(tmp_path / "p.data", d))
    for name in ("ids", "types", "radius", "density", "positions", "box"):
        np.testing.assert_array_equal(getattr(back, name), getattr(d, name), err_msg=name)
    assert back.n_types == d.n_types and np.all(back.box[:, 0] < pos.min(axis=0))


@pytest.mark.parametrize("kwargs, match", [
    (dict(radius=-1.0), "radius"), (dict(density=0.0), "density"), (dict(types=0), "types must be >= 1"),
    (dict(ids=[1, 1]), "unique"), (dict(box=[[0, 1e-3]] * 3), "outside the box")])
def test_bad_particle_data_is_refused(kwargs, match):
    args = dict(positions=[[0, 0, 0], [0.01, 0, 0]], radius=1e-3, density=1000.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        L.particle_data(**args)


def test_read_data_refuses_what_is_not_granular(tmp_path):
    p = tmp_path / "bad.data"
    p.write_text("title\n\n2 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n1 1 0.1\n")
    with pytest.raises(ValueError, match="header says 2 atoms"):
        L.read_data(p)
    with pytest.raises(FileNotFoundError, match="not found"):
        L.read_data(tmp_path / "none.data")


def test_render_deck_names_missing_and_unused_values(tmp_path):
    assert {"heat_conduction", "settle"} <= set(L.template_names())
    tpl = tmp_path / "t.in"
    tpl.write_text("variable a equal ${x}\nrun @{steps}\n")
    assert L.render_deck(tpl, steps=5) == "variable a equal ${x}\nrun 5\n"     # LIGGGHTS' $ untouched
    with pytest.raises(ValueError, match=r"needs values for \['steps'\]"):
        L.render_deck(tpl)
    with pytest.raises(ValueError, match=r"no placeholder for \['stpes'\]"):
        L.render_deck(tpl, steps=5, stpes=4)
    with pytest.raises(ValueError, match="unknown LIGGGHTS template"):
        L.render_deck("no_such_template")


def test_material_and_wall_commands():
    soft = L.GranularMaterial(young=5e6, poisson=0.3, density=2500.0, restitution=0.7, friction=0.3)
    text = L.material_commands([COPPER, soft])
    assert "youngsModulus peratomtype 110000000000 5000000" in text
    assert "coefficientRestitution peratomtypepair 2 0.5 0.6 0.6 0.7" in text
    with pytest.raises(ValueError, match="conductivity of every material"):
        L.material_commands([soft], heat=True)
    walls = L.wall_commands([L.PlaneWall("z", 0.0, temperature=300.0), L.CylinderWall("z", 0.01)])
    assert "primitive type 1 zplane 0 temperature 300" in walls and "zcylinder 0.01 0 0" in walls
    with pytest.raises(ValueError, match="axis"):
        L.PlaneWall("w", 0.0)
    with pytest.raises(ValueError, match="poisson"):
        L.GranularMaterial(young=1e9, poisson=0.6, density=1000.0)
    assert L.pair_local_columns(["heatFlux", "id", "pos"]) == ["x1", "y1", "z1", "x2", "y2", "z2", "id1", "id2",
                                                                 "periodic", "heat_flux"]


def test_dump_parser(tmp_path):
    p = tmp_path / "dump"
    frame = ("ITEM: TIMESTEP\n{s}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
             "ITEM: ATOMS id type f_Temp\n1 1 {a}\n2 1 {b}\n")
    p.write_text(frame.format(s=0, a=300.0, b=310.5) + frame.format(s=100, a=301.25, b=309.0))
    d = L.read_dump(p, columns=["id", "type", "Temp"])
    assert sorted(d) == [0, 100] and d[100]["Temp"].tolist() == [301.25, 309.0]
    assert d[0]["id"].dtype.kind == "i"
    p.write_text(frame.format(s=0, a=1, b=2)[:-8])
    with pytest.raises(ValueError, match="cut short"):
        L.read_dump(p)


# ------------------------------------------------------------------ real LIGGGHTS
def test_two_spheres_follow_liggghts_explicit_euler_exactly(liggghts_exe, tmp_path):
    """T1 - T2 after N steps is 100 K (1 - dt h_c (1/C1 + 1/C2))^N with h_c = 2 sqrt(pi) k a:
    the issue's 50.065 / 49.935 degC after 0.2 s."""
    d = L.particle_data([[0, 0, 0], [3.8e-3, 0, 0]], 2e-3, 8900.0)
    deck = L.heat_conduction_deck(d, [COPPER], 273.15, 1e-5, 20000, 5000, initial_temperature={1: 373.15})
    res = L.run_heat_conduction(deck, tmp_path, exe=liggghts_exe, progress=None)
    a = math.sqrt(2e-3 ** 2 - 1.9e-3 ** 2)
    h = 2.0 * math.sqrt(math.pi) * 385.0 * a
    C = 8900.0 * 172.0 * 4.0 / 3.0 * math.pi * 2e-3 ** 3
    table = res.temperature_table()
    assert list(table.index) == pytest.approx([0.0, 0.05, 0.1, 0.15, 0.2])
    for t, row in table.iterrows():
        n = round(t / 1e-5)
        diff = 100.0 * (1.0 - 1e-5 * 2.0 * h / C) ** n
        assert row[1] - row[2] == pytest.approx(diff, rel=1e-9, abs=1e-9)
        assert 0.5 * (row[1] + row[2]) == pytest.approx(323.15, abs=1e-9)
    assert table.loc[0.2, 1] - 273.15 == pytest.approx(50.065, abs=1e-3)
    c0 = res.contacts[0]
    assert len(c0) == 1 and c0["contact_area"].iloc[0] == pytest.approx(math.pi * a * a, rel=1e-5)
    assert -c0["heat_flux"].iloc[0] == pytest.approx(100.0 * h, rel=1e-5)


def test_a_failing_deck_surfaces_its_error_line(liggghts_exe, tmp_path):
    d = L.particle_data([[0, 0, 0], [3.8e-3, 0, 0]], 2e-3, 8900.0)
    deck = L.heat_conduction_deck(d, [COPPER], 273.15, 1e-5, 10, 5).deck.replace("hard_particles  yes\n", "")
    with pytest.raises(L.LiggghtsError) as err:
        L.run_deck(deck, tmp_path, files={"particles.data": L.format_data(d)}, exe=liggghts_exe, progress=None)
    assert err.value.error_line.startswith("ERROR: youngsModulus <= 1e9 required for SI units")
    assert err.value.error_line in str(err.value) and err.value.returncode != 0
    with pytest.raises(L.LiggghtsError, match="ERROR: Unknown command: not_a_command"):
        L.run_deck("units si\nnot_a_command 1\n", tmp_path / "b", exe=liggghts_exe, progress=None)


def test_timeout_and_missing_binary(liggghts_exe, tmp_path):
    slow = "variable i loop 100000000\nlabel l\nnext i\njump SELF l\n"
    with pytest.raises(L.LiggghtsError, match="did not finish within 1 s"):
        L.run_deck(slow, tmp_path, exe=liggghts_exe, timeout=1.0, progress=None)
    with pytest.raises(L.LiggghtsNotFound, match="apt-get install liggghts"):
        L.run_deck("units si\n", tmp_path, exe="/nonexistent/liggghts")
    with pytest.raises(L.LiggghtsNotFound, match="apt-get install liggghts"):
        L.find_liggghts("no-such-liggghts-binary")


def test_settle_a_packing_in_a_cylinder(liggghts_exe, tmp_path):
    R = 0.006
    mat = L.GranularMaterial(young=5e6, poisson=0.3, density=2500.0)
    walls = [L.CylinderWall("z", R), L.PlaneWall("z", 0.0)]
    box = [[-R - 1e-3, R + 1e-3]] * 2 + [[-1e-3, 0.04]]
    p = L.settle_packing(walls, L.CylinderRegion(R - 1e-3, 1e-3, 0.035), 150, [0.6e-3, 0.8e-3], [0.5, 0.5], mat, box,
                         2e-5, tmp_path, settle_time=1.0, ke_threshold=1e-10, exe=liggghts_exe, progress=None)
    assert p.n == 150 and p.settled and p.ke_per_particle < 1e-10
    assert set(np.round(p.radii, 9)) == {6e-4, 8e-4}
    rho_xy = np.hypot(p.centers[:, 0], p.centers[:, 1])
    assert np.all(rho_xy + p.radii <= R * 1.01) and np.all(p.centers[:, 2] - p.radii >= -0.01 * p.radii)
    assert p.centers[:, 2].max() < 0.02          # fell to the bottom from up to 35 mm


PLATE_STL = """solid plate
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 0
vertex 0.01 -0.01 0
vertex 0.01 0.01 0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 0
vertex 0.01 0.01 0
vertex -0.01 0.01 0
endloop
endfacet
endsolid plate
"""


def test_isothermal_plane_mesh_and_moving_particles(liggghts_exe, tmp_path):
    """A sphere on an isothermal floor warms as T_w - 100 K exp(-h t / C) per explicit step,
    h = 2 sqrt(pi) k a with a^2 = 2 r delta - delta^2; an STL floor gives the same numbers as
    the primitive plane; a soft sphere resting on the floor under gravity (moving particles,
    ``integrate``) warms as the same sphere held in place."""
    (tmp_path / "plate.stl").write_text(PLATE_STL)
    box = [[-0.01, 0.01]] * 2 + [[-0.005, 0.01]]
    d = L.particle_data([[0, 0, 1.9e-3]], 2e-3, 8900.0, box=box)
    out = {}
    for name, wall in (("plane", L.PlaneWall("z", 0.0, temperature=373.15)),
                       ("mesh", L.MeshWall(str(tmp_path / "plate.stl"), temperature=373.15))):
        deck = L.heat_conduction_deck(d, [COPPER], 273.15, 1e-6, 2000, 1000, walls=[wall])
        out[name] = L.run_heat_conduction(deck, tmp_path / name, exe=liggghts_exe, progress=None).temperature_table()
    soft = L.GranularMaterial(young=5e6, poisson=0.34, density=8900.0, conductivity=385.0, specific_heat=172.0)
    y_star = 5e6 / (2 * (1 - 0.34 ** 2))                   # sphere on a wall of the same material
    weight = 8900.0 * 4.0 / 3.0 * math.pi * 2e-3 ** 3 * 9.81
    delta_eq = (3 * weight / (4 * y_star * math.sqrt(2e-3))) ** (2 / 3)     # Hertz: F = 4/3 Y* sqrt(r) delta^1.5
    rest = L.particle_data([[0, 0, 2e-3 - delta_eq]], 2e-3, 8900.0, box=box)
    for name, integrate in (("held", False), ("resting", True)):
        deck = L.heat_conduction_deck(rest, [soft], 273.15, 1e-5, 20000, 5000, integrate=integrate, gravity=integrate,
                                      walls=[L.PlaneWall("z", 0.0, temperature=373.15)])
        out[name] = L.run_heat_conduction(deck, tmp_path / name, exe=liggghts_exe, progress=None).temperature_table()
    dl = 1e-4
    h = 2.0 * math.sqrt(math.pi) * 385.0 * math.sqrt(2 * 2e-3 * dl - dl * dl)
    C = 8900.0 * 172.0 * 4.0 / 3.0 * math.pi * 2e-3 ** 3
    for t, T in out["plane"][1].items():
        assert 373.15 - T == pytest.approx(100.0 * (1.0 - 1e-6 * h / C) ** round(t / 1e-6), rel=1e-9)
    np.testing.assert_allclose(out["mesh"].to_numpy(), out["plane"].to_numpy(), rtol=1e-12)
    assert out["held"][1].iloc[-1] > 280.0                  # it warms noticeably
    np.testing.assert_allclose(out["resting"].to_numpy(), out["held"].to_numpy(), rtol=1e-6)
    with pytest.raises(FileNotFoundError, match="STL"):
        L.wall_commands([L.MeshWall(str(tmp_path / "none.stl"))])


def test_settle_on_an_stl_floor(liggghts_exe, tmp_path):
    """The container may be an STL mesh: spheres settled on a triangulated floor rest on it."""
    (tmp_path / "plate.stl").write_text(PLATE_STL)
    R = 0.006
    mat = L.GranularMaterial(young=5e6, poisson=0.3, density=2500.0)
    walls = [L.CylinderWall("z", R), L.MeshWall(str(tmp_path / "plate.stl"))]
    box = [[-R - 1e-3, R + 1e-3]] * 2 + [[-1e-3, 0.03]]
    p = L.settle_packing(walls, L.CylinderRegion(R - 1e-3, 1e-3, 0.025), 60, [0.7e-3], [1.0], mat, box, 2e-5,
                         tmp_path / "run", settle_time=1.0, exe=liggghts_exe, progress=None)
    assert p.n == 60 and p.settled
    bottom = p.centers[:, 2] - p.radii
    assert bottom.min() > -0.02 * 0.7e-3 and np.sum(bottom < 0.05 * 0.7e-3) >= 10     # resting on the mesh


def test_bad_heat_deck_inputs_are_refused():
    d = L.particle_data([[0, 0, 0], [3.8e-3, 0, 0]], 2e-3, 8900.0)
    with pytest.raises(ValueError, match="temperature must be finite and > 0"):
        L.heat_conduction_deck(d, [COPPER], -5.0, 1e-5, 10, 5)
    with pytest.raises(ValueError, match="timestep must be > 0"):
        L.heat_conduction_deck(d, [COPPER], 300.0, 0.0, 10, 5)
    with pytest.raises(ValueError, match="atom ids not in the data"):
        L.heat_conduction_deck(d, [COPPER], 300.0, 1e-5, 10, 5, initial_temperature={7: 400.0})
    with pytest.raises(ValueError, match="area_correction needs young_original"):
        L.heat_conduction_deck(d, [COPPER], 300.0, 1e-5, 10, 5, area_correction=True)


def test_heat_deck_under_mpi_gives_the_same_temperatures(liggghts_exe, tmp_path):
    """The heat deck run by 2 MPI processes (``mpiexec -n 2 liggghts``, a 2 x 1 x 1 processor
    grid: each rank owns half the spheres and sees the other half's edge as ghosts) gives the
    same temperatures as one process, to the dump's precision: the cross-checks can run
    decomposed."""
    import shutil
    if shutil.which("mpiexec") is None and shutil.which("mpirun") is None:
        pytest.skip("no mpiexec")
    r = 1e-3
    pts = np.array([[2 * i * 0.98 * r, 2 * j * 0.98 * r, (1 + 2 * k) * 0.98 * r]
                    for i in range(10) for j in range(4) for k in range(3)]) - [9e-3, 3e-3, 0.0]
    box = [[-0.012, 0.012], [-0.006, 0.006], [-0.002, 0.01]]
    d = L.particle_data(pts, r, 8900.0, box=box)
    mat = L.GranularMaterial(young=1e8, poisson=0.3, density=8900.0, conductivity=385.0, specific_heat=172.0)
    tables, runs = {}, {}
    for ranks in (1, 2):
        deck = L.heat_conduction_deck(d, [mat], 273.15, 1e-6, 4000, 1000,
                                      walls=[L.PlaneWall("z", 0.0, temperature=373.15)])
        res = L.run_heat_conduction(deck, tmp_path / f"np{ranks}", exe=liggghts_exe, progress=None, ranks=ranks)
        tables[ranks], runs[ranks] = res.temperature_table(), res.run
    assert "2 by 1 by 1 MPI processor grid" in runs[2].text()
    assert (tables[1].to_numpy() - 273.15).max() > 10.0              # the floor heats the bed
    np.testing.assert_array_equal(tables[2].to_numpy(), tables[1].to_numpy())
    with pytest.raises(ValueError, match="ranks must be a whole number >= 1"):
        L.run_heat_conduction(deck, tmp_path / "bad", exe=liggghts_exe, progress=None, ranks=0)


def test_names_cannot_reach_the_deck_or_leave_the_work_directory(liggghts_exe, tmp_path):
    """Issue 36, item 8: a mesh path with a space and an embedded LIGGGHTS command works (the
    mesh is copied under the deck's own name) and runs nothing; file names with folder parts
    and values carrying a 'shell' command are refused."""
    odd = tmp_path / "my plates" / "plate x\nshell touch PWNED.stl"
    odd.parent.mkdir()
    odd.write_text(PLATE_STL)
    box = [[-0.01, 0.01]] * 2 + [[-0.005, 0.01]]
    d = L.particle_data([[0, 0, 1.9e-3]], 2e-3, 8900.0, box=box)
    deck = L.heat_conduction_deck(d, [COPPER], 273.15, 1e-6, 20, 10, walls=[L.MeshWall(str(odd), temperature=373.15)])
    assert "PWNED" not in deck.deck and "wall_mesh0.stl" in deck.deck
    L.run_heat_conduction(deck, tmp_path / "run", exe=liggghts_exe, progress=None)
    assert not list(tmp_path.rglob("PWNED*")) and not (Path.cwd() / "PWNED").exists()
    for bad in ("../escape.in", "/tmp/abs.data", "two words.data", ".hidden"):
        with pytest.raises(ValueError, match="not a plain file name"):
            L.run_deck("run 0", tmp_path / "w", files={bad: "x"}, exe=liggghts_exe)
    assert not (tmp_path / "escape.in").exists()
    with pytest.raises(ValueError, match="'shell' command"):
        L.render_deck("heat_conduction", data_file="x", walls="fix a all nve\nshell rm -rf /")
