"""Which parts of a head are not face: a starting choice the user confirms or changes.

Eyes, teeth, tongue, lashes and tear lines move with the face (they share its poses) but are
not skin, and a wrinkle on them is a bug. Three signs, any one enough:

- **names** of the part or its material: eye, iris, sclera, cornea, pupil, lash, tear,
  lacrimal, occlusion, blend (eye-blend shells), teeth, tongue, gum, mouth bag, caruncle —
  as words, also inside CamelCase (``M_IrisLeft``, ``EyeLeft``, ``M_GumsTongue``); "eyelid"
  and "eyebrow" are skin words, not eye words;
- **a small closed shell**: every edge shared by two triangles (an eyeball) and smaller than a
  fifth of the whole;
- **moved rigidly by the poses**: some pose moves it and every pose only turns or shifts it
  (an eye looking around, a jaw's teeth), where skin stretches;
- **see-through**: its material is alpha-cut or blended, or its base-colour texture is mostly
  transparent where it lies (brow, lash and hair cards: a furrow on a card is drawn on air).
  The file says so (``gltf_materials.see_through``); a part carries the reason.

Usable for an OBJ's parts and a glTF's meshes and materials alike: a part is its names, its
welded positions and triangles, and its positions in each key pose.

A whole-body export holds more than the head's parts: hair cards, joint markers (small cubes),
helper and clothing geometry. They are not merely not face but in the way (hair cards hang
before the forehead, a marker floats before each eye), so ``choose_parts`` leaves them out: by
name (helper, joint, hair, clothing words), or as a part no pose moves that shares no vertex
with one the poses move (a scalp sewn to the face stays).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray

NOT_FACE_WORDS = frozenset({
    "eye", "eyes", "eyeball", "eyeballs", "iris", "irises", "pupil", "pupils", "sclera",
    "cornea", "lash", "lashes", "eyelash", "eyelashes", "tear", "tears", "tearline", "lacrimal",
    "occlusion", "blend", "teeth", "tooth", "tongue", "gum", "gums", "mouthbag", "caruncle",
    "meniscus"})
SKIN_AFTER_EYE = frozenset({"lid", "lids", "brow", "brows", "socket", "bag", "bags"})
LEFT_OUT_WORDS = frozenset({
    "helper", "helpers", "joint", "joints", "marker", "markers", "hair", "haircard", "haircards",
    "cloth", "clothes", "clothing", "outfit", "shirt", "jacket", "pants", "trousers", "skirt",
    "dress", "tights", "shoe", "shoes", "boot", "boots", "hat", "cap", "glasses"})
SHELL_SHARE = 0.2  # a closed shell smaller than this share of the whole is an eye or a tooth
RIGID_RESIDUAL = 0.01  # of a pose's largest motion of the part: what still counts as rigid
MOVED_SHARE = 1e-5  # of the whole's size: a part moved less than this by every pose is still


def name_words(name: str) -> list[str]:
    """Lower-case words of a name: split at anything not a letter and at CamelCase humps
    ("M_EyeLashes" → m, eye, lashes; "Wolf3D_Teeth" → wolf, d, teeth)."""
    spaced = re.sub(r"(?<=[a-z])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", " ", name)
    return [w.lower() for w in re.split(r"[^A-Za-z]+", spaced) if w]


def is_not_face_name(name: str) -> bool:
    """A name that says eye, teeth, tongue…: a word of the list, or two words that make one
    ("mouth bag", "tear line"); "eye" followed by lid, brow or socket is skin."""
    words = name_words(name)
    for i, word in enumerate(words):
        after = words[i + 1] if i + 1 < len(words) else ""
        if word == "eye" and after in SKIN_AFTER_EYE:
            continue
        if word in NOT_FACE_WORDS or word + after in NOT_FACE_WORDS:
            return True
    return False


def suggest_names(names: Iterable[str]) -> list[str]:
    """The names that look like eyes, teeth or tongue, in the order given."""
    return [name for name in names if is_not_face_name(name)]


@dataclass
class Part:
    """A part of a head: its names (part, material…), welded positions, triangles over them,
    and its positions in each key pose (same rows)."""

    names: Sequence[str]
    rest: Array  # (n, 3)
    triangles: Array  # (m, 3) into rest
    poses: Sequence[Array] = field(default_factory=list)
    see_through: str = ""  # why its material is not skin ("alpha-cut material", …), or ""


def is_closed(triangles: Array) -> bool:
    """Every edge used by exactly two triangles (a watertight shell, or several); triangles
    collapsed to an edge (a UV sphere's poles, welded) do not count."""
    triangles = np.asarray(triangles)
    t = triangles
    triangles = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    if len(triangles) == 0:
        return False
    edges = np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool((counts == 2).all())


def moves_rigidly(rest: Array, poses: Sequence[Array]) -> bool:
    """Some pose moves the part, and each pose only turns and shifts it: the best rigid fit
    (Kabsch) leaves no vertex further than 1 % of that pose's largest motion."""
    rest = np.asarray(rest, np.float64)
    moved = False
    centre = rest.mean(axis=0)
    a = rest - centre
    for pose in poses:
        pose = np.asarray(pose, np.float64)
        motion = np.linalg.norm(pose - rest, axis=1).max(initial=0.0)
        if motion == 0.0:
            continue
        moved = True
        b = pose - pose.mean(axis=0)
        u, _, vt = np.linalg.svd(a.T @ b)
        d = np.sign(np.linalg.det(u @ vt)) or 1.0
        rotation = u @ np.diag([1.0, 1.0, d]) @ vt
        residual = np.linalg.norm(a @ rotation - b, axis=1).max()
        if residual > RIGID_RESIDUAL * motion:
            return False
    return moved


def suggest_parts(parts: Sequence[Part]) -> dict[int, str]:
    """The parts that look not face, each with why: what makes it see-through, "name", "small
    closed shell" or "moved rigidly". Size is measured against all the parts together."""
    if not parts:
        return {}
    points = np.concatenate([np.asarray(p.rest, np.float64) for p in parts])
    whole = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    out: dict[int, str] = {}
    for i, part in enumerate(parts):
        rest = np.asarray(part.rest, np.float64)
        size = float(np.linalg.norm(rest.max(axis=0) - rest.min(axis=0)))
        if part.see_through:
            out[i] = part.see_through
        elif any(is_not_face_name(n) for n in part.names):
            out[i] = "name"
        elif size < SHELL_SHARE * whole and is_closed(np.asarray(part.triangles)):
            out[i] = "small closed shell"
        elif moves_rigidly(rest, part.poses):
            out[i] = "moved rigidly"
    return out


def is_left_out_name(name: str) -> bool:
    """A name that says helper, joint marker, hair or clothing: geometry around a body that is
    no part of the face ("helper-tights", "joint-l-eye", "HairCards", "Outfit_Top")."""
    return any(word in LEFT_OUT_WORDS for word in name_words(name))


def choose_parts(parts: Sequence[Part], shared: Sequence[set[int]] | None = None
                 ) -> tuple[dict[int, str], dict[int, str]]:
    """(left out, not face): the parts to leave out of the face, each with why ("name", "no
    pose moves it"), and of the rest those suggested not face (``suggest_parts``). A part is
    left out unmoved only when some part moves and it touches none that does: ``shared[i]``
    holds the indices of the parts part i shares a vertex with (None: none share). The largest
    part the poses move (or the largest, when none moves) is always kept as face."""
    if not parts:
        return {}, {}
    points = np.concatenate([np.asarray(p.rest, np.float64) for p in parts])
    whole = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) or 1.0
    moved = [max((float(np.abs(np.asarray(pose) - part.rest).max(initial=0.0))
                  for pose in part.poses), default=0.0) > MOVED_SHARE * whole
             for part in parts]
    sizes = [len(part.triangles) for part in parts]
    face = max(range(len(parts)), key=lambda i: (moved[i], sizes[i]))
    left: dict[int, str] = {}
    for i, part in enumerate(parts):
        if i == face:
            continue
        if any(is_left_out_name(n) for n in part.names):
            left[i] = "name"
        elif (any(moved) and not moved[i] and not any(is_not_face_name(n) for n in part.names)
              and not any(moved[j] for j in (shared[i] if shared else ()))):
            left[i] = "no pose moves it"
    rest = [i for i in range(len(parts)) if i not in left]
    suggested = suggest_parts([parts[i] for i in rest])
    not_face = {rest[k]: why for k, why in suggested.items() if rest[k] != face}
    return left, not_face
