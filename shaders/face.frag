#version 330 core
// Face fragment shader: normal-mapped Blinn-Phong, blending a neutral and a wrinkled shading by
// the wrinkle weight of the technique (SPEC §4, §5), plus the debug views.
// Defines: TECHNIQUE_{FLAT,NONE,T1,T2}; T1_DIRECT (loop over every mask layer, the thesis's
// form, instead of the composed weight texture); BLEND_NORMALS (blend the two normals and light
// once, instead of the thesis's blend of two shaded colours).
#include "common.glsl"

in vec3 v_view_pos;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_bitangent;
in vec2 v_texcoord;
in float v_wrinkle;

uniform sampler2D u_diffuse;
uniform sampler2D u_normals;   // rg: neutral map's xy, ba: wrinkled map's xy (z rebuilt)
uniform int u_view_mode;       // 0 shaded, 1 wrinkle heat map, 2 normals, 3 UV checker

#if defined(TECHNIQUE_T1) && defined(T1_DIRECT)
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
#elif defined(TECHNIQUE_T1)
uniform sampler2D u_t1_weight;      // Σ mask·activation, composed when the activations change

float wrinkle_weight() { return texture(u_t1_weight, v_texcoord).r; }
#else
float wrinkle_weight() { return v_wrinkle; }
#endif

out vec4 frag_colour;

vec3 unpack_normal(vec2 xy) {
    vec2 n = xy * 2.0 - 1.0;
    return vec3(n, sqrt(max(1.0 - dot(n, n), 0.0)));
}

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
    vec3 albedo = srgb_to_linear(texture(u_diffuse, v_texcoord).rgb);
    vec4 normals = texture(u_normals, v_texcoord);
    vec3 n = normalize(tbn * unpack_normal(normals.xy));
#ifdef BLEND_NORMALS
    if (s > 0.0) n = normalize(mix(n, normalize(tbn * unpack_normal(normals.zw)), s));
    vec3 colour = shade(albedo, n, view_dir);
#else
    vec3 colour = shade(albedo, n, view_dir);
    if (s > 0.0) {
        vec3 n_w = normalize(tbn * unpack_normal(normals.zw));
        colour = mix(colour, shade(albedo, n_w, view_dir), s);   // the thesis's colour blend
        n = normalize(mix(n, n_w, s));
    }
#endif
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
