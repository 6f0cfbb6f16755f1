#version 330 core
// Normal and tangent of one render vertex from the blended positions, captured by transform
// feedback straight into the face's vertex buffer (position, normal, tangent with handedness).
// A gather over the vertex's triangle corners (lists made once per mesh), the same sums as
// core/mesh/geometry.py (normals, the thesis's frame) and core/mesh/tangent_frames.py
// (FRAME_MIKKTSPACE): the normal over every corner of the welded position (area-weighted, so a
// UV seam never creases the shading), the tangent over the render vertex's own corners.

#include "deform_data.glsl"

const float TINY = 1.17549435e-38;  // float32's smallest normal number
const float TANGENT_KEEP = 1e-4;    // tangent_frames.TANGENT_KEEP

in int in_weld;             // the welded position of this render vertex
in ivec2 in_normal_corners; // first and count in u_corners: every corner at that position
in ivec2 in_tangent_corners;// first and count in u_corners: this render vertex's corners
in float in_side;           // MikkTSpace: the UV side most of its corner angle lies on

uniform sampler2D u_positions;  // xyz: this frame's welded positions
uniform isampler2D u_triangles; // xyz: the welded corners of each triangle
uniform isampler2D u_corners;   // r: a corner, 3 * triangle + which corner
uniform sampler2D u_uv_terms;   // per triangle: thesis a b c d | MikkTSpace a b side

out vec3 out_position;
out vec3 out_normal;
out vec4 out_tangent;

// The triangle of a corner: its corners' positions, first the corner itself's index in it.
void corner_triangle(int corner, out int triangle, out int slot, out vec3 p0, out vec3 p1,
                     out vec3 p2) {
    triangle = corner / 3;
    slot = corner - 3 * triangle;
    ivec4 welded = fetch(u_triangles, triangle);
    p0 = fetch(u_positions, welded.x).xyz;
    p1 = fetch(u_positions, welded.y).xyz;
    p2 = fetch(u_positions, welded.z).xyz;
}

// Some unit vector perpendicular to n: n x the axis of n's smallest component (the first of
// equals), as tangent_frames.perpendicular.
vec3 perpendicular(vec3 n) {
    vec3 a = abs(n);
    vec3 axis = (a.x <= a.y && a.x <= a.z) ? vec3(1.0, 0.0, 0.0)
              : (a.y <= a.z ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
    return normalize(cross(n, axis));
}

void main() {
    int triangle, slot;
    vec3 p0, p1, p2;
    vec3 n = vec3(0.0);
    for (int k = 0; k < in_normal_corners.y; ++k) {
        corner_triangle(fetch(u_corners, in_normal_corners.x + k).r, triangle, slot, p0, p1, p2);
        n += cross(p1 - p0, p2 - p0);
    }
    float n2 = dot(n, n);
    n = n2 <= TINY ? vec3(0.0, 0.0, 1.0) : n * inversesqrt(n2);

    vec3 t = vec3(0.0);
#ifdef FRAME_MIKKTSPACE
    for (int k = 0; k < in_tangent_corners.y; ++k) {
        corner_triangle(fetch(u_corners, in_tangent_corners.x + k).r, triangle, slot, p0, p1,
                        p2);
        vec4 uv = fetch(u_uv_terms, triangle);
        if (uv.z != in_side) continue;  // a corner on the other side of a UV mirror line
        vec3 e1 = p1 - p0, e2 = p2 - p0, e3 = p2 - p1;
        vec3 direction = uv.x * e1 + uv.y * e2;
        float length_ = length(direction);
        if (length_ <= TINY) continue;
        float area = length(cross(e1, e2));
        float along = slot == 0 ? dot(e1, e2) : slot == 1 ? -dot(e1, e3) : dot(e2, e3);
        float angle = (area > 0.0 || along != 0.0) ? atan(area, along) : 0.0;
        t += direction / length_ * angle;
    }
    vec3 ortho = t - dot(n, t) * n;
    float ortho_length = length(ortho);
    bool usable = ortho_length > TANGENT_KEEP * length(t) && ortho_length > TINY;
    out_tangent = usable ? vec4(ortho / ortho_length, in_side) : vec4(perpendicular(n), 1.0);
#else
    vec3 b = vec3(0.0);
    for (int k = 0; k < in_tangent_corners.y; ++k) {
        corner_triangle(fetch(u_corners, in_tangent_corners.x + k).r, triangle, slot, p0, p1,
                        p2);
        vec4 uv = fetch(u_uv_terms, triangle);
        vec3 e1 = p1 - p0, e2 = p2 - p0;
        t += uv.x * e1 + uv.y * e2;
        b += uv.z * e1 + uv.w * e2;
    }
    float handedness = dot(cross(n, t), b) < 0.0 ? -1.0 : 1.0;
    vec3 ortho = t - dot(n, t) * n;
    float ortho2 = dot(ortho, ortho);
    bool usable = ortho2 > max(dot(t, t) * TANGENT_KEEP * TANGENT_KEEP, TINY);
    out_tangent = usable ? vec4(ortho * inversesqrt(ortho2), handedness)
                         : vec4(perpendicular(n), 1.0);
#endif
    out_normal = n;
    out_position = fetch(u_positions, in_weld).xyz;
}
