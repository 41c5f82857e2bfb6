"""Run Debian's LIGGGHTS 3.8.0 on a deck and report what it said.

Measured on this LIGGGHTS: when its stdout is a pipe and it aborts (``ERROR: ...``, then
``MPI_Abort``), the buffered output is lost, error line included. The runner therefore starts
it under ``stdbuf -o0 -e0`` with stdout going to a file in the work directory, and also keeps
LIGGGHTS' own log (``-log``); the first ``ERROR`` line of either is raised to the caller as
:class:`LiggghtsError`. A run longer than ``timeout`` is killed (its log is kept), and a
missing binary raises :class:`LiggghtsNotFound` with the install command.
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

__all__ = ["LiggghtsError", "LiggghtsNotFound", "LiggghtsRun", "find_liggghts", "mpi_command", "run_deck"]

INSTALL_HINT = "install it with `apt-get install liggghts` (Debian 12), or pass exe= the path of a LIGGGHTS binary"


class LiggghtsError(RuntimeError):
    """LIGGGHTS stopped on an error, or ran out of time. ``error_line`` is its ``ERROR`` line
    (or None), ``log`` the path of its log."""

    def __init__(self, message, error_line=None, log=None, returncode=None):
        super().__init__(message)
        self.error_line, self.log, self.returncode = error_line, log, returncode


class LiggghtsNotFound(FileNotFoundError):
    """No LIGGGHTS executable."""


@dataclass(frozen=True)
class LiggghtsRun:
    """A finished run: work directory, deck, log and stdout files, wall time [s], the
    warnings LIGGGHTS printed, and its last thermo line."""

    workdir: Path
    deck: Path
    log: Path
    stdout: Path
    elapsed_s: float
    warnings: tuple
    last_thermo: Optional[str]

    def text(self) -> str:
        """LIGGGHTS' screen output."""
        return self.stdout.read_text(errors="replace")


def find_liggghts(exe=None) -> str:
    """Path of the LIGGGHTS executable: ``exe``, else ``$YADE_ELECTRO_LIGGGHTS``, else
    ``liggghts`` on the PATH."""
    name = exe or os.environ.get("YADE_ELECTRO_LIGGGHTS") or "liggghts"
    path = name if os.sep in str(name) else shutil.which(name)
    if not path or not os.access(path, os.X_OK):
        raise LiggghtsNotFound(f"LIGGGHTS executable {name!r} not found; {INSTALL_HINT}")
    return str(path)


_ERROR = re.compile(r"^\s*ERROR(?: on proc \d+)?:\s*(.*)$")
_WARNING = re.compile(r"^\s*WARNING:\s*(.*)$")
_THERMO = re.compile(r"^\s*\d+\s+\d+\s")


def _scan(path: Path):
    error, warnings, thermo = None, [], None
    if not path.exists():
        return error, warnings, thermo
    for line in path.read_text(errors="replace").splitlines():
        m = _ERROR.match(line)
        if m and error is None:
            error = "ERROR: " + m.group(1).strip()
        w = _WARNING.match(line)
        if w:
            warnings.append(w.group(1).strip())
        if _THERMO.match(line):
            thermo = line.strip()
    return error, warnings, thermo


