"""The architecture's layers, enforced: core has no Qt and no GL, render has no Qt, no GLSL in
Python. A violation fails here with the offending file and import."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
QT = ("PySide6", "shiboken6", "pyqtgraph", "studio.widgets", "studio.app")
GL = ("moderngl", "glcontext", "OpenGL", "studio.render")


def imported_modules(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
    return names


def violations(package: str, forbidden: tuple[str, ...]) -> list[str]:
    found = []
    for path in sorted((ROOT / "studio" / package).rglob("*.py")):
        for name in imported_modules(path):
            if any(name == f or name.startswith(f + ".") for f in forbidden):
                found.append(f"{path.relative_to(ROOT)} imports {name}")
    return found


@pytest.mark.parametrize(("package", "forbidden"), [("core", QT + GL), ("render", QT)])
def test_lower_layers_do_not_import_upper_ones(package: str, forbidden: tuple[str, ...]) -> None:
    assert violations(package, forbidden) == []


def test_checker_sees_a_forbidden_import(tmp_path: Path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("import numpy\nfrom PySide6.QtCore import QObject\n")
    assert "PySide6.QtCore" in imported_modules(bad)


def test_no_glsl_inside_python() -> None:
    version_line = re.compile(r"#version\s+\d{3}")
    offenders = [str(p.relative_to(ROOT)) for p in (ROOT / "studio").rglob("*.py")
                 if version_line.search(p.read_text(encoding="utf-8"))]
    assert offenders == []


def test_widget_models_are_qt_free() -> None:
    """A panel's model (``studio/widgets/**/*_model.py``, napari's split) is tested without a
    display: it imports no Qt and no GL, and of the widgets only other models."""
    models = sorted((ROOT / "studio" / "widgets").rglob("*_model.py"))
    assert models  # the rule must look at something
    found = [f"{path.relative_to(ROOT)} imports {name}" for path in models
             for name in imported_modules(path)
             if any(name == f or name.startswith(f + ".") for f in QT + GL)
             and not name.endswith("_model")]
    assert found == []
