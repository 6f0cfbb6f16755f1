"""One undo step that swaps one image of the face's textures for another (a neutral or wrinkled
normal map, a cavity or colour map): ``put`` says how an image is put in place; undo puts the
old one back. The images are held whole, so the undo stack's memory budget counts them."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6.QtGui import QUndoCommand

from studio.widgets.document import Document


class ImageSwapCommand(QUndoCommand):
    """``old`` and ``new`` are the images before and after (None: no image); ``put`` puts one
    in place in the document's textures (the views are told after it)."""

    def __init__(self, doc: Document, old: np.ndarray | None, new: np.ndarray | None,
                 text: str, put: Callable[[np.ndarray | None], None]) -> None:
        super().__init__(text)
        self.doc, self.old, self.new, self._put = doc, old, new, put

    def redo(self) -> None:
        self._put(self.new)
        self.doc.texturesChanged.emit()

    def undo(self) -> None:
        self._put(self.old)
        self.doc.texturesChanged.emit()

    def nbytes(self) -> int:
        return sum(image.nbytes for image in (self.old, self.new) if image is not None)
