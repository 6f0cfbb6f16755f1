#version 330 core
// Selected vertices (technique-2 authoring) as round points, nudged toward the camera so the
// surface they lie on does not hide them; also the depth-only pass used for picking.
in vec3 in_position;
uniform mat4 u_view;
uniform mat4 u_proj;
uniform float u_point_size;
uniform float u_depth_bias;
void main() {
    gl_Position = u_proj * u_view * vec4(in_position, 1.0);
    gl_Position.z -= u_depth_bias * gl_Position.w;
    gl_PointSize = u_point_size;
}
