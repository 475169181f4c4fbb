#version 450 core
// Box overlays: the 24 vertices of a unit cube's 12 edges, instanced once
// per box; each instance carries its corners and colour (40 bytes, the
// layout of accelviz::ColoredBox).
layout(location = 0) in vec3 a_corner;  // 0 or 1 on each axis
layout(location = 1) in vec3 a_lo;
layout(location = 2) in vec3 a_hi;
layout(location = 3) in vec4 a_color;

uniform mat4 u_view_proj;

out vec4 v_color;

void main() {
  v_color = a_color;
  gl_Position = u_view_proj * vec4(mix(a_lo, a_hi, a_corner), 1.0);
}
