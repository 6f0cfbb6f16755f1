"""A head in production conventions, built by the tests themselves.

Real heads made elsewhere differ from the bundled sample in every convention the studio could
silently assume, so this one differs in all of them at once:

- **units**: millimetres (or centimetres, or metres) — ``scale`` model units per sample unit;
- **axes**: Z up, the face looking toward −Y (Blender's front view), moved far from the origin;
- **UV tiles**: skin on UDIM tile 1001, the eyes on 1002, the teeth on 1003 (u from 0 to 3);
- **separate objects**: eyes and teeth are their own OBJ objects and materials, not face;
- **ARKit names**: ``browInnerUp``, ``browDown_L``, ``mouthSmile_L``, ``eyeSquint_L``, …;
- **physically plausible poses**: a brow raise (vertical squeeze of the forehead), a frown
  (sideways squeeze between the brows with a bulge), a smile (the mouth corner driven up and
  out into the cheek: the nasolabial fold), a squint (skin drawn toward the outer eye corner:
  crow's feet); a jaw opening that only stretches, and an eye look that moves no skin.

The skin is the sample's geometry (its face coordinates tell where each region is), so the
expected region of every pose's wrinkles is known exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from studio.core.sample.mesh import (
    BROW_Y,
    CORNER_X,
    CORNER_Y,
    EYE_X,
    EYE_Y,
    MOUTH_X,
    MOUTH_Y,
    blob,
    build_geometry,
    vertex_normals,
)

Array = np.ndarray

# sample face coordinates (x toward the character's left, y up) where each pose's wrinkles form
REGIONS: dict[str, tuple[float, float]] = {
    "browInnerUp": (0.0, 0.40),
    "browDown_L": (0.07, 0.21),
    "browDown_R": (-0.07, 0.21),
    "mouthSmile_L": (0.26, -0.30),
    "mouthSmile_R": (-0.26, -0.30),
    "eyeSquint_L": (CORNER_X, CORNER_Y),
    "eyeSquint_R": (-CORNER_X, CORNER_Y),
}
COMPRESSING = tuple(REGIONS)
STRETCH_ONLY = "jawOpen"
EYES_ONLY = "eyeLookUp_L"
POSES = (*COMPRESSING, STRETCH_ONLY, EYES_ONLY)

# sample (x left, y up, z front) → world (Z up, face toward −Y): x → +X, y → +Z, z → −Y
Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
AXES = {"z": Z_UP, "y": np.eye(3)}  # "y": the sample's own axes (Y up, facing +Z)
OFFSET_M = np.array([0.35, -0.2, 1.55])  # where the head stands, metres (a standing character)


SQUINTS = ("corner", "lid")


def _skin_motion(name: str, x: Array, y: Array, squint: str = "corner"
                 ) -> tuple[Array, Array]:
    """In-surface motion (x, y, 0) and outward bulge of a skin pose, in sample units. A
    ``squint`` "corner" draws the skin toward the outer eye corner (the ICT head's); "lid"
    pushes the lower lid up and the cheek under it a little (an avatar maker's ARKit squint:
    the skin under the eye squeezed up and down, the temple untouched)."""
    move = np.zeros((len(x), 3))
    bulge = np.zeros(len(x))
    side = 1.0 if name.endswith("_L") else -1.0
    if name == "browInnerUp":
        # the inner brows lift, the hairline does not: the forehead shortens vertically
        above = np.exp(-0.5 * ((y - BROW_Y) / 0.2) ** 2)
        below = np.exp(-0.5 * ((y - BROW_Y) / 0.07) ** 2)
        move[:, 1] = 0.07 * np.where(y >= BROW_Y, above, below) * np.exp(-0.5 * (x / 0.2) ** 2)
    elif name.startswith("browDown"):
        # the corrugator draws one brow down and toward the nose: the skin between the brows
        # is squeezed sideways and bunches up
        pull = blob(x, y, side * 0.12, BROW_Y - 0.02, 0.1, 0.08)
        move[:, 0] = -side * 0.06 * pull
        move[:, 1] = -0.035 * blob(x, y, side * 0.16, BROW_Y, 0.14, 0.07)
        bulge = 0.01 * blob(x, y, side * 0.05, BROW_Y - 0.03, 0.05, 0.06)
    elif name.startswith("mouthSmile"):
        # zygomaticus: the mouth corner is pulled up and out toward the cheekbone, into a cheek
        # that moves less: the skin between them (the nasolabial fold) shortens along the pull
        corner = blob(x, y, side * MOUTH_X, MOUTH_Y, 0.09, 0.08)
        direction = np.array([side * 0.55, 0.83])
        move[:, :2] = 0.075 * corner[:, None] * direction
        move[:, 1] += 0.02 * blob(x, y, side * 0.3, -0.2, 0.12, 0.1)
        bulge = 0.02 * blob(x, y, side * 0.3, -0.22, 0.1, 0.08)
    elif name.startswith("eyeSquint") and squint == "lid":
        lid = blob(x, y, side * EYE_X, EYE_Y - 0.05, 0.10, 0.03)
        cheek = blob(x, y, side * (EYE_X + 0.03), EYE_Y - 0.14, 0.13, 0.07)
        move[:, 1] = 0.012 * (lid + 0.4 * cheek)
    elif name.startswith("eyeSquint"):
        # orbicularis oculi: the skin around the outer eye corner contracts toward it
        cx = side * CORNER_X
        ring = blob(x, y, cx, CORNER_Y, 0.09, 0.09)
        move[:, 0] = -0.45 * (x - cx) * ring
        move[:, 1] = (-0.45 * (y - CORNER_Y) * ring
                      + 0.02 * blob(x, y, side * EYE_X, EYE_Y - 0.035, 0.11, 0.035))
    else:
        raise KeyError(name)
    return move, bulge


CHIN_DROP = 0.25  # sample units from the mouth down to the chin


def _jaw_open(rest_sample: Array, y: Array) -> Array:
    """The skin from the mouth down to the chin moves down in proportion to its depth below the
    mouth (a vertical stretch, an affine scale > 1, which compresses nothing); below the chin
    everything is carried down with it, undeformed."""
    out = rest_sample.copy()
    out[:, 1] -= 0.12 * np.clip(MOUTH_Y - y, 0.0, CHIN_DROP)
    return out


def _sphere(centre: Array, radius: float, rows: int = 8, cols: int = 12
            ) -> tuple[Array, Array, Array]:
    """A UV sphere: (positions, triangles, uvs in 0–1) — an eyeball."""
    theta = np.linspace(0.0, np.pi, rows + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, cols + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1) * radius
    uv = np.stack([p / (2 * np.pi), 1.0 - t / np.pi], -1)
    idx = np.arange((rows + 1) * (cols + 1)).reshape(rows + 1, cols + 1)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])
    return pos.reshape(-1, 3) + centre, tris, uv.reshape(-1, 2)


def _teeth() -> tuple[Array, Array, Array]:
    """An arch of teeth behind the lips: a curved strip (sample units)."""
    angle = np.linspace(-1.0, 1.0, 9)
    height = np.array([MOUTH_Y - 0.06, MOUTH_Y + 0.06])
    a, h = np.meshgrid(angle, height, indexing="ij")
    pos = np.stack([0.22 * np.sin(a), h, 0.55 - 0.18 * (1 - np.cos(a))], -1)
    uv = np.stack([(a + 1) / 2, (h - height[0]) / 0.12], -1)
    idx = np.arange(pos.shape[0] * 2).reshape(-1, 2)
    q0, q1, q2, q3 = idx[:-1, 0], idx[1:, 0], idx[1:, 1], idx[:-1, 1]
    tris = np.concatenate([np.stack([q0, q1, q2], 1), np.stack([q0, q2, q3], 1)])
    return pos.reshape(-1, 3), tris, uv.reshape(-1, 2)


@dataclass
class Part:
    name: str  # OBJ object and material
    tile: int  # UDIM tile its UVs sit in
    rest: Array  # (n, 3) sample units
    triangles: Array  # (m, 3) into the part's own vertices
    uvs: Array  # (n, 2) in 0–1, before the tile offset
    weld: Array | None = None  # render vertex → position (the skin has seams)
    poses: dict[str, Array] = field(default_factory=dict)  # pose → (n, 3), sample units


@dataclass
class ProductionHead:
    """The head's parts in sample units, and the conventions it is written out in."""

    parts: list[Part]
    face_xy: Array  # skin vertices' sample face coordinates
    scale: float  # model units per sample unit (0.1 m per sample unit, in the chosen unit)
    unit: str
    axes: Array = field(default_factory=lambda: Z_UP)  # sample axes → world axes

    def to_world(self, points: Array) -> Array:
        return (np.asarray(points, float) @ self.axes.T) * self.scale + OFFSET_M * self.scale / 0.1

    def to_sample(self, points: Array) -> Array:
        """World points back to sample coordinates (x left, y up, z front)."""
        local = (np.asarray(points, float) - OFFSET_M * self.scale / 0.1) / self.scale
        return local @ self.axes

    def write_obj(self, path: Path, pose: str | None = None) -> Path:
        """One OBJ with an object and a material per part, UVs on each part's tile."""
        lines = ["# production-convention test head", f"# units: {self.unit}, Z up"]
        v_base = vt_base = 1
        for part in self.parts:
            positions = part.poses.get(pose, part.rest) if pose else part.rest
            world = self.to_world(positions)
            lines += [f"o {part.name}", f"usemtl {part.name}"]
            lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in world]
            uv = part.uvs + np.array([part.tile - 1001, 0.0])
            lines += [f"vt {u:.6f} {v:.6f}" for u, v in uv]
            weld = part.weld if part.weld is not None else np.arange(len(part.uvs))
            for tri in part.triangles:
                lines.append("f " + " ".join(f"{weld[i] + v_base}/{i + vt_base}" for i in tri))
            v_base += len(positions)
            vt_base += len(uv)
        path.write_text("\n".join(lines) + "\n")
        return path

    def write_set(self, folder: Path, poses: tuple[str, ...] = POSES) -> dict[str, Path]:
        """neutral.obj and one OBJ per pose: the files a user would pass to ``new``."""
        folder.mkdir(parents=True, exist_ok=True)
        files = {"neutral": self.write_obj(folder / "neutral.obj")}
        for name in poses:
            files[name] = self.write_obj(folder / f"{name}.obj", name)
        return files