def mpi_command(ranks: int) -> list:
    """The launcher of ``ranks`` MPI processes: ``mpiexec -n ranks`` (Open MPI's
    ``--oversubscribe``, so that more ranks than cores run, and ``--allow-run-as-root`` when
    run as root, as in a container); ValueError for ranks < 1, LiggghtsNotFound without
    ``mpiexec``."""
    if not isinstance(ranks, (int, np.integer)) or isinstance(ranks, bool) or ranks < 1:
        raise ValueError(f"ranks must be a whole number >= 1, got {ranks!r}")
    launcher = shutil.which("mpiexec") or shutil.which("mpirun")
    if launcher is None:
        raise LiggghtsNotFound("ranks > 1 needs mpiexec (Open MPI: `apt-get install openmpi-bin`)")
    cmd = [launcher, "--oversubscribe"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    return cmd + ["-n", str(int(ranks))]


def run_deck(deck, workdir, files=None, exe=None, timeout: float = 600.0, deck_name: str = "in.liggghts",
             progress: Optional[float] = 10.0, total_steps: Optional[int] = None,
             total_is_bound: bool = False, ranks: int = 1) -> LiggghtsRun:
    """Write ``deck`` (the text of an input deck) and ``files`` (name -> text) into
    ``workdir`` and run LIGGGHTS on it there.

    Parameters
    ----------
    deck : str
        The input deck (e.g. from :func:`~yade_electro.liggghts.deck.render_deck`).
    workdir : path
        Created if needed; the deck, its files, ``log.liggghts``, ``stdout.txt`` and the dumps
        are there.
    files : dict name -> str, bytes or path, optional
        Further input files (data file, included command files, meshes to copy), each name a
        plain file name (:func:`~yade_electro.liggghts.deck.safe_file_name`: it stays in
        ``workdir``).
    exe : str, optional
        LIGGGHTS binary (see :func:`find_liggghts`).
    timeout : float
        Seconds before the run is killed (then :class:`LiggghtsError`).
    progress : float or None
        Print LIGGGHTS' last thermo line every ``progress`` seconds of a long run (None: quiet).
    total_steps : int, optional
        With ``progress``: the steps expected, for an estimate of the time left;
        ``total_is_bound``: they are at most (a run that may stop early, as settling does).
    ranks : int
        MPI processes (``mpiexec -n ranks liggghts ...``, LIGGGHTS' own domain decomposition;
        1: a plain run). The dumps are gathered by LIGGGHTS into one file either way.

    Raises
    ------
    LiggghtsNotFound, LiggghtsError
    """
    from .deck import safe_file_name
    binary = find_liggghts(exe)
    for name in list(files or {}) + [deck_name]:
        safe_file_name(name, "run_deck")
    work = Path(workdir)
    work.mkdir(parents=True, exist_ok=True)
    for name, content in (files or {}).items():
        if isinstance(content, (bytes, bytearray)):
            (work / name).write_bytes(bytes(content))
        elif isinstance(content, os.PathLike):
            shutil.copyfile(content, work / name)
        else:
            (work / name).write_text(content)
    deck_path = work / deck_name
    deck_path.write_text(deck)
    log, out = work / "log.liggghts", work / "stdout.txt"
    for p in (log, out):
        if p.exists():
            p.unlink()
    from ..core.mpi_network import private_network, singleton_env
    cmd = [binary, "-in", deck_path.name, "-log", log.name, "-nocite"]
    if shutil.which("stdbuf"):
        cmd = ["stdbuf", "-o0", "-e0"] + cmd
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    if ranks != 1:                # off the network: mpiexec in a namespace of its own (loopback only)
        cmd = private_network(mpi_command(ranks) + cmd)
    else:                         # LIGGGHTS is an MPI program: alone, a singleton with no daemon, no TCP
        env = singleton_env(env)
    t0 = time.perf_counter()
    last_print = t0
    with open(out, "w") as fh:
        proc = subprocess.Popen(cmd, cwd=work, stdout=fh, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                env=env, start_new_session=True)
        while True:
            try:
                rc = proc.wait(timeout=0.5)
                break
            except subprocess.TimeoutExpired:
                pass
            now = time.perf_counter()
            if now - t0 > timeout:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                _, _, thermo = _scan(out)
                raise LiggghtsError(f"LIGGGHTS did not finish within {timeout:g} s and was stopped (deck "
                                    f"{deck_path}; last thermo line: {thermo!r}); raise timeout= or shorten "
                                    "the run", log=log, returncode=None)
            if progress and now - last_print >= progress:
                last_print = now
                _, _, thermo = _scan(out)
                _print_progress(thermo, now - t0, total_steps, total_is_bound)
    elapsed = time.perf_counter() - t0
    error, warnings, thermo = _scan(out)
    if error is None:
        error = _scan(log)[0]
    if error is not None or rc != 0:
        line = error or f"LIGGGHTS exited with code {rc} without an ERROR line"
        tail = "\n".join(out.read_text(errors="replace").splitlines()[-5:]) if out.exists() else ""
        raise LiggghtsError(f"LIGGGHTS stopped: {line}\n  deck: {deck_path}\n  log: {log}\n  last output:\n{tail}",
                            error_line=error, log=log, returncode=rc)
    return LiggghtsRun(workdir=work, deck=deck_path, log=log, stdout=out, elapsed_s=elapsed,
                       warnings=tuple(warnings), last_thermo=thermo)


def _print_progress(thermo, elapsed, total_steps, total_is_bound=False):
    msg = f"[liggghts] {elapsed:6.0f} s"
    if thermo:
        msg += f", step {thermo.split()[0]}"
        if total_steps:
            step = int(thermo.split()[0])
            if 0 < step < total_steps:
                most = "at most " if total_is_bound else ""
                msg += f" of {most}{total_steps}, {most}about {elapsed * (total_steps - step) / step:.0f} s left"
    print(msg, file=sys.stderr, flush=True)
