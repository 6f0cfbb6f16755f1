"""Baking a wrinkled normal map from a high-polygon mesh: exact on cases worked by hand, in the
renderer's tangent frame, and from the Maps menu as one undo step."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from studio.core.files.errors import MeshError
from studio.core.mesh.face_mesh import FaceMesh
from studio.core.mesh.geometry import DeformCache
from studio.core.wrinkles.bake import BakeCancelled, bake_normal_map, texel_samples

SIZE = 64
A, K = 0.02, 3  # the sculpt's height: A·sin(2πK·x)·cos(4π·y) over the unit square


def grid(n: int, height=None, uv_scale: float = 1.0, mirror_u: bool = False) -> FaceMesh:
    """An n × n vertex grid over the unit square (z = height(x, y)), UVs = (x, y)."""
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    z = np.zeros_like(x) if height is None else height(x, y)
    u = 1.0 - x if mirror_u else x  # mirrored: clockwise in UV space, tangent w = −1
    return FaceMesh(np.stack([x.ravel(), y.ravel(), z.ravel()], 1), triangles,
                    np.stack([u.ravel(), y.ravel()], 1) * uv_scale, np.arange(n * n),
                    source="high.obj")


def sculpt(x, y):
    return A * np.sin(2 * np.pi * K * x) * np.cos(4 * np.pi * y)


def analytic_normals(size: int, mirror_u: bool = False) -> np.ndarray:
    """The sculpt's unit normal (−∂h/∂x, −∂h/∂y, 1) at each texel centre, in the quad's
    tangent frame: row 0 is v = 1; a mirrored U flips the tangent, so x changes sign."""
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, 1.0 - c)
    x = 1.0 - u if mirror_u else u
    hx = A * 2 * np.pi * K * np.cos(2 * np.pi * K * x) * np.cos(4 * np.pi * v)
    hy = -A * 4 * np.pi * np.sin(2 * np.pi * K * x) * np.sin(4 * np.pi * v)
    n = np.stack([hx if mirror_u else -hx, -hy, np.ones_like(hx)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Degrees between unit vectors."""
    dot = (np.asarray(a, np.float64) * np.asarray(b, np.float64)).sum(-1)
    return np.degrees(np.arccos(np.clip(dot, -1.0, 1.0)))


def decode(image: np.ndarray) -> np.ndarray:
    n = image.astype(np.float64) / np.iinfo(image.dtype).max * 2.0 - 1.0
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


@pytest.fixture(scope="module")
def high() -> FaceMesh:
    return grid(241, sculpt)


@pytest.mark.core
def test_flat_quad_against_a_sinusoidal_sculpt_gives_the_analytic_normals(high):
    low = grid(2)  # one quad, two triangles
    result = bake_normal_map(low, high, SIZE, max_distance=0.1)
    assert result.covered.all() and result.hit.all() and result.hit_fraction == 1.0
    expected = analytic_normals(SIZE)
    assert angles(expected, expected[..., 2:] * [0, 0, 1]).max() > 15  # slopes are real
    # Interpolated vertex normals of a 240-quad grid: within 0.2° of the true normals (measured
    # 0.04°); through 8 bits, within 1° (quantisation alone is up to ~0.45°).
    assert angles(result.normals, expected).max() < 0.2
    assert angles(decode(result.image), expected).max() < 1.0
    assert result.image.dtype == np.uint8 and result.image.shape == (SIZE, SIZE, 3)
    sixteen = bake_normal_map(low, high, SIZE, max_distance=0.1, bits=16)
    assert sixteen.image.dtype == np.uint16
    assert angles(decode(sixteen.image), expected).max() < 0.2


@pytest.mark.core
def test_a_flat_sculpt_on_a_flat_face_bakes_a_flat_map():
    result = bake_normal_map(grid(3), grid(40), SIZE, max_distance=0.1)
    assert (result.image == (128, 128, 255)).all()


