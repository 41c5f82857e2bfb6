"""Resolved grains moved by real YADE (cases/grain_stack.py --quick): the engine against the
network made without YADE and against the finite-element answer, the pressure law fed by the
DEM's forces against the weights' closed form; and the engine's refusals when it is built."""


def test_grain_stack_quick(run_yade_script):
    res = run_yade_script("cases/grain_stack.py", "--quick", check=True, timeout=900)
    out = res.result
    d, s = out["two_discs"], out["stack"]
    assert d["engine_vs_network_K"] < 1e-9, out            # the engine's plumbing: the same network
    assert d["engine_vs_fem_pct"] < 1.0, out               # paper 003's two particles, 300 elements each
    assert len(s["contacts"]) == s["grains"] - 1 and all(a > 1e-4 for a in s["contact_area_m2"]), s
    assert all(abs(f - 1.0) < 0.01 for f in s["force_over_weight"]), s
    assert s["step_ratio_vs_dem_forces_pct"] < 0.2 and s["step_ratio_error_pct"] < 1.0, s
    assert s["contact_computations_falling"] > 0


REFUSED = """
from yade_electro.yade import HeatEngine, Material, Reader
from yade_electro.yade.grains import add_grain, grain_law
from yade_electro.network.grain_law import GrainSet
from yade_electro.packing.grains import grain_template
from yade_electro.geometry.shapes import Box
t = grain_template(Box((-5e-3, -5e-3, -2e-3), (5e-3, 5e-3, 2e-3)), 60, seed=2)
gs = GrainSet()
add_grain(gs, t, (0, 0, 0))
mat = Material(density=7800, specific_heat=500, conductivity=50.0)
for reader in (Reader(bonds="contacts"), Reader(bonds="contacts", clumps="lumped")):
    try:
        HeatEngine(material=mat, law=grain_law(gs, 1e-4), reader=reader, temperature=300.0)
    except ValueError as exc:
        print("REFUSED", exc)
for bad in (dict(position=(0, 0)), dict(rotation=[[1, 0, 0], [0, 1, 0], [0, 0, -1]])):
    try:
        add_grain(gs, t, **bad)
    except ValueError as exc:
        print("REFUSED", exc)
try:
    grain_law(gs, -2.0)
except Exception as exc:
    print("REFUSED", type(exc).__name__, exc)
from yade_electro.yade import Law
try:
    HeatEngine(material=mat, law=Law("grains", grains=gs, contact_resistance=float("nan")),
               reader=Reader(bonds="contacts", clumps="resolved"), temperature=300.0)
except Exception as exc:
    print("REFUSED", type(exc).__name__, exc)
"""


def test_grain_engines_refuse_bad_input_when_built(run_yade_script):
    res = run_yade_script(REFUSED, check=True, timeout=300)
    lines = [ln for ln in res.stdout.splitlines() if ln.startswith("REFUSED")]
    assert len(lines) == 6, res.stdout[-2000:]
    assert all("clumps='resolved'" in ln for ln in lines[:2]), lines
    assert "position must be 3 finite numbers" in lines[2]
    assert "rotation must be a 3x3 rotation matrix" in lines[3]
    assert all("BoundaryConditionError" in ln and "finite and >= 0" in ln for ln in lines[4:]), lines
