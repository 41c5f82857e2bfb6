"""Shared fixtures: the real YADE (in process or as ``yade-electro -n -x`` subprocess) and LIGGGHTS.

YADE and LIGGGHTS are required: a missing one fails the tests that need it, unless
``YADE_ELECTRO_ALLOW_SKIP=1`` is set, which turns those failures into skips.
Tests that use these fixtures are marked ``yade`` / ``liggghts`` automatically, so
``-m "not yade and not liggghts"`` (``make test-fast``) leaves them out.
"""
import collections
import json
import os
import shutil
import signal
import subprocess
import textwrap
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_TIMEOUT = 600.0  # s, for one yade script

YadeRun = collections.namedtuple("YadeRun", "returncode stdout stderr result")
YadeRun.__doc__ = """Outcome of one ``yade-electro -n -x`` run; ``result`` is the last JSON line of
stdout, parsed (None if there is none)."""

_AUTO_MARKS = {"yade_module": "yade", "yade_exe": "yade", "run_yade_script": "yade",
               "liggghts_exe": "liggghts"}


def pytest_collection_modifyitems(config, items):
    for item in items:
        for fixture, mark in _AUTO_MARKS.items():
            if fixture in getattr(item, "fixturenames", ()):
                item.add_marker(mark)


def _missing(what):
    """Fail (or skip, with YADE_ELECTRO_ALLOW_SKIP=1) because a required program is missing."""
    if os.environ.get("YADE_ELECTRO_ALLOW_SKIP") == "1":
        pytest.skip(what)
    pytest.fail("%s\nRun `make install` (scripts/install.sh), or set YADE_ELECTRO_ALLOW_SKIP=1 "
                "to skip the tests that need it." % what, pytrace=False)


def last_json_line(text):
    """The last line of ``text`` that parses as a JSON object or array, or None."""
    for line in reversed(text.splitlines()):
        line = line.strip()
        if line[:1] in ("{", "["):
            try:
                return json.loads(line)
            except ValueError:
                continue
    return None


@pytest.fixture(scope="session")
def yade_module():
    """The ``yade`` module, imported into this (Debian /usr/bin/python3) process."""
    from yade_electro.yade.runtime import import_yade
    try:
        return import_yade()
    except ImportError as exc:
        _missing(str(exc))


#: How the tests start YADE: yade-electro's launcher (YADE's own launcher script without its
#: remote servers), on Debian's interpreter, with this checkout on PYTHONPATH.
YADE_COMMAND = ["/usr/bin/python3", "-m", "yade_electro.yade.launcher"]


def yade_command():
    """The command list that runs ``yade`` (without open ports); fails if YADE is missing."""
    name = os.environ.get("YADE_ELECTRO_YADE", "yade")
    if shutil.which(name) is None:
        _missing("YADE launcher %r not found on PATH (Debian package `yade`)" % name)
    return list(YADE_COMMAND)


def repo_env(env=None):
    """The environment with this checkout first on PYTHONPATH."""
    run_env = dict(os.environ if env is None else env)
    run_env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO_ROOT), run_env.get("PYTHONPATH")) if p)
    return run_env


@pytest.fixture(scope="session")
def yade_exe():
    """The command (a list) that runs YADE's launcher without its remote servers."""
    return yade_command()


@pytest.fixture(scope="session")
def liggghts_exe():
    """Path of the LIGGGHTS executable (Debian package ``liggghts``)."""
    exe = "/usr/bin/liggghts" if os.access("/usr/bin/liggghts", os.X_OK) else shutil.which("liggghts")
    if exe is None:
        _missing("LIGGGHTS executable not found (/usr/bin/liggghts; Debian package `liggghts`)")
    return exe


@pytest.fixture
def run_yade_script(yade_exe, tmp_path):
    """Run a script with ``yade-electro -n -x`` (YADE without its remote servers) in a
    subprocess; returns a :data:`YadeRun`.

    ``run_yade_script(path_or_source, *args, timeout=600, cwd=None, env=None,
    check=False, repo_on_path=True)``

    - ``path_or_source``: a ``Path``, a ``str`` path ending in ``.py`` (relative paths are
      taken from the repository root), or the source text of a script.
    - ``args``: command-line arguments for the script (``sys.argv[1:]``).
    - ``cwd``: working directory, default a fresh temporary directory.
    - ``check``: fail the test, showing the output, if yade exits non-zero.
    - ``repo_on_path``: put this checkout first on PYTHONPATH, so the tree under test is
      the one imported even if the editable install points elsewhere.

    The script's figures are expected as one JSON line at the end of stdout: ``result``.
    """
    counter = [0]

    def run(path_or_source, *args, timeout=DEFAULT_TIMEOUT, cwd=None, env=None,
            check=False, repo_on_path=True):
        if isinstance(path_or_source, Path) or (
                "\n" not in path_or_source and path_or_source.endswith(".py")):
            script = Path(path_or_source)
            if not script.is_absolute():
                script = REPO_ROOT / script
            if not script.is_file():
                pytest.fail("yade script not found: %s" % script, pytrace=False)
        else:
            counter[0] += 1
            script = tmp_path / ("yade_script_%d.py" % counter[0])
            script.write_text(textwrap.dedent(path_or_source))
        run_env = repo_env(env) if repo_on_path else dict(os.environ if env is None else env)
        cmd = yade_exe + ["-n", "-x", str(script)] + [str(a) for a in args]
        proc = subprocess.Popen(cmd, cwd=str(cwd or tmp_path), env=run_env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, start_new_session=True)
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, err = proc.communicate()
            pytest.fail("yade timed out after %g s: %s\n--- stdout (tail)\n%s\n--- stderr (tail)\n%s"
                        % (timeout, " ".join(cmd), _tail(out), _tail(err)), pytrace=False)
        out = out.decode("utf-8", "replace")
        err = err.decode("utf-8", "replace")
        if check and proc.returncode != 0:
            pytest.fail("yade exited %d: %s\n--- stdout (tail)\n%s\n--- stderr (tail)\n%s"
                        % (proc.returncode, " ".join(cmd), _tail(out), _tail(err)),
                        pytrace=False)
        return YadeRun(proc.returncode, out, err, last_json_line(out))

    return run


def _tail(text, lines=40):
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    return "\n".join((text or "").splitlines()[-lines:])
