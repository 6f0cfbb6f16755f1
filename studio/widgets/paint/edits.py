"""Undo commands for technique-1 authoring, and the paint session both paint surfaces share.

Every change to areas, masks or links goes through one of these on ``doc.undo_stack``. Mask edits
store only the tiles they changed (before and after), never whole masks — except a resolution
change, which replaces every mask by definition. Commands refer to areas by object, not by index,
so a stroke still undoes into the right layer after the list was reordered.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TypeVar

import numpy as np
from PySide6.QtGui import QUndoCommand

from studio.core.files.errors import ImageError
from studio.core.files.images import load_grey, write_png
from studio.core.files.naming import unique_name
from studio.core.setup.mirror_area import mirrored_area
from studio.core.wrinkles import mask_ops
from studio.core.wrinkles.brush import Brush, Mirror, Rect, Stroke, tile_changes
from studio.core.wrinkles.colours import distinct_colour
from studio.core.wrinkles.influence import InfluenceArea
from studio.core.wrinkles.response import ResponseCurve
from studio.core.wrinkles.surface_mirror import SurfaceMirror
from studio.widgets.commands import push_flags
from studio.widgets.document import Document

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".tga", ".webp"}
T = TypeVar("T")  # a link's gain, or its curve


def _layer(doc: Document, area: InfluenceArea) -> int | None:
    for i, a in enumerate(doc.project.influence.areas):
        if a is area:
            return i
    return None


def _announce_region(doc: Document, area: InfluenceArea, rect: Rect) -> None:
    layer = _layer(doc, area)
    if layer is not None:
        doc.maskRegionChanged.emit(layer, *rect)


class MaskTilesCommand(QUndoCommand):
    """A mask edit stored as the tiles it changed; the first redo is a no-op when the edit was
    already applied live (a brush stroke)."""

    def __init__(self, doc: Document, area: InfluenceArea, text: str,
                 tiles: list[tuple[int, int, np.ndarray, np.ndarray]], applied: bool) -> None:
        super().__init__(text)
        self.doc, self.area, self.tiles = doc, area, tiles
        self._skip = applied

    @property
    def stored_pixels(self) -> int:
        return sum(before.size + after.size for _, _, before, after in self.tiles)

    def _put(self, which: int) -> None:
        mask = self.area.mask
        for tile in self.tiles:
            x, y, patch = tile[0], tile[1], tile[which]
            h, w = patch.shape
            mask[y:y + h, x:x + w] = patch
            _announce_region(self.doc, self.area, (x, y, w, h))

    def redo(self) -> None:
        if self._skip:
            self._skip = False
            return
        self._put(3)

    def undo(self) -> None:
        self._put(2)


def apply_mask_op(doc: Document, index: int, text: str,
                  op: Callable[[np.ndarray], np.ndarray]) -> None:
    """Run a whole-mask operation (fill, blur, …) as one undo step that stores changed tiles."""
    area = doc.project.influence.areas[index]
    after = np.clip(op(area.mask).astype(np.float32), 0.0, 1.0)
    tiles = tile_changes(area.mask, after)
    if tiles:
        doc.undo_stack.push(MaskTilesCommand(doc, area, f"{text} {area.name}", tiles, False))


class PaintSession:
    """One stroke on one area, live: each segment stamps dabs and announces the touched rectangle
    (the viewport uploads just that); ``end`` pushes the stroke as one undo step."""

    def __init__(self, doc: Document, index: int, brush: Brush, mirror: bool | Mirror = False,
                 text: str = "Paint") -> None:
        self.doc = doc
        self.area = doc.project.influence.areas[index]
        self.brush = copy.copy(brush)
        self.stroke = Stroke(self.area.mask, self.brush, mirror)
        self.text = text

    def _emit(self, rect: Rect | None) -> Rect | None:
        if rect is not None:
            _announce_region(self.doc, self.area, rect)
        return rect

    def jump(self, x: float, y: float, pressure: float = 1.0) -> Rect | None:
        return self._emit(self.stroke.jump(x, y, pressure))

    def to(self, x: float, y: float, pressure: float = 1.0) -> Rect | None:
        return self._emit(self.stroke.to(x, y, pressure))

    def end(self) -> MaskTilesCommand | None:
        tiles = self.stroke.backup.changes()
        if not tiles:
            return None
        verb = "Erase" if self.brush.erase else self.text
        command = MaskTilesCommand(self.doc, self.area, f"{verb} {self.area.name}", tiles, True)
        self.doc.undo_stack.push(command)
        return command


# --- the list of areas ---------------------------------------------------------------------------

Curves = dict[str, dict[str, ResponseCurve]]  # pose -> {area: curve}


def _copy_curves(curves: Curves, keep: set[str] | None = None) -> Curves:
    """A copy of the link curves (curves are immutable: one level deeper is enough), only those
    of the areas named in ``keep`` when given, so no curve outlives its area."""
    copied = {p: {a: c for a, c in by_area.items() if keep is None or a in keep}
              for p, by_area in curves.items()}
    return {p: by_area for p, by_area in copied.items() if by_area}


class AreasCommand(QUndoCommand):
    """Replaces the area list, the links and their curves together (add, duplicate, delete,
    reorder, import). Areas are kept by reference, so this stores no pixels."""

    def __init__(self, doc: Document, text: str, areas: list[InfluenceArea],
                 links: dict[str, dict[str, float]] | None = None,
                 curves: Curves | None = None) -> None:
        super().__init__(text)
        self.doc = doc
        influence = doc.project.influence
        self.old = (list(influence.areas), copy.deepcopy(influence.links),
                    _copy_curves(influence.curves))
        self.new = (list(areas), copy.deepcopy(influence.links if links is None else links),
                    _copy_curves(influence.curves if curves is None else curves,
                                 {a.name for a in areas}))

    def _apply(self, state) -> None:
        influence = self.doc.project.influence
        old_count = len(influence.areas)
        influence.areas[:] = state[0]
        influence.links = copy.deepcopy(state[1])
        influence.curves = _copy_curves(state[2])
        self.doc.areasChanged.emit()
        self.doc.masksChanged.emit()  # the texture array's layers follow the list
        if old_count != len(state[0]):
            self.doc.activationsChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)


def _links_without(links: dict[str, dict[str, T]], names: Iterable[str]
                      ) -> dict[str, dict[str, T]]:
    """The links (or their curves) without those of the areas ``names``."""
    gone = set(names)
    return {p: {a: g for a, g in gains.items() if a not in gone} for p, gains in links.items()}


def mask_shape(doc: Document, default: int = 1024) -> tuple[int, int]:
    return doc.project.influence.resolution or (default, default)


def next_colour(doc: Document) -> tuple[int, int, int]:
    """A colour unlike every other area's (and the vertex selection's)."""
    return distinct_colour(a.colour for a in doc.project.influence.areas)


def add_area(doc: Document, name: str = "area", mask: np.ndarray | None = None,
             links: dict[str, float] | None = None, wrinkle_map: str = "") -> InfluenceArea:
    """A new (empty) area after the others; ``links``: pose -> gain for it; ``wrinkle_map``:
    the map it reveals ("" = the first)."""
    h, w = mask_shape(doc)
    area = InfluenceArea(unique_name(name, (a.name for a in doc.project.influence.areas)),
                         np.zeros((h, w), np.float32) if mask is None else mask,
                         colour=next_colour(doc), wrinkle_map=wrinkle_map)
    new_links = copy.deepcopy(doc.project.influence.links)
    for pose, gain in (links or {}).items():
        new_links.setdefault(pose, {})[area.name] = float(gain)
    doc.undo_stack.push(AreasCommand(doc, f"Add area {area.name}",
                                     [*doc.project.influence.areas, area], new_links))
    return area


def duplicate_area(doc: Document, index: int) -> InfluenceArea:
    """A copy after the area: its mask, map and settings, driven by the same poses with the
    same gains and curves (a copy that no pose moves would look like a broken duplicate)."""
    influence = doc.project.influence
    src = influence.areas[index]
    taken = (a.name for a in influence.areas)
    area = InfluenceArea(unique_name(f"{src.name} copy", taken), src.mask.copy(),
                         colour=src.colour, activation=src.activation, visible=src.visible,
                         wrinkle_map=src.wrinkle_map)
    areas = list(influence.areas)
    areas.insert(index + 1, area)
    links = copy.deepcopy(influence.links)
    for gains in links.values():
        if src.name in gains:
            gains[area.name] = gains[src.name]
    curves = _copy_curves(influence.curves)
    for by_area in curves.values():
        if src.name in by_area:
            by_area[area.name] = by_area[src.name]
    doc.undo_stack.push(AreasCommand(doc, f"Duplicate {src.name}", areas, links, curves))
    return area


def mirror_area(doc: Document, index: int, mirror: SurfaceMirror) -> InfluenceArea:
    """The area mirrored to the other side of the face (through the mesh), as one step: a new
    area after it, or the paired area (``…_L`` → ``…_R``) replaced; linked to the paired poses."""
    made = mirrored_area(doc.project, index, mirror)
    influence = doc.project.influence
    areas = list(influence.areas)
    links = copy.deepcopy(influence.links)
    curves = _copy_curves(influence.curves)
    if made.replaces is None:
        areas.insert(index + 1, made.area)
    else:
        areas[made.replaces] = made.area
        links = _links_without(links, [made.area.name])
        curves = _links_without(curves, [made.area.name])
    for pose, gain in made.links.items():
        links.setdefault(pose, {})[made.area.name] = gain
    for pose, curve in made.curves.items():
        curves.setdefault(pose, {})[made.area.name] = curve
    doc.undo_stack.push(AreasCommand(doc, f"Mirror {influence.areas[index].name} to "
                                          f"{made.area.name}", areas, links, curves))
    return made.area


def delete_area(doc: Document, index: int) -> None:
    areas = list(doc.project.influence.areas)
    gone = areas.pop(index)
    doc.undo_stack.push(AreasCommand(doc, f"Delete {gone.name}", areas,
                                     _links_without(doc.project.influence.links, [gone.name])))


def move_area(doc: Document, index: int, to: int) -> None:
    areas = list(doc.project.influence.areas)
    if not (0 <= to < len(areas)) or to == index:
        return
    area = areas.pop(index)
    areas.insert(to, area)
    doc.undo_stack.push(AreasCommand(doc, f"Move {area.name}", areas))


class AreaValueCommand(QUndoCommand):
    def __init__(self, doc: Document, area: InfluenceArea, text: str, read, apply, value) -> None:
        super().__init__(text)
        self.doc, self.area, self._apply = doc, area, apply
        self.old, self.new = read(), value

    def redo(self) -> None:
        self._apply(self.new)
        self.doc.areasChanged.emit()

    def undo(self) -> None:
        self._apply(self.old)
        self.doc.areasChanged.emit()


def rename_area(doc: Document, index: int, name: str) -> bool:
    """Rename (links follow the name); False if the name is empty or taken."""
    influence = doc.project.influence
    area = influence.areas[index]
    name = name.strip()
    if not name or name == area.name or any(a.name == name for a in influence.areas):
        return False

    def apply(new: str) -> None:
        old = area.name
        area.name = new
        for table in (*influence.links.values(), *influence.curves.values()):
            if old in table:
                table[new] = table.pop(old)

    doc.undo_stack.push(AreaValueCommand(doc, area, f"Rename {area.name} to {name}",
                                         lambda: area.name, apply, name))
    return True


def _set_area_value(doc: Document, index: int, attr: str, value, text: str,
                    signal=None) -> None:
    """One property of an area as one undo step; ``signal`` tells the views what changed."""
    area = doc.project.influence.areas[index]
    if getattr(area, attr) == value:
        return

    def apply(v) -> None:
        setattr(area, attr, v)
        if signal is not None:
            signal.emit()

    doc.undo_stack.push(AreaValueCommand(doc, area, f"{text} {area.name}",
                                         lambda: getattr(area, attr), apply, value))


def set_area_visible(doc: Document, index: int, visible: bool) -> None:
    _set_area_value(doc, index, "visible", visible, "Show" if visible else "Hide",
                    doc.activationsChanged)


def set_visible_all(doc: Document, visible: tuple[bool, ...], text: str) -> None:
    """Solo / show all: every area's visibility at once, as one step."""
    push_flags(doc.undo_stack, list(doc.project.influence.areas), "visible", visible, text,
               lambda: (doc.areasChanged.emit(), doc.activationsChanged.emit()))


