"""Byte-preserving edits and atomic writes, on a deliberately nasty file."""

from __future__ import annotations

import difflib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ar3cli.infra.atomic import TEMP_MARKER, atomic_write, stale_temps, temp_files
from ar3cli.urdf.edits import Document
from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS, REPO, as_unprivileged

NASTY = (
    "\ufeff<?xml version='1.0' encoding='utf-8'?>\r\n"
    "<!-- a comment with <link name=\"fake\"> inside -->\r\n"
    "<robot name='nasty'>\r\n"
    "\t<!-- base -->\r\n"
    "\t<link name='base'/>\r\n"
    "\r\n"
    "\t<joint type='revolute' name='j1'><!-- type before name -->\r\n"
    "\t\t<parent link='base'/>\r\n"
    "\t\t<child link='arm'/>\r\n"
    "\t\t<axis xyz='0 0 1'/>\r\n"
    "\t\t<limit effort='1' velocity='1' lower='-1' upper='1'/>\r\n"
    "\t</joint>\r\n"
    "\t<link name='arm' note='a > b'>\r\n"
    "\t\t<visual><geometry><box size='0.1 0.2 0.4'/></geometry></visual>\r\n"
    "\t\t<collision>\r\n"
    "\t\t\t<!-- collision <box> -->\r\n"
    "\t\t\t<geometry><box size='0.1 0.2 0.4'/></geometry>\r\n"
    "\t\t</collision>\r\n"
    "\t\t<note><![CDATA[ <link name='cdata'> ]]></note>\r\n"
    "\t</link>\r\n"
    "\t<joint name='j2'   type = 'continuous' >\r\n"
    "\t\t<parent link='arm'/><child link='wheel'/>\r\n"
    "\t\t<limit lower='-1' upper='1' effort='2' velocity='3'></limit>\r\n"
    "\t</joint>\r\n"
    "\t<link name='wheel'><inertial><mass value='1'/><inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>\r\n"
    "\t<joint name='tcp_joint' type='fixed'><parent link='wheel'/><child link='tcp'/></joint>\r\n"
    "\t<link name='tcp'></link>\r\n"
    "</robot>\r\n"
).encode("utf-8")


@pytest.fixture
def nasty(tmp_path) -> Path:
    path = tmp_path / "nasty.urdf"
    path.write_bytes(NASTY)
    return path


def test_scanner_maps_every_element_of_the_nasty_file(nasty):
    model = load_model(nasty)
    document = Document(model.source_bytes)
    spans = document.bind(model.root)
    assert len(spans) == sum(1 for e in model.root.iter() if isinstance(e.tag, str))
    for span in document.spans:
        assert NASTY[span.start:span.end].startswith(f"<{span.tag}".encode())
        assert NASTY[span.start:span.end].endswith(b"/>" if span.self_closing else f"</{span.tag}>".encode())
    arm = document.span(model.link("arm").element)
    assert arm.attributes["note"].quote == b"'" and NASTY[arm.attributes["note"].value_start:
                                                          arm.attributes["note"].value_end] == b"a > b"
    assert document.newline == b"\r\n" and document.indent_unit == b"\t" and document.quote == b"'"


def test_splices_keep_every_other_byte(nasty):
    model = load_model(nasty)
    document = Document(model.source_bytes)
    document.bind(model.root)
    limit = document.span(model.joint("j2").element.find("limit"))
    document.remove_attribute(limit, "lower")
    document.set_attribute(limit, "upper", "2")
    document.set_attribute(limit, "new", "x")
    new = document.apply()
    assert new == NASTY.replace(b"<limit lower='-1' upper='1' effort='2' velocity='3'></limit>",
                                b"<limit upper='2' effort='2' velocity='3' new='x'></limit>")


def _only_inserted(old: bytes, new: bytes, may_change: tuple[str, ...] = ()) -> list[str]:
    """Lines added between old and new; asserts nothing else was removed or replaced."""
    a, b = old.decode("utf-8").splitlines(keepends=True), new.decode("utf-8").splitlines(keepends=True)
    added = []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        assert tag == "equal" or all(line in may_change for line in a[i1:i2]), (tag, a[i1:i2], b[j1:j2])
        added += b[j1:j2] if tag != "equal" else []
    return added


def test_fix_inertia_on_nasty_file_only_inserts_inertials(cli, nasty):
    result = cli("fix-inertia", str(nasty), "--density", "1000")
    assert result.code == 0, result.stderr
    new = nasty.read_bytes()
    assert new.startswith(b"\xef\xbb\xbf<?xml version='1.0' encoding='utf-8'?>\r\n")
    added = _only_inserted(NASTY, new, may_change=("\t<link name='tcp'></link>\r\n",))
    assert all(line.endswith("\r\n") and line.startswith("\t\t") for line in added[:5]), added
    assert "\t\t<inertial>\r\n" in added and "\t\t\t<mass value='8'/>\r\n" in added  # 0.1*0.2*0.4 m3 * 1000
    assert "\t\t\t<mass value='1e-06'/>\r\n" in added  # the tcp frame link
    assert b"\t<link name='tcp'>\r\n\t\t<inertial>" in new and b"</inertial>\r\n\t</link>\r\n</robot>" in new
    assert cli("fix-inertia", str(nasty), "--check").code == 0


def test_fix_continuous_on_nasty_file_changes_one_line(cli, nasty):
    result = cli("fix-continuous", str(nasty), "--no-verify")
    assert result.code == 0, result.stderr
    assert nasty.read_bytes() == NASTY.replace(b"<limit lower='-1' upper='1' effort='2'",
                                               b"<limit effort='2'")


