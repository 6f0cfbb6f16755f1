"""File ▸ Export ▸ Folder for a Game Engine…: the folder and the engine layout to write.

Why a dialog of its own (not the animation export's): an engine layout is a set of textures and a
sheet, not frames. Its layout list is built from core/engine_layouts.LAYOUTS, each entry showing
what the layout costs the engine's material for this project (samplers) and whether the engine
can hold it; a refused export or a failed write is a dialog naming the problem. Where the engine
blends fewer masks than the project has and merging fits it (O3DE's 16), the dialog offers to
merge the weakest, naming each merge, instead of refusing.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLineEdit,
    QMessageBox,
    QPushButton,
    QWidget,
)

from studio.core.engines.export import export_layout
from studio.core.engines.layouts import LAYOUTS, STUDIO
from studio.core.engines.plan import plan_export
from studio.core.files.errors import StudioError
from studio.widgets.dialog_buttons import action_buttons


def layout_entry(project, key: str) -> str:
    """The combo box's text for a layout: its name, its sampler cost, and a refusal's reason."""
    plan = plan_export(project, key)
    layout = plan.layout
    text = f"{layout.label} — {plan.samplers} samplers"
    if plan.used > layout.limit:
        text += f" (too many {layout.limit_unit}: {plan.used} of {layout.limit}"
        text += f"; the {plan.used - layout.limit} weakest can be merged)" if plan.mergeable \
            else ")"
    return text


def ask_to_merge(window, project, key: str) -> bool | None:
    """Whether to merge the weakest masks: False when the layout fits as it is, None when the
    user declines the merges the dialog lists."""
    if not plan_export(project, key).mergeable:
        return False
    merged = plan_export(project, key, merge=True).merged
    answer = QMessageBox.question(
        window, "Export for a Game Engine",
        f"The engine blends fewer masks than this face has. Merge the {len(merged)} weakest?\n"
        + "\n".join(f"• {m.describe()}" for m in merged))
    return True if answer == QMessageBox.StandardButton.Yes else None


class EngineExportDialog(QDialog):
    def __init__(self, window, parent: QWidget | None = None) -> None:
        super().__init__(parent or window)
        self.setWindowTitle("Export for a Game Engine")
        doc = window.doc
        form = QFormLayout(self)
        self.layout_choice = QComboBox()
        for key in LAYOUTS:
            self.layout_choice.addItem(layout_entry(doc.project, key), key)
        self.layout_choice.setCurrentIndex(self.layout_choice.findData(STUDIO.key))
        form.addRow("Layout", self.layout_choice)
        folder = doc.path.parent if doc.path else Path.cwd()
        self.folder = QLineEdit(str(folder / f"{doc.display_name.replace(' ', '_')}_engine"))
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row = QHBoxLayout()
        row.addWidget(self.folder, 1)
        row.addWidget(browse)
        form.addRow("Folder", row)
        self.buttons = action_buttons(self, "Export", self._accept)
        form.addRow(self.buttons)

    def _browse(self) -> None:
        name = QFileDialog.getExistingDirectory(self, "Export for a game engine",
                                                self.folder.text())
        if name:
            self.folder.setText(name)

    def _accept(self) -> None:
        if not self.folder.text().strip():
            self.folder.setFocus()
            return
        self.accept()

    def choice(self) -> tuple[str, Path]:
        """(layout key, folder)."""
        return self.layout_choice.currentData(), Path(self.folder.text().strip())


def open_engine_export(window) -> None:
    """The menu action: ask, export, and say where it went and what it left out."""
    dialog = EngineExportDialog(window)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return
    key, folder = dialog.choice()
    doc = window.doc
    merge = ask_to_merge(window, doc.project, key)
    if merge is None:
        return
    try:
        plan, files = export_layout(doc.project, folder, key, inputs=[doc.path],
                                    tangent_frame=doc.view.tangent_frame, merge=merge)
    except StudioError as exc:
        window.show_error("Cannot export", exc)
        return
    merged = f", {len(plan.merged)} weakest masks merged" if plan.merged else ""
    window.statusBar().showMessage(
        f"Exported {len(files)} files to {folder} ({plan.samplers} samplers{merged})", 8000)
    if plan.unassigned:
        QMessageBox.information(window, "Export for a Game Engine",
                                "These areas fit no region of the layout and were left out:\n"
                                + "\n".join(f"• {area}: {why}" for area, why in plan.unassigned))
