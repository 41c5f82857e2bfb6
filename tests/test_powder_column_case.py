"""The pressed column (cases/powder_column.py) in the real YADE: Hertz-Mindlin contacts, the
contact law with the Hertz radius gives the exact chain resistance (measured 1e-5 %) and the
slope -1/3 of log R against log F (6e-6 %); the geometric radius about 1/sqrt(2) of R; a random
packing pressed between plate and lid, whose R is the network's of YADE's contact forces. And
the contact-radius models on a pair with exact answers (numpy only)."""
import math
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "powder_column.py")
sys.path.insert(0, os.path.join(ROOT, "cases"))


def test_contact_radius_models():
    from yade_electro.laws.factors import contact_radius, make_law
    from yade_electro.core.graph import ContactGraph
    r, delta = 1e-3, 1e-6
    g = ContactGraph(np.array([[0, 0, 0], [2 * r - delta, 0, 0]], float), np.array([r, r]), np.array([[0, 1]]))
    assert contact_radius(g, model="hertz")[0] == pytest.approx(math.sqrt(r / 2 * delta), rel=1e-9)
    assert contact_radius(g)[0] == pytest.approx(math.sqrt(r * delta - delta ** 2 / 4), rel=1e-6)
    assert make_law("contact", radius="hertz").factor(g)[0] == pytest.approx(2 * math.sqrt(r / 2 * delta), rel=1e-9)
    with pytest.raises(ValueError, match="radius must be one of"):
        make_law("liggghts", radius="jkr")


@pytest.mark.yade
def test_column_follows_the_hertz_chain(run_yade_script, tmp_path):
    row = run_yade_script(CASE, "--n", "6", "--random", "60", "--out", str(tmp_path), timeout=900, check=True).result
    assert row["case"] == "powder_column" and row["contacts"] == 5
    assert abs(row["slope_error_pct"]) < 1.0                 # the target
    assert abs(row["slope_error_pct"]) < 1e-3 and row["max_R_error_pct"] < 1e-3
    assert abs(row["slope_geometric"] + 1 / 3) < 2e-3
    for r in row["rows"]:
        assert r["R_geometric"] / r["R_hertz"] == pytest.approx(1 / math.sqrt(2), rel=2e-3)
    # the plate as an electrode: slope -1/3; YADE's wall contact has R* = r / 2 (measured), and
    # against that contact the plate resistance is exact
    assert abs(row["slope_error_pct_plate"]) < 1e-3
    assert row["plate_r_star_over_r"] == pytest.approx(0.5, rel=1e-5)
    assert row["max_R_error_pct_plate_vs_yade_wall"] < 1e-3
    # against Hertz's sphere on a half-space (R* = r) the plate contact's share of R, whose
    # radius is 2^(1/6) too large, comes out 1 - 2^(-1/6) low
    w = 2 ** (-1 / 3)                   # the plate contact's resistance over a sphere-sphere one
    share = w / (row["n"] - 1 + w)
    assert row["max_R_error_pct_plate"] == pytest.approx(100 * share * (1 - 2 ** (-1 / 6)), rel=1e-3)
    # the random packing between plate and lid: the engine's R (from the overlaps) is the R of
    # the network built from YADE's contact forces with Hertz's law, solved by SciPy
    assert row["random_n"] == 60
    rr = row["random_rows"]
    assert len(rr) == 5 and row["max_R_check_error_pct"] < 0.1
    assert all(a["R"] > b["R"] for a, b in zip(rr, rr[1:]))          # pressed harder, conducts better
    assert all(abs(r["plate_force_error"]) < 1e-3 for r in rr)
    # the contacts of the smallest force alone scale nearly as a chain; the contacts made on the way
    # make the packing's slope steeper
    assert abs(row["slope_fixed_contacts"] + 1 / 3) < 0.03
    assert row["slope_random"] < row["slope_fixed_contacts"] < -0.3
    # a surface film on every contact (Holm): the chain is exact with it too, its slope between the
    # constriction's -1/3 and the film's -2/3; the random bed steeper with the film than without
    assert row["max_R_error_pct_film"] < 1e-3 and abs(row["slope_error_pct_film"]) < 1e-3
    assert -2 / 3 < row["slope_film_exact"] < -1 / 3
    assert row["slope_random_film"] < row["slope_random"]


def test_a_contact_film_is_in_series_with_the_constriction():
    """Two spheres pressed together, a film of specific resistance s: R = rho / (2 a) + s / (pi a^2),
    electrically; the thermal factor does not see it."""
    from yade_electro.core.graph import ContactGraph
    from yade_electro.laws.factors import conductance, make_law
    r, delta, rho, s = 1e-3, 1e-6, 1e-7, 5e-12
    g = ContactGraph(np.array([[0, 0, 0], [2 * r - delta, 0, 0]], float), np.array([r, r]), np.array([[0, 1]]))
    a = math.sqrt(r / 2 * delta)
    c = conductance(g, rho, "contact", radius="hertz", film=s)
    assert 1 / c[0] == pytest.approx(rho / (2 * a) + s / (math.pi * a * a), rel=1e-12)
    law = make_law("contact", radius="hertz", film=s)
    assert law.factor(g)[0] == pytest.approx(2 * a, rel=1e-12)        # heat: the constriction only
    assert law.wall_film_resistance([r], [delta])[0] == pytest.approx(s / (math.pi * r * delta), rel=1e-12)
    with pytest.raises(ValueError, match="film must be finite and >= 0"):
        make_law("contact", film=-1.0)