def set_area_map(doc: Document, index: int, wrinkle_map: str) -> None:
    """Which wrinkled normal map the area reveals (by name; "" = the first map)."""
    _set_area_value(doc, index, "wrinkle_map", wrinkle_map, "Wrinkled map of",
                    doc.areasChanged)


def set_area_colour(doc: Document, index: int, colour: tuple[int, int, int]) -> None:
    _set_area_value(doc, index, "colour", tuple(int(c) for c in colour), "Colour")


class LinksCommand(QUndoCommand):
    def __init__(self, doc: Document, text: str, links: dict[str, dict[str, float]]) -> None:
        super().__init__(text)
        self.doc = doc
        self.old = copy.deepcopy(doc.project.influence.links)
        self.new = copy.deepcopy(links)

    def _apply(self, links) -> None:
        self.doc.project.influence.links = copy.deepcopy(links)
        self.doc.areasChanged.emit()
        self.doc.activationsChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)


def set_link(doc: Document, pose: str, area: str, gain: float) -> None:
    """How much moving toward ``pose`` activates ``area`` (0 removes the link)."""
    links = copy.deepcopy(doc.project.influence.links)
    gains = links.setdefault(pose, {})
    if gain == 0.0:
        gains.pop(area, None)
        if not gains:
            links.pop(pose)
    else:
        gains[area] = float(gain)
    if links != doc.project.influence.links:
        doc.undo_stack.push(LinksCommand(doc, f"Link {pose} → {area}", links))


