"""Put each known regression back by hand and check that the tests meant to catch it go red.

Why: a test suite can stay green while the code it watches is broken (issue #18 found seven such
changes). This script keeps those seven honest: for each one it edits the production line in
place, runs the tests that should catch it, prints the first failing assertion, and restores the
file (also on Ctrl+C). It exits non-zero if any regression leaves its tests green, or if a file
is not byte-for-byte restored.

Usage: python scripts/regressions.py [NAME ...]   (from the repository root, with the venv's
python; names as in REGRESSIONS, default all). Takes a few minutes: some checks are GUI tests.
"""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Regression:
    """One deliberate bug: replace ``old`` (which must occur exactly once) by ``new``."""

    name: str
    path: str
    old: str
    new: str
    tests: tuple[str, ...]


REGRESSIONS = (
    Regression(
        "t2-falloff", "shaders/face.vert",
        "clamp(magnitude * (1.0 - alpha / theta) * u_expression, 0.0, 1.0)",
        "clamp(magnitude * (1.0 - alpha * alpha / (theta * theta)) * u_expression, 0.0, 1.0)",
        ("tests/test_gpu_reference.py::test_technique_2_falloff_by_hand",
         "tests/test_gpu_reference.py::test_technique_2_visibility_on_the_gpu_is_the_formula")),
    Regression(  # in the per-frame path that feeds the renderer
        "handedness-ignored", "studio/core/mesh/geometry.py",
        "np.multiply(mask, np.float32(-2.0), out=row[:, 9])\n        row[:, 9] += np.float32(1.0)",
        "row[:, 9] = 1.0",
        ("tests/test_gpu_reference.py::test_a_mirrored_uv_island_tilts_its_normals_the_same_way",
         "tests/test_gpu_reference.py::"
         "test_a_wrinkle_across_a_uv_seam_and_a_mirrored_island_shades_alike")),
    Regression(  # the same in the MikkTSpace frame, the default since #21
        "mikktspace-handedness-ignored", "studio/core/mesh/tangent_frames.py",
        "    out[:, 3] = handedness\n", "    out[:, 3] = 1.0\n",
        ("tests/test_gpu_reference.py::test_a_mirrored_uv_island_tilts_its_normals_the_same_way",
         "tests/test_tangent_frames.py")),
    Regression(  # in the plain reference the per-frame path is checked against
        "handedness-ignored-reference", "studio/core/mesh/geometry.py",
        'out[:, 3] = np.where(np.einsum("ij,ij->i", np.cross(n, t_sum), b_sum) < 0.0, -1.0, 1.0)',
        "out[:, 3] = 1.0",
        ("tests/test_geometry.py",)),
    Regression(
        "t1-compose-no-clamp", "shaders/t1_compose.frag",
        "weight = clamp(s, 0.0, 1.0);", "weight = s;",
        ("tests/test_gpu_reference.py::test_technique_1_compose_pass_on_the_gpu_is_the_formula",)),
    Regression(
        "archive-nested-path-check", "studio/core/project/reader.py",
        '            or any(p in ("", ".", "..") for p in parts))',
        "            )",
        ("tests/test_project_file.py::test_a_member_whose_name_leads_outside_the_archive_is_refused",)),
    Regression(
        "smooth-made-linear", "studio/core/animation/timeline.py",
        "[f, parke_cosine(f), f * f * (3.0 - 2.0 * f)],", "[f, parke_cosine(f), f],",
        ("tests/test_timeline.py",)),
    Regression(
        "middle-drag-pan-orbit-swapped", "studio/widgets/viewport/viewport.py",
        '                return "zoom"\n            return "pan" if shift else "orbit"',
        '                return "zoom"\n            return "orbit" if shift else "pan"',
        ("tests/test_navigation_gui.py",)),
    Regression(
        "undo-budget-ignores-stroke-tiles", "studio/widgets/undo_budget.py",
        "        total += _array_bytes(value, depth=2)",
        "        total += _array_bytes(value, depth=0)",
        ("tests/test_autosave.py::test_the_budget_counts_a_paint_strokes_tiles",)),
)


def first_failure(output: str) -> str:
    """The failing test and its first ``E`` lines (the assertion), from pytest's output."""
    lines = output.splitlines()
    failed = next((ln for ln in lines if ln.startswith("FAILED")), "")
    errors = [ln[1:].strip() for ln in lines if ln.startswith("E ") and ln[1:].strip()][:3]
    return failed + "".join(f"\n      {e}" for e in errors)


def check(regression: Regression) -> bool:
    """Apply the regression, run its tests, restore the file; True when the tests went red."""
    path = ROOT / regression.path
    original = path.read_bytes()
    text = original.decode()
    if text.count(regression.old) != 1:
        print(f"{regression.name}: the production line was not found once in {regression.path}"
              " — update this script")
        return False
    try:
        path.write_text(text.replace(regression.old, regression.new))
        run = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
             *regression.tests],
            cwd=ROOT, capture_output=True, text=True, check=False)
    finally:
        path.write_bytes(original)
    red = run.returncode == 1
    verdict = "RED (caught)" if red else f"NOT CAUGHT (pytest exit {run.returncode})"
    print(f"{regression.name}: {verdict}")
    if red:
        print(f"      {first_failure(run.stdout + run.stderr)}")
    else:
        print(run.stdout[-2000:])
    return red


def main(names: list[str]) -> int:
    """Check the named regressions (all by default); 0 when every one is caught."""
    chosen = [r for r in REGRESSIONS if not names or r.name in names]
    caught = [check(r) for r in chosen]
    diff = subprocess.run(["git", "diff", "--stat", "--", *{r.path for r in chosen}],
                          cwd=ROOT, capture_output=True, text=True, check=False).stdout
    if diff.strip():
        print("production files differ from git after restoring:\n" + diff)
        return 2
    print(f"{sum(caught)} of {len(chosen)} regressions caught")
    return 0 if all(caught) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
