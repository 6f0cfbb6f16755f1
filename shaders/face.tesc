#version 400 core
// Face tessellation control, relief "displace": wrinkles in silhouette.
// Patches are the mesh's triangles. Each edge is split into segments about u_tess_pixels long on
// screen (the edge's bounding sphere projected at its distance, so an edge seen end-on at the
// silhouette is refined as finely as one seen face-on), up to u_tess_max; the cost follows the
// face's size on screen. An edge along which no wrinkle can show stays whole: its level depends
// only on its two ends (and, for technique 1, the weight texture at its ends and middle), so the
// two triangles sharing it agree and no cracks open; so does an edge facing well away from the
// eye. Triangles wholly outside the view (with a margin for the displacement) are dropped.
#include "relief.glsl"

layout(vertices = 3) out;

in vec3 v_view_pos[];
in vec3 v_normal[];
in vec3 v_tangent[];
in vec3 v_bitangent[];
in vec2 v_texcoord[];
in vec4 v_weights[];
in float v_skin[];

out vec3 tc_view_pos[];
out vec3 tc_normal[];
out vec3 tc_tangent[];
out vec3 tc_bitangent[];
out vec2 tc_texcoord[];
out vec4 tc_weights[];
out float tc_skin[];

uniform mat4 u_proj;
uniform vec2 u_viewport_size;   // pixels
uniform float u_tess_pixels;    // wanted screen length of one segment, pixels
uniform float u_tess_max;       // most segments per edge
uniform float u_relief_depth;   // model units: the largest displacement

bool wrinkled(int i) {
    return any(greaterThan(surface_weights(v_texcoord[i], v_weights[i], v_skin[i]), vec4(0.0)));
}

bool edge_wrinkled(int a, int b) {
    bool ends = wrinkled(a) || wrinkled(b);
#ifdef TECHNIQUE_T1
    // the weight texture may rise between the ends; skin is interpolated along the edge
    vec2 mid = 0.5 * (v_texcoord[a] + v_texcoord[b]);
    ends = ends || any(greaterThan(textureLod(u_t1_weight, mid, 0.0) * (v_skin[a] + v_skin[b]),
                                   vec4(0.0)));
#endif
    return ends;
}

// An edge whose two ends both face well away from the eye is hidden behind the face (or seen
// edge-on at most): it is not refined.
bool edge_hidden(int a, int b) {
    return dot(normalize(v_normal[a]), normalize(v_view_pos[a])) > 0.3
        && dot(normalize(v_normal[b]), normalize(v_view_pos[b])) > 0.3;
}

float edge_level(int a, int b) {
    if (!edge_wrinkled(a, b) || edge_hidden(a, b)) return 1.0;
    vec3 centre = 0.5 * (v_view_pos[a] + v_view_pos[b]);
    float diameter = distance(v_view_pos[a], v_view_pos[b]);
    float depth = max(-centre.z, 1e-4);
    float pixels = diameter * u_proj[1][1] * 0.5 * u_viewport_size.y / depth;
    return clamp(pixels / u_tess_pixels, 1.0, u_tess_max);
}

bool outside_view() {
    vec4 c[3];
    for (int i = 0; i < 3; ++i) {
        c[i] = u_proj * vec4(v_view_pos[i], 1.0);
    }
    float margin = 2.0 * u_relief_depth * max(u_proj[0][0], u_proj[1][1]);
    for (int axis = 0; axis < 2; ++axis) {
        if (c[0][axis] > c[0].w + margin && c[1][axis] > c[1].w + margin
            && c[2][axis] > c[2].w + margin) return true;
        if (c[0][axis] < -c[0].w - margin && c[1][axis] < -c[1].w - margin
            && c[2][axis] < -c[2].w - margin) return true;
    }
    return false;
}

void main() {
#define ID gl_InvocationID
    tc_view_pos[ID] = v_view_pos[ID];
    tc_normal[ID] = v_normal[ID];
    tc_tangent[ID] = v_tangent[ID];
    tc_bitangent[ID] = v_bitangent[ID];
    tc_texcoord[ID] = v_texcoord[ID];
    tc_weights[ID] = v_weights[ID];
    tc_skin[ID] = v_skin[ID];
    if (ID != 0) return;   // the levels: once per patch
    if (outside_view()) {
        gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = 0.0;
        gl_TessLevelInner[0] = 0.0;
        return;
    }
    // outer level k belongs to the edge opposite vertex k
    float e0 = edge_level(1, 2), e1 = edge_level(2, 0), e2 = edge_level(0, 1);
    gl_TessLevelOuter[0] = e0;
    gl_TessLevelOuter[1] = e1;
    gl_TessLevelOuter[2] = e2;
    gl_TessLevelInner[0] = max(max(e0, e1), e2);
}
