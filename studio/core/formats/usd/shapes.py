"""A USD mesh's blend shapes (``UsdSkelBlendShape``) as sparse offsets, in-betweens included.

The mesh names its shapes in ``skel:blendShapes`` (the names an animation drives, ARKit's
``jawOpen``…) and points at their prims through ``skel:blendShapeTargets``, in the same order.
Each shape holds ``offsets`` of the points ``pointIndices`` lists (all of them, in order, when
it lists none). An in-between (``inbetweens:NAME``, at a ``weight`` between 0 and 1) is the
face part of the way there, a shape of its own that a straight line to the full shape misses (a
lid half closed, bulging): the studio's key poses are straight lines, so each in-between is a
key pose of its own, named "SHAPE at WEIGHT".

``shape_plan`` names every target before any offset is read, so the caller can check its
budgets on what the file declares; ``read_shape`` then reads one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from studio.core.files.errors import MeshError

Array = np.ndarray


@dataclass(frozen=True)
class Target:
    """One key pose a blend shape gives: the shape itself, or one of its in-betweens."""

    name: str
    shape: object  # UsdSkel.BlendShape
    inbetween: object | None  # UsdSkel.InbetweenShape, None for the shape at full weight


def shape_plan(prim, path: object) -> list[Target]:
    """Every key pose the mesh's blend shapes give, in the file's order, each shape followed by
    its in-betweens (by weight); nothing is read but names and weights."""
    from pxr import UsdSkel

    binding = UsdSkel.BindingAPI(prim)
    targets = binding.GetBlendShapeTargetsRel().GetTargets()
    if not targets:
        return []
    names = binding.GetBlendShapesAttr().Get()
    names = [str(n) for n in names] if names is not None else [t.name for t in targets]
    where = f"mesh {prim.GetPath()}"
    if len(names) != len(targets):
        raise MeshError(f"{where} names {len(names)} blend shapes (skel:blendShapes) but "
                        f"points at {len(targets)} (skel:blendShapeTargets)", path)
    out = []
    for name, target in zip(names, targets, strict=True):
        shape = UsdSkel.BlendShape(prim.GetStage().GetPrimAtPath(target))
        if not shape:
            raise MeshError(f"{where}'s blend shape '{name}' points at {target}, which is "
                            "not a BlendShape", path)
        out.append(Target(name, shape, None))
        between = []
        for inbetween in shape.GetInbetweens():
            weight = inbetween.GetWeight()
            if weight is None or not np.isfinite(weight):
                raise MeshError(f"{where}'s blend shape '{name}' has an in-between without a "
                                f"weight ({inbetween.GetAttr().GetName()})", path)
            between.append((float(weight), inbetween))
        out += [Target(f"{name} at {w:g}", shape, ib)
                for w, ib in sorted(between, key=lambda pair: pair[0])]
    return out


def read_shape(target: Target, n_points: int, where: str, path: object) -> tuple[Array, Array]:
    """(the points it moves, (K, 3) float64 offsets of them, in the mesh's own space)."""
    shape = target.shape
    offsets = (shape.GetOffsetsAttr().Get() if target.inbetween is None
               else target.inbetween.GetOffsets())
    offsets = np.asarray(offsets if offsets is not None else [], np.float64).reshape(-1, 3)
    indices = shape.GetPointIndicesAttr().Get()
    what = f"{where}'s blend shape '{target.name}'"
    if indices is None:
        if len(offsets) != n_points:
            raise MeshError(f"{what} has {len(offsets)} offsets and no pointIndices, the mesh "
                            f"{n_points} points", path)
        indices = np.arange(n_points)
    indices = np.asarray(indices, np.int64).reshape(-1)
    if len(indices) != len(offsets):
        raise MeshError(f"{what} has {len(offsets)} offsets for {len(indices)} pointIndices",
                        path)
    outside = indices[(indices < 0) | (indices >= n_points)]
    if len(outside):
        raise MeshError(f"{what} moves point {int(outside[0])}: the mesh has {n_points}",
                        path)
    if not np.isfinite(offsets).all():
        raise MeshError(f"{what} has a non-finite offset (NaN or infinity)", path)
    return indices, offsets
