#version 330 core
// Face fragment shader: normal-mapped Blinn-Phong, blending a neutral and a wrinkled shading by
// the wrinkle weight of the technique (SPEC §4, §5), plus the debug views.
#include "common.glsl"

in vec3 v_view_pos;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_bitangent;
in vec2 v_texcoord;
in float v_wrinkle;

uniform sampler2D u_diffuse;
uniform sampler2D u_normal_neutral;
uniform sampler2D u_normal_wrinkled;
uniform int u_view_mode;    // 0 shaded, 1 wrinkle heat map, 2 normals, 3 UV checker

#ifdef TECHNIQUE_T1
uniform sampler2DArray u_masks;     // one layer per influence area; the layer count is read here
uniform sampler2D u_activations;    // 1 x N, R32F: the activation vector

float wrinkle_weight() {
    int areas = textureSize(u_masks, 0).z;
    float s = 0.0;
    for (int i = 0; i < areas; ++i) {
        float a = texelFetch(u_activations, ivec2(i, 0), 0).r;
        if (a > 0.0) s += texture(u_masks, vec3(v_texcoord, float(i))).r * a;
    }
    return clamp(s, 0.0, 1.0);
}
#else
float wrinkle_weight() { return v_wrinkle; }
#endif

out vec4 frag_colour;

vec3 heat(float t) {
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0),
                      1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

void main() {
    vec3 n_geo = normalize(v_normal);
    vec3 view_dir = normalize(-v_view_pos);
    float s = wrinkle_weight();
#ifdef TECHNIQUE_FLAT
    vec3 colour = shade(vec3(0.62), n_geo, view_dir);
    vec3 n = n_geo;
#else
    mat3 tbn = mat3(normalize(v_tangent), normalize(v_bitangent), n_geo);
    vec2 dx = dFdx(v_texcoord), dy = dFdy(v_texcoord);   // outside the branch: valid gradients
    vec3 albedo = srgb_to_linear(texture(u_diffuse, v_texcoord).rgb);
    vec3 n = normalize(tbn * decode_normal(texture(u_normal_neutral, v_texcoord).rgb));
    vec3 colour = shade(albedo, n, view_dir);
    if (s > 0.0) {
        vec3 n_w = normalize(tbn * decode_normal(
            textureGrad(u_normal_wrinkled, v_texcoord, dx, dy).rgb));
        colour = mix(colour, shade(albedo, n_w, view_dir), s);   // the thesis's colour blend
        n = normalize(mix(n, n_w, s));
    }
#endif
    if (u_view_mode == 1) {
        colour = mix(srgb_to_linear(heat(s)), colour * 0.3, 0.35);
    } else if (u_view_mode == 2) {
        colour = srgb_to_linear(n * 0.5 + 0.5);
    } else if (u_view_mode == 3) {
        vec2 cell = floor(v_texcoord * 16.0);
        float check = mod(cell.x + cell.y, 2.0);
        vec3 base = mix(vec3(0.9, 0.9, 0.9), vec3(0.25, 0.45, 0.85), check);
        colour = srgb_to_linear(base) * (0.3 + max(dot(n_geo, normalize(u_light_dir)), 0.0));
    }
    frag_colour = vec4(linear_to_srgb(colour), 1.0);
}
