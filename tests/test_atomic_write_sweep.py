"""What a save leaves behind, and what the next save sweeps away.

A save killed half-way leaves a hidden, locked temporary file (``.NAME.XXXX.tmp``) or a
backup's staging link (``.NAME.bak.PID-START.staging``: its process id and start time); the
next save of the same file removes those nobody is writing any more, and nothing else: not
another file's temporaries, not one a live save holds locked, not a link or a folder that
happens to have such a name, not a staging link of a process still running. New files get the
permissions the umask gives, a replaced file keeps its own.
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

import pytest

from studio.core.files.atomic_write import (
    remove_stale_temps,
    stale_backup_staging,
    temp_prefix,
    write_atomic,
)
from studio.core.files.errors import StudioError
from studio.core.files.processes import process_tag, tag_alive

pytestmark = pytest.mark.core

NAME = "face.wrinkle"
DEAD_PID = 4_194_000  # above Linux's largest pid: no process has it


def touch(folder: Path, name: str) -> Path:
    path = folder / name
    path.write_bytes(b"half a save")
    return path


def test_temporaries_nobody_writes_are_swept_and_nothing_else(tmp_path: Path) -> None:
    assert temp_prefix(NAME) == ".face.wrinkle."
    stale = touch(tmp_path, ".face.wrinkle.ab12.tmp")
    other = touch(tmp_path, ".other.wrinkle.ab12.tmp")
    upper = touch(tmp_path, ".face.wrinkle.ab12.TMP")
    kept_name = touch(tmp_path, "face.wrinkle.ab12.tmp")  # not hidden: not ours
    held = touch(tmp_path, ".face.wrinkle.cd34.tmp")
    (tmp_path / ".face.wrinkle.dir.tmp").mkdir()
    os.symlink(other, tmp_path / ".face.wrinkle.link.tmp")
    with open(held, "rb") as handle:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX)  # a save writing it right now
        remove_stale_temps(tmp_path, NAME)
        assert held.exists()
    assert not stale.exists()
    assert other.exists() and upper.exists() and kept_name.exists()
    assert (tmp_path / ".face.wrinkle.dir.tmp").is_dir()
    assert (tmp_path / ".face.wrinkle.link.tmp").is_symlink() and other.exists()


def test_staging_links_of_dead_processes_are_stale(tmp_path: Path) -> None:
    dead = touch(tmp_path, f".face.wrinkle.bak.{DEAD_PID}.staging")
    mine = touch(tmp_path, f".face.wrinkle.bak.{os.getpid()}.staging")
    live = touch(tmp_path, ".face.wrinkle.bak.1.staging")  # init: running since boot
    odd = touch(tmp_path, ".face.wrinkle.bak.abc.staging")
    other = touch(tmp_path, f".other.wrinkle.bak.{DEAD_PID}.staging")
    assert stale_backup_staging(tmp_path, NAME) == [str(dead)]
    assert stale_backup_staging(tmp_path / "missing", NAME) == []
    remove_stale_temps(tmp_path, NAME)
    assert not dead.exists()
    assert mine.exists() and live.exists() and odd.exists() and other.exists()


def test_a_write_sweeps_before_it_writes_and_leaves_only_the_file(tmp_path: Path) -> None:
    touch(tmp_path, ".face.wrinkle.ab12.tmp")
    touch(tmp_path, f".face.wrinkle.bak.{DEAD_PID}.staging")
    write_atomic(tmp_path / NAME, b"project")
    assert sorted(p.name for p in tmp_path.iterdir()) == [NAME]


def test_permissions_come_from_the_umask_or_the_replaced_file(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        write_atomic(tmp_path / "new.bin", b"1")
        assert (tmp_path / "new.bin").stat().st_mode & 0o777 == 0o640
        existing = tmp_path / "kept.bin"
        existing.write_bytes(b"0")
        existing.chmod(0o604)
        write_atomic(existing, b"1")
        assert existing.stat().st_mode & 0o777 == 0o604
    finally:
        os.umask(old)
    assert os.umask(old) == old  # the umask itself is left as it was


def test_a_write_names_what_it_could_not_write(tmp_path: Path) -> None:
    with pytest.raises(StudioError) as caught:
        write_atomic(tmp_path / "missing" / "a.bin", b"1")
    assert caught.value.problem.startswith("cannot write the file: ")
    write_atomic(tmp_path / "made" / "a.bin", b"1", make_folders=True)
    assert (tmp_path / "made" / "a.bin").read_bytes() == b"1"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)")
def test_a_live_process_that_reused_a_dead_saves_id_does_not_keep_its_staging_link(
        tmp_path: Path) -> None:
    """The staging link shares its inode with the project, so later saves' links renew its
    ctime: the dead save's id, now a running process's, must not keep the link. The start time
    in its name tells them apart."""
    tag = process_tag()
    pid, _, ticks = tag.partition("-")
    reused = touch(tmp_path, f".face.wrinkle.bak.{pid}-{int(ticks) + 1}.staging")
    earlier = touch(tmp_path, f".face.wrinkle.bak.{pid}-{int(ticks) - 1}.staging")
    mine = touch(tmp_path, f".face.wrinkle.bak.{tag}.staging")
    live = touch(tmp_path, f".face.wrinkle.bak.1-{_init_ticks()}.staging")
    assert sorted(stale_backup_staging(tmp_path, NAME)) == sorted([str(reused), str(earlier)])
    assert tag_alive(f"{DEAD_PID}-5") is False and tag_alive("12x") is None
    remove_stale_temps(tmp_path, NAME)
    assert mine.exists() and live.exists() and not reused.exists()


def _init_ticks() -> int:
    return int(Path("/proc/1/stat").read_text().rsplit(")", 1)[1].split()[19])


def test_a_save_names_its_staging_link_with_its_process_start(tmp_path: Path,
                                                               monkeypatch) -> None:
    from studio.core.project import writer

    target = tmp_path / NAME
    target.write_bytes(b"old")
    seen: list[str] = []
    real_replace = os.replace
    monkeypatch.setattr(writer.os, "replace",
                        lambda a, b: (seen.append(Path(a).name), real_replace(a, b)))
    writer.keep_backup(target)
    assert seen == [f".{NAME}.bak.{process_tag()}.staging"]
    assert (tmp_path / f"{NAME}.bak").read_bytes() == b"old"
