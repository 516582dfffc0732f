"""install-check: is this Python environment able to run ar3cli and PyBullet properly?

Each check returns a :class:`Check` with a status (``ok``, ``warn``, ``fail``, ``info``), a
detail, and, when not ok, a hint that says exactly what to run. A check that crashes becomes a
``fail`` with the exception as its detail: the doctor itself never raises.
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata
import os
import platform
import statistics
import struct
import sys
import time
from collections.abc import Callable
from pathlib import Path

from ar3cli.install_check.record import Check
from ar3cli.sim.capture import capture_fds

MIN_PYTHON = (3, 10)
STEPS = 240


def _version(distribution: str) -> str:
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return "unknown version"


def check_python() -> Check:
    bits = struct.calcsize("P") * 8
    version = platform.python_version()
    if sys.version_info < MIN_PYTHON:
        return Check("python", "fail", f"Python {version} ({bits}-bit)",
                     f"install Python >= {MIN_PYTHON[0]}.{MIN_PYTHON[1]} and recreate the environment")
    if bits != 64:
        return Check("python", "fail", f"Python {version} is {bits}-bit",
                     "install a 64-bit Python: pybullet wheels are 64-bit only")
    return Check("python", "ok", f"Python {version} ({bits}-bit, {platform.machine()}, {sys.executable})")


def check_pybullet() -> Check:
    try:
        with capture_fds():
            import pybullet
    except ImportError as exc:
        return Check("pybullet", "fail", f"cannot import pybullet: {exc}", "pip install pybullet")
    numpy_enabled = bool(pybullet.isNumpyEnabled())
    return Check("pybullet", "ok", f"pybullet {_version('pybullet')} (API {pybullet.getAPIVersion()}, "
                                   f"numpy support {'on' if numpy_enabled else 'off'})")


def check_numpy() -> Check:
    """numpy's version, and whether pybullet hands camera images back as numpy arrays."""
    try:
        import numpy
    except ImportError as exc:
        return Check("numpy", "fail", f"cannot import numpy: {exc}", "pip install numpy")
    from ar3cli.sim.session import Session

    with Session() as session:
        image = session.p.getCameraImage(8, 8, renderer=session.p.ER_TINY_RENDERER, physicsClientId=session.client)
    rgb = image[2]
    if not isinstance(rgb, numpy.ndarray):
        return Check("numpy", "warn", f"numpy {numpy.__version__}; pybullet returns camera images as "
                                      f"{type(rgb).__name__}, not numpy arrays (slow image handling)",
                     "pip install --force-reinstall --no-binary pybullet pybullet  # build it against numpy")
    return Check("numpy", "ok", f"numpy {numpy.__version__}; getCameraImage returns numpy arrays "
                                f"(shape {tuple(rgb.shape)})")


def _small_scene(session) -> list[int]:
    """A ground plane and a stack of boxes falling onto it: enough contacts to exercise the solver."""
    p, client = session.p, session.client
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    p.createMultiBody(0, plane, physicsClientId=client)
    box = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.05, 0.05, 0.05], physicsClientId=client)
    return [p.createMultiBody(0.2, box, basePosition=[0.01 * i, 0.0, 0.1 + 0.12 * i], physicsClientId=client)
            for i in range(8)]


def _final_states(seconds_per_step: list[float] | None = None) -> list[tuple]:
    from ar3cli.sim.session import Session

    with Session() as session:
        bodies = _small_scene(session)
        for _ in range(STEPS):
            start = time.perf_counter()
            session.step()
            if seconds_per_step is not None:
                seconds_per_step.append(time.perf_counter() - start)
        return [session.p.getBasePositionAndOrientation(b, physicsClientId=session.client) for b in bodies]


def check_physics() -> Check:
    timings: list[float] = []
    _final_states(timings)
    median_ms = statistics.median(timings) * 1000.0
    detail = f"DIRECT connect and {STEPS} steps of a plane + 8 boxes: median {median_ms:.3f} ms/step"
    if median_ms > 5.0:
        return Check("physics", "warn", detail + " (slow)",
                     "close other CPU-heavy programs; a debug build of pybullet is also slow: pip install -U pybullet")
    return Check("physics", "ok", detail)


def check_determinism() -> Check:
    first, second = _final_states(), _final_states()
    if first != second:
        return Check("determinism", "fail", "the same simulation run twice gave different states",
                     "pip install --force-reinstall pybullet  # a patched or multi-threaded build is not deterministic")
    return Check("determinism", "ok", f"the same {STEPS}-step simulation twice gave bit-identical states")


def check_pybullet_data() -> Check:
    try:
        import pybullet_data
    except ImportError:
        return Check("pybullet_data", "fail", "pybullet_data is missing", "pip install --force-reinstall pybullet")
    root = Path(pybullet_data.getDataPath())
    if not (root / "plane.urdf").is_file():
        return Check("pybullet_data", "fail", f"{root} has no plane.urdf", "pip install --force-reinstall pybullet")
    count = sum(1 for _ in root.rglob("*.urdf"))
    return Check("pybullet_data", "ok", f"{root} ({count} URDF files)")


