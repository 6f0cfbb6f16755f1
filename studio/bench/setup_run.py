"""``wrinkle-studio bench --setup``: each head of ``setup_heads`` set up as ``new --auto`` sets
it up (the sample as the studio's first start builds it) and its project written, each head in
a fresh process (``python -m studio.bench.setup_run INDEX``: an empty cache, no memory held
from the head before), with each stage's wall time, CPU time and peak memory
(``stage_clock``): a table, ``setup.csv`` and ``setup.md``."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

from studio.bench.setup_heads import BenchHead, bench_heads
from studio.core.files.atomic_write import write_atomic
from studio.core.files.errors import StudioError
from studio.core.setup.stage_clock import StageClock, StageFigures, peak_mb, reset_peak, stage

STAGES = ("reading", "face finding", "orientation", "strain", "synthesis", "masks", "vectors",
          "writing")
TOTAL = "total"


def set_up(head: BenchHead, folder: Path) -> dict[str, dict[str, float]]:
    """Set the head up from its files in ``folder`` and write the project there: {stage:
    figures} in ``STAGES`` order, then the whole's, the peak the largest of any stage's."""
    from studio.core.project.writer import save_project
    from studio.core.setup.new_setup import new_project
    from studio.core.setup.sample_setup import ready_sample

    files = None if head.sample else head.write(folder)
    clock = StageClock()
    reset_peak()
    wall, cpu = time.perf_counter(), time.process_time()
    with clock.running():
        if head.sample:
            project = ready_sample()
        else:
            project = new_project(files[0], files[1], auto=True).project
        with stage("writing"):
            save_project(project, folder / "head.wrinkle", backup=False)
    whole = StageFigures(time.perf_counter() - wall, time.process_time() - cpu, peak_mb())
    figures = {name: clock.figures.get(name, StageFigures()) for name in STAGES}
    figures[TOTAL] = StageFigures(whole.wall_s, whole.cpu_s,
                                  max(f.peak_mb for f in figures.values()))
    return {name: asdict(f) for name, f in figures.items()}


def measure(quick: bool = False, say=print) -> list[tuple[str, dict[str, dict[str, float]]]]:
    """Every head's figures, each head set up in a fresh process (this module run as a
    script); ``say`` hears each head's table as it is done."""
    results = []
    for index, head in enumerate(bench_heads(quick)):
        say(f"setting up {head.label} …")
        done = subprocess.run([sys.executable, "-m", "studio.bench.setup_run", str(index),
                               *(["--quick"] if quick else [])], stdout=subprocess.PIPE,
                              text=True, check=False)
        if done.returncode != 0:
            raise StudioError(f"setting up {head.label} failed (exit code {done.returncode})")
        figures = json.loads(done.stdout.splitlines()[-1])
        results.append((head.label, figures))
        say(table([(head.label, figures)]))
    return results


def table(results: list[tuple[str, dict[str, dict[str, float]]]]) -> str:
    """A Markdown table: a row per head and stage, seconds and MB."""
    lines = ["| head | stage | wall s | CPU s | peak MB |", "|---|---|---:|---:|---:|"]
    for label, figures in results:
        for name, f in figures.items():
            if f["wall_s"] or name == TOTAL:
                lines.append(f"| {label if name == TOTAL else ''} | {name} | {f['wall_s']:.2f} "
                             f"| {f['cpu_s']:.2f} | {f['peak_mb']:.0f} |")
    return "\n".join(lines)


def write_results(results: list[tuple[str, dict[str, dict[str, float]]]], out: Path,
                  notes: Sequence[str] = ()) -> None:
    """``setup.md`` (the table, then ``notes``: a line each) and ``setup.csv`` (a row per head
    and stage) in ``out``."""
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(["head", "stage", "wall_s", "cpu_s", "peak_mb"])
    for label, figures in results:
        for name, f in figures.items():
            writer.writerow([label, name, round(f["wall_s"], 3), round(f["cpu_s"], 3),
                             round(f["peak_mb"], 1)])
    write_atomic(out / "setup.csv", text.getvalue().encode(), what="results")
    text = "\n\n".join([table(results), *notes]) + "\n"
    write_atomic(out / "setup.md", text.encode(), what="results")


def main(argv: list[str] | None = None) -> int:
    """Set up one head (by its index in ``bench_heads``) and print its figures as JSON."""
    args = argv if argv is not None else sys.argv[1:]
    with tempfile.TemporaryDirectory(prefix="wrinkle-bench-") as folder:
        figures = set_up(bench_heads("--quick" in args)[int(args[0])], Path(folder))
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
