"""The README's web-player picture: the sample exported with ``export --web``, its page opened in
headless Chromium (WebGL2 on SwiftShader) at a pose, with the panel; also prints what each
technique changes on the page and how much of it the face fills.

    python scripts/web_picture.py [OUT.png] [--pose NAME] [--technique t1|t2] [--size N]

``open_page`` is the one way the tests and this script drive Chromium.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
FLAGS = ("--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--hide-scrollbars", "--mute-audio", "--no-first-run")
CHANGED = 8  # a pixel changed when a channel moved by more than this (of 255)


class NoChromium(RuntimeError):
    pass


def chromium() -> str:
    found = shutil.which("chromium")
    if found is None:
        raise NoChromium("Chromium is not installed: run 'bash scripts/setup.sh' (it installs "
                         "the Debian packages in resources/debian-packages.txt) or apt-get "
                         "install chromium")
    return found


def open_page(page: Path, query: str, out: Path | None, size: int = 800,
              settle_ms: int = 30000) -> str:
    """Chromium's screenshot of the page into ``out`` (or, with ``out=None``, its DOM) after
    ``settle_ms`` of virtual time, which runs the page's own timers, promises (its data is
    inflated asynchronously) and animation frames before Chromium takes the picture. Returns
    what Chromium printed (the DOM)."""
    with tempfile.TemporaryDirectory() as profile:
        args = [chromium(), *FLAGS, f"--window-size={size},{size}",
                f"--virtual-time-budget={settle_ms}", f"--user-data-dir={profile}"]
        args += [f"--screenshot={out}"] if out is not None else ["--dump-dom"]
        done = subprocess.run([*args, f"{page.as_uri()}?{query}"], capture_output=True,
                              text=True, timeout=180, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"chromium failed ({done.returncode}): {done.stderr[-2000:]}")
    return done.stdout


def pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.int16)


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pixels where any channel moved by more than ``CHANGED``."""
    return np.abs(a - b).max(axis=2) > CHANGED


def face_share(image: np.ndarray) -> float:
    """Share of the picture that is not the background (the top-left pixel's colour)."""
    return float((np.abs(image - image[0, 0]).max(axis=2) > 6).mean())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", type=Path,
                        default=ROOT / "docs" / "images" / "web_player.png")
    parser.add_argument("--pose", default="browInnerUp_L")
    parser.add_argument("--technique", choices=("t1", "t2"), default="t2")
    parser.add_argument("--size", type=int, default=800)
    args = parser.parse_args()
    from studio.cli import main as studio
    from studio.core.files.atomic_write import atomic_output

    with tempfile.TemporaryDirectory() as temp:
        temp_dir = Path(temp)
        project = temp_dir / "sample.wrinkle"
        if studio(["sample", "-o", str(project)]) or \
                studio(["export", str(project), "--web", str(temp_dir / "web")]):
            return 1
        page = temp_dir / "web" / "index.html"
        print(f"page: {page.stat().st_size / 1e6:.1f} MB")
        shots = {}
        for technique in ("none", "t1", "t2"):
            shot = temp_dir / f"{technique}.png"
            open_page(page, f"pose={args.pose}&weight=1&technique={technique}&ui=0", shot,
                      args.size)
            shots[technique] = pixels(shot)
        print(f"face fills {face_share(shots['none']):.1%} of the picture")
        for technique in ("t1", "t2"):
            print(f"{technique} changes {changed(shots[technique], shots['none']).mean():.2%} "
                  f"of the pixels at {args.pose} 1")
        shot = temp_dir / "picture.png"
        open_page(page, f"pose={args.pose}&weight=1&technique={args.technique}", shot, args.size)
        with atomic_output(args.out, make_folders=True, what="picture") as handle:
            Image.open(shot).convert("RGB").save(handle, format="PNG", optimize=True)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
