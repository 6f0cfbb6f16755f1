#version 330 core
// Wireframe overlay: positions only, drawn after the face with polygon offset.
in vec3 in_position;
uniform mat4 u_view;
uniform mat4 u_proj;
void main() {
    gl_Position = u_proj * u_view * vec4(in_position, 1.0);
}
