"""Where the studio's shaders and resources are, installed or in a checkout.

An installed wheel carries them inside the package (``studio/shaders``); a checkout or an editable
install keeps them at the repository root, next to ``studio/``.
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    for candidate in (_PACKAGE / name, _PACKAGE.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"the studio's {name}/ folder is missing from {_PACKAGE}")


def shader_dir() -> Path:
    return _data_dir("shaders")


def resource_dir() -> Path:
    return _data_dir("resources")
