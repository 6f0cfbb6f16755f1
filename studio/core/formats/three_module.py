"""The three.js module ``wrinkles.js`` and its example page, written beside every glTF export.

A web developer loading our glTF with three.js's GLTFLoader gets the face, its morph targets and
the timeline as a clip, but none of the wrinkles: those need the normal-map blend, the masks,
the activations and technique 2's vectors. ``wrinkles.js`` (``resources/web/wrinkles.js``, an ES
module that imports ``three`` and needs no build step) does it in one call,
``attachWrinkles(gltf)``, from the file's ``extras.wrinklePlayer`` (core/formats/gltf/player.py).
Its activations are the web page's own code (``resources/web/activations.js``), put in where the
module marks it, so the two players compute them from one source.
"""

from __future__ import annotations

import json
from pathlib import Path

from studio.core.files.atomic_write import write_atomic
from studio.paths import resource_dir

MODULE = "wrinkles.js"
EXAMPLE = "example.html"
ACTIVATIONS_MARK = "// {{ACTIVATIONS}}"
MODEL_MARK = "{{MODEL}}"


def three_module_paths(model: Path) -> list[Path]:
    """Where the module and the example page go for the export ``model``."""
    return [model.with_name(MODULE), model.with_name(EXAMPLE)]


def module_text() -> str:
    """``wrinkles.js`` as shipped: the module with the shared activation code put in."""
    web = resource_dir() / "web"
    module = (web / MODULE).read_text(encoding="utf-8")
    return module.replace(ACTIVATIONS_MARK, (web / "activations.js").read_text(encoding="utf-8"))


def ship_three_module(model: str | Path) -> list[Path]:
    """Write ``wrinkles.js`` and ``example.html`` (which loads ``model`` by its file name)
    beside the export ``model``; returns the files written."""
    model = Path(model)
    module, example = three_module_paths(model)
    write_atomic(module, module_text().encode("utf-8"), what="three.js module")
    page = (resource_dir() / "web" / EXAMPLE).read_text(encoding="utf-8")
    name = json.dumps(model.name).replace("<", "\\u003c")  # a JS string, safe in <script>
    write_atomic(example, page.replace(MODEL_MARK, name).encode("utf-8"), what="example page")
    return [module, example]
