"""Feedback off a terminal (issue 36, item 8): a plain progress line every few seconds, and a note when
one isolated step (lint-urdf --sim on a humanoid, ~7 s) works long. Times are shortened here; no test
asserts a wall-clock time."""

from __future__ import annotations

import time

import pytest

from ar3cli.infra.process_pool import can_fork


def test_a_loop_off_a_terminal_prints_plain_lines(monkeypatch, capsys) -> None:
    from ar3cli.output import progress

    monkeypatch.setattr(progress, "PLAIN_EVERY_S", 0.0)
    with progress.progress_bar("scanning", 3, unit="files") as advance:
        advance(1)
        advance(2)
    lines = capsys.readouterr().err.splitlines()
    assert [line.split(",")[0] for line in lines] == ["scanning: 1/3 files", "scanning: 3/3 files"]
    assert all("files/s" in line and line.endswith(" s") for line in lines)


def test_a_short_loop_prints_nothing(capsys) -> None:
    from ar3cli.output.progress import progress_bar

    with progress_bar("sampling", 2) as advance:
        advance(2)
    assert capsys.readouterr().err == ""


@pytest.mark.skipif(not can_fork(), reason="isolation forks (Linux only)")
def test_a_slow_isolated_step_is_announced_with_its_stage(monkeypatch) -> None:
    from ar3cli.infra import isolation

    said: list[str] = []
    monkeypatch.setattr(isolation, "SLOW_FIRST_S", 0.0)
    monkeypatch.setattr(isolation, "SLOW_EVERY_S", 0.5)
    isolation.announce_slow_work(said.append)
    try:
        def work() -> int:
            isolation.report_stage("simulating it")
            time.sleep(1.5)
            return 7

        assert isolation.run_isolated(work, "g1.urdf") == 7
    finally:
        isolation.announce_slow_work(None)
    assert said and said[0].startswith("g1.urdf: still ")
    assert any("simulating it" in line for line in said)
