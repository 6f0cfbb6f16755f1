#version 330 core
// Face fragment shader: normal-mapped Blinn-Phong, blending the neutral shading with up to four
// wrinkled shadings by the per-map wrinkle weights of the technique, plus the
// debug views.
// Defines: TECHNIQUE_{FLAT,NONE,T1,T2,STRAIN}; SKIN (the skin look of skin.glsl, lit by a rig,
// instead of common.glsl's clay); SKIN_TONE (with SKIN, for a face whose wrinkled maps have
// colour and cavity maps: blended by the same weights, the colour tints the albedo and the
// cavity darkens diffuse, ambient and specular; studio/core/wrinkles/skin_tone.py); T1_DIRECT (loop over every mask layer, the
// thesis's form, instead of the composed weight texture); BLEND_NORMALS (blend the normals and
// light once, instead of the thesis's blend of shaded colours); RELIEF_PARALLAX (parallax
// occlusion mapping of the wrinkles, below); RELIEF_DISPLACE needs nothing here (the
// tessellation stages move the surface, face.tesc and face.tese).
//
// Several wrinkled maps, order-independent: with weights w_m (one per map, each in [0, 1]) and
// W = sum of w_m, weights are scaled by 1 / W where W > 1; the result is
// (1 - W) * neutral + sum of w_m * wrinkled_m — a weighted average, the same whatever order the
// areas or maps come in. With one map it is exactly the thesis's mix(neutral, wrinkled, w).
#include "common.glsl"

in vec3 v_view_pos;
in vec3 v_normal;
in vec3 v_tangent;
in vec3 v_bitangent;
in vec2 v_texcoord;
in vec4 v_weights;
in float v_skin;

uniform sampler2D u_diffuse;
uniform sampler2D u_normals;          // rg: neutral map's xy, ba: first wrinkled map's xy
#ifndef WRINKLE_MAPS
#define WRINKLE_MAPS 4   // the face's number of wrinkled maps: no code for maps it lacks
#endif
uniform sampler2DArray u_more_maps;   // rg: xy of wrinkled maps 1, 2, 3 (layer = map - 1)
uniform int u_view_mode;  // 0 shaded, 1 heat of the weight, 2 normals, 3 UV checker, 4 heat of
                          // what shows: the weight times |wrinkled - neutral| over SHOWS_FULL
// |wrinkled - neutral| of unit normals at which the heat of what shows is hot (a furrow's wall,
// about 23 degrees; studio/core/wrinkles/shading.py holds the same number)
const float SHOWS_FULL = 0.4;

#if defined(TECHNIQUE_T1) && defined(T1_DIRECT)
uniform sampler2DArray u_masks;     // one layer per influence area; the layer count is read here
uniform sampler2D u_activations;    // 1 x N, RG32F: activation, index of the area's map

vec4 wrinkle_weights() {
    int areas = textureSize(u_masks, 0).z;
    vec4 s = vec4(0.0);
    for (int i = 0; i < areas; ++i) {
        vec2 a = texelFetch(u_activations, ivec2(i, 0), 0).rg;
        if (a.x > 0.0) s[int(a.y)] += texture(u_masks, vec3(v_texcoord, float(i))).r * a.x;
    }
    return clamp(s, 0.0, 1.0);
}
#elif defined(TECHNIQUE_T1)
uniform sampler2D u_t1_weight;      // per map: sum of mask * activation, composed on change

vec4 wrinkle_weights() { return texture(u_t1_weight, v_texcoord); }
#else
vec4 wrinkle_weights() { return v_weights; }
#endif

out vec4 frag_colour;

// The light a normal receives, added with a weight (the blends average it), and the colour it
// gives an albedo: the skin look's (skin.glsl) or clay's (common.glsl).
#ifdef SKIN
#include "skin.glsl"
void add_light(inout vec3 dif, inout vec3 spe, vec3 n, vec3 view_dir, float weight) {
    vec3 d, s;
    skin_receive(n, view_dir, d, s);
    dif += weight * d;
    spe += weight * s;
}
vec3 finish(vec3 albedo, vec3 dif, vec3 spe) {
    return skin_finish(albedo, dif, spe);
}
#else
void add_light(inout vec3 dif, inout vec3 spe, vec3 n, vec3 view_dir, float weight) {
    vec2 r = light(n, view_dir);
    dif += weight * r.x;
    spe += weight * r.y;
}
vec3 finish(vec3 albedo, vec3 dif, vec3 spe) {
    return albedo * (u_ambient + dif) + spe;
}
#endif

#ifdef SKIN_TONE
uniform sampler2DArray u_tone;   // layer m: rgb wrinkled map m's colour, a its cavity

// (tint, light kept): the neutral (no change) and each map's tone, blended by the weights
vec4 blended_tone(vec4 w, float total, vec2 uv) {
    vec4 tone = vec4(1.0 - total);
    for (int m = 0; m < WRINKLE_MAPS; ++m) {
        if (w[m] > 0.0) {
            vec4 texel = texture(u_tone, vec3(uv, float(m)));
            tone += w[m] * vec4(texel.rgb * (255.0 / 128.0), texel.a);
        }
    }
    return tone;
}
#endif

vec3 unpack_normal(vec2 xy) {
    vec2 n = xy * 2.0 - 1.0;
    return vec3(n, sqrt(max(1.0 - dot(n, n), 0.0)));
}

