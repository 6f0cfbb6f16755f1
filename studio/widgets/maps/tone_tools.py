"""Each wrinkled map's cavity and colour maps (core/wrinkles/skin_tone.py) in the Maps menu,
beside its normal map: replace one with an image (a painter's own, or one exported and painted
over), export it to paint over, or remove it (the skin's tone then stays as it is under that
map). Every change is one undo step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtWidgets import QFileDialog, QMenu

from studio.core.files.images import load_grey, load_rgb, write_png
from studio.core.wrinkles.textures import tone_image
from studio.widgets.document import Document
from studio.widgets.maps.image_swap import ImageSwapCommand

KINDS = {"cavity": "cavity map", "colour": "colour map"}


def tone_maps(doc: Document, kind: str) -> dict[str, np.ndarray]:
    return getattr(doc.project.textures, f"{kind}_maps")


def load_tone(kind: str, path: Path) -> np.ndarray:
    """The image as the kind of map it replaces: greyscale 8-bit (cavity) or RGB (colour)."""
    if kind == "cavity":
        return np.rint(load_grey(path) * 255.0).astype(np.uint8)
    return load_rgb(path)


class SetToneCommand(ImageSwapCommand):
    """Replace (or remove, with None) one wrinkled map's cavity or colour map."""

    def __init__(self, doc: Document, name: str, kind: str, image: np.ndarray | None,
                 text: str) -> None:
        def put(tone: np.ndarray | None) -> None:
            if tone is None:
                tone_maps(doc, kind).pop(name, None)
            else:
                doc.project.textures.set_tone(name, **{kind: tone})

        super().__init__(doc, tone_maps(doc, kind).get(name), image, text, put)


class ToneTools:
    """The cavity and colour entries of a wrinkled map's submenu; ``tools``: the Maps menu's
    MapTools (its file dialog and error reporting)."""

    def __init__(self, tools) -> None:
        self.tools = tools

    @property
    def doc(self) -> Document:
        return self.tools.doc

    def replace(self, name: str, kind: str) -> None:
        label = f"{KINDS[kind]} of “{name}”"
        path = self.tools._ask_image(f"Replace the {label}")
        image = self.tools._load(lambda p: tone_image(kind, load_tone(kind, p), name),
                                 path) if path else None
        if image is None:
            return
        self.doc.undo_stack.push(SetToneCommand(self.doc, name, kind, image,
                                                f"Replace {label}"))

    def export(self, name: str, kind: str) -> None:
        image = tone_maps(self.doc, kind)[name]
        target, _ = QFileDialog.getSaveFileName(
            self.tools.window, f"Export the {KINDS[kind]} of “{name}”",
            self.tools._beside_project(f"{name} {kind}.png"), "PNG image (*.png)")
        if target:
            path = Path(target) if target.lower().endswith(".png") else Path(target + ".png")
            self.tools._export(lambda: write_png(path, image), str(path))

    def remove(self, name: str, kind: str) -> None:
        self.doc.undo_stack.push(SetToneCommand(self.doc, name, kind, None,
                                                f"Remove {KINDS[kind]} of {name}"))

    def add_actions(self, menu: QMenu, name: str) -> None:
        """Per kind: Replace…, and Export… and Remove where the map has one."""
        for kind, label in KINDS.items():
            menu.addSeparator()
            title = label.title()
            menu.addAction(f"Replace {title}…", lambda k=kind: self.replace(name, k))
            if name in tone_maps(self.doc, kind):
                menu.addAction(f"Export {title}…", lambda k=kind: self.export(name, k))
                menu.addAction(f"Remove {title}", lambda k=kind: self.remove(name, k))
