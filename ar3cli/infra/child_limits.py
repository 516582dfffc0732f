"""The limits every forked child of ar3cli lives under: memory, wall-clock time, and its parent's life.

A robot file under lint may come from a stranger's pull request, and pybullet, V-HACD or CoACD
read its meshes in C: a 2 GB sparse STL asks for more than 8 GB, a FIFO named as a mesh blocks
forever. So each child

- gets ``RLIMIT_AS``: it may map :func:`memory_limit` more than the address space it inherited
  (half of the physical memory, at most :data:`MAX_MEMORY_BYTES`, at least :data:`MIN_MEMORY_BYTES`;
  ``AR3CLI_CHILD_MEMORY_MB`` overrides it, 0 for no limit). Relative, because what a process has
  mapped before it forks varies: ~0.5 GB for ar3cli itself, several GB of reservations in a Ray
  worker (an absolute 4 GB cap there failed the next ``import lxml``). A child of
  ``sample-collisions`` on Romeo maps ~270 MB more, so the cap only stops runaway reads. Python
  then raises MemoryError (which comes back as a one-line error), or C code aborts (a one-line
  crash report);
- is given :func:`timeout` seconds of wall-clock time per file by the process that waits for it
  (the command's ``--timeout``, set with :func:`set_timeout`), then stopped;
- dies with its parent (``prctl(PR_SET_PDEATHSIG, SIGKILL)``), even when the parent was killed
  with SIGKILL and could not stop it: a worker left behind ran at 99% CPU for a minute and a half.

:func:`prepare` runs in the parent before it forks (once: it loads ``ctypes`` and reads the limit,
~2 ms), :func:`enter_child` is the first thing a forked child does (two or three system calls), so
starting a child stays as cheap as it was.
"""

from __future__ import annotations

import math
import os
import signal

DEFAULT_TIMEOUT_S = 120.0
"""Per file, for every command but sample-collisions. A ``lint-urdf --sim`` of Romeo or Talos (the
largest robots of example-robot-data) takes 1-3 s, so this leaves a slow, loaded CI machine a
margin of 40x or more, and a hung child still ends in two minutes."""
LONG_TIMEOUT_S = 900.0
"""Per file (per mesh for fix-collision) for the commands whose work grows with a number the user
gives. sample-collisions: its 10,000 default samples of Romeo take ~8 s on one core, 100,000 about
80 s. fix-collision: V-HACD on Talos's largest mesh (torso_2.STL, 24,072 faces) takes 1.7 s at the
default 100,000 voxels, 43 s at 1,000,000, over 120 s at 4,000,000. More needs a larger ``--timeout``."""
MIN_MEMORY_BYTES = 1 << 30
MAX_MEMORY_BYTES = 4 << 30
MEMORY_VARIABLE = "AR3CLI_CHILD_MEMORY_MB"
"""Environment variable: the address-space limit of each child in MB (0: no limit)."""

_timeout: float | None = DEFAULT_TIMEOUT_S
_PR_SET_PDEATHSIG = 1
_prctl: object = None
"""libc's prctl, once :func:`prepare` looked it up (False: not available)."""
_limit: int | None = None
"""The memory limit :func:`prepare` read last."""


def set_timeout(seconds: float | None) -> None:
    """Set the wall-clock limit of each child, per file (the command's ``--timeout``); 0, infinity or
    None: none. NaN is a usage error (it would silently mean no limit)."""
    global _timeout
    if seconds is not None and math.isnan(seconds):
        from ar3cli.errors import UserError

        raise UserError("--timeout must be a number of seconds (0: no limit), not nan")
    _timeout = seconds if seconds and math.isfinite(seconds) and seconds > 0 else None


def timeout() -> float | None:
    """Seconds a child may run for one file (None: no limit)."""
    return _timeout


def memory_limit() -> int | None:
    """Bytes of address space each child may map (None: no limit); see the module's docstring."""
    text = os.environ.get(MEMORY_VARIABLE, "").strip()
    if text:
        try:
            megabytes = float(text)
        except ValueError:
            megabytes = -1.0
        if math.isfinite(megabytes) and megabytes >= 0:
            return int(megabytes * (1 << 20)) or None
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return MAX_MEMORY_BYTES
    return max(MIN_MEMORY_BYTES, min(MAX_MEMORY_BYTES, physical // 2))


def describe_memory_limit() -> str:
    """``4 GB``-style text for messages (``no limit``)."""
    limit = memory_limit()
    return "no limit" if limit is None else f"{limit / (1 << 30):.3g} GB more than it starts with"


def prepare() -> None:
    """In the parent, before forking: look up what the children need (prctl once, the memory limit)."""
    global _prctl, _limit
    if _prctl is None:
        _prctl = False
        try:
            import ctypes

            _prctl = ctypes.CDLL(None, use_errno=True).prctl
        except (OSError, AttributeError):  # pragma: no cover - not Linux, or no libc symbol
            pass
    _limit = memory_limit()


def _mapped_bytes() -> int:
    """This process's address space now (Linux: the first field of ``/proc/self/statm``; 0 elsewhere)."""
    try:
        with open("/proc/self/statm", "rb") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def enter_child(parent: int) -> None:
    """In a just-forked child (after :func:`prepare` in the parent): die with ``parent`` (SIGKILL
    when it ends; ending now if it is already gone: it may have died before the request was made),
    and cap the address space (:func:`memory_limit`)."""
    if _prctl is None:
        prepare()
    if _prctl:
        _prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)  # type: ignore[operator]
    if os.getppid() != parent:
        os._exit(1)
    limit = _limit
    if limit is not None:
        import resource

        limit += _mapped_bytes()
        try:
            soft, hard = resource.getrlimit(resource.RLIMIT_AS)
            if hard != resource.RLIM_INFINITY:
                limit = min(limit, hard)
            if soft == resource.RLIM_INFINITY or soft > limit:
                resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
        except (ValueError, OSError):  # pragma: no cover - a platform without the limit
            pass
