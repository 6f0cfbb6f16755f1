"""The sample kept set up in the user's cache (widgets/sample_cache.py): the first start sets the
ICT head up and writes it, even when the studio is closed at once; later starts read it (with
the camera already framing the face) instead of setting it up again; older caches go."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

from studio.widgets import sample_cache

FIRST_START = """
import sys
from studio.widgets.sample_cache import cached_sample
cached_sample()
sys.exit(0)  # closed at once: the write on its worker thread must still finish
"""


def test_the_first_start_keeps_the_sample_and_later_starts_read_it(tmp_path, monkeypatch
                                                                   ) -> None:
    """Red once: with the writer a daemon thread, the process that exits at once left no
    cache, and the next start set the head up again."""
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"), QT_QPA_PLATFORM="offscreen")
    subprocess.run([sys.executable, "-c", FIRST_START], env=env, check=True, timeout=600,
                   cwd=Path(__file__).resolve().parents[1])
    kept = list((tmp_path / "cache").rglob("sample-*.wrinkle"))
    assert len(kept) == 1 and kept[0].stem == f"sample-{sample_cache.fingerprint()}"
    folder = kept[0].parent

    old = folder / "sample-0123456789abcdef.wrinkle"  # a cache of an older studio
    old.write_bytes(b"old")
    monkeypatch.setattr(sample_cache, "cache_dir", lambda: folder)
    import studio.core.setup.sample_setup as setup

    def never() -> None:
        raise AssertionError("the sample was set up again instead of read from the cache")

    monkeypatch.setattr(setup, "sample_project", never)
    project = sample_cache.cached_sample()
    assert "camera" in project.view  # framed once, when it was set up
    assert len(project.poses) > 10 and project.influence.areas and project.wdv.areas
    assert old.exists()  # only a new write clears older caches

    monkeypatch.setattr(sample_cache, "fingerprint", lambda: "fedcba9876543210")
    calls = []
    monkeypatch.setattr(setup, "sample_project", lambda: calls.append(1) or project)
    sample_cache.cached_sample()  # another studio: set up again (here: handed the same head)
    for thread in threading.enumerate():
        if thread.name == "sample-cache":
            thread.join()
    assert calls == [1]
    assert sorted(p.name for p in folder.glob("sample-*.wrinkle")) == [
        "sample-fedcba9876543210.wrinkle"]
