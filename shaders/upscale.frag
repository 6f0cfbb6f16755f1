#version 330 core
// The frame drawn at reduced size while the user moves, stretched over the viewport (bilinear),
// with its depth (nearest), so that overlays drawn afterwards at full size are hidden behind
// the face as in a full-size frame.
uniform sampler2D u_frame;
uniform sampler2D u_depth;
in vec2 v_texcoord;
out vec4 frag_colour;
void main() {
    frag_colour = texture(u_frame, v_texcoord);
    gl_FragDepth = texture(u_depth, v_texcoord).r;
}
