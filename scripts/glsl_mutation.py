"""Mutation testing of the GLSL in shaders/: the part of the studio core's mutation testing
(scripts/mutation.sh, mutmut on studio/core) never reaches.

Each mutant is one small change to one shader file — an arithmetic operator (+ −, * /, and
their compound assignments), a comparison (< <=, > >=, == !=), && ||, a numeric constant
(plus one), a swizzle (components reversed, or a single one moved on: x→y→z→x, w→x) — written
into a COPY of shaders/ in a temporary folder; the tests that draw with that file then run with
WRINKLE_SHADER_DIR pointing at the copy (studio/render/shaders.py loads from there), so the
tree's own shaders are never touched. A mutant is caught when a test fails (pytest -x stops at
the first), or when its run takes longer than ``TIMEOUT_FACTOR`` times the unmutated run (the
rule mutmut has too). A mutant the driver refuses to compile or link is not valid GLSL: it is
counted apart and left out of the score (it says nothing about the tests).

Comments and preprocessor lines are never mutated. The tests each file is judged by are in
``TESTS``; the fastest, most telling ones come first so a caught mutant is usually caught in
seconds.

Usage: python scripts/glsl_mutation.py [--sample N] [--seed S] [--jobs J] [--list] [FILE ...]
  FILE ...     shader files to mutate (default: every file with tests in TESTS)
  --sample N   run N mutants drawn at random (seeded) across the chosen files instead of all:
               the whole set takes hours of software rendering; the score is then an estimate
  --list       print the mutants and stop
At the end it prints a table (per file: mutants, run, invalid GLSL, caught, not caught, score)
and writes the survivors, each with its line before and after, to
docs/glsl-mutation-survivors.txt.
"""

from __future__ import annotations

import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHADERS = ROOT / "shaders"
SURVIVORS = ROOT / "docs" / "glsl-mutation-survivors.txt"
ENV = "WRINKLE_SHADER_DIR"  # studio.render.shaders.SHADER_DIR_ENV (not imported: no GL here)
TIMEOUT_FACTOR = 4.0

FRAGMENT = "tests/test_fragment_reference.py"
RENDER = "tests/test_render.py"
GPU_REFERENCE = "tests/test_gpu_reference.py"
DEFORM = "tests/test_gpu_deform.py"
TANGENT = "tests/test_tangent_render.py"
RELIEF = "tests/test_relief.py"
TESSELLATION = "tests/test_tessellation_reference.py"
# each shader file and the tests that draw with it, quickest and most telling first
TESTS: dict[str, tuple[str, ...]] = {
    "face.frag": (FRAGMENT, TANGENT, RENDER, RELIEF),  # relief: the parallax code
    "common.glsl": (FRAGMENT, TANGENT, RENDER, RELIEF),
    "face.vert": (GPU_REFERENCE, FRAGMENT, TANGENT, RENDER),
    "t1_compose.frag": (FRAGMENT, GPU_REFERENCE, RENDER),
    "t1_compose.vert": (FRAGMENT, GPU_REFERENCE, RENDER),
    "deform_blend.vert": (DEFORM,),
    "deform_frame.vert": (DEFORM,),
    "deform_strain.vert": (DEFORM,),
    "deform_data.glsl": (DEFORM,),
    "relief.glsl": (TESSELLATION, RELIEF),
    "face.tesc": (TESSELLATION, RELIEF),
    "face.tese": (TESSELLATION, RELIEF),
}

_NUMBER = r"(?<![\w.])(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])"
_SWIZZLE = r"(?<=[\w)\]])\.(?:[xyzw]{1,4}|[rgba]{1,4})\b"
_OPERATOR = r"&&|\|\||\+\+|--|[-+*/]=|<=|>=|==|!=|[<>+\-*/]"
_TOKEN = re.compile(f"(?P<number>{_NUMBER})|(?P<swizzle>{_SWIZZLE})|(?P<op>{_OPERATOR})")
_SWAP = {"+": "-", "-": "+", "*": "/", "/": "*", "+=": "-=", "-=": "+=", "*=": "/=",
         "/=": "*=", "<": "<=", "<=": "<", ">": ">=", ">=": ">", "==": "!=", "!=": "==",
         "&&": "||", "||": "&&"}
_NEXT = {"x": "y", "y": "z", "z": "x", "w": "x", "r": "g", "g": "b", "b": "r", "a": "r"}


