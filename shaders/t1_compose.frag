#version 330 core
// Technique 1, composed once per change of the activation vector: each texel of the weight
// texture sums its (at most four) strongest areas' mask values times their activations, into
// the component of the wrinkled map each area reveals. The face shader then reads one texel,
// whatever the number of areas (see studio/core/mask_sparse.py).
uniform usampler2D u_t1_index;        // area index per slot
uniform sampler2D u_t1_slot_weight;   // mask value per slot
uniform sampler2D u_activations;      // 1 x N, RG32F: activation, index of the area's map

out vec4 weight;

vec4 add(vec4 sum, uint area, float mask) {
    vec2 a = texelFetch(u_activations, ivec2(int(area), 0), 0).rg;
    sum[int(a.y)] += mask * a.x;
    return sum;
}

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    uvec4 index = texelFetch(u_t1_index, texel, 0);
    vec4 w = texelFetch(u_t1_slot_weight, texel, 0);
    vec4 s = add(add(add(add(vec4(0.0), index.x, w.x), index.y, w.y), index.z, w.z),
                 index.w, w.w);
    weight = clamp(s, 0.0, 1.0);
}
