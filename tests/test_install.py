"""The installation: scripts/install.sh left a stack that works from /usr/bin/python3 and
inside ``yade -n -x``, with Debian's numpy/scipy untouched, and LIGGGHTS runs."""
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy
import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]

SYSTEM_PY = "/usr/bin/python3"
DEBIAN_DIST = "/usr/lib/python3/dist-packages/"
INSTALL_SH = REPO_ROOT / "scripts" / "install.sh"
HINT = "run `make install` (scripts/install.sh) in %s" % REPO_ROOT

PROBE = """
import json, sys
import numpy, scipy, pyamg, skfem, yade_electro
print(json.dumps({"yade_electro": yade_electro.__file__, "executable": sys.executable,
                  "numpy": numpy.__version__, "numpy_file": numpy.__file__,
                  "scipy": scipy.__version__, "scipy_file": scipy.__file__,
                  "pyamg": pyamg.__version__, "skfem": skfem.__version__}))
"""


def debian_version(package):
    """Upstream version of an installed Debian package: '1:1.24.2-1+deb12u1' -> '1.24.2'."""
    out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", package],
                         capture_output=True, text=True, check=True).stdout
    return out.split(":", 1)[-1].rsplit("-", 1)[0].split("+")[0]


def clean_env():
    """This environment without PYTHONPATH, so only the installed package can be imported."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def assert_stack(info, where):
    assert Path(info["yade_electro"]).resolve().is_relative_to(REPO_ROOT), (
        "%s imports yade_electro from %s, not from this checkout: %s"
        % (where, info["yade_electro"], HINT))
    for name in ("numpy", "scipy"):
        assert info[name + "_file"].startswith(DEBIAN_DIST), (
            "%s: %s %s comes from %s, not from Debian's python3-%s: a pip copy shadows it"
            % (where, name, info[name], info[name + "_file"], name))
        assert info[name] == debian_version("python3-" + name), (where, name, info[name])


def test_system_python_imports_the_stack(tmp_path):
    proc = subprocess.run([SYSTEM_PY, "-c", PROBE], cwd=tmp_path, env=clean_env(),
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, "%s\n%s" % (proc.stderr, HINT)
    assert_stack(json.loads(proc.stdout.strip().splitlines()[-1]), SYSTEM_PY)


def test_yade_imports_the_stack(run_yade_script, tmp_path):
    run = run_yade_script(PROBE, env=clean_env(), repo_on_path=False, timeout=120)
    assert run.returncode == 0, "%s\n%s" % (run.stderr[-3000:], HINT)
    assert run.result is not None, run.stdout
    assert os.path.realpath(run.result["executable"]).startswith("/usr/bin/python3")
    assert_stack(run.result, "yade -n -x")


def test_tests_run_on_debian_numpy():
    assert numpy.__file__.startswith(DEBIAN_DIST), (
        "pytest runs on %s with numpy from %s: run the tests with %s -m pytest (make test)"
        % (sys.executable, numpy.__file__, SYSTEM_PY))
    assert numpy.__version__ == debian_version("python3-numpy")


def test_pyamg_and_skfem_solve():
    import pyamg
    from skfem import Basis, ElementTetP1, MeshTet, condense, solve
    from skfem.models.poisson import laplace, unit_load

    A = pyamg.gallery.poisson((30, 30), format="csr")
    b = numpy.ones(A.shape[0])
    x = pyamg.smoothed_aggregation_solver(A).solve(b, tol=1e-10)
    assert numpy.linalg.norm(b - A @ x) < 1e-8 * numpy.linalg.norm(b)

    basis = Basis(MeshTet().refined(3), ElementTetP1())
    u = solve(*condense(laplace.assemble(basis), unit_load.assemble(basis),
                        D=basis.mesh.boundary_nodes()))
    # -lap u = 1 on the unit cube, u = 0 on its boundary: u(centre) = 0.05620...
    assert u.max() == pytest.approx(0.0562, rel=0.05)


def test_import_yade_in_process(yade_module):
    from yade_electro.yade.runtime import in_yade
    assert hasattr(yade_module, "O") and in_yade()


def test_import_yade_error_says_how_to_install(tmp_path):
    code = ("from yade_electro.yade import runtime as r\n"
            "r.yade_python_dirs = lambda: []\n"
            "try:\n    r.import_yade()\nexcept ImportError as e:\n    print(e)\n")
    env = dict(clean_env(), PYTHONPATH=str(REPO_ROOT))
    out = subprocess.run([SYSTEM_PY, "-c", code], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=60).stdout
    assert "make install" in out and "apt-get install yade" in out and "/usr/bin/python3" in out


def test_yade_script_result_and_args(run_yade_script):
    run = run_yade_script("""
        import json, sys
        from yade import O
        print("not json {")
        print(json.dumps({"argv": sys.argv[1:], "bodies": len(O.bodies)}))
        """, "--n", 5, check=True, timeout=120)
    assert run.result == {"argv": ["--n", "5"], "bodies": 0}


def test_liggghts_runs_a_trivial_deck(liggghts_exe, tmp_path):
    deck = ("units si\natom_style granular\nboundary p p p\n"
            "region box block 0 1 0 1 0 1 units box\ncreate_box 1 box\n"
            "variable x equal 6*7\nprint \"LIGGGHTS_OK ${x}\"\n")
    # stdbuf: LIGGGHTS loses its last messages when stdout is a pipe and it aborts
    proc = subprocess.run(["stdbuf", "-o0", "-e0", liggghts_exe, "-log", "none", "-nocite"],
                          input=deck, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "LIGGGHTS_OK 42" in proc.stdout, proc.stdout + proc.stderr


@pytest.mark.skipif(not INSTALL_SH.is_file(), reason="no scripts/install.sh")
def test_install_script_plans_a_fresh_machine():
    """--dry-run on a machine where all is present plans nothing; with everything assumed
    missing it plans apt-get for the Debian packages and pip --no-deps for the rest."""
    def dry_run(missing=""):
        env = dict(clean_env(), YADE_ELECTRO_ASSUME_MISSING=missing)
        proc = subprocess.run(["bash", str(INSTALL_SH), "--dry-run"], env=env,
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stdout + proc.stderr
        return [l for l in proc.stdout.splitlines() if l.startswith("[install] + ")]

    assert dry_run() == [], HINT
    plan = dry_run("yade liggghts python3-meshio pyamg scikit-fem yade-electro")
    apt = [l for l in plan if " apt-get install " in l]
    assert len(apt) == 1 and apt[0].split()[-3:] == ["yade", "liggghts", "python3-meshio"], plan
    assert any(" apt-get update" in l for l in plan), plan
    pip = [l for l in plan if " pip install " in l]
    assert len(pip) == 2 and all("--no-deps" in l and "--break-system-packages" in l
                                 for l in pip), pip
    assert "pyamg==" in pip[0] and "scikit-fem==" in pip[0] and " -e " in pip[1], pip


def test_the_kernels_were_built_at_install_and_need_no_compiler(tmp_path):
    # every compiled kernel is there, and a run with no compiler on the PATH uses them
    script = tmp_path / "no_compiler.py"
    script.write_text(textwrap.dedent("""
        import glob, os, json
        import numpy as np
        from yade_electro import native
        from yade_electro.native.loader import HERE, library_path
        names = [os.path.basename(p)[:-4] for p in glob.glob(os.path.join(HERE, "*.cpp"))]
        built = {n: str(library_path(n)) for n in names if n != "delaunay_cgal"}
        helper = str(native.cgal_executable())
        rng = np.random.default_rng(1)
        pts = rng.random((2000, 3))
        from yade_electro.geometry.tessellation import tessellate
        t = tessellate(pts, 2000, backend="cgal")
        print(json.dumps({"built": built, "helper": helper, "ridges": int(t.n_ridges)}))
    """))
    env = dict(os.environ, PATH=str(tmp_path))                 # no g++, no cc: nothing to compile with
    res = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert len(out["built"]) == 9 and out["ridges"] > 0
    assert all(path.startswith(str(REPO_ROOT)) for path in out["built"].values())