@dataclass(frozen=True)
class Mutant:
    file: str
    line: int  # 1-based
    start: int  # column span in the line
    end: int
    replacement: str
    kind: str  # operator | comparison | constant | swizzle

    def apply(self, lines: list[str]) -> str:
        changed = list(lines)
        text = changed[self.line - 1]
        changed[self.line - 1] = text[:self.start] + self.replacement + text[self.end:]
        return "".join(changed)

    def describe(self, lines: list[str]) -> tuple[str, str]:
        before = lines[self.line - 1].rstrip("\n")
        after = before[:self.start] + self.replacement + before[self.end:]
        return before.strip(), after.strip()


def _code_part(line: str) -> str:
    """The line up to a // comment; "" for preprocessor lines."""
    if line.lstrip().startswith("#"):
        return ""
    return line.split("//", 1)[0]


def _constant(text: str) -> str:
    if re.fullmatch(r"\d+", text):
        return str(int(text) + 1)
    value = float(text) + 1.0
    return repr(value) if "e" not in repr(value) else f"{value:.6f}"


def _swizzle(text: str) -> str:
    parts = text[1:]
    if len(parts) == 1:
        return "." + _NEXT[parts]
    reversed_ = parts[::-1]
    if reversed_ == parts:  # .xx: move the first component on instead
        return "." + _NEXT[parts[0]] + parts[1:]
    return "." + reversed_


def mutants_of(file: str) -> list[Mutant]:
    """Every mutant of one shader file, in reading order."""
    out = []
    in_block_comment = False
    for number, line in enumerate((SHADERS / file).read_text().splitlines(keepends=True), 1):
        if in_block_comment or "/*" in line:  # the shaders use // comments; skip any /* */
            in_block_comment = "*/" not in line
            continue
        code = _code_part(line)
        for match in _TOKEN.finditer(code):
            text = match.group()
            if match.lastgroup == "number":
                out.append(Mutant(file, number, *match.span(), _constant(text), "constant"))
            elif match.lastgroup == "swizzle":
                out.append(Mutant(file, number, *match.span(), _swizzle(text), "swizzle"))
            elif text in _SWAP:
                before = code[:match.start()].rstrip()
                if text in "+-" and before.endswith(("e", "E")) and re.search(
                        r"\d[eE]$", before):
                    continue  # an exponent's sign is part of a number
                kind = "comparison" if text in ("<", "<=", ">", ">=", "==", "!=", "&&",
                                                "||") else "operator"
                out.append(Mutant(file, number, *match.span(), _SWAP[text], kind))
    return out


@dataclass
class Result:
    mutant: Mutant
    outcome: str  # caught | survived | invalid | timeout
    seconds: float


def _pytest(tests: tuple[str, ...], shader_dir: Path | None, timeout: float | None
            ) -> tuple[int | None, str, float]:
    env = dict(os.environ)
    if shader_dir is not None:
        env[ENV] = str(shader_dir)
    env.setdefault("LP_NUM_THREADS", "1")  # llvmpipe: one core per job, the jobs in parallel
    start = time.monotonic()
    try:
        done = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p",
                               "no:cacheprovider", "--no-header", *tests], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "", time.monotonic() - start
    return done.returncode, done.stdout + done.stderr, time.monotonic() - start


def _invalid(output: str) -> bool:
    return "GLSL Compiler failed" in output or "GLSL Linker failed" in output


def run_mutant(mutant: Mutant, baseline: dict[str, float]) -> Result:
    lines = (SHADERS / mutant.file).read_text().splitlines(keepends=True)
    with tempfile.TemporaryDirectory(prefix="glsl-mutant-") as folder:
        copy = Path(folder) / "shaders"
        shutil.copytree(SHADERS, copy)
        (copy / mutant.file).write_text(mutant.apply(lines))
        tests = TESTS[mutant.file]
        code, output, seconds = _pytest(tests, copy, TIMEOUT_FACTOR * baseline[mutant.file] + 10)
    if code is None:
        return Result(mutant, "timeout", seconds)
    if code == 0:
        return Result(mutant, "survived", seconds)
    return Result(mutant, "invalid" if _invalid(output) else "caught", seconds)