def check_import(module: str, distribution: str) -> Callable[[], Check]:
    """A check that ``module`` imports, reporting the installed version of ``distribution``."""

    def run() -> Check:
        try:
            importlib.import_module(module)
        except Exception as exc:  # noqa: BLE001 - broken installs raise more than ImportError
            return Check(module, "fail", f"cannot import {module}: {exc}", f"pip install --force-reinstall {distribution}")
        return Check(module, "ok", f"{distribution} {_version(distribution)}")

    run.__name__ = f"check_{module}"
    return run


def check_conda_pip_mix() -> Check:
    """In a conda environment, numeric packages installed by pip next to conda's are a classic breakage."""
    conda_meta = Path(sys.prefix) / "conda-meta"
    if not conda_meta.is_dir():
        return Check("conda/pip", "ok", "not a conda environment")
    by_pip = []
    for distribution in ("pybullet", "numpy"):
        try:
            installer = (importlib.metadata.distribution(distribution).read_text("INSTALLER") or "").strip()
        except importlib.metadata.PackageNotFoundError:
            continue
        conda_records = list(conda_meta.glob(f"{distribution}-*.json"))
        if installer == "pip" and not conda_records:
            by_pip.append(distribution)
    if by_pip and any(conda_meta.glob("python-*.json")):
        return Check("conda/pip", "warn", f"conda environment with {', '.join(by_pip)} installed by pip",
                     f"conda install -c conda-forge {' '.join(by_pip)}  # or use a plain venv")
    return Check("conda/pip", "ok", "conda environment, packages not mixed")


def check_renderer() -> Check:
    """Info only: whether hardware (EGL) rendering could be used; TinyRenderer always works."""
    import ctypes.util
    import importlib.util

    egl_plugin = importlib.util.find_spec("eglRenderer") is not None
    egl_library = ctypes.util.find_library("EGL") is not None
    display = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    detail = (f"EGL plugin {'found' if egl_plugin else 'missing'}, libEGL {'found' if egl_library else 'missing'}, "
              f"display {'present' if display else 'absent'}; TinyRenderer (CPU) always available")
    return Check("renderer", "info", detail)


CHECKS: list[Callable[[], Check]] = [
    check_python,
    check_pybullet,
    check_numpy,
    check_physics,
    check_determinism,
    check_pybullet_data,
    check_import("xacro", "xacro"),
    check_import("trimesh", "trimesh"),
    check_import("typer", "typer"),
    check_import("rich", "rich"),
    check_import("lxml.etree", "lxml"),
    check_conda_pip_mix,
    check_renderer,
]


def run_checks(checks: list[Callable[[], Check]] | None = None) -> list[Check]:
    """Run ``checks`` (default: :data:`CHECKS`, then one per capability of
    :mod:`ar3cli.install_check.capabilities`), each in a forked child (:mod:`ar3cli.infra.isolation`): an exception inside
    one becomes a ``fail`` for that check only, and so does a crash of pybullet's C code (a broken
    build), which would otherwise end install-check with no report at all."""
    from ar3cli.infra.isolation import CrashError, run_isolated

    if checks is None:
        from ar3cli.install_check.capabilities import CAPABILITY_CHECKS

        checks = [*CHECKS, *CAPABILITY_CHECKS]
    results = []
    for check in checks:
        name = check.__name__.removeprefix("check_")
        try:
            result = run_isolated(functools.partial(_run_one, check), f"install-check {name}")
        except CrashError as exc:
            result = Check(name, "fail", f"pybullet crashed ({exc.signal_name}) during this check",
                           "pip install --force-reinstall pybullet  # a broken or incompatible build")
        results.append(result)
        if result.name == "pybullet" and result.status == "ok":
            import_pybullet_here()
        if result.name == "trimesh" and result.status == "ok":
            from ar3cli.infra.held_import import import_holding_interrupts

            import_holding_interrupts("trimesh")  # the capability checks' children inherit it (~0.5 s each otherwise)
    return results


def _run_one(check: Callable[[], Check]) -> Check:
    try:
        return check()
    except Exception as exc:  # noqa: BLE001 - a check that fails in any way is a "fail" row, never a crash
        name = check.__name__.removeprefix("check_")
        return Check(name, "fail", f"check crashed: {type(exc).__name__}: {exc}",
                     "pip install --force-reinstall ar3cli  # and report this if it persists")


def import_pybullet_here() -> None:
    """Import pybullet in this process once a child has shown that it imports without crashing, so
    that the next checks' children start with it loaded (the import takes ~0.15 s)."""
    with capture_fds():
        import pybullet  # noqa: F401 - imported for its side effect: later children inherit it
