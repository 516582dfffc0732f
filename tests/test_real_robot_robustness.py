"""Real robots that crashed or fooled pybullet: link order, contained crashes, no NaN, no leftovers.

The fixtures in tests/data/link_order/ are one small robot (a 4-level chain with a branch) written
in the link orders found in real descriptions, plus a file that really crashes pybullet 3.2.7
(a link with two parent joints). ``docs/pybullet-facts.md`` section 10 has the measurements.
"""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from ar3cli.errors import UserError
from ar3cli.infra.isolation import CrashError, report_stage, run_isolated
from ar3cli.infra.process_pool import can_fork
from ar3cli.sim.loadable_copy import loadable_document, parent_first_order
from ar3cli.urdf.model import load_model

DATA = Path(__file__).parent / "data" / "link_order"
REORDERED = ["root_last.urdf", "root_middle.urdf", "child_before_parent.urdf"]
CRASHES = DATA / "two_parents.urdf"
needs_fork = pytest.mark.skipif(not can_fork(), reason="crash containment forks (Linux only)")


# ---- the order pybullet is given ----------------------------------------------------------------
def test_parent_first_order_keeps_an_ordered_file_as_it_is() -> None:
    edges = [("base", "a"), ("a", "b"), ("base", "c")]
    assert parent_first_order(["base", "a", "b", "c"], edges) == ["base", "a", "b", "c"]


def test_parent_first_order_puts_the_root_first_and_parents_before_children() -> None:
    edges = [("base", "a"), ("a", "b"), ("b", "c"), ("base", "d")]
    assert parent_first_order(["c", "d", "b", "a", "base"], edges) == ["base", "a", "b", "c", "d"]


def test_parent_first_order_survives_cycles_and_two_parents() -> None:
    cycle = parent_first_order(["a", "b"], [("a", "b"), ("b", "a")])
    assert sorted(cycle) == ["a", "b"]
    two = parent_first_order(["x", "p", "q"], [("p", "x"), ("q", "x")])
    assert sorted(two) == ["p", "q", "x"] and two.index("p") < two.index("x")


@pytest.mark.parametrize("name", REORDERED)
def test_the_copy_lists_links_parent_first_and_keeps_everything_else(name: str) -> None:
    from lxml import etree

    model = load_model(DATA / name)
    copy = etree.fromstring(loadable_document(model))
    links = [element.get("name") for element in copy.iter("link")]
    assert links[0] == "base"
    parents = {joint.child: joint.parent for joint in model.joints}
    assert all(links.index(parents[link]) < links.index(link) for link in links[1:])
    assert sorted(links) == sorted(link.name for link in model.links)
    assert [j.get("name") for j in copy.iter("joint")] == [joint.name for joint in model.joints]


def test_the_users_model_is_not_reordered() -> None:
    model = load_model(DATA / "root_last.urdf")
    loadable_document(model)
    assert [element.get("name") for element in model.root.iter("link")][-1] == "base"


# ---- every order loads, with the right frame under every name -----------------------------------
def _frames(name: str, positions: dict[str, float]) -> dict[str, tuple]:
    from ar3cli.sim.session import Session

    with Session() as session:
        body = session.load(load_model(DATA / name))
        body.set_positions(positions)
        return body.link_frames()


@needs_fork
@pytest.mark.parametrize("name", REORDERED)
def test_files_that_crashed_or_gave_nan_load_with_the_same_frames(name: str) -> None:
    positions = {"j1": 0.3, "j2": -0.7, "j3": 1.1, "j4": 0.4, "jb": -1.2}
    expected = _frames("in_order.urdf", positions)
    frames = run_isolated(lambda: _frames(name, positions), name)  # a regression must not kill pytest
    assert frames.keys() == expected.keys()
    for link, (position, orientation) in expected.items():
        assert frames[link][0] == pytest.approx(position, abs=1e-9), link
        assert frames[link][1] == pytest.approx(orientation, abs=1e-9), link


@needs_fork
@pytest.mark.parametrize("name", REORDERED)
def test_fk_verify_passes_without_nan(cli, name: str) -> None:
    result = cli("fk-verify", str(DATA / name), "--samples", "5", "--format", "json")
    assert result.code == 0, result.stderr
    assert "NaN" not in result.stdout
    data = json.loads(result.stdout)
    assert data["passed"] is True and len(data["links"]) == 6