// Tangent-space normal of wrinkled map m (0 comes with the neutral map's fetch).
vec3 wrinkled_normal(int m, vec4 normals, vec2 uv) {
    if (m == 0) return unpack_normal(normals.zw);
    return unpack_normal(texture(u_more_maps, vec3(uv, float(m - 1))).xy);
}

#ifdef RELIEF_PARALLAX
// Parallax occlusion mapping (for GL 3.3 or a low budget). The surface is taken to lie
// at height H(uv) = u_relief_depth * sum of w_m * h_m (model units; h from studio/core/relief.py,
// |h| <= 1, valleys negative); the view ray is marched down through the height range
// [-depth * W, depth * W] in a handful of steps (more at grazing angles) until it passes under
// H, and the crossing is refined linearly. Only wrinkled pixels (W > 0) come here.
uniform sampler2D u_relief;      // rgba: wrinkle height of wrinkled maps 0..3
uniform float u_relief_depth;    // model units
uniform float u_uv_per_unit;     // texcoord units per model unit on the surface (mesh average)

vec2 parallax_texcoord(vec2 uv, vec4 w, float total, mat3 tbn, vec3 view_dir, vec2 dx,
                       vec2 dy) {
    vec3 v = view_dir * tbn;   // tangent space: x along +u, y along +v, z along the normal
    v.z = max(v.z, 0.2);       // limit the offset at grazing angles
    // texcoord shift per model unit of height; texcoord y runs down the image (1 - v)
    vec2 shift = vec2(v.x, -v.y) / v.z * u_uv_per_unit;
    int steps = int(mix(6.0, 16.0, 1.0 - v.z));
    float top = u_relief_depth * total;
    float dz = 2.0 * top / float(steps);
    float z = top;
    float above = top - u_relief_depth * dot(w, textureGrad(u_relief, uv + shift * z, dx, dy));
    for (int i = 1; i <= steps; ++i) {
        float next = z - dz;
        float gap = next - u_relief_depth * dot(w, textureGrad(u_relief, uv + shift * next, dx,
                                                                 dy));
        if (gap <= 0.0) {   // the ray went under the surface between z and next
            return uv + shift * (z - dz * above / (above - gap));
        }
        z = next;
        above = gap;
    }
    return uv + shift * z;
}
#endif

vec3 heat(float t) {
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0),
                      1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

void main() {
    vec3 n_geo = normalize(v_normal);
    vec3 view_dir = normalize(-v_view_pos);
    vec4 w = wrinkle_weights() * v_skin;
    float total = w.x + w.y + w.z + w.w;
    if (total > 1.0) {
        w /= total;
        total = 1.0;
    }
    vec2 uv = v_texcoord;
    float shows = 0.0;   // sum of w_m * |wrinkled_m - neutral|: what the weights change
    vec3 dif = vec3(0.0), spe = vec3(0.0);
#ifdef TECHNIQUE_FLAT
    add_light(dif, spe, n_geo, view_dir, 1.0);
    vec3 colour = finish(vec3(0.62), dif, spe);
    vec3 n = n_geo;
#else
    mat3 tbn = mat3(normalize(v_tangent), normalize(v_bitangent), n_geo);
#ifdef RELIEF_PARALLAX
    vec2 uv_dx = dFdx(uv), uv_dy = dFdy(uv);   // before any branch: derivatives need all lanes
    if (total > 0.0) uv = parallax_texcoord(uv, w, total, tbn, view_dir, uv_dx, uv_dy);
#endif
    vec3 albedo = srgb_to_linear(texture(u_diffuse, uv).rgb);
#ifdef SKIN_TONE
    vec4 tone = blended_tone(w, total, uv);
    albedo *= tone.rgb;
#endif
    vec4 normals = texture(u_normals, uv);
    vec3 t_neutral = unpack_normal(normals.xy);
    vec3 n_neutral = normalize(tbn * t_neutral);
    vec3 n_sum = n_neutral * (1.0 - total);
#ifdef BLEND_NORMALS
    for (int m = 0; m < WRINKLE_MAPS; ++m) {
        if (w[m] > 0.0) {
            vec3 t_m = wrinkled_normal(m, normals, uv);
            n_sum += w[m] * normalize(tbn * t_m);
            shows += w[m] * length(t_m - t_neutral);
        }
    }
    vec3 n = normalize(n_sum);
    add_light(dif, spe, n, view_dir, 1.0);
    vec3 colour = finish(albedo, dif, spe);
#else
    // the thesis's blend of shaded colours, as the same blend of the light each normal receives
    // (common.glsl: the weights sum to 1, so the ambient term is whole)
    add_light(dif, spe, n_neutral, view_dir, 1.0 - total);
    for (int m = 0; m < WRINKLE_MAPS; ++m) {
        if (w[m] > 0.0) {
            vec3 t_m = wrinkled_normal(m, normals, uv);
            vec3 n_m = normalize(tbn * t_m);
            add_light(dif, spe, n_m, view_dir, w[m]);
            n_sum += w[m] * n_m;
            shows += w[m] * length(t_m - t_neutral);
        }
    }
    vec3 colour = finish(albedo, dif, spe);
    vec3 n = normalize(n_sum);
#endif
#ifdef SKIN_TONE
    colour *= tone.a;
#endif
#endif
    if (u_view_mode == 1 || u_view_mode == 4) {
        float t = u_view_mode == 1 ? total : clamp(shows / SHOWS_FULL, 0.0, 1.0);
        colour = mix(srgb_to_linear(heat(t)), colour * 0.3, 0.35);
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
