"""A full-body OBJ as an open-source parametric human exports it, imported as a new user would:
``new --mesh body.obj --pose … --auto`` with no ``--keep`` and no ``--not-face``.

The rig is built here, in that pipeline's conventions and none of the studio's: decimetres,
Y up, the face toward +Z, 16 dm above the feet; one OBJ of *groups* and no materials — the body
(the production test head's skin on a torso and legs, the head on a quarter of the UV square),
hair cards hanging before the forehead, eyes, teeth, lashes and small joint-marker cubes (one
floating before each eye); expression units named the way that pipeline names them
(``eyebrows-left-down``, ``eye-left-slit``, ``mouth-corner-puller`` …). The face must be found
and framed from the front, the helpers left out, the eyes, teeth and lashes kept but never
wrinkled, and brow raise, frown and smile must each change ≥ 1 % of a default 800 × 800 render
with both techniques.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from studio.cli import main
from studio.core.project.reader import load_project
from tests.production_head import build_head
from tests.visibility import least

HEAD_AT = np.array([0.0, 16.0, 0.0])  # decimetres: where the head stands (a sample unit is 1 dm)
# the pipeline's unit names → the production head's poses they are made of
UNITS = {"eyebrows-inner-up": ("browInnerUp",), "eyebrows-left-down": ("browDown_L",),
         "eyebrows-right-down": ("browDown_R",),
         "mouth-corner-puller": ("mouthSmile_L", "mouthSmile_R"),
         "eye-left-slit": ("eyeSquint_L",), "mouth-open": ("jawOpen",)}
# each expression judged as the units that make it, at full weight (a frown lowers both brows)
JUDGED = {"brow raise": {"eyebrows-inner-up": 1.0},
          "frown": {"eyebrows-left-down": 1.0, "eyebrows-right-down": 1.0},
          "smile": {"mouth-corner-puller": 1.0}, "squint": {"eye-left-slit": 1.0}}
# below the 1 %: the squint's crow's feet, ≥ 0.5 % (the bar for a small
# avatar's); and the frown's two short lines between the brows, an artist's "11" (issue 38),
# ≥ 0.5 % (0.82 / 0.60 % with t1 / t2 here, 0.71 / 0.62 % on the VRM avatar; 1.6 / 1.4 % and
# 1.5 / 1.5 % as a comb of three lines up the forehead; 1.15 / 0.98 % before its mask and
# vectors held its glabellar lines whole)
HELPERS = ("short02", "joint-head", "joint-l-eye", "joint-r-eye", "helper-tights")
NOT_SKIN = ("HighPolyEyes", "teeth_base", "Eyelashes01")


@dataclass
class Group:
    name: str
    rest: np.ndarray  # (n, 3) decimetres, world
    triangles: np.ndarray  # (m, 3) into rest
    uvs: np.ndarray  # (n, 2)
    weld: np.ndarray | None = None  # render vertex → position, when the UVs have seams
    poses: dict[str, np.ndarray] = field(default_factory=dict)  # unit → (n, 3), world


def _grid_box(centre, size, cells: int, uv_lo, uv_hi) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
    """A box of ``cells`` × ``cells`` squares a side (a torso, legs): positions, triangles and
    UVs spread over a cell of the UV square (six sides side by side)."""
    pos, tris, uvs = [], [], []
    t = np.linspace(-0.5, 0.5, cells + 1)
    a, b = np.meshgrid(t, t, indexing="ij")
    idx = np.arange((cells + 1) ** 2).reshape(cells + 1, cells + 1)
    quads = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    for side in range(6):
        axis, sign = divmod(side, 2)
        face = np.zeros((a.size, 3))
        others = [k for k in range(3) if k != axis]
        face[:, axis] = 0.5 if sign else -0.5
        face[:, others[0]], face[:, others[1]] = a.ravel(), b.ravel()
        base = sum(len(p) for p in pos)
        q = quads if (axis == 1) == bool(sign) else quads[:, ::-1]
        tris.append(np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]) + base)
        pos.append(face * size + centre)
        u = (side + (a.ravel() + 0.5)) / 6
        uvs.append(np.column_stack([u, b.ravel() + 0.5]))
    lo, hi = np.asarray(uv_lo, float), np.asarray(uv_hi, float)
    return np.concatenate(pos), np.concatenate(tris), np.concatenate(uvs) * (hi - lo) + lo


def _cube(centre, edge: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return _grid_box(centre, np.full(3, edge), 1, (0.9, 0.9), (1.0, 1.0))


def build_body(vertices: int = 2172) -> list[Group]:
    """The rig's groups, every unit's positions included (see the module's docstring)."""
    head = build_head("m", vertices=vertices, up="y")
    skin, eye_l, eye_r, teeth = head.parts

    def world(points):  # sample units are decimetres already; Y up, +Z front
        return np.asarray(points, float) + HEAD_AT

    def unit(part, poses) -> np.ndarray:
        moved = part.rest.copy()
        for pose in poses:
            moved += part.poses.get(pose, part.rest) - part.rest
        return world(moved)

    body_poses = {u: unit(skin, p) for u, p in UNITS.items()}  # the torso: under the neck
    torso = _grid_box((0, 11.2, 0), (3.6, 6.6, 2.2), 8, (0.5, 0.0), (1.0, 1.0))
    legs = _grid_box((0, 4.2, 0), (3.0, 8.0, 1.8), 8, (0.0, 0.0), (0.5, 0.5))
    n_skin = len(skin.rest)
    rest = np.concatenate([world(skin.rest), torso[0], legs[0]])
    weld = np.concatenate([skin.weld, np.arange(len(torso[0])) + n_skin,
                           np.arange(len(legs[0])) + n_skin + len(torso[0])])
    tris = np.concatenate([skin.triangles, torso[1] + len(skin.uvs),
                           legs[1] + len(skin.uvs) + len(torso[0])])
    uvs = np.concatenate([skin.uvs * 0.5 + [0.0, 0.5], torso[2], legs[2]])
    still = rest[n_skin:]
    body = Group("body", rest, tris, uvs, weld,
                 {u: np.concatenate([p, still]) for u, p in body_poses.items()})
    groups = [body]
    # eyes (closed spheres, still), teeth (carried down by the mouth opening, rigidly)
    eyes = [world(eye_l.rest), world(eye_r.rest)]
    eye_tris = np.concatenate([eye_l.triangles, eye_r.triangles + len(eye_l.rest)])
    groups.append(Group("HighPolyEyes", np.concatenate(eyes), eye_tris,
                        np.concatenate([eye_l.uvs, eye_r.uvs]) * 0.1 + 0.9))
    drop = np.array([0.0, -0.03, 0.0])
    groups.append(Group("teeth_base", world(teeth.rest), teeth.triangles, teeth.uvs * 0.1 + 0.9,
                        poses={"mouth-open": world(teeth.rest) + drop}))
    # lashes: a strip above each eye, lowered a little by the slit (rigidly)
    lash_pos, lash_tris = [], []
    for side in (1.0, -1.0):
        xs = np.linspace(-0.12, 0.12, 6) + side * 0.27
        top = np.column_stack([xs, np.full(6, 0.17), np.full(6, 0.6)])
        low = top + np.array([0.0, -0.03, 0.04])
        base = 12 * len(lash_pos)
        lash_pos.append(np.concatenate([top, low]))
        i = np.arange(5) + base
        lash_tris.append(np.concatenate([np.stack([i, i + 1, i + 7], 1),
                                         np.stack([i, i + 7, i + 6], 1)]))
    lashes = world(np.concatenate(lash_pos))
    moved = lashes.copy()
    moved[:12] += [0.0, -0.01, 0.0]
    groups.append(Group("Eyelashes01", lashes, np.concatenate(lash_tris),
                        np.full((24, 2), 0.95), poses={"eye-left-slit": moved}))
    # hair cards: quads hanging from the scalp down before the forehead (a fringe)
    cards, card_tris = [], []
    for k, x in enumerate(np.linspace(-0.5, 0.5, 7)):
        quad = np.array([[x - 0.09, 0.95, 0.55], [x + 0.09, 0.95, 0.55],
                         [x + 0.09, 0.35, 0.95], [x - 0.09, 0.35, 0.95]])
        cards.append(quad)
        card_tris.append(np.array([[0, 1, 2], [0, 2, 3]]) + 4 * k)
    groups.append(Group("short02", world(np.concatenate(cards)), np.concatenate(card_tris),
                        np.tile([[0, 0], [1, 0], [1, 1], [0, 1]], (7, 1)) * 0.1 + 0.9))
    # joint markers: small cubes at joints, one floating before each eye
    for name, centre in (("joint-head", (0.0, 0.3, 0.0)), ("joint-l-eye", (0.27, 0.09, 0.8)),
                         ("joint-r-eye", (-0.27, 0.09, 0.8))):
        pos, tris, uv = _cube(world(centre), 0.06)
        groups.append(Group(name, pos, tris, uv))
    # a helper that wraps the legs (tights), as the body's own shape
    pos, tris, uv = _grid_box((0, 4.2, 0), (3.1, 8.1, 1.9), 4, (0.0, 0.0), (0.5, 0.5))
    groups.append(Group("helper-tights", pos, tris, uv))
    return groups


def write_obj(groups: list[Group], path: Path, unit: str | None = None) -> Path:
    """One OBJ of groups, no materials; ``unit``: the positions in that expression unit."""
    lines = ["# full-body export, decimetres, Y up"]
    v_base = vt_base = 1
    for g in groups:
        positions = g.poses.get(unit, g.rest) if unit else g.rest
        lines.append(f"g {g.name}")
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in positions]
        lines += [f"vt {u:.6f} {v:.6f}" for u, v in g.uvs]
        weld = g.weld if g.weld is not None else np.arange(len(g.uvs))
        lines += ["f " + " ".join(f"{weld[i] + v_base}/{i + vt_base}" for i in tri)
                  for tri in g.triangles]
        v_base += len(positions)
        vt_base += len(g.uvs)
    path.write_text("\n".join(lines) + "\n")
    return path


