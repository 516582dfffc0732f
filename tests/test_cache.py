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
    return json.loads((folder / "facts-v1" / "common.json").read_text())


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
    facts = FileFacts("facts", 1, max_entries=12)  # a shard keeps a quarter: 3
    for key in "abc":
        facts.store(key, key)
    facts.save()
    again = FileFacts("facts", 1, max_entries=12)  # the next run
    assert again.lookup("a") == "a"
    again.store("a", "A")  # stored again: now the newest
    again.store("d", "d")
    again.save()
    assert list(saved(folder)) == ["c", "a", "d"]
    assert FileFacts("facts", 1).lookup("b") is MISSING


def test_a_store_that_is_not_a_regular_file_is_ignored(folder, tmp_path) -> None:
    import os

    (folder / "facts-v1").mkdir(parents=True)
    os.mkfifo(folder / "facts-v1" / "common.json")
    assert FileFacts("facts", 1).lookup("a") is MISSING  # returns at once, no writer needed
    assert path_state(str(tmp_path / "nothing")) is None


def test_a_folder_has_one_shard_and_a_run_reads_only_the_shards_it_asks_about(folder, tmp_path) -> None:
    """Facts about a folder's files share one of the shard files; a later run asking about one
    folder parses that shard alone (with one store file, every run parsed every entry ever saved).
    Files of older versions are left alone (an older ar3cli may share the cache folder)."""
    import os

    from ar3cli.infra.file_cache import SHARDS, shard_of

    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    first, second = tmp_path / "a" / "one.stl", tmp_path / "b" / "two.stl"
    for mesh in (first, second):
        mesh.write_bytes(b"solid")
    folder.mkdir()
    (folder / "facts-v1.json").write_text("{}")  # ar3cli 0.1's store
    facts = FileFacts("facts", 1)
    facts.put(first, os.stat(first), 1)
    facts.put(second, os.stat(second), 2)
    facts.save()
    assert sorted(path.name for path in (folder / "facts-v1").glob("*.json")) == sorted(
        {f"{shard_of(mesh)}.json" for mesh in (first, second)})
    assert (folder / "facts-v1.json").read_text() == "{}"
    again = FileFacts("facts", 1)
    assert again.get(first, os.stat(first)) == 1
    assert list(again._shards) == [shard_of(first)]
    assert shard_of(first) == shard_of(tmp_path / "a" / "other.stl")
    assert len({shard_of(tmp_path / str(n) / "x.stl") for n in range(1000)}) == SHARDS  # never more files
