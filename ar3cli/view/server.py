"""Serving the viewer: viser (the optional extra ``ar3cli[view]``) on a local address, the poll loop,
and a stop that leaves nothing behind.

- viser is imported here only; without it :func:`import_viser` is one line naming the pip command.
- The server listens on 127.0.0.1 unless asked otherwise; the address is checked before viser gets
  it (viser would try the next port, forever, on an address it cannot bind). A busy default port
  moves to the next free one (the URL printed is the real one); a busy ``--port`` is an error.
- viser's own output (a banner, "Server stopped") is kept off stdout, which may carry the JSON line.
- viser's client has a "share" button that asks the server to open a public tunnel to the page;
  the button is hidden and the server refuses the request: a robot file under review stays local.
- Ctrl-C and SIGTERM (a KeyboardInterrupt in this thread, :mod:`ar3cli.infra.shutdown`) end the
  loop; the viewer then closes its pybullet children and the server stops. trimesh catches
  ``BaseException`` in places (its optional imports, some of its methods): a SIGTERM raised while
  trimesh runs can be swallowed, and only the first SIGTERM is raised (a second one must not cut a
  cleanup short). Measured: a SIGTERM 1.2 s after the start, during ``import trimesh`` with viser's
  threads running, left the viewer running and deaf to every later SIGTERM. So the loop checks
  :func:`ar3cli.infra.shutdown.received` and raises the SIGTERM itself, and the first meshes are
  read before viser starts its threads (:func:`prepare`).
"""

from __future__ import annotations

import errno
import socket
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError

INSTALL_HINT = "pip install 'ar3cli[view]'"
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8080
"""viser's own default; taken, the next free port is used."""
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")
SHADOWS = False
"""Lights cast no shadows: a robot's links lie on and in each other, and the self-shadowing striped
every curved surface (shadow acne, in SwiftShader and on GPUs alike) without showing anything ar3cli
knows; the viewer is about geometry and findings, not looks."""
ENVIRONMENT_MAP = None
"""viser lights its scene with an HDR environment map by default; without a GPU (a browser's software
WebGL, headless Chromium's SwiftShader) preparing it held the first picture of the page for 23-26 s
against 5.3 s without it (the kuka_iiwa, 2 cores under load). The default lights alone shade well."""


def import_viser() -> Any:
    """Import viser; a one-line UserError naming the extra to install when it is missing."""
    try:
        import viser
    except ImportError as exc:
        raise UserError(f"the viewer needs viser, which is not installed ({exc}); run: {INSTALL_HINT}") from None
    return viser


def is_local(host: str) -> bool:
    return host in LOCAL_HOSTS


def url_of(host: str, port: int) -> str:
    """The address a browser opens (all interfaces: this machine's loopback)."""
    shown = "127.0.0.1" if host in ("0.0.0.0", "") else "[::1]" if host == "::" else \
        f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}/"


def check_address(host: str, port: int | None) -> int:
    """The port to hand viser: ``port``, or the default (whose neighbours viser tries when it is
    taken). A host that cannot be bound, or a given port in use, is a one-line UserError."""
    wanted = DEFAULT_PORT if port is None else port
    try:
        infos = socket.getaddrinfo(host, wanted, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise UserError(f"--host {host}: not an address of this machine ({exc})") from None
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE and port is None:
                return wanted  # viser moves to the next free port
            what = "is in use; choose another --port (0: any free port)" if exc.errno == errno.EADDRINUSE \
                else f"cannot be listened on: {exc.strerror or exc}"
            raise UserError(f"{host} port {wanted} {what}") from None
    return wanted


def start_server(host: str, port: int | None) -> Any:
    """A running viser server on ``host``:``port`` with its output silenced and sharing refused."""
    import os

    viser = import_viser()
    wanted = check_address(host, port)
    import rich

    rich.reconfigure(file=open(os.devnull, "w"))  # noqa: SIM115 - for the process's life: viser prints through rich's console
    server = viser.ViserServer(host=host, port=wanted, verbose=False)
    server.request_share_url = _refuse_share  # the client's share button would tunnel the page to the internet
    server.scene.configure_environment_map(hdri=ENVIRONMENT_MAP)
    server.scene.configure_default_lights(cast_shadow=SHADOWS)
    return server


def prepare(analysis: Any) -> None:
    """Answer what the first draw needs (meshes, poses, inertia boxes, the static lint) before any
    thread starts: importing trimesh and scipy takes seconds, and only in a process with one thread
    does :func:`ar3cli.infra.held_import.import_holding_interrupts` hold a Ctrl-C or a SIGTERM until
    the import is done (with other threads, the signal reaches one of them and Python raises it in
    the main thread anyway). A file that does not load has nothing to prepare."""
    from ar3cli.analysis.findings import static_findings
    from ar3cli.analysis.inertia_boxes import inertia_boxes
    from ar3cli.analysis.meshes import link_meshes
    from ar3cli.analysis.poses import posing

    if analysis.model is None:
        return
    for question in (link_meshes, posing, inertia_boxes, static_findings):
        try:
            question(analysis)
        except UserError:
            return  # the viewer says why when it draws


def _refuse_share(*_args: object, **_kwargs: object) -> None:
    return None


def serve(path: Path, settings: Any, host: str, port: int | None, seed: int, open_browser: bool,
          announce: Callable[[str], None], log: Callable[[str], None]) -> None:
    """Load ``path``, draw it, call ``announce(url)`` and redraw it as it changes, until interrupted;
    ``log`` gets the progress lines (what was drawn, the findings, the contacts at home). The standard
    streams are fork-safe meanwhile (:mod:`ar3cli.view.streams`): pybullet children are forked while
    other threads write."""
    from ar3cli.view.streams import fork_safe_streams

    import_viser()
    with fork_safe_streams():
        _serve(path, settings, host, port, seed, open_browser, announce, log)


def _serve(path: Path, settings: Any, host: str, port: int | None, seed: int, open_browser: bool,
           announce: Callable[[str], None], log: Callable[[str], None]) -> None:
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.infra import shutdown
    from ar3cli.view.viewer import POLL_SECONDS, Viewer

    if not is_local(host):
        log(f"warning: listening on {host}: whoever can reach this address sees the robot, its mesh geometry, its "
            "names and the findings; bind 127.0.0.1 (the default) to keep them on this machine")
    analysis = RobotAnalysis.load(path, settings)
    prepare(analysis)  # the heavy imports and the first meshes while this process has one thread
    server = start_server(host, port)
    viewer = None
    try:
        viewer = Viewer(server, analysis, seed, log=log)
        url = url_of(host, server.get_port())
        announce(url)
        if open_browser:
            import webbrowser

            webbrowser.open(url)
        while True:
            time.sleep(POLL_SECONDS)
            if shutdown.received():
                raise shutdown.Terminated  # a SIGTERM that library code swallowed (see the docstring)
            viewer.poll()
    finally:
        if viewer is not None:
            viewer.close()
        else:
            analysis.close()
        server.stop()
