#version 330 core
// The strain mode's wrinkle weight of one render vertex from the blended positions (transform
// feedback into the face's strain attribute): the mean over its welded position's edges of
// max(0, 1 - length / rest length), over the compression that shows wrinkles fully, clamped
// (core/wrinkles/strain.py is the reference).

#include "deform_data.glsl"

in int in_weld;      // the welded position of this render vertex
in ivec2 in_edges;   // first and count of its edges in u_neighbours and u_rest_lengths

uniform sampler2D u_positions;    // xyz: this frame's welded positions
uniform isampler2D u_neighbours;  // r: the welded position at an edge's other end
uniform sampler2D u_rest_lengths; // r: the edge's length in the neutral pose
uniform float u_full_at;          // compression at which the wrinkles fully show

out float out_strain;

void main() {
    vec3 here = fetch(u_positions, in_weld).xyz;
    float total = 0.0;
    for (int k = 0; k < in_edges.y; ++k) {
        float rest = fetch(u_rest_lengths, in_edges.x + k).r;
        if (rest <= 0.0) continue;
        float length_ = distance(here, fetch(u_positions, fetch(u_neighbours, in_edges.x + k).r)
                                 .xyz);
        total += clamp(1.0 - length_ / rest, 0.0, 1.0);
    }
    float compression = total / float(max(in_edges.y, 1));
    out_strain = clamp(compression / max(u_full_at, 1e-6), 0.0, 1.0);
}
