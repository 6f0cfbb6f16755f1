#version 330 core
// Face vertex shader. The loader defines exactly one of TECHNIQUE_FLAT, TECHNIQUE_NONE,
// TECHNIQUE_T1, TECHNIQUE_T2, TECHNIQUE_STRAIN. Technique 2 is computed here,
// per vertex, and interpolated to the fragment shader as v_weights (one weight per wrinkled map);
// so is the strain mode's weight (skin compression, computed on the CPU with the normals), which
// reveals the first map.

in vec3 in_position;
in vec3 in_normal;
in vec4 in_tangent;   // xyz tangent, w handedness: bitangent = w * cross(N, T)
in vec2 in_uv;        // v up; images are stored top row first, so textures are read at (u, 1 - v)
in float in_skin;     // 1 where wrinkles may show, 0 on vertices marked not-face (eyes, teeth)

uniform mat4 u_view;
uniform mat4 u_proj;

out vec3 v_view_pos;
out vec3 v_normal;
out vec3 v_tangent;
out vec3 v_bitangent;
out vec2 v_texcoord;
out vec4 v_weights;   // per wrinkled map (techniques 2 and strain; technique 1 reads textures)
out float v_skin;

#ifdef TECHNIQUE_T2
in vec3 in_rest;      // neutral-pose position
in mat4 in_wdv;       // column s: wrinkle direction xyz and authored length (0 = unused slot)
in vec4 in_cone;      // cone half-angle (radians) of each slot
in vec4 in_slot_map;  // index of the wrinkled map each slot's area reveals
uniform float u_expression;   // k, the expression factor
uniform bool u_scale_free;    // divide |delta| by the authored length

// Strongest visibility over the vertex's slots, per wrinkled map (order-independent):
// w = clamp(|delta| * (1 - alpha / theta_max) * k, 0, 1) inside the cone, 0 outside.
vec4 wdv_visibility(vec3 delta) {
    float len = length(delta);
    vec4 w = vec4(0.0);
    if (len <= 0.0) return w;
    for (int s = 0; s < 4; ++s) {
        vec4 d = in_wdv[s];
        float theta = in_cone[s];
        if (d.w <= 0.0 || theta <= 0.0) continue;
        float alpha = acos(clamp(dot(delta, d.xyz) / len, -1.0, 1.0));
        if (alpha >= theta) continue;
        float magnitude = u_scale_free ? len / d.w : len;
        int m = int(in_slot_map[s]);
        w[m] = max(w[m], clamp(magnitude * (1.0 - alpha / theta) * u_expression, 0.0, 1.0));
    }
    return w;
}
#endif

#ifdef TECHNIQUE_STRAIN
in float in_strain;   // wrinkle weight from skin compression against the neutral pose
#endif

void main() {
    vec4 view_pos = u_view * vec4(in_position, 1.0);
    mat3 to_view = mat3(u_view);   // rigid camera: rotation only
    v_view_pos = view_pos.xyz;
    v_normal = to_view * in_normal;
    v_tangent = to_view * in_tangent.xyz;
    v_bitangent = in_tangent.w * cross(v_normal, v_tangent);
    v_texcoord = vec2(in_uv.x, 1.0 - in_uv.y);
    v_skin = in_skin;
#if defined(TECHNIQUE_T2)
    v_weights = wdv_visibility(in_position - in_rest);
#elif defined(TECHNIQUE_STRAIN)
    v_weights = vec4(in_strain, 0.0, 0.0, 0.0);
#else
    v_weights = vec4(0.0);
#endif
    gl_Position = u_proj * view_pos;
}
