"""grasp-demo: the AR3 really picks up the cube, deterministically; the GIF shows it; IK facts."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ar3cli.grasp.pick_and_lift import PHASES, GraspSettings, gripper_yaw, run_grasp, sample_cube_pose, strip_wall_clock
from ar3cli.infra.assets import asset
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model


@pytest.fixture(scope="module")
def default_run():
    """``ar3cli grasp-demo --format json`` for the default seed, as a user runs it."""
    from conftest import run_cli

    result = run_cli("grasp-demo", "--format", "json")
    return result


def test_default_seed_succeeds_with_real_numbers(default_run):
    assert default_run.code == 0, default_run.stderr
    data = json.loads(default_run.stdout)  # stdout holds the JSON alone
    assert data["success"] is True and data["seed"] == 0
    assert data["lift_height_m"] >= 0.05
    assert data["cube_between_fingers"] is True
    assert [phase["name"] for phase in data["phases"]] == list(PHASES)
    assert all(phase["ok"] for phase in data["phases"])
    for key in ("cube_start", "steps", "sim_time_s", "wall_time_s", "realtime_factor"):
        assert key in data
    assert data["steps"] == round(data["sim_time_s"] * 240)
    phases = {phase["name"]: phase for phase in data["phases"]}
    # open jaw before the grasp, closed on the 45 mm cube after it
    assert phases["descend"]["gripper_opening_m"] == pytest.approx(0.08, abs=1e-3)
    assert phases["hold"]["gripper_opening_m"] == pytest.approx(0.045, abs=2e-3)
    # the cube rests on the ground until the lift, then sits 10 cm higher
    assert phases["close"]["cube_height_m"] == pytest.approx(0.0225, abs=1e-3)
    assert phases["hold"]["cube_height_m"] - data["cube_start"][2] == pytest.approx(0.10, abs=0.01)
    assert max(phase["tcp_error_m"] for phase in data["phases"]) < 0.002


def test_text_output_shows_phases_and_verdict(cli):
    result = cli("grasp-demo", "--seed", "5")
    assert result.code == 0, result.stderr
    for phase in PHASES:
        assert phase in result.stdout
    assert "seed 5" in result.stdout
    assert "success: cube lifted" in result.stdout
    assert "x real time" in result.stdout


def test_same_seed_same_result_except_wall_clock():
    first, second = run_grasp(7).to_dict(), run_grasp(7).to_dict()
    assert strip_wall_clock(first) == strip_wall_clock(second)
    assert set(first) - set(strip_wall_clock(first)) == {"wall_time_s", "realtime_factor"}
    assert run_grasp(8).to_dict()["cube_start"] != first["cube_start"]


@pytest.mark.parametrize("seed", [1, 2, 3, 42])
def test_other_seeds_succeed(seed):
    result = run_grasp(seed)
    assert result.success, f"seed {seed}: {result.failed_phase}: {result.reason}"
    assert result.lift_height_m >= 0.05 and result.cube_between_fingers


def test_friction_does_the_holding_no_constraints():
    """No constraint exists in the world at any step: the cube is held by friction only."""
    seen = []

    def hook(scene, step):
        if step % 50 == 0:
            seen.append(scene.p.getNumConstraints(physicsClientId=scene.client))

    assert run_grasp(0, frame_hook=hook).success
    assert seen and set(seen) == {0}


def test_weak_gripper_fails_in_lift_with_exit_1(cli):
    result = cli("grasp-demo", "--gripper-force", "0.1", "--format", "json")
    assert result.code == 1
    data = json.loads(result.stdout)
    assert data["success"] is False
    assert data["failed_phase"] == "lift"
    assert "slipped" in data["reason"]
    assert data["lift_height_m"] < 0.05
    text = cli("grasp-demo", "--gripper-force", "0.1")
    assert text.code == 1 and "FAILED in lift: cube slipped" in text.stdout


def test_trials_report_rate_and_runs(cli):
    result = cli("grasp-demo", "--trials", "3", "--seed", "10", "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["trials"] == 3 and data["successes"] == 3 and data["success_rate"] == 1.0
    assert [run["seed"] for run in data["runs"]] == [10, 11, 12]
    assert data["failures"] == []


def test_trials_below_target_exit_1(cli):
    result = cli("grasp-demo", "--trials", "2", "--gripper-force", "0.1")
    assert result.code == 1
    assert "0/2 succeeded" in result.stdout and "BELOW TARGET" in result.stdout
    assert "failed: seed 0 in lift" in result.stdout


def red_centroid(frame) -> tuple[float, float, int]:
    """Centre (x, y) in pixels of the cube's red, and how many red pixels there are."""
    rgb = np.asarray(frame.convert("RGB"), dtype=int)
    red = (rgb[..., 0] > 150) & (rgb[..., 1] < 80) & (rgb[..., 2] < 80)
    ys, xs = np.nonzero(red)
    return float(xs.mean()), float(ys.mean()), int(red.sum())


