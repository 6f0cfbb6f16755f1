"""Which OpenGL the studio draws with: the highest core context the driver offers, and how it
is named to the user (features beyond 3.3, such as tessellation, are enabled by it)."""

from __future__ import annotations

import moderngl

from studio.core.files.errors import RenderError

#: Core-profile versions asked for, highest first. NVIDIA's drivers answer exactly the version
#: asked for (3.3 when asked for 3.3, although they offer 4.6), Mesa the highest it has; so the
#: highest is asked for first, and each lower one in turn where the driver refuses it.
GL_VERSIONS = (460, 450, 440, 430, 420, 410, 400, 330)


def create_standalone_context() -> moderngl.Context:
    """The highest OpenGL core context (4.6 down to 3.3) the driver offers, with no display
    (EGL; Mesa's llvmpipe on a machine without GPU)."""
    errors = []
    for kwargs in ({"backend": "egl"}, {}):
        refused: Exception | None = None
        for version in GL_VERSIONS:
            try:
                return moderngl.create_standalone_context(require=version, **kwargs)
            except Exception as exc:  # the GL loaders raise plain Exception subclasses
                refused = exc
        text = str(refused).strip()
        errors.append(text.splitlines()[0] if text else repr(refused))
    raise RenderError("cannot create an OpenGL 3.3 context without a display "
                      f"(is Mesa's EGL installed? libegl1 libegl-mesa0 libgl1-mesa-dri): "
                      f"{'; '.join(errors)}")


def gl_version(ctx: moderngl.Context) -> str:
    """``"4.5"``: the OpenGL version of a context, as features are gated on it."""
    return f"{ctx.version_code // 100}.{ctx.version_code % 100 // 10}"


def describe_gl(ctx: moderngl.Context) -> str:
    """One line naming the OpenGL in use: version, renderer and the driver's own version text
    (what ``bench`` prints first, and Help ▸ About and the status bar show)."""
    info = ctx.info
    return (f"OpenGL {gl_version(ctx)} core, {info.get('GL_RENDERER', '?')} "
            f"({info.get('GL_VERSION', '?')})")


def highest_gl_version() -> tuple[int, int]:
    """The highest core version a context of this driver gets, found with a throwaway
    standalone context; (3, 3) where none can be made (the viewport then says why)."""
    try:
        ctx = create_standalone_context()
    except RenderError:
        return (3, 3)
    code = ctx.version_code
    ctx.release()
    return (code // 100, code % 100 // 10)


#: Words in GL_RENDERER that name a renderer drawing on the CPU (Mesa's, Microsoft's, VMware's
#: on a host without 3-D, Google's SwiftShader): virtual machines and remote desktops.
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software rasterizer",
                      "basic render", "apple software renderer", "swiftshader")

#: Anisotropic filtering of the face maps on a GPU (samples along the longer axis of a pixel's
#: footprint in the texture: sharp maps on surfaces seen at a slant).
ANISOTROPY = 8.0


def is_software_name(renderer: str) -> bool:
    """Whether a GL_RENDERER string names a renderer that draws on the CPU."""
    renderer = renderer.lower()
    return any(word in renderer for word in SOFTWARE_RENDERERS)


def is_software(ctx: moderngl.Context) -> bool:
    """Whether the context draws on the CPU (vertex shaders on the calling thread, pixels
    on a few cores): reduced resolution while moving, and numpy deformation, pay there."""
    return is_software_name(str(ctx.info.get("GL_RENDERER", "")))


def map_anisotropy(renderer: str) -> float:
    """Anisotropic filtering for the face maps on the renderer GL_RENDERER names: none (1,
    trilinear) on a software renderer. Mesa's (llvmpipe, softpipe) filters anisotropically by
    walking every texel of the pixel's footprint ellipse (Heckbert's EWA), whatever the maximum
    anisotropy asked for; a sliver triangle (a few hundredths of a pixel, as a posed face has
    somewhere at most angles) has a nearly flat ellipse thousands of texels long, and one such
    pixel took 3.5 s of a frame of the ICT head (issue #28). Trilinear costs the same on every
    triangle."""
    return 1.0 if is_software_name(renderer) else ANISOTROPY