class ResolutionCommand(QUndoCommand):
    """Resample every mask to a new size (whole masks by necessity: every pixel changes)."""

    def __init__(self, doc: Document, size: int) -> None:
        super().__init__(f"Mask resolution {size}²")
        self.doc = doc
        self.areas = list(doc.project.influence.areas)
        self.old = [a.mask for a in self.areas]
        self.new = [mask_ops.resample(a.mask, size) for a in self.areas]

    def _apply(self, masks) -> None:
        for area, mask in zip(self.areas, masks, strict=True):
            area.mask = mask
        self.doc.masksChanged.emit()
        self.doc.areasChanged.emit()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)


def set_resolution(doc: Document, size: int) -> None:
    if doc.project.influence.resolution in (None, (size, size)):
        return
    doc.undo_stack.push(ResolutionCommand(doc, size))


# --- images in and out ---------------------------------------------------------------------------

def image_files(folder: Path) -> list[Path]:
    return sorted(p for p in Path(folder).iterdir()
                  if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES)


def read_mask(path: Path, shape: tuple[int, int], dark_is_strong: bool = False) -> np.ndarray:
    """A greyscale image as a mask of the project's size (resampled if it differs)."""
    mask = load_grey(path)
    if dark_is_strong:
        mask = 1.0 - mask
    if mask.shape != shape:
        mask = mask_ops.resample(mask, (shape[1], shape[0]))
    return np.clip(mask, 0.0, 1.0).astype(np.float32)