def import_body(folder: Path, *extra: str) -> tuple[int, str]:
    """``wrinkle-studio new --mesh body.obj --pose unit=… --auto``; (exit code, output)."""
    groups = build_body()
    args = ["new", "--mesh", str(write_obj(groups, folder / "body.obj")), "--auto",
            "-o", str(folder / "body.wrinkle"), *extra]
    for name in UNITS:
        args += ["--pose", f"{name}={write_obj(groups, folder / f'{name}.obj', name)}"]
    out = io.StringIO()
    with redirect_stdout(out):
        code = main(args)
    return code, out.getvalue()


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("body")
    code, out = import_body(folder)
    assert code == 0, out
    return load_project(folder / "body.wrinkle"), out


@pytest.mark.core
def test_helpers_are_left_out_and_eyes_teeth_lashes_are_not_face_in_one_line(imported) -> None:
    project, out = imported
    line = next(line for line in out.splitlines() if line.startswith("OBJ groups"))
    for name in HELPERS:
        assert name in line.split("left out")[1], (name, line)
    for name in NOT_SKIN:
        assert name in line.split("not face")[1].split("left out")[0], (name, line)
    # the helpers are gone from the mesh: nothing before the eyes but the eyes' own skin
    assert project.mesh.n_welded == sum(len(g.rest) for g in build_body()
                                        if g.name not in HELPERS)
    assert project.not_face is not None


