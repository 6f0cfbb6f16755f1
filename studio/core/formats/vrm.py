"""VRM avatars (``.vrm``): a glTF binary with a VRM extension, read as the glTF it is.

What the extension adds that a plain glTF does not say:

- **expressions**: VRM 0.x's ``extensions.VRM.blendShapeMaster.blendShapeGroups`` (a preset
  name such as ``joy`` or ``blink_l``, and binds of mesh, morph target and weight 0–100) and
  VRM 1.0's ``extensions.VRMC_vrm.expressions`` (``preset`` and ``custom``, binds of node,
  morph target and weight 0–1). Each becomes a key pose named after VRM 1.0's preset
  (``happy``, ``angry``, ``blinkLeft``…; a custom one keeps its name): a rig's morph targets
  are parts (one brow, a mouth corner) that its expressions combine, and a user animates the
  expressions. A morph target no expression uses stays a key pose of its own name.
- **which way the avatar faces**: VRM 0.x avatars face −Z, VRM 1.0 avatars +Z, both Y up —
  where guessing from a blink's motion took −Z for up and showed the underside of the head.

Toggles (``HideHairBalls``: morphs that hide or show an accessory) are found by
``toggle_poses`` in any glTF: they are not expressions and must not be set up as wrinkles.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from studio.core.animation.poses import KeyPose
from studio.core.files.budgets import POSES
from studio.core.files.errors import MeshError
from studio.core.files.naming import shown
from studio.core.formats.face_parts import name_words
from studio.core.formats.gltf.scene import target_names
from studio.core.project.model import Project

Array = np.ndarray

SUFFIX = ".vrm"
# VRM 0.x preset names → VRM 1.0's, the names the key poses get
PRESETS_0 = {"joy": "happy", "angry": "angry", "sorrow": "sad", "fun": "relaxed", "a": "aa",
             "i": "ih", "u": "ou", "e": "ee", "o": "oh", "blink": "blink",
             "blink_l": "blinkLeft", "blink_r": "blinkRight", "lookup": "lookUp",
             "lookdown": "lookDown", "lookleft": "lookLeft", "lookright": "lookRight",
             "neutral": "neutral"}
TOGGLE_WORDS = frozenset({"hide", "hidden", "show", "toggle", "visible", "invisible"})
WHOLE_SHARE = 0.999  # a piece moved on this share of its vertices is moved whole
MOVED_SHARE = 1e-5  # of the face's size: a vertex moved less is not moved


@dataclass
class Expression:
    """A VRM expression: its key pose's name and its binds (mesh index, morph target index,
    weight 0–1)."""

    name: str
    binds: list[tuple[int, int, float]] = field(default_factory=list)


@dataclass
class VrmInfo:
    version: str  # "0.x" or "1.0"
    front: str  # the axis the avatar faces: "-z" (0.x) or "+z" (1.0)
    expressions: list[Expression]


def _whole(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _weight(value: object, scale: float) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    weight = float(value) / scale
    return weight if np.isfinite(weight) else None


def vrm_info(doc: dict, path: object = None) -> VrmInfo | None:
    """The VRM extension of a glTF document, None when it has none. A bind naming no mesh or
    morph target of the file is skipped (VRM tools write such leftovers); an extension that
    is not the shape the specifications give is refused, naming the file."""
    extensions = doc.get("extensions") if isinstance(doc, dict) else None
    if not isinstance(extensions, dict):
        return None
    try:
        if isinstance(extensions.get("VRMC_vrm"), dict):
            return VrmInfo("1.0", "+z", _expressions_1(doc, extensions["VRMC_vrm"]))
        if isinstance(extensions.get("VRM"), dict):
            return VrmInfo("0.x", "-z", _expressions_0(extensions["VRM"]))
    except (AttributeError, TypeError, KeyError) as exc:
        raise MeshError(f"the VRM extension is malformed ({type(exc).__name__}: {exc})",
                        path) from None
    return None


def _expressions_0(vrm: dict) -> list[Expression]:
    groups = (vrm.get("blendShapeMaster") or {}).get("blendShapeGroups") or []
    POSES.check(len(groups), "the VRM expression count", None, MeshError)
    out = []
    for group in groups:
        preset = str(group.get("presetName") or "unknown").lower()
        name = PRESETS_0.get(preset) or shown(str(group.get("name") or preset))
        binds = []
        for bind in group.get("binds") or []:
            weight = _weight(bind.get("weight", 100), 100.0)
            if _whole(bind.get("mesh")) and _whole(bind.get("index")) and weight:
                binds.append((bind["mesh"], bind["index"], weight))
        out.append(Expression(name, binds))
    return out


def _expressions_1(doc: dict, vrm: dict) -> list[Expression]:
    expressions = vrm.get("expressions") or {}
    nodes = doc.get("nodes") or []
    named = [*(expressions.get("preset") or {}).items(), *(expressions.get("custom") or {}).items()]
    POSES.check(len(named), "the VRM expression count", None, MeshError)
    out = []
    for name, spec in named:
        binds = []
        for bind in spec.get("morphTargetBinds") or []:
            node = bind.get("node")
            mesh = nodes[node].get("mesh") if _whole(node) and node < len(nodes) else None
            weight = _weight(bind.get("weight", 1.0), 1.0)
            if _whole(mesh) and _whole(bind.get("index")) and weight:
                binds.append((mesh, bind["index"], weight))
        out.append(Expression(shown(str(name)), binds))
    return out


def apply_expressions(project: Project, info: VrmInfo, target_names: Sequence[list[str]],
                      report: list[str]) -> None:
    """Replace the project's morph-target poses by the VRM's expressions (``target_names``:
    each mesh's morph target names, as the poses are named): an expression's pose is the sum
    of its binds' offsets, each at its weight; a morph target no expression binds stays; an
    expression whose binds move nothing of the face is left out. The avatar's axes are set in
    ``project.view`` ("up", "front"), and what was done said in ``report``."""
    rest = project.mesh.rest.astype(np.float64)
    by_name = {p.name: p for p in project.poses}
    used: set[str] = set()
    made: list[KeyPose] = []
    mapped: list[str] = []
    for expression in info.expressions:
        offset = np.zeros_like(rest)
        parts = []
        for mesh, index, weight in expression.binds:
            names = target_names[mesh] if mesh < len(target_names) else []
            target = names[index] if index < len(names) else None
            if target in by_name:
                offset += weight * (by_name[target].positions - rest)
                used.add(target)
                parts.append(target)
        taken = {p.name for p in made}
        if not parts or not np.abs(offset).max() > 0 or expression.name in taken:
            continue
        made.append(KeyPose(expression.name, rest + offset))
        mapped.append(f"{expression.name} ← {', '.join(dict.fromkeys(parts))}")
    names = {p.name for p in made}
    kept = [p for p in project.poses if p.name not in used and p.name not in names]
    project.poses = made + kept
    project.view["up"] = "+y"
    project.view["front"] = info.front
    report.append(f"VRM {info.version}: faces {info.front.upper()}, Y up; "
                  f"{len(made)} expressions as key poses"
                  + (f" ({'; '.join(mapped)})" if mapped else "")
                  + (f", {len(kept)} morph targets no expression uses kept" if kept else ""))


def _pieces(triangles: Array, n: int) -> Array:
    """(n,) the connected piece each vertex belongs to (vertices sharing a triangle)."""
    label = np.arange(n)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]]])
    while True:  # label propagation: each vertex takes the smallest label of its neighbours
        low = np.minimum(label[edges[:, 0]], label[edges[:, 1]])
        before = label.copy()
        np.minimum.at(label, edges[:, 0], low)
        np.minimum.at(label, edges[:, 1], low)
        label = label[label]  # jump: long chains settle in log steps
        if np.array_equal(label, before):
            return label


def toggle_poses(project: Project) -> dict[str, tuple[str, Array]]:
    """The key poses that are toggles, not expressions, each with why and the skin it moves: a
    name that says hide or show (``HideHairBalls``), or a pose whose skin motion is only of
    whole separate pieces (an accessory shrunk away or slid into the head) — an expression
    pulls some skin and leaves the skin around it. A pose that moves only parts already not
    face (an eye looking up) is no toggle: the set-up says it moves no skin."""
    mesh = project.mesh
    rest = mesh.rest.astype(np.float64)
    skin = project.skin_weights() > 0
    size = float(np.linalg.norm(np.ptp(rest[skin] if skin.any() else rest, axis=0))) or 1.0
    pieces = count = None
    out: dict[str, tuple[str, Array]] = {}
    for pose in project.poses:
        moved = skin & (np.linalg.norm(pose.positions - rest, axis=1) > MOVED_SHARE * size)
        if not moved.any():
            continue
        if any(w in TOGGLE_WORDS for w in name_words(pose.name)):
            out[pose.name] = ("its name says so", moved)
            continue
        if pieces is None:  # found once, for the first pose not named a toggle
            pieces = _pieces(mesh.welded_triangles, mesh.n_welded)
            count = np.bincount(pieces[skin], minlength=mesh.n_welded)
        touched = np.unique(pieces[moved])
        share = np.bincount(pieces[moved], minlength=mesh.n_welded)[touched] / count[touched]
        if (share >= WHOLE_SHARE).all() and count[touched].sum() < skin.sum():
            out[pose.name] = ("it moves whole pieces only", moved)
    return out


def leave_out_toggles(project: Project, report: list[str]) -> set[str]:
    """The toggles (``toggle_poses``), to be left out of the wrinkle set-up; the skin they move
    (hair balls, earrings) marked not face; said in one line. They stay key poses: a user may
    still play them."""
    toggles = toggle_poses(project)
    if not toggles:
        return set()
    moved = np.zeros(project.mesh.n_welded, bool)
    for _, part in toggles.values():
        moved |= part
    skin = project.skin_weights() > 0
    marked = moved & skin
    if (skin & ~marked).any():  # never all the skin
        project.not_face = marked if project.not_face is None else project.not_face | marked
    else:
        marked[:] = False
    report.append("toggles, not set up as wrinkles: "
                  + ", ".join(f"{name} ({why})" for name, (why, _) in toggles.items())
                  + (f"; the {int(marked.sum())} vertices they move marked not face"
                     if marked.any() else ""))
    return set(toggles)


def vrm_target_names(doc: dict) -> list[list[str]]:
    """Each mesh's morph target names, as the glTF reader names the poses."""
    return [target_names(m) if isinstance(m, dict) else [] for m in doc.get("meshes") or []]


def check_suffix(path: object) -> bool:
    """Whether a path names a VRM file."""
    return str(path).lower().endswith(SUFFIX)