@pytest.mark.core
def test_a_groove_shows_as_two_tilted_walls():
    """The issue's case: a plane with a V groove along v, 0.1 wide and 0.02 deep at u = 0.5."""
    def groove(x, y):
        return -0.02 * np.clip(1.0 - np.abs(x - 0.5) / 0.05, 0.0, None)

    result = bake_normal_map(grid(2), grid(201, groove), SIZE, max_distance=0.05)
    red = result.image[SIZE // 2, :, 0].astype(int)
    col = (np.arange(SIZE) + 0.5) / SIZE
    slope = 0.02 / 0.05
    tilt = round((slope / np.hypot(slope, 1.0) * 0.5 + 0.5) * 255)  # n_x = sin(atan(0.4))
    left = (col > 0.455) & (col < 0.49)  # the wall falling toward +u: normal toward +x
    right = (col > 0.51) & (col < 0.545)
    outside = np.abs(col - 0.5) > 0.06
    assert (np.abs(red[left] - tilt) <= 1).all()
    assert (np.abs(red[right] - (255 - tilt)) <= 1).all()
    assert (red[outside] == 128).all()


@pytest.mark.core
def test_the_tangent_frame_is_the_renderers_whatever_the_pose_or_handedness(high):
    """The map is read in each texel's tangent frame, so moving the face and sculpt together
    changes nothing, and a mirrored UV layout (tangent w = −1) mirrors the map."""
    low = grid(2)
    plain = bake_normal_map(low, high, SIZE, max_distance=0.1).normals
    angle = np.radians(50)
    c, s = np.cos(angle), np.sin(angle)
    rotate = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ np.array([[1, 0, 0], [0, c, -s],
                                                                        [0, s, c]])
    moved = [FaceMesh(m.rest @ rotate.T + [3, -2, 1], m.triangles, m.uvs, m.weld)
             for m in (low, high)]
    turned = bake_normal_map(*moved, SIZE, max_distance=0.1).normals
    assert angles(turned, plain).max() < 0.05  # float32 positions, rotated and moved
    mirror_low = grid(2, mirror_u=True)
    assert (DeformCache(mirror_low).update(mirror_low.rest)[:, 9] == -1).all()  # w = −1
    mirrored = bake_normal_map(mirror_low, grid(241, sculpt, mirror_u=True), SIZE,
                               max_distance=0.1).normals
    assert angles(mirrored, analytic_normals(SIZE, mirror_u=True)).max() < 0.2


def cylinder(segments: int, rows: int, uv_jitter: float = 0.0) -> FaceMesh:
    """A third of a unit cylinder around y (θ from −60° to 60°, y from 0 to 1), UVs (θ, y)."""
    theta, y = np.meshgrid(np.linspace(-np.pi / 3, np.pi / 3, segments + 1),
                           np.linspace(0, 1, rows + 1))
    idx = np.arange(theta.size).reshape(theta.shape)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])  # outward
    rest = np.stack([np.sin(theta), y, np.cos(theta)], -1).reshape(-1, 3)
    uv = np.stack([(theta + np.pi / 3) / (2 * np.pi / 3), y], -1).reshape(-1, 2)
    uv[:, 1] += uv_jitter * np.random.default_rng(1).uniform(-1, 1, len(uv)) * (uv[:, 1] > 0)
    return FaceMesh(rest, triangles, uv, np.arange(len(rest)))