# ---- a real crash is contained ---------------------------------------------------------------------
@needs_fork
def test_lint_sim_batch_reports_every_file_when_pybullet_crashes_on_one(cli, tmp_path) -> None:
    good = DATA / "in_order.urdf"
    result = cli("lint-urdf", "--sim", "--no-cache", "--jobs", "1", str(good), str(CRASHES), str(good.parent / "root_last.urdf"),
                 "--format", "json", env={"TMPDIR": str(tmp_path)})
    assert result.code == 2, result.stderr
    data = json.loads(result.stdout)
    files = {Path(entry["path"]).name: entry for entry in data["files"]}
    assert files["in_order.urdf"]["error"] is None and files["root_last.urdf"]["error"] is None
    assert "pybullet crashed (SIGSEGV" in files["two_parents.urdf"]["error"] or \
        "pybullet crashed (SIGABRT" in files["two_parents.urdf"]["error"]
    assert data["summary"]["files_not_checked"] == 1 and data["summary"]["failed"] is True
    assert any(f["rule"] == "S006" for f in data["findings"])  # the static findings of the crashed file stay
    errors = [line for line in result.stderr.splitlines() if line.startswith("ar3cli: error:")]
    assert len(errors) == 1 and "two_parents.urdf" in errors[0] and "'extra' is the child of 2 joints" in errors[0]
    assert list(tmp_path.iterdir()) == []  # the crashed child's temporary folder is gone too


@needs_fork
def test_lint_sim_with_jobs_reports_the_crash_as_well(cli) -> None:
    result = cli("lint-urdf", "--sim", "--no-cache", "--jobs", "2", str(DATA))
    assert result.code == 2, result.stderr
    assert "5 files checked" in result.stdout and "1 not fully checked (pybullet crashed, or ran out of time or memory)" in result.stdout
    assert result.stderr.count("pybullet crashed") == 1


@needs_fork
@pytest.mark.parametrize("command", [["render", "-o", "{tmp}/x.png"], ["fk-verify", "--samples", "3"],
                                     ["sample-collisions", "--samples", "10"]])
def test_single_file_commands_turn_a_crash_into_one_line(cli, tmp_path, command: list[str]) -> None:
    args = [part.replace("{tmp}", str(tmp_path)) for part in command]
    result = cli(args[0], str(CRASHES), *args[1:], env={"TMPDIR": str(tmp_path)})
    assert result.code == 2
    assert result.stderr.startswith("ar3cli: error: ") and result.stderr.count("\n") == 1, result.stderr
    assert "pybullet crashed" in result.stderr and "Traceback" not in result.stderr
    assert [p.name for p in tmp_path.iterdir()] == []  # nothing written, no temporary folder left


# ---- the isolation itself ----------------------------------------------------------------------------
@needs_fork
def test_run_isolated_returns_results_and_passes_user_errors_on() -> None:
    assert run_isolated(lambda: {"answer": 42}, "x") == {"answer": 42}
    with pytest.raises(UserError, match="bad input"):
        run_isolated(lambda: (_ for _ in ()).throw(UserError("bad input")), "x")
    with pytest.raises(RuntimeError, match="ZeroDivisionError"):
        run_isolated(lambda: 1 / 0, "x")


@needs_fork
def test_run_isolated_names_the_signal_and_the_stage(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))

    def dies() -> None:
        import tempfile

        Path(tempfile.mkdtemp(prefix="ar3cli-")).joinpath("half-written").write_text("x")
        report_stage("loading it")
        os.kill(os.getpid(), signal.SIGABRT)

    with pytest.raises(CrashError) as raised:
        run_isolated(dies, "robot.urdf", cause=lambda: "link 'x' is odd")
    assert raised.value.message == "robot.urdf: pybullet crashed (SIGABRT) while loading it; link 'x' is odd"
    assert raised.value.exit_code == 2
    assert list(tmp_path.iterdir()) == []


@needs_fork
def test_install_check_reports_a_crashing_check_and_goes_on() -> None:
    from ar3cli.install_check.checks import Check, run_checks

    def check_boom() -> Check:
        os.kill(os.getpid(), signal.SIGSEGV)
        raise AssertionError("unreachable")

    def check_fine() -> Check:
        return Check("fine", "ok", "fine")

    boom, fine = run_checks([check_boom, check_fine])
    assert boom.status == "fail" and "SIGSEGV" in boom.detail and boom.hint
    assert fine.status == "ok"


