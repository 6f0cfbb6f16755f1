#version 330 core
// Technique 1, composed once per change of the activation vector: each texel of the weight
// texture sums its (at most four) strongest areas' mask values times their activations. The face
// shader then reads one texel, whatever the number of areas (see studio/core/mask_sparse.py).
uniform usampler2D u_t1_index;        // area index per slot
uniform sampler2D u_t1_slot_weight;   // mask value per slot
uniform sampler2D u_activations;      // 1 x N activation vector

out float weight;

float activation(uint area) {
    return texelFetch(u_activations, ivec2(int(area), 0), 0).r;
}

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    uvec4 index = texelFetch(u_t1_index, texel, 0);
    vec4 w = texelFetch(u_t1_slot_weight, texel, 0);
    float s = w.x * activation(index.x) + w.y * activation(index.y)
            + w.z * activation(index.z) + w.w * activation(index.w);
    weight = clamp(s, 0.0, 1.0);
}