def decoded_error(low: FaceMesh, result, frame: str) -> float:
    """The largest angle between the fine cylinder's normal and the map decoded the way
    face.frag does, normalize(mat3(T̂, B̂, N̂) · n), with the vertex buffer of ``frame``."""
    rows, cols, tri, bary = texel_samples(low, SIZE)
    buffer = DeformCache(low, frame).update(low.rest).astype(np.float64)
    n, t, w = buffer[:, 3:6], buffer[:, 6:9], buffer[:, 9:10]
    corners = low.triangles[tri]

    def interpolated(values):
        v = np.einsum("nk,nkj->nj", bary, values[corners])
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    tn, bn, nn = interpolated(t), interpolated(w * np.cross(n, t)), interpolated(n)
    assert np.abs((bn * nn).sum(1)).max() > 0.01  # the frames really are skewed (~1°)
    local = result.normals[rows, cols].astype(np.float64)
    shaded = local[:, :1] * tn + local[:, 1:2] * bn + local[:, 2:] * nn
    shaded /= np.linalg.norm(shaded, axis=1, keepdims=True)
    # Where the ray p + s·N̂ meets the cylinder x² + z² = 1, the normal is (x, 0, z).
    p = np.einsum("nk,nkj->nj", bary, low.rest.astype(np.float64)[corners])
    qa = nn[:, 0] ** 2 + nn[:, 2] ** 2
    qb = 2 * (p[:, 0] * nn[:, 0] + p[:, 2] * nn[:, 2])
    qc = p[:, 0] ** 2 + p[:, 2] ** 2 - 1
    s = (-qb + np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    hit = p + s[:, None] * nn
    expected = hit * [1, 0, 1]
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    inside = result.hit[rows, cols]
    return float(angles(shaded[inside], expected[inside]).max())


@pytest.mark.core
@pytest.mark.parametrize("frame", ["mikktspace", "thesis"])
def test_the_shader_reading_the_map_gets_the_sculpt_normal_back_on_a_curved_face(frame):
    """A coarse cylinder (4 facets, UVs jittered so its interpolated tangent frames are not
    orthonormal) baked against a fine one in either tangent frame: decoding the map the way
    face.frag does, in the same frame, gives the fine cylinder's normal where the ray meets
    it; decoded in the other frame (the renderer set to another frame than the bake), it
    does not — the baker bakes in the frame it is given."""
    low = cylinder(4, 1, uv_jitter=0.15)
    result = bake_normal_map(low, cylinder(240, 1), SIZE, max_distance=0.1,
                             tangent_frame=frame)
    assert result.hit_fraction > 0.99
    assert decoded_error(low, result, frame) < 0.2
    other = "thesis" if frame == "mikktspace" else "mikktspace"
    assert decoded_error(low, result, other) > 0.5  # (0.76°, against 0.08° in its own)


@pytest.mark.core
def test_texels_without_a_hit_take_the_normal_at_the_same_uv(high):
    far = FaceMesh(high.rest + np.float32([0, 0, 5]), high.triangles, high.uvs, high.weld)
    result = bake_normal_map(grid(2), far, SIZE, max_distance=0.1)
    assert not result.hit.any() and result.from_uv.all() and result.hit_fraction == 0.0
    assert angles(result.normals, analytic_normals(SIZE)).max() < 0.2


@pytest.mark.core
def test_charts_are_padded_and_the_rest_is_flat():
    half = grid(2, uv_scale=0.5)  # the face covers the lower-left quarter of the map
    tilted = grid(20, lambda x, y: 0.3 * x, uv_scale=0.5)
    result = bake_normal_map(half, tilted, SIZE, max_distance=0.5, padding=4)
    inside = result.image[SIZE - 1, 0]
    assert inside[0] < 100  # rising toward +u: normal toward −x
    q = SIZE // 2
    assert (result.image[q:, q:q + 4] == inside).all()  # four texels of padding
    assert (result.image[:q - 4] == (128, 128, 255)).all()
    assert (result.image[:, q + 4:] == (128, 128, 255)).all()


@pytest.mark.core
def test_another_uv_layout_is_refused_naming_the_file(high):
    other = FaceMesh(high.rest, high.triangles, high.uvs * 0.5, high.weld, source="sculpt.obj")
    with pytest.raises(MeshError, match="UV layout differs") as info:
        bake_normal_map(grid(2), other, SIZE, max_distance=0.1)
    assert "sculpt.obj" in str(info.value)
    with pytest.raises(MeshError, match="distance must be positive"):
        bake_normal_map(grid(2), high, SIZE, max_distance=0.0)


@pytest.mark.core
def test_progress_rises_to_one_and_cancel_stops(high):
    seen: list[float] = []
    bake_normal_map(grid(2), high, SIZE, max_distance=0.1, progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) > 3
    calls = []

    def cancel_soon() -> bool:
        calls.append(1)
        return len(calls) > 2

    with pytest.raises(BakeCancelled):
        bake_normal_map(grid(2), high, SIZE, max_distance=0.1, cancelled=cancel_soon)


# --------------------------------------------------------------------------------------------
# The Maps menu
# --------------------------------------------------------------------------------------------


@pytest.fixture
def sculpt_file(window, tmp_path):
    """The window's face with ridges across the forehead, saved as the high-polygon OBJ."""
    from studio.core.mesh.geometry import vertex_normals
    from studio.core.mesh.meshio import save_obj

    mesh = window.doc.project.mesh
    normals = vertex_normals(mesh.rest, mesh.welded_triangles)
    size = float(np.ptp(mesh.rest[:, 1]))
    ridges = 0.004 * size * np.sin(mesh.rest[:, 1] / size * 80)
    path = tmp_path / "sculpt.obj"
    save_obj(path, mesh, mesh.rest + normals * ridges[:, None].astype(np.float32))
    return path


def menu_action(window, text: str):
    bar = window.menuBar()
    maps = next(a.menu() for a in bar.actions() if a.text().replace("&", "") == "Maps")
    return next(a for a in maps.actions() if a.text() == text)


def test_bake_from_the_maps_menu_is_one_undo_step(window, qtbot, monkeypatch, sculpt_file):
    from PySide6.QtWidgets import QDialog

    from studio.core.wrinkles.textures import flat_normal_map
    from studio.widgets.maps.bake_tools import BakeDialog

    doc = window.doc
    textures = doc.project.textures
    textures.set_wrinkle_map("smile", flat_normal_map(512))  # a second map, baked into
    first = textures.normal_wrinkled
    assert first.shape[1] != 512

    def fill(dialog):
        dialog.mesh.edit.setText(str(sculpt_file))
        assert dialog.target.count() == len(textures.wrinkle_maps)
        assert dialog.map_size() == first.shape[1]  # the first map, at first
        dialog.target.setCurrentIndex(dialog.target.findText("smile"))
        assert dialog.map_size() == 512  # the resolution follows the chosen map
        return QDialog.DialogCode.Accepted

    monkeypatch.setattr(BakeDialog, "exec", fill)
    old = textures.wrinkle_maps["smile"]
    menu_action(window, "Bake Wrinkled Normal Map from High-Poly Mesh…").trigger()
    tools = window.bake_tools
    assert tools.busy and tools.progress.isVisible()
    qtbot.waitUntil(lambda: not tools.busy, timeout=120_000)
    new = textures.wrinkle_maps["smile"]
    assert new.shape == (512, 512, 3) and new is not old
    assert textures.normal_wrinkled is first
    assert doc.undo_stack.count() == 1
    assert doc.undo_stack.text(0) == "Bake wrinkled map “smile” from high-poly mesh"
    # The ridges show: rows of the map alternate between tilting up and down (green).
    green = new[:, :, 1].astype(int)
    assert green.max() - green.min() > 40
    assert "found the high-poly mesh" in window.statusBar().currentMessage()
    doc.undo_stack.undo()
    assert textures.wrinkle_maps["smile"] is old
    doc.undo_stack.redo()
    assert textures.wrinkle_maps["smile"] is new


def test_cancelling_the_bake_leaves_the_map(window, qtbot, monkeypatch, sculpt_file):
    from PySide6.QtWidgets import QPushButton

    import studio.widgets.maps.bake_tools as bake_tools

    release = threading.Event()
    real_load = bake_tools.load_mesh

    def slow_load(path):
        release.wait(30)  # until the test has pressed Cancel
        return real_load(path)

    monkeypatch.setattr(bake_tools, "load_mesh", slow_load)
    old = window.doc.project.textures.normal_wrinkled
    tools = window.bake_tools
    tools.start(sculpt_file, 512, 0.01)
    cancel = tools.progress.findChild(QPushButton)
    assert cancel.text() == "Cancel"
    cancel.click()
    release.set()
    qtbot.waitUntil(lambda: not tools.busy, timeout=60_000)
    assert window.doc.project.textures.normal_wrinkled is old
    assert window.doc.undo_stack.count() == 0
    assert "cancelled" in window.statusBar().currentMessage()


def test_a_sculpt_without_uvs_is_reported_by_name(window, qtbot, tmp_path, dialogs):
    bare = tmp_path / "no_uvs.obj"
    bare.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    tools = window.bake_tools
    tools.start(bare, 512, 0.01)
    qtbot.waitUntil(lambda: not tools.busy, timeout=60_000)
    assert len(dialogs) == 1 and "no_uvs.obj" in dialogs[0][1]
    assert "texture coordinates" in dialogs[0][1]
    assert window.doc.undo_stack.count() == 0


# --------------------------------------------------------------------------------------------
# The command line
# --------------------------------------------------------------------------------------------


@pytest.mark.core
def test_cli_bakes_into_the_project_and_a_png(tmp_path, capsys):
    from studio.cli import main
    from studio.core.files.images import load_rgb
    from studio.core.mesh.meshio import save_obj
    from studio.core.project.reader import load_project
    from studio.core.project.writer import save_project
    from studio.core.sample.synthetic import make_test_face

    project = make_test_face(561, texture_size=64, mask_size=32)
    save_project(project, tmp_path / "face.wrinkle")
    mesh = project.mesh
    save_obj(tmp_path / "sculpt.obj", mesh, mesh.rest * np.float32(1.001))
    name = project.textures.wrinkle_map_names[-1]
    assert main(["bake", str(tmp_path / "face.wrinkle"), "--high", str(tmp_path / "sculpt.obj"),
                 "--size", "64", "--map", name, "--png", str(tmp_path / "map.png"),
                 "-o", str(tmp_path / "baked.wrinkle")]) == 0
    assert f"wrinkled map '{name}' at 64²" in capsys.readouterr().out
    baked = load_project(tmp_path / "baked.wrinkle").textures.wrinkle_maps[name]
    assert baked.shape == (64, 64, 3)
    assert np.array_equal(baked, load_rgb(tmp_path / "map.png"))
    # A scaled copy of the face is nearly flat against it: the map is close to (128, 128, 255).
    assert np.abs(baked.astype(int) - (128, 128, 255)).mean() < 3

    code = main(["bake", str(tmp_path / "face.wrinkle"), "--high", str(tmp_path / "sculpt.obj"),
                 "--map", "nope", "--png", str(tmp_path / "x.png")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "no wrinkled map named 'nope'" in err
    flat = grid(3, uv_scale=0.3)  # a UV layout in one corner
    save_obj(tmp_path / "elsewhere.obj", flat)
    code = main(["bake", str(tmp_path / "face.wrinkle"), "--high",
                 str(tmp_path / "elsewhere.obj"), "--png", str(tmp_path / "x.png")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "elsewhere.obj" in err and "UV layout differs" in err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.core
def test_where_an_eye_overlaps_the_skin_in_uv_the_skin_is_baked(high):
    """An eye shell (a quad in front of the face, drawn after it, its UVs turned a quarter)
    covers the left half of the skin's UV square: with the skin's triangles named, the skin
    owns those texels and gets the sculpt's normals there as elsewhere; without, the eye takes
    them, in its own tangent frame."""
    face = grid(2)
    eye_rest = np.array([[0.0, 0.0, 0.3], [0.5, 0.0, 0.3], [0.5, 1.0, 0.3], [0.0, 1.0, 0.3]])
    eye_uvs = np.array([[0.5, 0.0], [0.5, 1.0], [0.0, 1.0], [0.0, 0.0]])  # turned: own frame
    low = FaceMesh(np.r_[face.rest, eye_rest], np.r_[face.triangles, [[4, 5, 6], [4, 6, 7]]],
                   np.r_[face.uvs, eye_uvs], np.arange(8))
    skin = np.array([True, True, False, False])
    expected = analytic_normals(SIZE)
    left = (slice(None), slice(2, SIZE // 2 - 2))
    baked = bake_normal_map(low, high, SIZE, max_distance=0.1, skin=skin)
    assert angles(baked.normals[left], expected[left]).max() < 0.5
    taken = bake_normal_map(low, high, SIZE, max_distance=0.1)
    assert angles(taken.normals[left], expected[left]).max() > 10.0


# --------------------------------------------------------------------------------------------
# UDIM heads: the face packed into an atlas, the sculpt in UDIM tiles
# --------------------------------------------------------------------------------------------

def two_tiles(n: int, height=None) -> FaceMesh:
    """Two unit squares side by side, x ∈ [0, 1] on tile 1001 and x ∈ [1, 2] on tile 1002
    (UV = (x, y)), each ``grid(n, height)`` of its own square (the same sculpt on each)."""
    a = grid(n, height)
    rest = np.r_[a.rest, a.rest + np.array([1.0, 0.0, 0.0])]
    uvs = np.r_[a.uvs, a.uvs + np.array([1.0, 0.0])]
    triangles = np.r_[a.triangles, a.triangles + n * n]
    return FaceMesh(rest, triangles, uvs, np.arange(2 * n * n), source="sculpt.obj")


def cell_normals(layout, tile: int, size: int) -> tuple[tuple[slice, slice], np.ndarray]:
    """The texels well inside ``tile``'s cell of a ``size``² atlas, and the sculpt's analytic
    normal at each (the tile's own square, as ``analytic_normals``)."""
    x0, y0, x1, y1 = layout.pixel_box(tile, (size, size))
    box = (slice(y0 + 2, y1 - 2), slice(x0 + 2, x1 - 2))
    rows, cols = np.mgrid[box]
    atlas = np.stack([(cols.ravel() + 0.5) / size, 1.0 - (rows.ravel() + 0.5) / size], 1)
    local = layout.from_atlas(atlas, np.full(len(atlas), layout.index(tile))) - [tile - 1001, 0]
    x, y = local[:, 0], local[:, 1]
    hx = A * 2 * np.pi * K * np.cos(2 * np.pi * K * x) * np.cos(4 * np.pi * y)
    hy = -A * 4 * np.pi * np.sin(2 * np.pi * K * x) * np.sin(4 * np.pi * y)
    n = np.stack([-hx, -hy, np.ones_like(hx)], -1)
    return box, (n / np.linalg.norm(n, axis=-1, keepdims=True)).reshape(*rows.shape, 3)


@pytest.mark.core
def test_a_udim_sculpt_bakes_into_the_face_s_atlas_cells():
    """The face's two tiles were packed into one atlas when it was imported; the sculpt comes
    in the same UDIM tiles. Its UVs go into the same cells, and every texel of both cells
    finds it, with the sculpt's normals; a tile the face lacks is refused by name."""
    from studio.core.files.errors import StudioError
    from studio.core.mesh.uv_tiles import pack_mesh
    from studio.core.wrinkles.bake import sculpt_for

    low, tiles = pack_mesh(two_tiles(2))
    high = two_tiles(241, sculpt)
    with pytest.raises(MeshError, match="UV layout differs"):  # before: the UDIM UVs as they came
        bake_normal_map(low, high, SIZE * 2, max_distance=0.1)
    result = bake_normal_map(low, sculpt_for(high, tiles), SIZE * 2, max_distance=0.1)
    assert result.hit_fraction > 0.999
    for tile in (1001, 1002):
        box, expected = cell_normals(tiles.layout, tile, SIZE * 2)
        assert angles(result.normals[box], expected).max() < 0.5

    stray = two_tiles(3)
    stray.uvs[len(stray.uvs) // 2:] += [1.0, 0.0]  # the second square on tile 1003
    with pytest.raises(StudioError, match=r"sculpt\.obj.*tile 1003, which the face does not "
                                          r"\(its tiles: 1001, 1002\)"):
        sculpt_for(stray, tiles)
    assert sculpt_for(high, None) is high  # a face on one tile takes the sculpt as it is


@pytest.mark.core
def test_cli_bakes_a_udim_sculpt_into_a_udim_head(tmp_path, capsys):
    from studio.cli import main
    from studio.core.formats.assemble import project_from_files
    from studio.core.mesh.meshio import save_obj
    from studio.core.project.writer import save_project

    save_obj(tmp_path / "head.obj", two_tiles(2))
    project = project_from_files(tmp_path / "head.obj")
    assert project.uv_tiles is not None and project.uv_tiles.layout.tiles == (1001, 1002)
    save_project(project, tmp_path / "head.wrinkle")
    save_obj(tmp_path / "sculpt.obj", two_tiles(121, sculpt))
    assert main(["bake", str(tmp_path / "head.wrinkle"), "--high", str(tmp_path / "sculpt.obj"),
                 "--size", "128", "--png", str(tmp_path / "map.png")]) == 0
    assert "100% of the face's texels found the high-polygon mesh" in capsys.readouterr().out
