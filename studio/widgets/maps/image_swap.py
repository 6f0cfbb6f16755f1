"""One undo step that swaps one image of the face's textures for another (a neutral or wrinkled
normal map, a cavity or colour map): the subclass says how an image is put in place; undo puts
the old one back. The images are held whole, so the undo stack's memory budget counts them."""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QUndoCommand

from studio.widgets.document import Document


class ImageSwapCommand(QUndoCommand):
    """``old`` and ``new`` are the images before and after (None: no image)."""

    def __init__(self, doc: Document, old: np.ndarray | None, new: np.ndarray | None,
                 text: str) -> None:
        super().__init__(text)
        self.doc, self.old, self.new = doc, old, new

    def _apply(self, image: np.ndarray | None) -> None:
        """Put ``image`` in place and tell the views (the document's texturesChanged)."""
        raise NotImplementedError

    def redo(self) -> None:
        self._apply(self.new)
        self.doc.texturesChanged.emit()

    def undo(self) -> None:
        self._apply(self.old)
        self.doc.texturesChanged.emit()

    def nbytes(self) -> int:
        return sum(image.nbytes for image in (self.old, self.new) if image is not None)