def test_record_writes_gif_where_the_cube_rises(cli, tmp_path):
    from PIL import Image

    path = tmp_path / "pick.gif"
    result = cli("grasp-demo", "--record", str(path), "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    with Image.open(path) as gif:
        assert gif.n_frames > 10 and gif.n_frames == data["record"]["frames"]
        gif.seek(0)
        first = red_centroid(gif)
        gif.seek(gif.n_frames - 1)
        last = red_centroid(gif)
        total_ms = 0
        for index in range(gif.n_frames):
            gif.seek(index)
            total_ms += gif.info["duration"]
    assert first[2] > 20 and last[2] > 20  # the cube is in view at both ends
    assert first[1] - last[1] > 10  # image y grows downwards: the cube moved up > 10 px
    assert total_ms / 1000 == pytest.approx(data["sim_time_s"], abs=0.1)  # plays at sim speed


@pytest.mark.parametrize("args, message", [
    (["--record", "out.png"], "must end in .gif"),
    (["--record", "no/such/dir/out.gif"], "does not exist"),
    (["--gripper-force", "31"], "exceeds the finger effort limit 30 N"),
    (["--gripper-force", "0"], "must be positive"),
    (["--trials", "3", "--record", "x.gif"], "without --trials"),
])
def test_bad_options_exit_2_with_one_line(cli, tmp_path, args, message):
    result = cli("grasp-demo", *args, cwd=tmp_path)
    assert result.code == 2
    assert message in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


def test_gui_without_display_is_a_clear_error(cli):
    result = cli("grasp-demo", "--gui", env={"DISPLAY": "", "WAYLAND_DISPLAY": ""})
    assert result.code == 2
    assert "--gui needs a display" in result.stderr


def test_gripper_yaw_squares_the_jaw_with_a_small_wrist_turn():
    settings = GraspSettings()
    for seed in range(30):
        xy, cube_yaw = sample_cube_pose(seed, settings)
        radius = math.hypot(*xy)
        assert settings.radius_range[0] <= radius <= settings.radius_range[1]
        yaw = gripper_yaw(cube_yaw, xy)
        natural = math.atan2(xy[1], xy[0]) + math.pi / 2
        assert abs(yaw - natural) <= math.pi / 4 + 1e-9
        quarter_turns = (yaw - cube_yaw) / (math.pi / 2)
        assert quarter_turns == pytest.approx(round(quarter_turns), abs=1e-9)


# --- pybullet IK facts the demo relies on (shared/docs/pybullet-facts.md, section 8) --------------

@pytest.fixture(scope="module")
def ik_arm():
    with Session() as session:
        body = session.load(load_model(asset("ar3/ar3.urdf")))
        yield session, body


def _ik(session, body, **kwargs):
    p = session.p
    body.set_positions([0.0, 1.0, 1.4, 0.0, 0.7, 0.0, 0.0, 0.0])
    down = p.getQuaternionFromEuler([0.0, math.pi, 0.0])
    return np.array(p.calculateInverseKinematics(body.id, body.link_index["tcp"], [0.0, -0.35, 0.1], down,
                                                 physicsClientId=session.client, **kwargs))


def test_ik_maxiter_keyword_raises(ik_arm):
    session, body = ik_arm
    with pytest.raises(TypeError):
        _ik(session, body, maxIter=100)
    assert len(_ik(session, body, maxNumIterations=100, residualThreshold=1e-6)) == 8  # 8 movable DOF


def test_ik_null_space_lists_need_one_entry_per_movable_dof(ik_arm):
    session, body = ik_arm
    movable = body.actuated_joints
    assert len(movable) == 8
    lower = [joint.lower for joint in movable]
    upper = [joint.upper for joint in movable]
    ranges = [hi - lo for lo, hi in zip(lower, upper)]
    rest = [0.5, 0.3, 1.0, 0.5, 1.2, -0.5, 0.0, 0.0]  # far from the start: the null space pulls here
    plain = _ik(session, body, maxNumIterations=100)
    full = _ik(session, body, lowerLimits=lower, upperLimits=upper, jointRanges=ranges, restPoses=rest,
               maxNumIterations=100)
    arm_only = _ik(session, body, lowerLimits=lower[:6], upperLimits=upper[:6], jointRanges=ranges[:6],
                   restPoses=rest[:6], maxNumIterations=100)
    assert np.abs(full - plain).max() > 1e-3  # the full-length lists change the answer
    np.testing.assert_allclose(arm_only, plain, atol=1e-12)  # 6 entries (arm only): silently ignored
