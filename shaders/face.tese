#version 400 core
// Face tessellation evaluation, relief "displace": every varying of face.frag is
// interpolated across the patch, and the point moves along its normal by
// u_relief_depth * sum over maps m of w_m * h_m, with w the wrinkle weights the fragment shader
// shades with (scaled to sum at most 1, as there) and h_m map m's wrinkle height (0 = none,
// valleys negative, |h| <= 1; studio/core/relief.py). Shading is unchanged: the same normals
// and normal maps, so only the silhouette and the occlusion gain the wrinkles.
#include "relief.glsl"

layout(triangles, fractional_odd_spacing, ccw) in;

in vec3 tc_view_pos[];
in vec3 tc_normal[];
in vec3 tc_tangent[];
in vec3 tc_bitangent[];
in vec2 tc_texcoord[];
in vec4 tc_weights[];
in float tc_skin[];

// precise: no fused or reordered arithmetic, so that a point on an edge shared by two patches
// (its tessellation coordinates swapped) lands on exactly the same position from both, and no
// pinholes open between them
precise out vec3 v_view_pos;
precise out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_bitangent;
precise out vec2 v_texcoord;
precise out vec4 v_weights;
precise out float v_skin;
precise gl_Position;

uniform mat4 u_proj;
uniform sampler2D u_relief;     // rgba: wrinkle height of wrinkled maps 0..3
uniform float u_relief_depth;   // model units
uniform float u_relief_texels_per_unit;   // height-map texels per model unit (mesh average)
uniform vec2 u_viewport_size;   // pixels
uniform float u_tess_pixels;    // the screen length of a segment (face.tesc)

#define LERP3(a) (gl_TessCoord.x * a[0] + gl_TessCoord.y * a[1] + gl_TessCoord.z * a[2])

void main() {
    v_view_pos = LERP3(tc_view_pos);
    v_normal = LERP3(tc_normal);
    v_tangent = LERP3(tc_tangent);
    v_bitangent = LERP3(tc_bitangent);
    v_texcoord = LERP3(tc_texcoord);
    v_weights = LERP3(tc_weights);
    v_skin = LERP3(tc_skin);
    vec4 w = surface_weights(v_texcoord, v_weights, v_skin);
    float total = w.x + w.y + w.z + w.w;
    if (total > 0.0) {
        w /= max(total, 1.0);
        // the heights filtered to about the segments' size (a segment of u_tess_pixels on
        // screen spans this many texels here; one level finer keeps shallow notches in the
        // outline). A function of the point alone, so a point on an edge shared by two patches
        // samples the same height from both (a per-patch level would open cracks).
        float unit_pixels = u_proj[1][1] * 0.5 * u_viewport_size.y / max(-v_view_pos.z, 1e-4);
        float lod = log2(max(u_tess_pixels * u_relief_texels_per_unit / unit_pixels, 1.0)) - 1.0;
        float height = dot(w, textureLod(u_relief, v_texcoord, lod));
        v_view_pos += normalize(v_normal) * (u_relief_depth * height);
    }
    gl_Position = u_proj * vec4(v_view_pos, 1.0);
}