SCALES = {"mm": 100.0, "cm": 10.0, "m": 0.1}  # a sample unit is 10 cm


def build_head(unit: str = "mm", vertices: int = 2172, up: str = "z", squint: str = "corner"
               ) -> ProductionHead:
    geo = build_geometry(vertices)
    rest = geo.rest.astype(np.float64)
    x, y = geo.face_xy[:, 0], geo.face_xy[:, 1]
    tri_welded = geo.weld[geo.triangles]
    normals = vertex_normals(rest, tri_welded)
    poses: dict[str, Array] = {}
    for name in COMPRESSING:
        move, bulge = _skin_motion(name, x, y, squint)
        move *= geo.front[:, None]
        bulge = bulge * geo.front
        tangential = move - np.sum(move * normals, axis=1, keepdims=True) * normals
        poses[name] = rest + tangential + bulge[:, None] * normals
    poses[STRETCH_ONLY] = _jaw_open(rest, y)
    poses[EYES_ONLY] = rest
    skin = Part("head", 1001, rest, geo.triangles, geo.uvs.astype(np.float64), geo.weld,
                poses)
    eye_parts = []
    for side, name in ((1.0, "eye_L"), (-1.0, "eye_R")):
        centre = np.array([side * EYE_X, EYE_Y, 0.48])
        pos, tris, uv = _sphere(centre, 0.1)
        part = Part(name, 1002, pos, tris, uv)
        for pose in POSES:
            part.poses[pose] = pos
        if name == "eye_L":  # the eye looks up: a rotation about its centre
            c, s = np.cos(0.35), np.sin(0.35)
            rot = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
            part.poses[EYES_ONLY] = (pos - centre) @ rot.T + centre
        eye_parts.append(part)
    pos, tris, uv = _teeth()
    teeth = Part("teeth", 1003, pos, tris, uv, poses={p: pos for p in POSES})
    return ProductionHead([skin, *eye_parts, teeth], geo.face_xy, SCALES[unit], unit, AXES[up])
