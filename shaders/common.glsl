// Shared shading: tangent-space normal decoding and the studio's Blinn-Phong skin light.
// Lighting is done in view space; the key light direction is camera-relative (like Blender's
// studio light), so the face stays lit while the user orbits.

uniform vec3 u_light_dir;      // view-space direction toward the key light (normalised)
uniform float u_ambient;       // ambient term
uniform float u_specular;      // specular strength
uniform float u_shininess;     // Blinn-Phong exponent

vec3 decode_normal(vec3 rgb) {
    return normalize(rgb * 2.0 - 1.0);
}

vec3 srgb_to_linear(vec3 c) { return pow(c, vec3(2.2)); }
vec3 linear_to_srgb(vec3 c) { return pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)); }

// The light a surface normal receives from the key light plus a dim fill from the opposite side:
// x diffuse, y specular. A shaded colour is albedo * (u_ambient + x) + y (face.frag's finish), so a
// weighted average of shaded colours (the thesis's blend) is the same average of these two
// numbers: a blend of several shadings costs two floats per extra normal, not a colour.
vec2 light(vec3 n, vec3 view_dir) {
    vec3 l = normalize(u_light_dir);
    vec3 fill = normalize(vec3(-l.x, 0.2, 0.6));
    float key = max(dot(n, l), 0.0);
    float back = max(dot(n, fill), 0.0) * 0.25;
    vec3 h = normalize(l + view_dir);
    float spec = key > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) * u_specular : 0.0;
    return vec2(key + back, spec);
}
