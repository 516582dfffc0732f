"""Safe writes on an untrusted repository (issue 22 item 3): no write through a planted symlink unless
--follow-symlinks, in-place fixes keep mode/owner/group and refuse what the caller may not write or
what changed meanwhile, a dead run's temporary files are removed, fix-collision's part folders stay
inside the URDF's folder."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ar3cli.errors import UserError
from ar3cli.infra.atomic import atomic_write, check_writable, remove_stale_temps, stale_temps, temp_files
from tests.conftest import ASSETS, REPO, as_unprivileged

ROBOT = ASSETS / "examples" / "ar3_fake_continuous.urdf"
PRECIOUS = b"precious: must not be overwritten\n"


@pytest.fixture
def planted(tmp_path):
    """``repo/`` (where the command writes) and ``outside/victim`` (what a planted link points to)."""
    repo, outside = tmp_path / "repo", tmp_path / "outside"
    repo.mkdir()
    outside.mkdir()
    victim = outside / "victim"
    victim.write_bytes(PRECIOUS)
    return repo, victim


def plant(repo: Path, name: str, victim: Path) -> Path:
    link = repo / name
    link.symlink_to(victim)
    return link


def one_line_refusal(stderr: str, link: Path) -> None:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ar3cli: error: "), stderr
    assert str(link) in lines[0] and "is a symbolic link" in lines[0] and "--follow-symlinks" in lines[0]


@pytest.mark.parametrize(("name", "args"), [
    ("out.srdf", ["sample-collisions", str(ROBOT), "-n", "10", "--srdf"]),
    ("out.png", ["sample-collisions", str(ROBOT), "-n", "10", "--png"]),
    ("out.urdf", ["fix-continuous", str(ROBOT), "--no-verify", "-o"]),
    ("out.png", ["render", str(ROBOT), "-o"]),
    ("out.png", ["info", str(ROBOT), "--png"]),
    ("out.gif", ["grasp-demo", "--record"]),
    ("baseline.json", ["lint-urdf", str(ROBOT), "--write-baseline"]),
], ids=["srdf", "heat-map-png", "fixer-output", "render", "info-png", "grasp-record", "baseline"])
def test_a_symlinked_output_is_refused(cli, planted, name, args):
    repo, victim = planted
    link = plant(repo, name, victim)
    result = cli(*args, str(link))
    assert result.code == 2, result.stdout + result.stderr
    one_line_refusal(result.stderr, link)
    assert victim.read_bytes() == PRECIOUS and link.is_symlink()


def test_follow_symlinks_writes_the_links_target(cli, planted):
    repo, victim = planted
    link = plant(repo, "tree.png", victim)
    result = cli("info", str(ROBOT), "--png", str(link), "--follow-symlinks")
    assert result.code == 0, result.stderr
    assert victim.read_bytes().startswith(b"\x89PNG") and link.is_symlink()
    assert not temp_files(repo) and not temp_files(victim.parent)


def test_an_in_place_fix_of_a_symlinked_urdf_needs_follow_symlinks(cli, planted):
    repo, victim = planted
    original = ROBOT.read_bytes()
    victim.write_bytes(original)
    link = plant(repo, "robot.urdf", victim)
    result = cli("fix-continuous", str(link), "--no-verify")
    assert result.code == 2
    one_line_refusal(result.stderr, link)
    assert victim.read_bytes() == original
    result = cli("fix-continuous", str(link), "--no-verify", "--follow-symlinks")
    assert result.code == 0, result.stderr
    assert b'lower="-100"' not in victim.read_bytes() and link.is_symlink()
    assert not temp_files(repo) and not temp_files(victim.parent)  # the temp file lived beside the target


def test_an_in_place_fix_keeps_mode_owner_and_group(cli, tmp_path):
    path = tmp_path / "robot.urdf"
    shutil.copyfile(ROBOT, path)
    path.chmod(0o640)
    owner = (4321, 4322) if os.geteuid() == 0 else (os.getuid(), os.getgid())  # only root may give files away
    os.chown(path, *owner)
    result = cli("fix-continuous", str(path), "--no-verify")
    assert result.code == 0, result.stderr
    after = path.stat()
    assert b'lower="-100"' not in path.read_bytes()
    assert (after.st_mode & 0o7777, after.st_uid, after.st_gid) == (0o640, *owner)


def test_a_file_the_caller_may_not_write_is_refused(tmp_path, monkeypatch):
    """``os.access`` decides (a group or other write bit may allow it, the owner's alone may not); as
    root, os.access says yes to everything, so a file with no write bit at all is refused as well."""
    path = tmp_path / "robot.urdf"
    path.write_bytes(b"old")
    path.chmod(0o664)
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: not (Path(p) == path and mode == os.W_OK))
    with pytest.raises(UserError, match="is read-only for you"):
        atomic_write(path, b"new")
    monkeypatch.undo()
    path.chmod(0o444)
    with pytest.raises(UserError, match="is read-only for you"):
        atomic_write(path, b"new")
    assert path.read_bytes() == b"old"


def test_a_group_read_only_file_of_the_caller_is_refused_for_real(open_tmp_path):
    """No patched ``os.access``: the kernel's answer, as a user without root's rights (see as_unprivileged)."""
    path = open_tmp_path / "robot.urdf"
    path.write_bytes(b"old")
    path.chmod(0o464)  # the group may write, the owner (the caller) may not

    def refused() -> None:
        with pytest.raises(UserError, match="is read-only for you"):
            check_writable(path)

    as_unprivileged(refused, path)


def test_an_edit_made_while_fixing_is_kept(tmp_path):
    """The fix is refused ("changed while fixing, run again") and the edit stays: before, 9 of 40
    tries lost it silently. The slow write makes the window wide enough to hit every time."""
    target = tmp_path / "robot.urdf"
    padding = b"".join(b"<!-- padding line %d -->\n" % i for i in range(20000))
    old = ROBOT.read_bytes().replace(b"<robot name", padding + b"<robot name", 1)
    target.write_bytes(old)
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_TEST_SLOW_WRITE": "0.1"}
    process = subprocess.Popen([sys.executable, "-m", "ar3cli", "fix-continuous", str(target), "--no-verify"],
                               env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not temp_files(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.01)
    edited = old.replace(b"<robot name", b"<!-- my edit -->\n<robot name", 1)
    target.write_bytes(edited)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 2 and "changed while fixing, run again" in stderr and stderr.count("\n") == 1
    assert target.read_bytes() == edited and not temp_files(tmp_path)


def test_changed_while_fixing_compares_bytes_just_before_the_rename(tmp_path):
    target = tmp_path / "robot.urdf"
    target.write_bytes(b"edited")
    with pytest.raises(UserError, match="changed while fixing, run again"):
        atomic_write(target, b"new", expect=b"old")
    atomic_write(target, b"new", expect=b"edited")
    assert target.read_bytes() == b"new" and not temp_files(tmp_path)


def dead_pid() -> int:
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait()
    return process.pid


def test_stale_temps_of_a_dead_run_are_removed_a_live_runs_are_kept(tmp_path):
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        dead = tmp_path / f".x.urdf.ar3cli-tmp-{dead_pid()}-abcd1234"
        alive = tmp_path / f".x.urdf.ar3cli-tmp-{live.pid}-abcd1234"
        old_style = tmp_path / ".x.urdf.ar3cli-tmp-q1w2e3r4"  # no pid: an older ar3cli; goes by age
        young_old_style = tmp_path / ".y.urdf.ar3cli-tmp-q1w2e3r4"
        for temp in (dead, alive, old_style, young_old_style):
            temp.write_bytes(b"half a file")
        two_days_ago = time.time() - 2 * 24 * 3600
        os.utime(old_style, (two_days_ago, two_days_ago))
        assert stale_temps(tmp_path) == sorted([dead, old_style])
        atomic_write(tmp_path / "x.urdf", b"new")  # the first write in the folder sweeps it
        assert temp_files(tmp_path) == sorted([alive, young_old_style])
        assert remove_stale_temps(tmp_path) == []  # once per folder and process
    finally:
        live.kill()
        live.wait()


def test_a_killed_fixs_temp_is_removed_by_the_next_run(cli, tmp_path):
    """The reproducer: kill -9 left 31 temp files that nothing removed."""
    target = tmp_path / "robot.urdf"
    shutil.copyfile(ROBOT, target)
    leftovers = [tmp_path / f".robot.urdf.ar3cli-tmp-{dead_pid()}-k{i}" for i in range(3)]
    for temp in leftovers:
        temp.write_bytes(b"<robot")
    result = cli("fix-continuous", str(target), "--no-verify")
    assert result.code == 0, result.stderr
    assert not temp_files(tmp_path)


def test_fix_collision_does_not_follow_a_planted_collision_folder(cli, tmp_path):
    from tests.test_fix_collision import ROBOT as COLLISION_ROBOT
    from tests.test_fix_collision import U_CELLS, voxel_mesh

    repo, outside = tmp_path / "repo", tmp_path / "outside"
    (repo / "meshes").mkdir(parents=True)
    outside.mkdir()
    voxel_mesh(U_CELLS).export(repo / "meshes" / "u.stl")
    voxel_mesh([(0, 0, 0)]).export(repo / "meshes" / "cube.stl")
    path = repo / "robot.urdf"
    path.write_text(COLLISION_ROBOT, encoding="utf-8")
    (repo / "collision").symlink_to(outside, target_is_directory=True)
    result = cli("fix-collision", str(path), "--resolution", "20000", "--no-verify")
    assert result.code == 2, result.stdout + result.stderr
    line = result.stderr.strip().splitlines()[-1]
    assert line.startswith("ar3cli: error: ") and "is a symbolic link" in line and "outside" in line
    assert list(outside.iterdir()) == [] and path.read_text(encoding="utf-8") == COLLISION_ROBOT
    # a link that stays inside the URDF's folder is fine
    (repo / "collision").unlink()
    (repo / "parts").mkdir()
    (repo / "collision").symlink_to("parts", target_is_directory=True)
    result = cli("fix-collision", str(path), "--resolution", "20000", "--no-verify")
    assert result.code == 0, result.stdout + result.stderr
    assert sorted(p.name for p in (repo / "parts" / "base").iterdir())[0] == "part_00.obj"


FIFO = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
OUTPUTS = [
    ["sample-collisions", str(ROBOT), "-n", "10", "--srdf"],
    ["sample-collisions", str(ROBOT), "-n", "10", "--pybullet-filter"],
    ["sample-collisions", str(ROBOT), "-n", "10", "--png"],
    ["fix-continuous", str(ROBOT), "--no-verify", "-o"],
    ["render", str(ROBOT), "-o"],
    ["report", str(ROBOT), "-n", "2", "-o"],
    ["info", str(ROBOT), "--png"],
    ["grasp-demo", "--record"],
    ["lint-urdf", str(ROBOT), "--write-baseline"],
]


@FIFO
@pytest.mark.parametrize("args", OUTPUTS, ids=["srdf", "pybullet-filter", "heat-map-png", "fixer-output", "render",
                                               "report", "info-png", "grasp-record", "baseline"])
def test_an_output_that_is_a_fifo_is_refused_not_replaced(cli, tmp_path, args):
    """``render -o FIFO`` replaced the FIFO with a regular file (as root, ``-o /dev/null`` replaced
    the system's /dev/null): an existing output that is not a regular file is one line, exit 2."""
    suffix = {"-o": ".png", "--png": ".png", "--record": ".gif"}.get(args[-1], "")
    fifo = tmp_path / (("out.urdf" if args[0].startswith("fix-") else "out.html" if args[0] == "report" else "out")
                       if not suffix else f"out{suffix}")
    os.mkfifo(fifo)
    result = cli(*args, str(fifo), timeout=120)
    assert result.code == 2, result.stdout + result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines[-1] == f"ar3cli: error: {fifo}: exists and is not a regular file (a FIFO); refusing to replace it: " \
                        "give the name of a file", result.stderr
    assert stat_kind(fifo) == "fifo"


def stat_kind(path: Path) -> str:
    import stat

    mode = os.lstat(path).st_mode
    return "fifo" if stat.S_ISFIFO(mode) else "link" if stat.S_ISLNK(mode) else "file"


def test_a_device_is_refused_by_the_one_check(tmp_path):
    with pytest.raises(UserError, match=r"^/dev/null: exists and is not a regular file \(a device\)"):
        check_writable(Path("/dev/null"))
    with pytest.raises(UserError, match="cannot write: File name too long"):
        check_writable(tmp_path / ("x" * 300))


@FIFO
def test_scan_report_keep_list_and_scan_store_follow_the_same_rules(cli, tmp_path, planted):
    """``scan --store`` followed a planted symlink (SQLite writes in place, not through the atomic
    writer): the store and the files SQLite keeps beside it are checked by the same rules."""
    repo, victim = planted
    (repo / "robots").mkdir()
    shutil.copyfile(ROBOT, repo / "robots" / "r.urdf")
    link = plant(repo, "scan.sqlite", victim)
    result = cli("scan", "robots", "--store", "scan.sqlite", cwd=repo)
    assert result.code == 2
    one_line_refusal(result.stderr, Path("scan.sqlite"))
    assert victim.read_bytes() == PRECIOUS and link.is_symlink()
    link.unlink()
    side = plant(repo, "scan.sqlite-wal", victim)
    result = cli("scan", "robots", "--store", "scan.sqlite", cwd=repo)
    assert result.code == 2
    assert result.stderr.strip().splitlines() == [
        "ar3cli: error: scan.sqlite-wal: SQLite's wal file of the store is not a regular file (a symbolic link, "
        "FIFO or device); refusing to write through it: remove it"]
    assert victim.read_bytes() == PRECIOUS and side.is_symlink() and not (repo / "scan.sqlite").exists()
    side.unlink()
    (repo / "scan.sqlite").touch(mode=0o640)
    os.chmod(repo / "scan.sqlite", 0o640)
    result = cli("scan", "robots", "--store", "scan.sqlite", cwd=repo)
    assert result.code == 0, result.stderr
    assert (repo / "scan.sqlite").stat().st_mode & 0o777 == 0o640  # written in place: its mode kept
    os.mkfifo(repo / "keep.txt")
    result = cli("scan-report", "scan.sqlite", "--keep-list", "keep.txt", cwd=repo)
    assert result.code == 2 and "keep.txt: exists and is not a regular file (a FIFO)" in result.stderr
    assert stat_kind(repo / "keep.txt") == "fifo"
