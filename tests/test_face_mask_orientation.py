"""An ARKit face mask right side up (studio/core/setup/face_frame.py): a front-only face of
about 1,220 vertices, no UVs, no eyeballs and no eye sockets (the lids lie closed and flush, the
brow is flat, the mouth corners tuck in), in metres, Y up or Z up either way, with ARKit poses
(the inner brows rise, a brow is drawn down, the lids close, the jaw opens). Pits in such a
mask may pair up anywhere: its mouth corners made a pair of "eye sockets" below the nose, and
the anatomy's weak guess turned the face on its head against what every pose's motion said.
The same mask subdivided past 250,000 vertices must come out the same way."""

from __future__ import annotations

import time

import numpy as np
import pytest

from studio.core.sample.mesh import BROW_Y, EYE_X, EYE_Y, MOUTH_X, MOUTH_Y, blob
from studio.core.setup.face_frame import detect_face_frame
from tests.production_head import build_head

pytestmark = pytest.mark.core

MASK_VERTICES = 1220  # ARKit's ARFaceGeometry
# the sample's axes (x left, y up, z front) → the world's, as columns: where left, up, front go
UPS = {
    "+Y": np.eye(3),
    "+Z": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
    "-Z": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
}
POSES = ("browInnerUp", "browDown_L", "browDown_R", "mouthSmile_L", "mouthSmile_R",
         "jawOpen")


def _blink(rest: np.ndarray, x: np.ndarray, y: np.ndarray, side: float) -> np.ndarray:
    """The upper lid closing: the skin over one eye drawn down (sample units)."""
    out = rest.copy()
    out[:, 1] -= 0.05 * blob(x, y, side * EYE_X, EYE_Y + 0.04, 0.1, 0.05)
    return out


def arkit_mask(vertices: int = MASK_VERTICES) -> tuple[np.ndarray, np.ndarray,
                                                       dict[str, np.ndarray]]:
    """(rest, triangles, poses by ARKit name) in sample axes and metres: the production head's
    front cut out as a mask (forehead to chin, no back, no neck), its sockets and eyeballs
    filled flush, its brow ridge flattened and its mouth corners tucked in. The head's density
    is searched for the mask to have ``vertices`` vertices."""
    for head_vertices in range(2 * vertices, 4 * vertices, 7):
        head = build_head("m", vertices=head_vertices, up="y")
        skin = head.parts[0]
        x, y = head.face_xy[:, 0], head.face_xy[:, 1]
        keep = (skin.rest[:, 2] > 0.1) & (y > -0.75) & (y < 0.65)
        tris = skin.weld[skin.triangles]
        tris = tris[keep[tris].all(axis=1)]
        used = np.unique(tris)
        if len(used) >= vertices:
            break
    ax = np.abs(x)
    flush = (0.095 * blob(ax, y, EYE_X, EYE_Y + 0.01, 0.12, 0.085)  # the socket filled
             - 0.065 * blob(ax, y, EYE_X, EYE_Y, 0.085, 0.045)  # the eyeball's bulge gone
             - 0.012 * blob(ax, y, EYE_X, EYE_Y + 0.06, 0.085, 0.018)  # no lid fold
             - 0.045 * blob(ax, y, 0.20, BROW_Y, 0.17, 0.05)  # a flat brow
             - 0.04 * blob(ax, y, MOUTH_X, MOUTH_Y, 0.04, 0.03))  # corners tucked in
    shift = np.zeros_like(skin.rest)
    shift[:, 2] = flush
    rest = skin.rest + shift
    poses = {name: skin.poses[name] + shift for name in POSES}
    poses["eyeBlink_L"] = _blink(rest, x, y, 1.0)
    poses["eyeBlink_R"] = _blink(rest, x, y, -1.0)
    # trim to exactly ``vertices``: drop the highest forehead rows' vertices beyond the count
    order = used[np.argsort(-y[used], kind="stable")]
    drop = order[:len(used) - vertices]
    tris = tris[~np.isin(tris, drop).any(axis=1)]
    used = np.unique(tris)
    index = np.full(len(rest), -1)
    index[used] = np.arange(len(used))
    metres = 0.1  # a sample unit is 10 cm
    return (rest[used] * metres, index[tris],
            {name: p[used] * metres for name, p in poses.items()})


