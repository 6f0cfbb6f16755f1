// The skin look (face.frag with SKIN defined): a wrapped diffuse, one wrap width per channel
// (a cheap fit of Penner's pre-integrated skin: red reaches past the terminator), two GGX
// specular lobes with Schlick's Fresnel at skin's F0 and Kelemen's visibility, lit by a rig of
// three lights.
// studio/core/wrinkles/skin_light.py holds the numpy reference, its constants and the rigs.

uniform vec3 u_rig_dir[3];      // view space, toward each light (unit)
uniform vec3 u_rig_colour[3];   // linear RGB intensity of each light (black: unused)
uniform vec3 u_rig_ambient;     // linear RGB

const vec3 SCATTER = vec3(0.35, 0.15, 0.08);
const float F0 = 0.028;
const float SPECULAR = 0.5;
const float PI = 3.14159265;

float ggx(float n_h, float roughness) {
    float a2 = roughness * roughness * roughness * roughness;
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// The rig's diffuse (rgb) and specular (rgb) light on unit normal n, ambient excluded.
void skin_receive(vec3 n, vec3 view_dir, out vec3 diffuse, out vec3 specular) {
    diffuse = vec3(0.0);
    specular = vec3(0.0);
    for (int i = 0; i < 3; ++i) {
        vec3 l = u_rig_dir[i];
        float n_l = dot(n, l);
        diffuse += u_rig_colour[i] * pow(clamp((vec3(n_l) + SCATTER) / (1.0 + SCATTER), 0.0,
                                                1.0), 1.0 + SCATTER);
        vec3 h = view_dir + l;
        h /= max(length(h), 1e-6);
        float n_h = clamp(dot(n, h), 0.0, 1.0);
        float l_h = clamp(dot(l, h), 0.0, 1.0);
        float fresnel = F0 + (1.0 - F0) * pow(1.0 - l_h, 5.0);
        float lobes = 0.8 * ggx(n_h, 0.5) + 0.2 * ggx(n_h, 0.25);
        float spec = SPECULAR * fresnel * lobes / max(4.0 * l_h * l_h, 0.1);
        specular += u_rig_colour[i] * spec * clamp(n_l, 0.0, 1.0);
    }
}

vec3 skin_finish(vec3 albedo, vec3 diffuse, vec3 specular) {
    return albedo * (u_rig_ambient + diffuse) + specular;
}