def import_masks(doc: Document, paths: list[Path], dark_is_strong: bool = False
                 ) -> tuple[list[InfluenceArea], list[ImageError]]:
    """Each readable image becomes an area (one undo step for all); unreadable ones are returned
    as errors naming their file, so the panel can say which."""
    shape = mask_shape(doc)
    names = {a.name for a in doc.project.influence.areas}
    new: list[InfluenceArea] = []
    errors: list[ImageError] = []
    for path in paths:
        try:
            mask = read_mask(Path(path), shape, dark_is_strong)
        except ImageError as exc:
            errors.append(exc)
            continue
        name, k = Path(path).stem, 2
        while name in names:
            name, k = f"{Path(path).stem} {k}", k + 1
        names.add(name)
        colour = distinct_colour([*(a.colour for a in doc.project.influence.areas),
                                  *(a.colour for a in new)])
        new.append(InfluenceArea(name, mask, colour=colour))
    if new:
        what = new[0].name if len(new) == 1 else f"{len(new)} masks"
        doc.undo_stack.push(AreasCommand(doc, f"Import {what}",
                                         [*doc.project.influence.areas, *new]))
    return new, errors


def export_mask(area: InfluenceArea, path: Path, bits: int = 16) -> None:
    """The mask as a greyscale PNG (white = strong), 8 or 16 bit."""
    top = 65535.0 if bits == 16 else 255.0
    dtype = np.uint16 if bits == 16 else np.uint8
    write_png(path, np.rint(np.clip(area.mask, 0.0, 1.0) * top).astype(dtype))


def file_name(area: InfluenceArea) -> str:
    """A safe PNG file name for an area (no folder separators)."""
    stem = "".join("_" if c in '/\\:*?"<>|' else c for c in area.name).strip() or "area"
    return f"{stem}.png"
