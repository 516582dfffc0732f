"""The on-disk caches: concurrent saves merge, the newest entries survive trimming, junk is ignored."""

from __future__ import annotations

import json

import pytest

from ar3cli.infra.file_cache import MISSING, FileFacts, path_state


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv("AR3CLI_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("AR3CLI_NO_CACHE", raising=False)
    return tmp_path / "cache"


def saved(folder) -> dict:
    return json.loads((folder / "facts-v1.json").read_text())


def test_two_processes_saving_at_once_keep_both_their_entries(folder) -> None:
    """pre-commit runs several ar3cli processes at once: each loads the store, learns, saves."""
    first, second = FileFacts("facts", 1), FileFacts("facts", 1)  # two processes, in effect
    first.lookup("nothing yet")
    second.lookup("nothing yet")
    first.store("a.urdf", 1)
    second.store("b.urdf", 2)
    first.save()
    second.save()
    assert saved(folder) == {"a.urdf": 1, "b.urdf": 2}


def test_trimming_keeps_the_most_recently_stored(folder) -> None:
    facts = FileFacts("facts", 1, max_entries=3)
    for key in "abc":
        facts.store(key, key)
    facts.save()
    again = FileFacts("facts", 1, max_entries=3)  # the next run
    assert again.lookup("a") == "a"
    again.store("a", "A")  # stored again: now the newest
    again.store("d", "d")
    again.save()
    assert list(saved(folder)) == ["c", "a", "d"]
    assert FileFacts("facts", 1).lookup("b") is MISSING


def test_a_store_that_is_not_a_regular_file_is_ignored(folder, tmp_path) -> None:
    import os

    folder.mkdir()
    os.mkfifo(folder / "facts-v1.json")
    assert FileFacts("facts", 1).lookup("a") is MISSING  # returns at once, no writer needed
    assert path_state(str(tmp_path / "nothing")) is None
