#version 330 core
uniform vec4 u_colour;
uniform bool u_round;
out vec4 frag_colour;
void main() {
    if (u_round) {
        vec2 p = gl_PointCoord * 2.0 - 1.0;
        float r = dot(p, p);
        if (r > 1.0) discard;
        // a dark rim keeps the dot readable on skin of any colour
        frag_colour = r > 0.7 ? vec4(0.05, 0.05, 0.05, u_colour.a) : u_colour;
    } else {
        frag_colour = u_colour;
    }
}
