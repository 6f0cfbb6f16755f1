#version 330 core
// Wrinkle direction vectors as short lines (tail dim, head bright), in each area's colour.
// With identity matrices the same program draws the selection tool's 2-D outline.
in vec3 in_position;
in vec4 in_colour;
uniform mat4 u_view;
uniform mat4 u_proj;
uniform float u_depth_bias;
out vec4 v_colour;
void main() {
    gl_Position = u_proj * u_view * vec4(in_position, 1.0);
    gl_Position.z -= u_depth_bias * gl_Position.w;
    v_colour = in_colour;
}
