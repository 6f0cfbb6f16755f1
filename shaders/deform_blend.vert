#version 330 core
// Key-pose blend on the GPU, one welded vertex per invocation, captured by transform feedback:
// P = P_neutral + sum_k w_k (P_k - P_neutral) over the poses that move this vertex (sparse: a
// pose's offset is stored only where it is not zero; core/animation/poses.py is the reference).

#include "deform_data.glsl"

in vec3 in_rest;        // neutral position
in ivec2 in_offsets;    // first and count of this vertex's offsets in u_offsets

uniform sampler2D u_offsets;   // xyz: a pose's offset of this vertex, w: the pose's index
uniform sampler2D u_weights;   // r: the pose's weight this frame

out vec4 out_position;

void main() {
    vec3 moved = vec3(0.0);
    for (int k = 0; k < in_offsets.y; ++k) {
        vec4 offset = fetch(u_offsets, in_offsets.x + k);
        moved += fetch(u_weights, int(offset.w)).r * offset.xyz;
    }
    out_position = vec4(in_rest + moved, 1.0);
}
