"""Keeping the MPI processes this package starts off the network: no socket of theirs listens
beyond loopback.

Measured with Open MPI 4.1.4 (Debian 12), ``ss -ltnp`` while each runs:

* a process that initialises MPI outside ``mpiexec`` (``import petsc4py`` for
  ``solver='petsc'``, a serial LIGGGHTS run) is an MPI *singleton*: it starts an ``orted``
  daemon and both listen on ``0.0.0.0`` and ``[::]`` (Open MPI's out-of-band channel and its
  TCP transport). With ``ess_singleton_isolated`` (no daemon: a singleton that never spawns
  needs none) and the transports ``self,vader`` (shared memory: no TCP), nothing listens;
  :func:`quiet_singleton` sets both for this process, :func:`singleton_env` for a child;
* ``mpiexec`` binds its out-of-band listener to every interface whatever
  ``oob_tcp_if_include`` says (the listener binds ``INADDR_ANY``; discussed on the Open MPI
  developers' list in 2015, unchanged in 4.1). :func:`private_network` runs it in a network
  namespace of its own (``unshare -n``, ``-rn`` when not root) whose only interface is
  loopback: its listeners are then reachable from that namespace's loopback alone. Where
  namespaces are not allowed the command is run as it is, with a warning.

Only what the package itself starts is changed: a user's own ``mpiexec`` runs across machines
are left alone (the variables are set only where not set, and never under ``mpiexec``).

Units: none.
"""
from __future__ import annotations

import functools
import os
import shutil
import subprocess
import warnings
from typing import List, Optional

__all__ = ["SINGLETON_ENV", "under_mpiexec", "quiet_singleton", "singleton_env", "private_network",
           "namespaces_available"]

#: Open MPI's settings for a process that runs alone: no daemon, no TCP transport
SINGLETON_ENV = {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_btl": "self,vader"}


def under_mpiexec(env: Optional[dict] = None) -> bool:
    """True when the process (or one started with ``env``) is a rank of ``mpiexec``."""
    env = os.environ if env is None else env
    return any(k in env for k in ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"))


def singleton_env(env: Optional[dict] = None) -> dict:
    """``env`` (default this process's) with :data:`SINGLETON_ENV` where not set, for a child
    that initialises MPI on its own (a serial LIGGGHTS run); unchanged under ``mpiexec``."""
    out = dict(os.environ if env is None else env)
    if not under_mpiexec(out):
        for k, v in SINGLETON_ENV.items():
            out.setdefault(k, v)
    return out


def quiet_singleton() -> None:
    """Set :data:`SINGLETON_ENV` in this process before it initialises MPI, unless it runs
    under ``mpiexec`` or the variables are set already."""
    if not under_mpiexec():
        for k, v in SINGLETON_ENV.items():
            os.environ.setdefault(k, v)


@functools.lru_cache(maxsize=None)
def namespaces_available() -> Optional[List[str]]:
    """The ``unshare`` options that make a private network namespace here (``['-n']`` as root,
    ``['-rn']`` otherwise), or None when none can be made (or ``ip`` is missing)."""
    unshare, ip = shutil.which("unshare"), shutil.which("ip")
    if unshare is None or ip is None:
        return None
    for opts in (["-n"], ["-rn"]) if hasattr(os, "geteuid") and os.geteuid() == 0 else (["-rn"],):
        try:
            r = subprocess.run([unshare, *opts, ip, "link", "set", "lo", "up"], capture_output=True, timeout=20,
                               stdin=subprocess.DEVNULL)
        except (OSError, subprocess.SubprocessError):
            continue
        if r.returncode == 0:
            return opts
    return None


def private_network(cmd: List[str]) -> List[str]:
    """``cmd`` (an ``mpiexec`` command line) run in a network namespace whose only interface
    is loopback, brought up first; ``cmd`` itself, with a warning, where none can be made."""
    opts = namespaces_available()
    if opts is None:
        warnings.warn("no private network namespace here (unshare -n is not allowed, or ip is missing): mpiexec "
                      "runs as it is, and Open MPI's daemon listens on every interface while it runs", stacklevel=2)
        return list(cmd)
    # a user namespace (-r) makes the user root inside, which mpiexec refuses unless told
    allow = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " if "-rn" in opts else ""
    return [shutil.which("unshare"), *opts, "sh", "-c", f'ip link set lo up && {allow}exec "$@"', "sh", *cmd]
