"""``yade-electro``: run YADE scripts and ``yade-batch`` campaigns without YADE's open ports.

Every ``yade script.py`` (also ``yade -n -x``, and every job of ``yade-batch``) starts two
servers before the script runs (``yade.remote.runServers``): a Python prompt on port 9000 of
*all* interfaces (although its banner says localhost), guarded by a six-letter cookie drawn
from one word's letters and printed to the log, and an unauthenticated XMLRPC server on port
21000. On a shared or cluster node that is a remote Python shell for whoever guesses the
cookie. YADE skips them only when it is imported as a module or runs under MPI.

This launcher runs Debian's own ``yade`` launcher script, unchanged, in this process, with
one difference: ``yade.remote.runServers`` does nothing. Everything else (options, the
script's namespace, ``-x``, ``readParamsFromTable``) is YADE's::

    yade-electro -n -x script.py [args]          # instead of:  yade -n -x script.py [args]
    yade-electro batch table script.py [opts]    # instead of:  yade-batch table script.py
    yade-electro gather 'logs/*.log' --out t.csv # the jobs' final JSON lines in one table

``batch`` runs ``yade-batch`` with its jobs started by this launcher (``--executable``) and
without its own HTTP summary server (port 9080 on all interfaces): the jobs' logs are the
record. ``gather`` reads those logs (:mod:`yade_electro.post.campaign`; no YADE needed).
``python3 -m yade_electro.yade.launcher`` is the same command.

Environment: ``YADE_ELECTRO_YADE`` / ``YADE_ELECTRO_YADE_BATCH`` name other YADE launchers.
"""
from __future__ import annotations

import importlib.abc
import importlib.machinery
import os
import re
import runpy
import shutil
import sys

__all__ = ["main", "disable_remote_servers", "find_launcher"]

NOTICE = "yade-electro: YADE's remote servers (Python prompt :9000, XMLRPC :21000) are not started\n"


def _no_servers():
    sys.stderr.write(NOTICE)


class _PatchedLoader(importlib.abc.Loader):
    def __init__(self, loader):
        self._loader = loader

    def create_module(self, spec):
        return self._loader.create_module(spec)

    def exec_module(self, module):
        self._loader.exec_module(module)
        module.runServers = _no_servers


class _RemoteFinder(importlib.abc.MetaPathFinder):
    """Finds ``yade.remote`` with the other finders and hands back a loader that replaces its
    ``runServers`` once the module has run."""

    def find_spec(self, name, path, target=None):
        if name != "yade.remote":
            return None
        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        if spec is None or spec.loader is None:
            return None
        spec.loader = _PatchedLoader(spec.loader)
        return spec


def disable_remote_servers() -> None:
    """Make ``yade.remote.runServers`` a no-op in this process (before or after the import)."""
    mod = sys.modules.get("yade.remote")
    if mod is not None:
        mod.runServers = _no_servers
        return
    if not any(isinstance(f, _RemoteFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _RemoteFinder())


def find_launcher(name: str, env: str) -> str:
    """Path of a YADE launcher script (``yade``, ``yade-batch``)."""
    exe = os.environ.get(env) or shutil.which(name)
    if not exe:
        raise SystemExit(f"yade-electro: {name!r} not found on PATH; install YADE (`make install`, or "
                         f"`apt-get install yade`) or set {env}")
    return os.path.realpath(exe)


def _disable_batch_http():
    import http.server

    class NoHTTPServer(http.server.HTTPServer):
        def __init__(self, *a, **k):
            raise OSError("yade-electro: yade-batch's HTTP summary server is not started")
    http.server.HTTPServer = NoHTTPServer
    sys.stderr.write("yade-electro: yade-batch's HTTP summary server (port 9080) is not started; "
                     "read the jobs' logs\n")


def _self_command() -> str:
    """The shell command that starts this launcher, for yade-batch's ``--executable``
    (yade-batch runs its jobs through the shell)."""
    import shlex
    return f"{shlex.quote(sys.executable)} -m yade_electro.yade.launcher"


def made_log_directories(args) -> list:
    """Create the directories the jobs' logs go to. yade-batch replaces ``$`` in ``--log`` by
    the script's path as given (``cases/x.py``: a subdirectory), ``%`` by the line number and
    ``@`` by the description, and it hangs, its jobs never started, when that directory does
    not exist. Returns the directories created."""
    pattern, positional = "$.@.log", []
    it = iter(args)
    for a in it:
        if a == "--log":
            pattern = next(it, pattern)
        elif a.startswith("--log="):
            pattern = a.split("=", 1)[1]
        elif not a.startswith("-"):
            positional.append(a)
    scripts = [p for p in positional if p.endswith(".py")] or [""]
    made = []
    for script in scripts:
        d = os.path.dirname(pattern.replace("$", script))
        if d and "@" not in d and "%" not in d and not os.path.isdir(d):
            os.makedirs(d, exist_ok=True)
            made.append(d)
    return made


_SHELL_SAFE = re.compile(r"^[A-Za-z0-9_./+=:,@%-]+$")


def check_batch_words(args) -> None:
    """Refuse what yade-batch would put unquoted into a job's shell command (it runs jobs with
    ``os.system``): a script name, or a table's ``!SCRIPT``, ``!EXEC`` or environment cell,
    with characters the shell reads (spaces, ``; | & $ ` < > ( )``, quotes, newlines).
    SystemExit naming the word."""
    positional = [a for a in args if not a.startswith("-")]
    for a in positional:
        if a.endswith(".py") and not _SHELL_SAFE.match(a):
            raise SystemExit(f"yade-electro batch: the script name {a!r} has characters the shell would read "
                             "(yade-batch runs each job through the shell, unquoted): rename it")
    for a in positional:
        if a.endswith(".py") or not os.path.isfile(a):
            continue
        rows = [ln.split() for ln in open(a, errors="replace").read().splitlines()
                if ln.strip() and not ln.lstrip().startswith("#")]
        if not rows:
            continue
        head = rows[0]
        for n, row in enumerate(rows[1:], start=2):
            for col, val in zip(head, row):
                if col.startswith("!") and col not in ("!AFFINITY", "!COUNT") and not _SHELL_SAFE.match(val):
                    raise SystemExit(f"yade-electro batch: table {a!r}, row {n}, column {col}: {val!r} has characters "
                                     "the shell would read (yade-batch puts it unquoted into the job's command)")


def main(argv=None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["gather"]:
        from ..post.campaign import main as gather_main
        sys.exit(gather_main(argv[1:]))
    if argv[:1] == ["batch"]:
        args = argv[1:]
        if not any(a == "--executable" or a.startswith("--executable=") for a in args):
            args = ["--executable", _self_command()] + args
        check_batch_words(args)
        _disable_batch_http()
        made_log_directories(args)
        path = find_launcher("yade-batch", "YADE_ELECTRO_YADE_BATCH")
        sys.argv = [path] + args
        _run_as_main(path)
        return
    disable_remote_servers()
    path = find_launcher("yade", "YADE_ELECTRO_YADE")
    sys.argv = [path] + argv
    _run_as_main(path)


def _run_as_main(path):
    # YADE evaluates ``__builtins__.name = ...`` in __main__: there __builtins__ must be the
    # module (as in a real __main__), not the dict exec() would put in
    import builtins
    runpy.run_path(path, init_globals={"__builtins__": builtins}, run_name="__main__")


if __name__ == "__main__":
    main()
