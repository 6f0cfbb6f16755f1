"""Orbit camera: framing, matrices, projection of points and picking rays (numpy only).

The camera orbits a target; yaw 0 and pitch 0 look at the face from its front, with its up on
screen. The face's axes are the ``basis`` (columns: the character's left, up, front in model
space; the identity for a Y-up face looking toward +Z, like the bundled sample), so a Z-up head
facing −Y orbits the same way. Matrices are row-major numpy arrays (transpose for GLSL).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray


def look_at(eye: Array, target: Array, up: Array) -> Array:
    f = target - eye
    f = f / np.linalg.norm(f)
    s = np.cross(f, up)
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> Array:
    f = 1.0 / math.tan(math.radians(fov_y_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2.0 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


@dataclass
class OrbitCamera:
    target: Array = field(default_factory=lambda: np.zeros(3))
    distance: float = 5.0
    yaw: float = 20.0  # degrees, positive turns the camera toward the face's left (+X)
    pitch: float = 5.0  # degrees, positive looks from above
    fov_y: float = 30.0
    radius: float = 1.0  # size of what is framed; sets the clipping planes
    basis: Array = field(default_factory=lambda: np.eye(3))  # the face's left, up, front

    @property
    def up(self) -> Array:
        return self.basis[:, 1]

    def frame(self, lo: Array, hi: Array, margin: float = 1.1) -> None:
        """Centre on a bounding box and back off until its corners fit a square view, seen
        from the current direction (so any model size or position frames well)."""
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        self.frame_points(np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                                    for z in (lo[2], hi[2])]), margin)

    def frame_points(self, points: Array, margin: float = 1.1) -> None:
        """Centre on points (a box's corners) and back off until they fit a square view."""
        points = np.asarray(points, float)
        lo, hi = points.min(axis=0), points.max(axis=0)
        self.target = (lo + hi) / 2.0
        self.radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 1e-6)
        corners = points - self.target
        view = look_at(self.direction(), np.zeros(3), self.up)
        right, up, toward = corners @ view[0, :3], corners @ view[1, :3], -(corners @ view[2, :3])
        tan_half = math.tan(math.radians(self.fov_y) / 2.0)
        needed = np.maximum(np.abs(right), np.abs(up)) * margin / tan_half - toward
        self.distance = max(float(needed.max()), self.radius * 0.1)

    def stand_clear_of(self, points: Array, margin: float = 0.05) -> None:
        """Back the eye off, along its direction, until it stands outside everything in front of
        the framed face, and widen the clipping planes to keep it whole. Framing fits the face's
        box only; hair, a hat or a low-poly hair shell reaching further toward the camera than
        the eye would otherwise surround it (or be cut by the near plane), and the first picture
        would show the inside of the hair. Only points within the framed window (seen along the
        view) can stand between the eye and the face; the rest of a body is left out."""
        points = np.asarray(points, float)
        if len(points) == 0:
            return
        view = look_at(self.direction(), np.zeros(3), self.up)
        rel = points - self.target
        # (the view's third row points from the target toward the eye)
        right, up, toward = rel @ view[0, :3], rel @ view[1, :3], rel @ view[2, :3]
        # the framed window at the target's depth: what framing fitted, seen from the eye
        half = self.distance * math.tan(math.radians(self.fov_y) / 2.0)
        before = (np.abs(right) <= half) & (np.abs(up) <= half) & (toward > 0)
        if not before.any():
            return
        nearest = float(toward[before].max())
        clearance = margin * max(self.radius, 1e-6)
        self.distance = max(self.distance, nearest + clearance)
        # near = distance - 2 radius must fall before the nearest point (clip_planes)
        self.radius = max(self.radius, (nearest + clearance) / 2.0)

    def direction(self) -> Array:
        """Unit vector from the target toward the eye (yaw and pitch in the face's axes)."""
        y, p = math.radians(self.yaw), math.radians(self.pitch)
        local = np.array([math.sin(y) * math.cos(p), math.sin(p), math.cos(y) * math.cos(p)])
        return self.basis @ local

    def eye(self) -> Array:
        return self.target + self.distance * self.direction()

    def view_matrix(self) -> Array:
        return look_at(self.eye(), self.target, self.up)

    def clip_planes(self) -> tuple[float, float]:
        near = max(self.distance - 2.0 * self.radius, self.distance * 0.01, 1e-4)
        return near, self.distance + 2.0 * self.radius

    def projection_matrix(self, aspect: float) -> Array:
        return perspective(self.fov_y, aspect, *self.clip_planes())

    def view_projection(self, width: int, height: int) -> Array:
        return self.projection_matrix(width / max(height, 1)) @ self.view_matrix()

    # --- interaction -------------------------------------------------------------------------
    def orbit(self, d_yaw: float, d_pitch: float) -> None:
        self.yaw = (self.yaw + d_yaw) % 360.0
        self.pitch = float(np.clip(self.pitch + d_pitch, -89.0, 89.0))

    def pan(self, dx: float, dy: float) -> None:
        """Move the target by a fraction of the view height (dx right, dy up)."""
        view = self.view_matrix()
        right, up = view[0, :3], view[1, :3]
        scale = 2.0 * self.distance * math.tan(math.radians(self.fov_y) / 2.0)
        self.target = self.target + (dx * right + dy * up) * scale

    def zoom(self, factor: float) -> None:
        """Multiply the distance to the target (factor < 1 moves closer)."""
        self.distance = float(np.clip(self.distance * factor, self.radius * 0.05,
                                      self.radius * 100.0))

    # --- screen <-> world --------------------------------------------------------------------
    def project(self, points: Array, width: int, height: int) -> tuple[Array, Array]:
        """Pixel coordinates (x right, y down) and view depth of world points."""
        pts = np.asarray(points, float).reshape(-1, 3)
        clip = np.c_[pts, np.ones(len(pts))] @ self.view_projection(width, height).T
        ndc = clip[:, :3] / clip[:, 3:4]
        px = np.c_[(ndc[:, 0] + 1.0) * 0.5 * width, (1.0 - ndc[:, 1]) * 0.5 * height]
        return px, clip[:, 3]

    def ray(self, x: float, y: float, width: int, height: int) -> tuple[Array, Array]:
        """World-space origin and unit direction of the ray through pixel (x, y)."""
        inv = np.linalg.inv(self.view_projection(width, height))
        ndc = np.array([2.0 * x / width - 1.0, 1.0 - 2.0 * y / height])
        near = inv @ np.array([ndc[0], ndc[1], -1.0, 1.0])
        far = inv @ np.array([ndc[0], ndc[1], 1.0, 1.0])
        near, far = near[:3] / near[3], far[:3] / far[3]
        d = far - near
        return near, d / np.linalg.norm(d)

    def to_dict(self) -> dict:
        return {"target": [float(v) for v in self.target], "distance": self.distance,
                "yaw": self.yaw, "pitch": self.pitch, "fov_y": self.fov_y, "radius": self.radius,
                "basis": [[float(v) for v in row] for row in self.basis]}

    @classmethod
    def from_dict(cls, data: dict) -> OrbitCamera:
        cam = cls()
        cam.target = np.asarray(data.get("target", [0, 0, 0]), float)
        for key in ("distance", "yaw", "pitch", "fov_y", "radius"):
            if key in data:
                setattr(cam, key, float(data[key]))
        if "basis" in data:  # a rotation, else (damaged) the default axes
            basis = np.asarray(data["basis"], float)
            if basis.shape == (3, 3) and np.isfinite(basis).all() and np.allclose(
                    basis.T @ basis, np.eye(3), atol=1e-4):
                cam.basis = basis
        return cam