@pytest.mark.core
def test_the_face_is_framed_from_the_front_and_each_unit_named_after_its_place(imported
                                                                              ) -> None:
    from studio.core.setup.face_frame import face_frame

    project, out = imported
    frame = face_frame(project)
    assert np.allclose(frame.up, (0, 1, 0)) and np.allclose(frame.front, (0, 0, 1))
    assert abs(frame.centre[1] - HEAD_AT[1]) < 1.0  # the head, not the body's middle
    lines = {line.split(":")[0].strip(): line for line in out.splitlines()
             if line.startswith("  ")}
    assert "brow" not in lines["eye-left-slit"], lines["eye-left-slit"]
    assert "eye" in lines["eye-left-slit"] or "cheek" in lines["eye-left-slit"]


def not_skin_pixels(project, size: int) -> np.ndarray:
    """(size, size) bool: where a default render shows a part marked not face — the pixels
    that change when those parts are taken away (moved far behind the camera's back)."""
    import copy

    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    with OffscreenStudio(project, size, size) as studio:
        whole = studio.render(RenderSettings(technique="none"), {}).astype(int)
        camera = studio.camera.to_dict()
    bare = copy.deepcopy(project)
    rest = bare.mesh.rest.copy()
    rest[bare.not_face] -= 1000.0 * np.ptp(rest, axis=0).max()
    bare.mesh = type(bare.mesh)(rest, bare.mesh.triangles, bare.mesh.uvs, bare.mesh.weld)
    bare.poses = []
    bare.view["camera"] = camera
    with OffscreenStudio(bare, size, size) as studio:
        without = studio.render(RenderSettings(technique="none"), {}).astype(int)
    return np.abs(whole - without).max(-1) > 8


