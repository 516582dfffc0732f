"""ar3cli scan / scan-report: every file stored once, resume after SIGINT and SIGKILL, nothing
rescanned twice, the keep-list, per-file crash and timeout rows, and the Ray backend's rows equal
to the local backend's (real Ray, local, 2 CPUs). Assets are generated in tmp_path."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
COMPARED = "path, sha256, settings, status, findings, message, dof, mass, links, joints, errors, warnings, infos"


def chain(links: int, name: str = "r", mass: str = "1") -> str:
    """A serial chain of ``links`` boxes joined by revolute joints."""
    body = "".join(f'<link name="l{i}"><inertial><mass value="{mass}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
                   f'ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry>'
                   f'</collision></link>' for i in range(links))
    body += "".join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                    f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                    f'</joint>' for i in range(links - 1))
    return f'<?xml version="1.0"?>\n<robot name="{name}">{body}</robot>\n'


def make_assets(folder: Path, count: int, links: int = 3) -> list[Path]:
    """``count`` robot files in two subfolders: chains, one without masses (findings), one broken XML."""
    paths = []
    for index in range(count):
        path = folder / f"set{index % 2}" / f"robot{index:03d}.urdf"
        path.parent.mkdir(parents=True, exist_ok=True)
        text = chain(links, f"r{index}", mass="0" if index == 1 else "1")
        path.write_text("<robot name='broken'><link" if index == 2 else text)
        paths.append(path)
    return paths


def ar3cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_NO_CACHE": "1"}
    return subprocess.run([sys.executable, "-m", "ar3cli", *args], capture_output=True, text=True, env=env,
                          timeout=timeout)


def stored(store: Path) -> list[tuple]:
    with sqlite3.connect(store) as db:
        return db.execute(f"SELECT {COMPARED} FROM files ORDER BY path").fetchall()


def test_scan_stores_every_file_once_and_a_second_run_rescans_nothing(tmp_path: Path) -> None:
    paths = make_assets(tmp_path / "robots", 12)
    store = tmp_path / "scan.sqlite"
    first = ar3cli("scan", str(tmp_path / "robots"), "--store", str(store), "-f", "json")
    assert first.returncode == 0, first.stderr
    summary = json.loads(first.stdout)
    assert (summary["files"], summary["checked"], summary["skipped"]) == (12, 12, 0)
    rows = {row[0]: row for row in stored(store)}
    assert sorted(rows) == sorted(str(path.resolve()) for path in paths)
    broken, massless, plain = (rows[str(paths[i].resolve())] for i in (2, 1, 0))
    assert broken[3] == "error" and json.loads(broken[4])[0]["rule"] == "F002" and broken[6] is None
    assert plain[6:10] == (2, 3.0, 3, 2)  # dof, mass, links, joints
    assert massless[3] == "findings" and massless[10] >= 1
    with sqlite3.connect(store) as db:
        assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        written = db.execute("SELECT path, scanned_at FROM files").fetchall()

    again = json.loads(ar3cli("scan", str(tmp_path / "robots"), "--store", str(store), "-f", "json").stdout)
    assert (again["checked"], again["skipped"]) == (0, 12)
    with sqlite3.connect(store) as db:
        assert db.execute("SELECT path, scanned_at FROM files").fetchall() == written

    paths[0].write_text(chain(4, "changed"))  # a changed file is checked again; --rescan checks all
    assert json.loads(ar3cli("scan", str(tmp_path / "robots"), "--store", str(store), "-f", "json").stdout)["checked"] == 1
    assert json.loads(ar3cli("scan", str(tmp_path / "robots"), "--store", str(store), "-f", "json",
                             "--rescan").stdout)["checked"] == 12
    assert len(stored(store)) == 12


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGKILL])
def test_an_interrupted_scan_resumes_with_no_file_lost_or_doubled(tmp_path: Path, how: signal.Signals) -> None:
    # 40 chains of 1,000 links: each takes ~0.1 s to lint, so one worker needs seconds
    make_assets(tmp_path / "robots", 40, links=1000)
    store = tmp_path / "scan.sqlite"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    process = subprocess.Popen([sys.executable, "-m", "ar3cli", "scan", str(tmp_path / "robots"), "--store", str(store),
                                "-j", "1"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               # a CI started as a background job hands SIGINT down ignored: a user's scan has it
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if store.exists():
            try:
                with sqlite3.connect(store) as db:
                    if db.execute("SELECT count(*) FROM files").fetchone()[0]:
                        break  # the first batch is committed: interrupt the scan now
            except sqlite3.OperationalError:
                pass  # the table is being created
        time.sleep(0.05)
    process.send_signal(how)
    _, err = process.communicate(timeout=60)
    assert process.returncode == (130 if how is signal.SIGINT else -signal.SIGKILL), err
    partial = len(stored(store))
    assert 0 < partial < 40
    if how is signal.SIGINT:  # it says what is stored and how to go on
        assert f"files checked in this run; {partial} files are stored in {store}" in err, err
        assert "Run the same command again to go on" in err

    rerun = ar3cli("scan", str(tmp_path / "robots"), "--store", str(store), "-f", "json")
    assert rerun.returncode == 0, rerun.stderr
    summary = json.loads(rerun.stdout)
    assert (summary["checked"], summary["skipped"]) == (40 - partial, partial)
    with sqlite3.connect(store) as db:
        assert db.execute("SELECT count(*), count(DISTINCT path) FROM files").fetchone() == (40, 40)
        assert db.execute("PRAGMA integrity_check").fetchone()[0] == "ok"


def test_scan_report_counts_worst_files_and_keep_list(tmp_path: Path) -> None:
    make_assets(tmp_path / "robots", 6)
    store = tmp_path / "scan.sqlite"
    assert ar3cli("scan", str(tmp_path / "robots"), "--store", str(store)).returncode == 0
    keep = tmp_path / "keep.txt"
    result = ar3cli("scan-report", str(store), "--keep", "no errors", "--keep-list", str(keep), "-f", "json")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["files"] == 6 and data["statuses"]["error"] == 1
    assert data["worst"][0]["status"] == "error" and data["worst"][0]["top_rules"] == ["F002"]
    assert {"F002"} <= {rule["rule"] for rule in data["rules"]}
    assert data["keep"]["filters"] == ["no-errors"]
    assert keep.read_text().splitlines() == data["keep"]["paths"] and "robot002" not in keep.read_text()
    markdown = ar3cli("scan-report", str(store), "--format", "markdown", "--keep", "loads", "--keep", "min-dof=2")
    assert markdown.returncode == 0 and "| status | files |" in markdown.stdout and "5 kept by loads and min-dof=2" \
        in markdown.stdout
    for bad in (["--keep", "shiny"], ["--keep", "max-dof=x"]):
        wrong = ar3cli("scan-report", str(store), *bad)
        assert wrong.returncode == 2 and wrong.stderr.startswith("ar3cli: error: ") and len(wrong.stderr.splitlines()) == 1
    missing = ar3cli("scan-report", str(tmp_path / "none.sqlite"))
    assert missing.returncode == 2 and "no such scan store" in missing.stderr


def _work(item: str) -> str:
    if item == "crash":
        os.kill(os.getpid(), signal.SIGSEGV)
    if item == "slow":
        time.sleep(60)
    return item.upper()


def test_the_pool_streams_each_item_once_with_crash_and_timeout_outcomes() -> None:
    from ar3cli.infra.streaming_pool import stream

    items = ["a", "crash", "b", "slow", "c", "d"]
    outcomes = dict(stream(_work, items, workers=2, timeout=1.0))
    assert set(outcomes) == set(items)
    assert outcomes["a"] == ("ok", "A") and outcomes["d"] == ("ok", "D")
    assert outcomes["crash"][0] == "crash" and "SIGSEGV" in outcomes["crash"][1]
    assert outcomes["slow"][0] == "timeout"


def test_ray_backend_without_ray_is_one_line_exit_2(monkeypatch) -> None:
    import importlib.util

    from ar3cli.errors import UserError
    from ar3cli.scan.ray_backend import require_ray

    monkeypatch.setattr(importlib.util, "find_spec", lambda name: None)
    with pytest.raises(UserError, match=r"pip install 'ar3cli\[ray\]'") as raised:
        require_ray()
    assert raised.value.exit_code == 2


@pytest.fixture
def ray_head(tmp_path: Path):
    """A real Ray head on 127.0.0.1 (``ray start --head --block``) with token authentication on, as Ray
    2.60 starts it wherever ``~/.ray/auth_token`` exists (any earlier local ``ray.init()`` writes one), in
    its own session and temporary folders and a HOME of its own: yields (its address, the environment
    to join it with); its whole process group is stopped afterwards."""
    import shutil
    import socket
    import tempfile

    if shutil.which("ray") is None and not (Path(sys.executable).parent / "ray").exists():
        pytest.skip("Ray is not installed (pip install 'ar3cli[ray]')")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    home = tmp_path / "home"
    home.mkdir()
    temp = Path(tempfile.mkdtemp(prefix="ray", dir="/tmp"))  # Ray's socket paths must stay short
    env = {**os.environ, "HOME": str(home), "RAY_USAGE_STATS_ENABLED": "0"}
    env.pop("RAY_AUTH_MODE", None)
    ray = str(Path(sys.executable).parent / "ray")
    subprocess.run([ray, "get-auth-token", "--generate"], env=env, capture_output=True, check=True, timeout=60)
    command = [ray, "start", "--head", "--block", "--node-ip-address", "127.0.0.1",
               "--port", str(port), "--num-cpus", "1", "--include-dashboard", "false", "--temp-dir", str(temp),
               "--disable-usage-stats"]
    head = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        said = []
        for line in head.stdout:  # type: ignore[union-attr]
            said.append(line)
            if "Ray runtime started" in line:
                break
        else:
            pytest.fail("ray start --head ended: " + "".join(said[-5:]))
        assert (home / ".ray" / "auth_token").is_file(), "".join(said)  # token authentication, Ray's default
        yield f"127.0.0.1:{port}", env
    finally:  # the head's own group, and only it: SIGTERM keeps `ray start --block` busy for 30 s and more
        with contextlib.suppress(ProcessLookupError):
            os.killpg(head.pid, signal.SIGKILL)
        head.wait()
        shutil.rmtree(temp, ignore_errors=True)


def test_ray_joins_a_running_head_and_gives_the_local_backends_rows(tmp_path: Path, ray_head) -> None:
    """issue 36 item 9: a driver given --address joined no token-authenticated cluster; and a scan that
    starts its own Ray must not join the one running here (it failed: "num_cpus ... must not be provided")."""
    address, env = ray_head
    make_assets(tmp_path / "robots", 8)
    local, joined, own = tmp_path / "local.sqlite", tmp_path / "joined.sqlite", tmp_path / "own.sqlite"
    assert ar3cli("scan", str(tmp_path / "robots"), "--store", str(local)).returncode == 0

    def scan(store: Path, *extra: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "ar3cli", "scan", str(tmp_path / "robots"), "--store", str(store),
                               "--backend", "ray", "-f", "json", *extra], capture_output=True, text=True, timeout=300,
                              env={**env, "PYTHONPATH": str(REPO)})

    result = scan(joined, "--address", address)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["backend"] == "ray" and result.stderr == ""  # Ray's own logging kept quiet
    assert stored(joined) == stored(local) and len(stored(joined)) == 8
    started = scan(own, "--jobs", "1")
    assert started.returncode == 0, started.stderr
    assert stored(own) == stored(local)


def test_a_wrong_ray_address_is_one_line_at_once(tmp_path: Path) -> None:
    import socket

    pytest.importorskip("ray")
    make_assets(tmp_path / "robots", 1)
    with socket.socket() as probe:  # a port nobody listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    result = ar3cli("scan", str(tmp_path / "robots"), "--store", str(tmp_path / "s.sqlite"), "--backend", "ray",
                    "--address", f"127.0.0.1:{port}", timeout=60)
    assert result.returncode == 2
    assert result.stderr.startswith(f"ar3cli: error: cannot reach Ray at 127.0.0.1:{port}: ")
    assert result.stderr.count("\n") == 1
