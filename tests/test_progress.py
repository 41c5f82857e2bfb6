"""Progress lines of long work (yade_electro.core.progress): pure Python, no YADE."""
import io

from yade_electro.core import progress as P


def test_nothing_printed_for_short_work():
    out = io.StringIO()
    p = P.Progress("x", "items", 10, every=60.0, stream=out)
    for k in range(10):
        p.update(k + 1)
    p.waiting("busy")
    p.done()
    assert out.getvalue() == ""


def test_lines_with_done_total_and_time_left():
    out = io.StringIO()
    p = P.Progress("bonding", "bonds set", 1000, every=0.0, stream=out)
    p.update(0)
    p.update(250)
    p.waiting("one step")
    p.done()
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("[bonding] bonds set: 0 of 1,000") and "time left unknown yet" in lines[0]
    assert "250 of 1,000" in lines[1] and "s left" in lines[1]
    assert "one step" in lines[2] and "so far" in lines[2]
    assert lines[3].startswith("[bonding] bonds set: done in")


def test_default_interval_read_when_the_report_starts(monkeypatch):
    monkeypatch.setattr(P, "PROGRESS_EVERY", 0.0)
    out = io.StringIO()
    p = P.Progress("x", "items", 2, stream=out)
    p.update(1)
    assert "1 of 2" in out.getvalue()


def test_jamming_shows_progress_within_trials(monkeypatch, capsys):
    """Every trial of the jamming (and the initial cloud's relaxation) reports while it runs;
    the packing is the same as without the lines."""
    import numpy as np
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.packing import dense_packing
    from yade_electro.packing import jamming
    rod = Cylinder((0, 0, 0), (0, 0, 5e-3), 1e-3)
    quiet = dense_packing(rod, n=150, seed=3, cache_dir=False)
    capsys.readouterr()
    monkeypatch.setattr(jamming, "PROGRESS_EVERY", 0.0)
    loud = dense_packing(rod, n=150, seed=3, cache_dir=False)
    err = capsys.readouterr().err.splitlines()
    assert any("relaxing the initial random cloud: FIRE step" in l for l in err) or \
        any("relaxing trial 1 " in l for l in err), err[:5]
    assert any("relaxing trial" in l and "of at most 3000" in l for l in err), err[:5]
    assert any("more trials of about" in l for l in err)
    assert np.array_equal(quiet.centers, loud.centers) and np.array_equal(quiet.radii, loud.radii)


def test_sweeps_print_runs_done_and_time_left(tmp_path, capsys):
    import os
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases"))
    import caselib
    rows = caselib.sweep_runs(lambda n, law: {"n": n, "law": law}, [10, 20], ["a"], str(tmp_path), "s.csv",
                              ["n", "law"], lambda row: f"n={row['n']}")
    err = capsys.readouterr().err
    assert len(rows) == 2
    assert "[sweep] runs: 1 of 2 in 0 s, about 0 s left" in err and "[sweep] runs: 2 of 2" in err
    assert (tmp_path / "s.csv").read_text().splitlines() == ["n,law", "10,a", "20,a"]


def test_tessellation_slabs_report_through_the_same_reporter(monkeypatch, capsys):
    from yade_electro.geometry import ghosts
    monkeypatch.setattr(P, "PROGRESS_EVERY", 0.0)
    report = ghosts.progress_lines(1234)
    report(1, 4, 0.1)
    report(4, 4, 0.2)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("[voronoi] 1,234 points, slabs tessellated: 1 of 4 in")
    assert err[-1].startswith("[voronoi] 1,234 points, slabs tessellated: done in")
