"""Benchmark output: a table, ``results.csv``, and PNG plots with the thesis beside ours."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

from PIL import Image, ImageDraw, ImageFont

from studio.bench.configs import (
    AREA_MODEL,
    COMPARISON_AREAS,
    THESIS_BY_VERTICES,
    THESIS_T1_BY_AREAS,
)
from studio.bench.runner import Result
from studio.core.mesh.tangent_frames import DEFAULT_TANGENT_FRAME

COLUMNS = ["technique", "areas", "vertices", "width", "height", "frames", "mean_ms", "fps_mean",
           "fps_min", "fps_max", "fps_std", "relief", "draw", "poses", "frame", "cpu_ms", "look"]


def table(results: Sequence[Result]) -> str:
    lines = [f"{'configuration':<50}{'ms':>9}{'fps':>9}{'min':>9}{'max':>9}{'std':>8}"
             f"{'cpu ms':>9}{'deform ms':>11}"]
    for r in results:
        row = r.row()
        lines.append(f"{r.config.label:<50}{row['mean_ms']:>9.2f}{row['fps_mean']:>9.1f}"
                     f"{row['fps_min']:>9.1f}{row['fps_max']:>9.1f}{row['fps_std']:>8.1f}"
                     f"{row['cpu_ms']:>9.2f}{row['deform_ms']:>11.2f}")
    return "\n".join(lines)


def write_csv(results: Sequence[Result], path: Path) -> None:
    import io

    from studio.core.files.atomic_write import write_atomic

    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for r in results:
        writer.writerow(r.row())
    write_atomic(path, text.getvalue().encode(), what="results")


def _font() -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    """A TrueType font where the system has one (Pillow's bitmap default drops spaces)."""
    for path in ("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                 "/usr/share/fonts/TTF/DejaVuSans.ttf", "DejaVuSans.ttf", "Arial.ttf"):
        try:
            return ImageFont.truetype(path, 12)
        except OSError:
            continue
    return ImageFont.load_default()


def line_plot(path: Path, title: str, x_label: str, series: dict[str, list[tuple[float, float]]],
              size: tuple[int, int] = (760, 460), log_x: bool = False) -> None:
    """A small dependency-free line chart (Pillow): FPS against a parameter."""
    import math

    colours = [(31, 119, 180), (214, 39, 40), (44, 160, 44), (148, 103, 189), (255, 127, 14),
               (140, 86, 75), (23, 190, 207)]
    w, h = size
    left, right, top, bottom = 70, 40, 40, 60
    img = Image.new("RGB", size, "white")
    draw = ImageDraw.Draw(img)
    draw.font = _font()
    points = [p for s in series.values() for p in s]
    if not points:
        return
    fx = (lambda v: math.log2(v)) if log_x else (lambda v: v)
    xs = [fx(x) for x, _ in points]
    x0, x1 = min(xs), max(xs) if max(xs) > min(xs) else min(xs) + 1
    y1 = max(y for _, y in points) * 1.1 or 1.0

    def to_px(x: float, y: float) -> tuple[float, float]:
        return (left + (fx(x) - x0) / (x1 - x0) * (w - left - right),
                h - bottom - y / y1 * (h - top - bottom))

    draw.rectangle((left, top, w - right, h - bottom), outline=(120, 120, 120))
    for i in range(6):
        y = y1 * i / 5
        _, py = to_px(x0 if not log_x else 2 ** x0, y)
        draw.line((left, py, w - right, py), fill=(230, 230, 230))
        draw.text((8, py - 6), f"{y:.0f}", fill=(60, 60, 60))
    last = -math.inf
    for x in sorted({x for x, _ in points}):
        px, _ = to_px(x, 0)
        if px - last >= 30:  # close values (2091, 2172) would print over each other
            draw.text((px - 10, h - bottom + 6), f"{x:g}", fill=(60, 60, 60))
            last = px
    draw.text((left, 12), title, fill=(0, 0, 0))
    draw.text((w // 2 - 40, h - 22), x_label, fill=(0, 0, 0))
    draw.text((8, top - 20), "FPS", fill=(0, 0, 0))
    for k, pts in enumerate(series.values()):
        colour = colours[k % len(colours)]
        xy = [to_px(x, y) for x, y in sorted(pts)]
        if len(xy) > 1:
            draw.line(xy, fill=colour, width=2)
        for px, py in xy:
            draw.ellipse((px - 3, py - 3, px + 3, py + 3), fill=colour)
    # the legend on a white box, so that no line runs through it
    draw.rectangle((w - right - 236, top + 4, w - right - 4, top + 12 + 16 * len(series)),
                   fill="white", outline=(200, 200, 200))
    for k, name in enumerate(series):
        colour = colours[k % len(colours)]
        ly = top + 14 + 16 * k
        draw.line((w - right - 230, ly, w - right - 212, ly), fill=colour, width=3)
        draw.text((w - right - 206, ly - 7), name, fill=colour)
    from studio.core.files.atomic_write import atomic_output

    with atomic_output(path, what="plot") as handle:
        img.save(handle, format="PNG")


def write_plots(results: Sequence[Result], out: Path) -> list[Path]:
    # reliefs, the many-poses and still cases and the thesis's tangent frame: in the table only
    results = [r for r in results if r.config.relief == "off" and not r.config.poses
               and not r.config.still and r.config.frame == DEFAULT_TANGENT_FRAME
               and r.config.look == "clay"]
    whole = [r for r in results if r.config.draw == "whole"]
    results = [r for r in results if r.config.draw == "split"]
    by_areas = {"ours: t1": [(r.config.areas, float(r.fps.mean())) for r in results
                             if r.config.technique == "t1" and r.config.vertices == AREA_MODEL]}
    every = [(r.config.areas, float(r.fps.mean())) for r in whole if r.config.technique == "t1"]
    if every:  # the per-pixel cost: every triangle through the wrinkle program
        by_areas["ours: t1, no split draw"] = every
    for technique in ("none",):  # flat (about 4 × faster) would squash the others: table only
        base = [r for r in results
                if r.config.technique == technique and r.config.vertices == AREA_MODEL]
        if base and by_areas["ours: t1"]:
            by_areas[f"ours: {technique} (baseline)"] = [
                (a, float(base[0].fps.mean())) for a, _ in by_areas["ours: t1"]]
    by_areas["thesis: t1 (GeForce Go 6150)"] = [(a, 1000.0 / ms)
                                                 for a, ms in THESIS_T1_BY_AREAS.items()]
    by_vertices: dict[str, list[tuple[float, float]]] = {}
    for technique in ("t1", "t2", "strain", "none"):  # flat: in the table only, as above
        pts = [(r.config.vertices, float(r.fps.mean())) for r in results
               if r.config.technique == technique
               and (technique != "t1" or r.config.areas == COMPARISON_AREAS)]
        if pts:
            by_vertices[f"ours: {technique}"] = pts
    by_vertices["thesis: t1"] = [(v, 1000.0 / t1) for v, (t1, _) in THESIS_BY_VERTICES.items()]
    by_vertices["thesis: t2"] = [(v, 1000.0 / t2) for v, (_, t2) in THESIS_BY_VERTICES.items()]
    paths = [out / "fps_by_areas.png", out / "fps_by_vertices.png"]
    line_plot(paths[0], f"Technique 1: FPS against areas ({AREA_MODEL} vertices)",
              "influence areas (log scale)", by_areas, log_x=True)
    line_plot(paths[1], "FPS against vertices (technique 1 with 8 areas)", "vertices (log scale)",
              by_vertices, log_x=True)
    return paths
