"""``wrinkle-studio bake``: a project's wrinkled normal map baked from a high-polygon mesh (the
sculpt with the wrinkles, on the face's UV layout), as in Maps ▸ Bake in the studio."""

from __future__ import annotations

import argparse
from pathlib import Path

from studio.core.files.errors import StudioError


def parse_resolution(text: str) -> int:
    try:
        size = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 16 <= size <= 8192:
        raise argparse.ArgumentTypeError(f"{size}: the map's size must be 16 to 8192")
    return size


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bake", help="bake a wrinkled normal map from a high-polygon mesh")
    p.add_argument("project", help="the .wrinkle project whose face the map is for")
    p.add_argument("--high", required=True, metavar="MESH",
                   help="high-polygon mesh with the wrinkles, on the face's UV layout")
    p.add_argument("--size", type=parse_resolution, metavar="N",
                   help="width and height of the map (default: the replaced map's)")
    p.add_argument("--distance", type=float, metavar="D",
                   help="how far rays go along the face's normals, in model units (default: 2%% "
                        "of the face's bounding-box diagonal)")
    p.add_argument("--map", metavar="NAME", help="wrinkled map to replace (default: the first)")
    p.add_argument("--png", metavar="OUT.png", help="also write the map as a PNG")
    p.add_argument("-o", "--output", metavar="OUT.wrinkle",
                   help="write the project with the new map here (default: only --png)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from studio.core.files.images import write_png
    from studio.core.files.safe_io import check_output
    from studio.core.mesh.meshio import load_mesh
    from studio.core.project.reader import load_project
    from studio.core.project.view_settings import saved_view
    from studio.core.project.writer import save_project
    from studio.core.wrinkles.bake import (
        bake_normal_map,
        check_hits,
        default_max_distance,
        sculpt_for,
    )

    if not args.png and not args.output:
        raise StudioError("say where the map goes: --png OUT.png and/or -o OUT.wrinkle")
    inputs = [args.project, args.high]
    if args.png:
        check_output(args.png, inputs, what="map")
    if args.output:
        check_output(args.output, inputs, what="project")
    if args.png and args.output and Path(args.png).absolute() == Path(args.output).absolute():
        raise StudioError("--png and -o name the same file", args.png)
    project = load_project(Path(args.project))
    textures = project.textures
    name = args.map or textures.wrinkle_map_names[0]
    if name not in textures.wrinkle_maps:
        raise StudioError(f"no wrinkled map named '{name}' (the project has: "
                          f"{', '.join(textures.wrinkle_map_names)})", args.project)
    current = textures.wrinkle_maps[name]
    distance = default_max_distance(project.mesh) if args.distance is None else args.distance
    high = sculpt_for(load_mesh(args.high), project.uv_tiles)
    result = bake_normal_map(project.mesh, high, args.size or current.shape[1],
                             distance, bits=16 if current.dtype.itemsize == 2 else 8,
                             tangent_frame=saved_view(project.view).tangent_frame,
                             skin=project.skin_triangles())
    check_hits(result, project.mesh, distance, args.high)
    textures.set_wrinkle_map(name, result.image)
    if args.png:
        write_png(Path(args.png), result.image)
    if args.output:
        save_project(project, Path(args.output))
    written = " and ".join(str(p) for p in (args.png, args.output) if p)
    print(f"wrote {written}: wrinkled map '{name}' at {result.image.shape[1]}², "
          f"{result.hit_fraction:.0%} of the face's texels found the high-polygon mesh")
    return 0
