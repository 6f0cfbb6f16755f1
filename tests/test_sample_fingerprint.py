"""The bundled sample face does not change unnoticed.

The sample is what a new user sees first and what the README's pictures, the renders compared
by the GUI tests and the benchmark are made of; the other sample tests hold its properties
(regions, symmetry, soft wrinkles), and this one holds everything it is built of to a
fingerprint: each array's shape, mean, spread and a fixed weighted mean, each name and number
exactly. A deliberate change to the sample updates the reference: run this file with Python
(``python -m tests.test_sample_fingerprint``), which rewrites ``sample_fingerprint.json``, and
look at what changed in the diff.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from studio.core.sample.synthetic import make_test_face

pytestmark = pytest.mark.core

SIZE = (561, 64, 32)  # vertices, texture and mask size: every code path, small and quick
REFERENCE_FILE = Path(__file__).with_name("sample_fingerprint.json")


def fingerprint(value: Any, path: str = "project") -> dict[str, Any]:
    """{path: summary} for everything inside ``value`` (dataclasses, mappings, sequences,
    arrays, scalars): arrays by shape and three statistics rounded to 7 significant digits
    (steadier across machines than their bytes), everything else as it is."""
    if dataclasses.is_dataclass(value):
        found: dict[str, Any] = {}
        for field in dataclasses.fields(value):
            found.update(fingerprint(getattr(value, field.name), f"{path}.{field.name}"))
        return found
    if isinstance(value, dict):
        found = {f"{path}.keys": sorted(map(str, value))}
        for key in value:
            found.update(fingerprint(value[key], f"{path}[{key!r}]"))
        return found
    if isinstance(value, list | tuple):
        found = {f"{path}.len": len(value)}
        for i, item in enumerate(value):
            found.update(fingerprint(item, f"{path}[{i}]"))
        return found
    if isinstance(value, np.ndarray):
        data = value.astype(np.float64).ravel()
        weights = np.sin(np.arange(data.size) * 0.7853) + 1.5  # fixed, uneven: order matters
        stats = (data.mean(), data.std(), (data * weights).mean()) if data.size else ()
        shape = "x".join(map(str, value.shape))
        return {path: [shape, str(value.dtype), *(_round(s) for s in stats)]}
    if isinstance(value, float | np.floating):
        return {path: _round(float(value))}
    if value is None or isinstance(value, str | bool | int | np.integer):
        return {path: value if not isinstance(value, np.integer) else int(value)}
    public = {k: v for k, v in vars(value).items() if not k.startswith("_")}  # not caches
    return fingerprint(public, path)


def _round(x: float) -> float:
    return float(f"{x:.7g}")


def test_the_sample_is_built_exactly_as_recorded() -> None:
    """Every array, name and number of the sample (mesh, poses, maps, masks, areas, links,
    technique-2 set-up, timeline) matches the recorded fingerprint."""
    reference = json.loads(REFERENCE_FILE.read_text())
    found = json.loads(json.dumps(fingerprint(make_test_face(*SIZE))))  # tuples as lists
    assert sorted(found) == sorted(reference), "the sample's structure changed"
    for path, expected in reference.items():
        assert _close(found[path], expected), (path, found[path], expected)


def _close(found: Any, expected: Any) -> bool:
    """Numbers within a relative 1e-5 (a float32 sum may round otherwise elsewhere), the rest
    equal."""
    if isinstance(expected, list):
        return len(found) == len(expected) and all(map(_close, found, expected))
    if isinstance(expected, float):
        return found == pytest.approx(expected, rel=1e-5, abs=1e-7)
    return found == expected


if __name__ == "__main__":
    REFERENCE_FILE.write_text(json.dumps(fingerprint(make_test_face(*SIZE)), indent=1,
                                         sort_keys=True) + "\n")
