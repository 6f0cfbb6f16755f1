"""Finding words a person cannot read whole: elided or clipped text in labels, drop-downs, lists
and tabs, measured with each widget's own font against the room it has (issue #47: the test
that looked only for a panel's horizontal scroll bar passed over "Expression facto", "P…" and
"Sha…")."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QLabel,
    QStyle,
    QStyleOptionComboBox,
    QTabBar,
    QWidget,
)

TAB_PADDING = 12  # pixels a tab's frame takes around its words (Fusion: 6 a side)


def _shown(widget: QWidget) -> bool:
    return widget.isVisible() and not widget.visibleRegion().isEmpty()


def _label_cut(label: QLabel) -> str | None:
    text = label.text()
    if not text or label.wordWrap() or "<" in text or (label.pixmap() is not None and \
            not label.pixmap().isNull()):
        return None
    lines = text.splitlines() or [text]
    needed = max(label.fontMetrics().horizontalAdvance(line) for line in lines)
    room = label.contentsRect().width() - 2 * label.margin() - label.indent() * (
        label.indent() > 0)
    return f"label “{text}” needs {needed} px, has {room}" if needed > room else None


def _combo_cut(combo: QComboBox) -> str | None:
    text = combo.currentText()
    if not text or combo.isEditable():
        return None
    option = QStyleOptionComboBox()
    option.initFrom(combo)
    option.currentText = text
    option.currentIcon = combo.itemIcon(combo.currentIndex())
    option.iconSize = combo.iconSize()
    field = combo.style().subControlRect(QStyle.ComplexControl.CC_ComboBox, option,
                                         QStyle.SubControl.SC_ComboBoxEditField, combo)
    icon = 0 if option.currentIcon.isNull() else combo.iconSize().width() + 4
    needed = combo.fontMetrics().horizontalAdvance(text) + icon
    return f"drop-down “{text}” needs {needed} px, has {field.width()}" \
        if needed > field.width() else None


def _tabs_cut(bar: QTabBar) -> list[str]:
    cut = []
    for i in range(bar.count()):
        text = bar.tabText(i).replace("&", "")
        needed = bar.fontMetrics().horizontalAdvance(text) + TAB_PADDING
        rect = bar.tabRect(i)
        upright = bar.shape() in (QTabBar.Shape.RoundedWest, QTabBar.Shape.RoundedEast,
                                  QTabBar.Shape.TriangularWest, QTabBar.Shape.TriangularEast)
        room = rect.height() if upright else rect.width()
        if needed > room:
            cut.append(f"tab “{text}” needs {needed} px, has {room}")
    return cut


def cut_texts(root: QWidget) -> list[str]:
    """Every visible label, drop-down, list and tab under ``root`` whose words do not fit."""
    found: list[str] = []
    for label in root.findChildren(QLabel):
        if _shown(label) and (why := _label_cut(label)):
            found.append(why)
    for combo in root.findChildren(QComboBox):
        if _shown(combo) and (why := _combo_cut(combo)):
            found.append(why)
    for view in root.findChildren(QAbstractItemView):
        bar = view.horizontalScrollBar()
        if _shown(view) and bar.isVisible() and bar.maximum() > 0:
            found.append(f"list {type(view).__name__} scrolls sideways ({bar.maximum()} px)")
    for bar in root.findChildren(QTabBar):
        if _shown(bar):
            found.extend(_tabs_cut(bar))
    return found