def judge_renders(project, units: dict[str, dict[str, float]], size: int = 800
                  ) -> dict[tuple[str, str], float]:
    """Each expression (its units' weights) in a default render: the share of the picture t1
    and t2 change (``tests.visibility.least``), none of it on the eyes, teeth or lashes (edge
    pixels aside)."""
    from studio.render.offscreen import OffscreenStudio
    from studio.render.settings import RenderSettings

    eyes = not_skin_pixels(project, size)
    assert eyes.any()
    shares, on_eyes = {}, {}
    with OffscreenStudio(project, size, size) as studio:
        neutral = studio.render(RenderSettings(technique="none"), {}).astype(int)
        face = np.abs(neutral - neutral[0, 0]).max(-1) > 8
        assert face.mean() > 0.25  # the face fills the view, seen from the front
        for what, weights in units.items():
            plain = studio.render(RenderSettings(technique="none"), weights).astype(int)
            for technique in ("t1", "t2"):
                image = studio.render(RenderSettings(technique=technique), weights)
                changed = np.abs(image.astype(int) - plain).max(-1) > 4
                shares[what, technique] = float(changed.mean())
                on_eyes[what, technique] = float(changed[eyes].mean())
    print({k: f"{v:.2%}" for k, v in shares.items()}, on_eyes)
    for (what, technique), share in shares.items():
        assert share >= least(what), (what, technique, shares)
    assert max(on_eyes.values()) < 0.02, on_eyes
    return shares


def test_brow_raise_frown_and_smile_show_in_a_default_render_and_not_on_the_eyes(imported
                                                                                 ) -> None:
    judge_renders(imported[0], JUDGED)


@pytest.mark.core
def test_without_auto_it_is_a_suggestion_and_keep_or_not_face_override_it(tmp_path) -> None:
    every = sum(len(g.rest) for g in build_body())
    code, _ = import_body(tmp_path, "--keep", "body", "HighPolyEyes", "--not-face", "body",
                          "HighPolyEyes")
    assert code == 2  # the user's own choice, taken as given: no skin left
    folder = tmp_path / "plain"
    folder.mkdir()
    groups = build_body()
    mesh = write_obj(groups, folder / "body.obj")
    out_file = folder / "p.wrinkle"
    buffer = io.StringIO()
    with redirect_stdout(buffer):
        assert main(["new", "--mesh", str(mesh), "-o", str(out_file)]) == 0
    said = buffer.getvalue()
    # no poses: nothing shows which parts move; names still suggest
    assert "suggested, applied with --auto: OBJ groups: 9" in said
    assert "left out: joint-head (name)" in said and "short02" not in said.split("left out")[1]
    assert "a whole body" not in said and "up +Y" in said  # no face box to measure it by
    assert load_project(out_file).mesh.n_welded == every  # nothing applied
    code, said = import_body(tmp_path, "--keep", "body", "HighPolyEyes", "short02")
    assert code == 0
    line = next(x for x in said.splitlines() if x.startswith("OBJ groups"))
    assert "left out" not in line and "not face: HighPolyEyes (name)" in line
    kept = load_project(tmp_path / "body.wrinkle")
    assert kept.mesh.n_welded == sum(len(g.rest) for g in groups
                                     if g.name in ("body", "HighPolyEyes", "short02"))