NAMESPACED = """<?xml version="1.0"?>
<robot name="ns" xmlns:controller="http://example.org/controller">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="arm"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-100" upper="100" effort="1" velocity="1"/></joint>
  <controller:gazebo_ros_controller_manager name="m"><controller:rate>1</controller:rate></controller:gazebo_ros_controller_manager>
</robot>
"""


def test_elements_with_a_namespace_prefix_map_to_their_spans():
    """PR2 (example-robot-data) has <controller:...> elements; lxml names them {uri}name."""
    from lxml import etree

    document = Document(NAMESPACED.encode())
    root = etree.fromstring(NAMESPACED.encode())
    spans = document.bind(root)
    element = root.find("{http://example.org/controller}gazebo_ros_controller_manager")
    assert document.span(element).tag == "controller:gazebo_ros_controller_manager"
    assert len(spans) == 16


def test_fixers_edit_a_file_with_namespaced_elements(cli, tmp_path):
    path = tmp_path / "ns.urdf"
    path.write_text(NAMESPACED, encoding="utf-8")
    result = cli("fix-continuous", str(path), "--no-verify")
    assert result.code == 0, result.stderr
    assert path.read_text(encoding="utf-8") == NAMESPACED.replace('<limit lower="-100" upper="100" ', "<limit ")


def test_atomic_write_keeps_mode_and_leaves_no_temp(tmp_path):
    target = tmp_path / "robot.urdf"
    target.write_bytes(b"old")
    os.chmod(target, 0o640)
    atomic_write(target, b"new")
    assert target.read_bytes() == b"new" and (target.stat().st_mode & 0o777) == 0o640
    assert stale_temps(tmp_path) == []

    def refuse(temp: Path) -> None:
        assert temp.read_bytes() == b"newer" and TEMP_MARKER in temp.name
        raise ValueError("validation failed")

    with pytest.raises(ValueError):
        atomic_write(target, b"newer", refuse)
    assert target.read_bytes() == b"new" and stale_temps(tmp_path) == []


def test_kill_mid_write_leaves_the_old_file(tmp_path):
    """SIGKILL while the temp file is half written: the target is byte-identical to the old one."""
    source = (ASSETS / "examples" / "ar3_fake_continuous.urdf").read_bytes()
    target = tmp_path / "big.urdf"
    padding = b"".join(b"<!-- padding line %d -->\n" % i for i in range(20000))
    old = source.replace(b"<robot name", padding + b"<robot name", 1)
    target.write_bytes(old)
    env = {**os.environ, "PYTHONPATH": str(REPO), "AR3CLI_TEST_SLOW_WRITE": "0.3"}
    process = subprocess.Popen([sys.executable, "-m", "ar3cli", "fix-continuous", str(target), "--no-verify"],
                               env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not temp_files(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)  # a few chunks in
    process.send_signal(signal.SIGKILL)
    process.wait()
    temps = stale_temps(tmp_path)  # its pid is gone: stale
    assert len(temps) == 1 and 0 < temps[0].stat().st_size < len(old)  # really killed mid-write
    assert target.read_bytes() == old
    # the same run, not killed, gives the new file and removes the dead run's temp
    env.pop("AR3CLI_TEST_SLOW_WRITE")
    subprocess.run([sys.executable, "-m", "ar3cli", "fix-continuous", str(target), "--no-verify"], env=env,
                   check=True, capture_output=True)
    assert b'lower="-100"' not in target.read_bytes() and stale_temps(tmp_path) == []


def test_atomic_write_follows_symlinks_when_asked_and_refuses_directories(tmp_path):
    import pytest

    from ar3cli.errors import UserError

    real = tmp_path / "real.urdf"
    real.write_bytes(b"old")
    link = tmp_path / "link.urdf"
    link.symlink_to(real)
    with pytest.raises(UserError, match="--follow-symlinks"):
        atomic_write(link, b"new")
    assert real.read_bytes() == b"old"
    atomic_write(link, b"new", follow_symlinks=True)
    assert link.is_symlink() and real.read_bytes() == b"new"
    with pytest.raises(UserError, match="is a directory"):
        atomic_write(tmp_path, b"x")


def test_atomic_write_into_read_only_folder_is_a_user_error(open_tmp_path):
    import pytest

    from ar3cli.errors import UserError

    folder = open_tmp_path / "ro"
    folder.mkdir()

    def refused() -> None:
        with pytest.raises(UserError, match="cannot write in"):
            atomic_write(folder / "x.urdf", b"x")

    folder.chmod(0o555)
    try:
        as_unprivileged(refused, folder)  # as root the kernel would let the write through
    finally:
        folder.chmod(0o700)


def test_atomic_write_respects_a_read_only_file(tmp_path):
    import pytest

    from ar3cli.errors import UserError

    target = tmp_path / "robot.urdf"
    target.write_bytes(b"old")
    target.chmod(0o444)
    with pytest.raises(UserError, match="is read-only"):
        atomic_write(target, b"new")
    assert target.read_bytes() == b"old" and not stale_temps(tmp_path)


def test_diff_of_a_long_file_shows_only_the_changed_lines(tmp_path):
    """difflib's autojunk made frequent lines (</geometry>) look removed and added again past 200 lines."""
    from ar3cli.fix.driver import unified_diff

    old = "".join(f"<geometry>{i}</geometry>\n</geometry>\n" for i in range(300))
    new = old.replace("<geometry>150</geometry>", "<geometry>changed</geometry>")
    diff = unified_diff(tmp_path / "x.urdf", old.encode(), new.encode())
    assert [line for line in diff.splitlines() if line.startswith(("-", "+")) and not line.startswith(("---", "+++"))] \
        == ["-<geometry>150</geometry>", "+<geometry>changed</geometry>"]