def subdivide(arrays: list[np.ndarray], triangles: np.ndarray
              ) -> tuple[list[np.ndarray], np.ndarray]:
    """One step of midpoint subdivision, vectorised: every edge gets its midpoint (in each of
    the position arrays: the rest and every pose alike), every triangle becomes four."""
    corners = [(0, 1), (1, 2), (2, 0)]
    edges = np.sort(np.concatenate([triangles[:, c] for c in corners]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    count = len(arrays[0])
    mid = (count + inverse.reshape(-1)).reshape(3, -1).T  # (F, 3): edges 01, 12, 20
    a, b, c = triangles.T
    ab, bc, ca = mid.T
    out = np.concatenate([np.stack(t, axis=1) for t in
                          ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    grown = [np.concatenate([p, (p[unique[:, 0]] + p[unique[:, 1]]) / 2.0]) for p in arrays]
    return grown, out


def frame_for(up: str, dense: bool = False):
    rest, tris, poses = arkit_mask()
    names = list(poses)
    arrays = [rest, *poses.values()]
    if dense:
        while len(arrays[0]) <= 250_000:
            arrays, tris = subdivide(arrays, tris)
    turn = UPS[up]
    arrays = [p @ turn.T for p in arrays]  # (sample axes → world axes)
    return (detect_face_frame(arrays[0], tris, arrays[1:], names), turn, len(arrays[0]))


def test_the_mask_is_what_arkit_gives():
    """1,220 vertices, open (a mask), front only: no back of the head to close it."""
    rest, tris, poses = arkit_mask()
    assert len(rest) == MASK_VERTICES and len(np.unique(tris)) == MASK_VERTICES
    assert set(poses) >= {"browInnerUp", "jawOpen", "eyeBlink_L"}


@pytest.mark.parametrize("up", UPS)
def test_an_arkit_mask_without_eyes_comes_out_right_side_up(up: str):
    """Y up, and Z up either way: up is the sample's up, front its front, and the report says
    the poses' motion decided, how sure, and that the pits taken for sockets were overruled.
    Red before: "up −Y (the eyes above the nose (eye sockets))", front +Z, upside down."""
    frame, turn, _ = frame_for(up)
    np.testing.assert_allclose(frame.up, turn @ [0.0, 1.0, 0.0], atol=1e-9, err_msg=frame.how)
    np.testing.assert_allclose(frame.front, turn @ [0.0, 0.0, 1.0], atol=1e-9,
                               err_msg=frame.how)
    np.testing.assert_allclose(frame.left, turn @ [1.0, 0.0, 0.0], atol=1e-9)
    assert f"up {up} (from the motion of browInnerUp" in frame.how
    assert "how sure of up: fairly sure" in frame.how or "how sure of up: sure" in frame.how
    assert "(eye sockets) say" in frame.how and "overruled" in frame.how


@pytest.mark.parametrize("up", ["+Y", "-Z"])
def test_the_mask_subdivided_past_250k_vertices_comes_out_the_same(up: str):
    """Four steps of midpoint subdivision (over 250,000 vertices, built vectorised): the same
    frame as the mask's own, the face's coordinates not mirrored top to bottom (the region
    names follow them). Red before: "up −Y (eye sockets)". The time is printed, not
    asserted (about 8 s alone, was 36 s)."""
    coarse, turn, _ = frame_for(up)
    start = time.perf_counter()
    dense, _, count = frame_for(up, dense=True)
    elapsed = time.perf_counter() - start
    assert count > 250_000
    np.testing.assert_allclose(dense.up, turn @ [0.0, 1.0, 0.0], atol=1e-9, err_msg=dense.how)
    np.testing.assert_allclose(dense.front, coarse.front, atol=1e-9, err_msg=dense.how)
    # the forehead is above the chin in the face's own coordinates
    forehead, chin = turn @ [0.0, 0.05, 0.03], turn @ [0.0, -0.06, 0.03]
    assert dense.to_face(forehead[None])[0, 1] > dense.to_face(chin[None])[0, 1]
    print(f"dense frame: {count} vertices in {elapsed:.1f} s")