# ---- never an empty picture -----------------------------------------------------------------------
def test_render_refuses_a_picture_without_the_robot(cli, write_urdf, tmp_path) -> None:
    bare = write_urdf('<robot name="r"><link name="base"><inertial><mass value="1"/>'
                      '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    output = tmp_path / "bare.png"
    result = cli("render", str(bare), "-o", str(output))
    assert result.code == 2 and "shows no robot" in result.stderr
    assert not output.exists()


def test_a_robot_without_a_name_loads(session, write_urdf) -> None:
    """pybullet refuses <robot> without a name ("Expected a name for robot"); the copy gets one."""
    text = (DATA / "in_order.urdf").read_text(encoding="utf-8").replace('<robot name="chain">', "<robot>")
    body = session.load(load_model(write_urdf(text)))
    assert len(body.joints) == 5 and body.base_name == "base"


def test_render_frames_links_that_have_only_visual_geometry(cli, write_urdf, tmp_path) -> None:
    """pybullet's getAABB boxes collision shapes only: a visual-only sphere got a 1 mm box and the
    camera sat inside it (pybullet_data's sphere2red_nocol.urdf rendered blank)."""
    sphere = write_urdf('<robot name="s"><link name="base"><inertial><mass value="1"/>'
                        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
                        '<visual><geometry><sphere radius="0.5"/></geometry></visual></link></robot>')
    output = tmp_path / "sphere.png"
    result = cli("render", str(sphere), "-o", str(output), "--width", "64", "--height", "48")
    assert result.code == 0, result.stderr
    from PIL import Image

    pixels = Image.open(output).convert("RGB")
    assert len(pixels.getcolors(maxcolors=100_000)) > 10  # the sphere, shaded, fills the middle
    assert pixels.getpixel((32, 24)) != pixels.getpixel((0, 0))


DRAKE = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry>
      <drake:proximity_properties><drake:compliant_hydroelastic/></drake:proximity_properties></collision>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
</robot>
"""


def test_an_undeclared_namespace_prefix_is_a_warning_and_the_file_works(cli, write_urdf, tmp_path):
    """Drake's <drake:...> elements without xmlns:drake: PyBullet reads the file; lint warns (F005)."""
    path = write_urdf(DRAKE)
    data = json.loads(cli("lint-urdf", str(path), "--no-cache", "--format", "json").stdout)
    (finding,) = [f for f in data["findings"] if f["rule"] in ("F002", "F005")]
    assert finding["rule"] == "F005" and finding["line"] == 5 and "drake" in finding["message"]
    assert cli("render", str(path), "-o", str(tmp_path / "d.png"), "--width", "64", "--height", "48").code == 0
    assert path.read_text() == DRAKE  # only the parsed copy gets the declaration


def test_a_urdf_that_is_really_xacro_says_so(cli, write_urdf, tmp_path):
    path = write_urdf('<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
                      '  <xacro:property name="l" value="0.1"/>\n'
                      '  <link name="base"><visual><geometry><box size="${l} ${l} ${l}"/></geometry></visual></link>\n'
                      '</robot>\n')
    data = json.loads(cli("lint-urdf", str(path), "--no-cache", "--format", "json").stdout)
    (f006,) = [f for f in data["findings"] if f["rule"] == "F006"]
    assert "xacro source" in f006["hint"]
    result = cli("render", str(path), "-o", str(tmp_path / "x.png"))
    assert result.code == 2 and "is a xacro source" in result.stderr and not (tmp_path / "x.png").exists()


def test_pybullet_chatter_in_a_child_never_reaches_stdout(cli, write_urdf):
    """Romeo (example-robot-data): calculateInverseDynamics printed a b3Warning per non-unit axis on
    C stdout, in the middle of info's JSON."""
    text = (DATA / "in_order.urdf").read_text(encoding="utf-8").replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 2"/>')
    result = cli("info", str(write_urdf(text)), "--torques", "--samples", "3", "--format", "json")
    assert result.code == 0, result.stderr
    assert json.loads(result.stdout)["torques"]
