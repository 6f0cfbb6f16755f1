"""Recovery files without a window: which are offered, what they say, and the snapshot a worker
thread writes while edits go on (studio/core/project/recovery.py)."""

from __future__ import annotations

import json
import os
import time

import numpy as np
import pytest

from studio.core.project.recovery import (
    RecoveryFile,
    find_recoveries,
    recovery_meta,
    snapshot_project,
    write_json,
)

pytestmark = pytest.mark.core


def _orphan(folder, session: str, meta: dict | None) -> None:
    """What a window that died leaves: the project, its description, a lock nobody holds."""
    (folder / f"{session}.wrinkle").write_bytes(b"PK")
    if meta is not None:
        write_json(folder / f"{session}.json", meta)
    (folder / f"{session}.lock").write_bytes(b"")


def test_a_dead_windows_file_is_offered_newest_first_a_live_ones_is_not(tmp_path):
    _orphan(tmp_path, "old", {"name": "Old face", "original": "/p/old.wrinkle", "saved_at": 100.0})
    _orphan(tmp_path, "new", {"name": "New face", "original": None, "saved_at": 200.0})
    live = RecoveryFile(tmp_path, "live")
    live.take_lock()
    (tmp_path / "live.wrinkle").write_bytes(b"PK")
    try:
        found = find_recoveries(tmp_path)
    finally:
        live.release(delete_lock=True)
    assert [r.name for r in found] == ["New face", "Old face"]
    assert "Original file: never saved" in found[0].describe()
    assert "Original file: /p/old.wrinkle" in found[1].describe()


def test_a_damaged_description_still_offers_the_file_by_its_name(tmp_path):
    _orphan(tmp_path, "s1", None)
    (tmp_path / "s1.json").write_text("{not json", encoding="utf-8")
    _orphan(tmp_path, "s2", None)
    write_json(tmp_path / "s2.json", {"name": 7, "saved_at": "yesterday"})
    _orphan(tmp_path, "s3", None)
    (tmp_path / "s3.json").write_text("[1, 2]", encoding="utf-8")
    found = {r.project_file.stem: r for r in find_recoveries(tmp_path)}
    assert set(found) == {"s1", "s2", "s3"}
    assert found["s3"].name == "s3"
    assert found["s2"].name == "s2"  # not a string: the file's own name
    assert found["s2"].saved_at == pytest.approx(os.stat(tmp_path / "s2.wrinkle").st_mtime)


def test_a_stray_lock_of_a_window_that_never_saved_is_cleared(tmp_path):
    (tmp_path / "gone.lock").write_bytes(b"")
    assert find_recoveries(tmp_path) == []
    assert not (tmp_path / "gone.lock").exists()


def test_the_story_says_when_it_stopped_and_names_the_crash_log(tmp_path):
    log = tmp_path / "crash.log"
    log.write_text("Fatal Python error", encoding="utf-8")
    _orphan(tmp_path, "s", {"name": "Face", "saved_at": time.time() - 60,
                            "crash_log": str(log)})
    item, = find_recoveries(tmp_path)
    assert "stopped unexpectedly" in item.story()
    assert f"Crash log: {log}" in item.story()
    item.remove()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crash.log"]  # the log stays


def test_an_empty_crash_log_is_not_named(tmp_path):
    log = tmp_path / "crash.log"
    log.write_bytes(b"")
    _orphan(tmp_path, "s", recovery_meta("Face", None, log))
    item, = find_recoveries(tmp_path)
    assert item.crash_log is None and "Crash log" not in item.story()


def test_adopting_a_recovered_file_locks_it_and_lets_go_of_its_own(tmp_path):
    _orphan(tmp_path, "dead", {"name": "Face"})
    mine = RecoveryFile(tmp_path / "mine", "fresh")
    mine.take_lock()
    item, = find_recoveries(tmp_path)
    mine.adopt(item)
    try:
        assert mine.project_file == tmp_path / "dead.wrinkle"
        assert not (tmp_path / "mine" / "fresh.lock").exists()
        assert find_recoveries(tmp_path) == []  # held now: not offered to another window
    finally:
        mine.release(delete_lock=False)
    assert [r.name for r in find_recoveries(tmp_path)] == ["Face"]  # a crash: offered again


def test_meta_names_the_original_and_this_process(tmp_path):
    meta = recovery_meta("Face", tmp_path / "face.wrinkle", None)
    assert json.loads(json.dumps(meta)) == meta
    assert meta["original"] == str(tmp_path / "face.wrinkle") and meta["pid"] == os.getpid()
    assert recovery_meta("Face", None, None)["original"] is None


class _Holder:
    """A project-like object: arrays in attributes, lists and dicts, one read-only."""

    def __init__(self) -> None:
        self.mask = np.zeros((4, 4), np.float32)
        frozen = np.arange(6.0)
        frozen.flags.writeable = False
        self.parts = [{"image": frozen}, (np.ones(3),)]


def test_a_snapshot_is_out_of_reach_of_later_edits_and_shares_what_cannot_change():
    project = _Holder()
    snap = snapshot_project(project)  # type: ignore[arg-type]
    project.mask[1, 1] = 1.0  # a stroke written into the mask in place
    project.parts[1][0][0] = 5.0
    assert snap.mask.max() == 0.0 and snap.parts[1][0][0] == 1.0
    assert snap.parts[0]["image"] is project.parts[0]["image"]  # read-only: not copied


def test_kept_copies_are_reused_until_forgotten():
    project = _Holder()
    kept: dict = {}
    first = snapshot_project(project, kept)  # type: ignore[arg-type]
    assert id(project.mask) in kept
    second = snapshot_project(project, kept)  # type: ignore[arg-type]
    assert second.mask is first.mask  # unchanged since: the same copy
    kept.pop(id(project.mask))  # the mask was painted
    third = snapshot_project(project, kept)  # type: ignore[arg-type]
    assert third.mask is not first.mask
