"""Lint v3 with --sim (issue 24 item 3): P005, a part that passes through its own parent when its joint moves.

The fixtures (tests/data/sim_sweep/) are one small robot twice: a boom whose joint limits let it
swing down through its column, and the same boom stopping well before it. Both hold overlaps that are
the same at every angle (a column standing in its plate, a wheel spinning in its hub), which must stay
quiet, and links without geometry (looked through as a parent, skipped as a child).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.sim import pass_through as sim_sweep

DATA = Path(__file__).parent / "data" / "sim_sweep"


def _p005(path: Path) -> list:
    options = LintOptions(sim=True, select=["P005"])
    return [f for f in lint_file(path, options.rules(), options).findings if f.rule == "P005"]


def _line_of(path: Path, needle: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


def test_a_boom_swinging_through_its_column_is_found_at_its_joint():
    path = DATA / "passes_through.urdf"
    findings = _p005(path)
    assert [f.line for f in findings] == [_line_of(path, '<joint name="j_boom"')], findings
    message = findings[0].message
    assert "joint 'j_boom' to " in message and " rad " in message
    assert "link 'boom'" in message and "into its parent 'column'" in message  # looked through the geometry-less mount
    assert "mm into" in message and "at home: 0.0 µm" in message


def test_overlaps_that_are_the_same_as_at_home_stay_quiet():
    """The column stands 5 cm deep in its plate and the wheel in its hub at every angle: designed touching."""
    assert _p005(DATA / "quiet.urdf") == []


def test_the_sweep_is_capped(monkeypatch):
    """Only the first MAX_SWEPT_JOINTS driving joints are swept: j_boom is the second."""
    monkeypatch.setattr(sim_sweep, "MAX_SWEPT_JOINTS", 1)
    assert _p005(DATA / "passes_through.urdf") == []


@pytest.mark.parametrize(("lower", "upper", "continuous"), [(-1.0, 2.0, False), (0.0, 0.0, True)])
def test_sweep_values_include_the_limits_or_cover_a_full_turn(lower, upper, continuous):
    values = sim_sweep._sweep_values(lower, upper, continuous)
    assert len(values) == sim_sweep.SWEEP_STEPS
    if continuous:
        assert min(values) > -3.1416 and max(values) < 3.1416 and min(abs(values)) < 1e-12
    else:
        assert values[0] == lower and values[-1] == upper


def test_an_infinite_limit_leaves_the_other_rules_running(tmp_path):
    """``lower="-inf"`` ended a whole ``lint-urdf --sim`` of the file with exit 2 (the home pose of P002
    and P004 could not be sampled); F007 reports it at its line and the other findings stay."""
    text = (DATA / "quiet.urdf").read_text()
    start = text.index('lower="', text.index("<limit"))
    end = text.index('"', start + len('lower="'))
    path = tmp_path / "inf.urdf"
    path.write_text(text[:start] + 'lower="-inf' + text[end:])
    options = LintOptions(sim=True)
    rules = {f.rule for f in lint_file(path, options.rules(), options).findings}
    assert "F007" in rules