def table(results: list[Result], files: list[str], counts: dict[str, int]) -> str:
    rows = ["| file | mutants | run | invalid GLSL | caught | not caught | score |",
            "|---|---|---|---|---|---|---|"]
    totals = [0, 0, 0, 0, 0]
    for file in [*files, None]:
        mine = [r for r in results if file is None or r.mutant.file == file]
        total = sum(counts.values()) if file is None else counts[file]
        invalid = sum(r.outcome == "invalid" for r in mine)
        caught = sum(r.outcome in ("caught", "timeout") for r in mine)
        survived = sum(r.outcome == "survived" for r in mine)
        values = [total, len(mine), invalid, caught, survived] if file else totals
        if file:
            totals = [a + b for a, b in zip(totals, values, strict=True)]
        judged = values[3] + values[4]
        score = f"{100 * values[3] / judged:.1f} %" if judged else "–"
        name = file or "**shaders/**"
        rows.append(f"| {name} | " + " | ".join(f"{v:,}".replace(",", " ") for v in values)
                    + f" | {score} |")
    return "\n".join(rows)


def write_survivors(results: list[Result], files: list[str], sampled: bool,
                    seconds: float) -> None:
    """The survivors of this run, replacing the lines of the files it mutated; the lines of
    files it did not run stay, so a run of one file updates its part of the list."""
    survivors = [r for r in results if r.outcome == "survived"]
    kept = []
    if SURVIVORS.exists():
        kept = [line for line in SURVIVORS.read_text().splitlines()
                if line and not line.startswith("#") and line.split(":", 1)[0] not in files]
    head = [f"# GLSL mutants no test catches, written by scripts/glsl_mutation.py; the last run "
            f"({', '.join(files)}): {len(survivors)} of {len(results)} run"
            + (", a seeded sample" if sampled else "") + f", {seconds / 60:.0f} min.",
            "# file:line  kind  - before | + after", ""]
    body = []
    for r in survivors:
        lines = (SHADERS / r.mutant.file).read_text().splitlines(keepends=True)
        before, after = r.mutant.describe(lines)
        body.append(f"{r.mutant.file}:{r.mutant.line}  {r.mutant.kind}  - {before} | + {after}")
    order = {f: k for k, f in enumerate(TESTS)}

    def place(line: str) -> tuple[int, int]:
        file, rest = line.split(":", 1)
        return order.get(file, len(order)), int(rest.split()[0])

    SURVIVORS.write_text("\n".join(head + sorted(kept + body, key=place)) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", help="shader files (default: all with tests)")
    parser.add_argument("--sample", type=int, help="run this many mutants, drawn at random")
    parser.add_argument("--seed", type=int, default=29)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--list", action="store_true", help="print the mutants and stop")
    args = parser.parse_args(argv)
    files = args.files or list(TESTS)
    unknown = [f for f in files if f not in TESTS]
    if unknown:
        parser.error(f"no tests are named for {', '.join(unknown)} (TESTS in this script)")
    every = {f: mutants_of(f) for f in files}
    counts = {f: len(m) for f, m in every.items()}
    chosen = [m for f in files for m in every[f]]
    if args.sample and args.sample < len(chosen):
        chosen = sorted(random.Random(args.seed).sample(chosen, args.sample),
                        key=lambda m: (files.index(m.file), m.line, m.start))
    if args.list:
        for m in chosen:
            lines = (SHADERS / m.file).read_text().splitlines(keepends=True)
            before, after = m.describe(lines)
            print(f"{m.file}:{m.line} {m.kind}: {before}  ->  {after}")
        print(f"{len(chosen)} mutants")
        return 0
    start = time.monotonic()
    baseline: dict[str, float] = {}
    for tests in sorted({TESTS[f] for f in {m.file for m in chosen}}):
        code, output, seconds = _pytest(tests, None, None)
        if code != 0:
            print(output[-3000:])
            print(f"the unmutated shaders fail {' '.join(tests)}: fix that first")
            return 1
        for f in files:
            if TESTS[f] == tests:
                baseline[f] = seconds
        print(f"unmutated: {' '.join(tests)} pass in {seconds:.0f} s", flush=True)
    results: list[Result] = []
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for done, result in enumerate(pool.map(lambda m: run_mutant(m, baseline), chosen), 1):
            results.append(result)
            m = result.mutant
            print(f"[{done}/{len(chosen)}] {m.file}:{m.line} {m.kind} {result.outcome} "
                  f"({result.seconds:.0f} s)", flush=True)
    seconds = time.monotonic() - start
    print()
    print(table(results, files, counts))
    print(f"\n{len(results)} mutants in {seconds / 60:.1f} min"
          + (f" (a sample of {len(chosen)} of {sum(counts.values())}, seed {args.seed})"
             if args.sample else ""))
    write_survivors(results, files, bool(args.sample), seconds)
    print(f"survivors: {SURVIVORS.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
