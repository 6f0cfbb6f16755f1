#version 330 core
// One triangle over the whole target (no vertex buffer: corners from gl_VertexID), carrying the
// texture coordinates of the reduced frame it shows (studio/render/reduced.py).
out vec2 v_texcoord;
void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);  // (0,0) (2,0) (0,2)
    v_texcoord = corner;
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
