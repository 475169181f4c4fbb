#version 450 core
// Scene triangles in world space; one geometric normal per triangle,
// repeated on its three vertices (flat shading needs no index buffer).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;  // per-instance colours; read only when u_vertex_colors is 1

uniform mat4 u_view_proj;

out vec3 v_world;
flat out vec3 v_normal;
flat out vec4 v_color;

void main() {
  v_world = a_position;
  v_normal = a_normal;
  v_color = a_color;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
