#version 450 core
// Headlight flat shading: the light sits at the eye, so a face is as bright
// as it faces the viewer. Two-sided (abs), because scenes are not
// necessarily closed or consistently wound. u_shaded = 0 draws u_color as
// is (wireframe overlay, highlighted primitives). u_vertex_colors = 1 shades
// each triangle's own colour (per-instance colours) instead of u_color's rgb.
in vec3 v_world;
flat in vec3 v_normal;
flat in vec4 v_color;

uniform vec3 u_eye;
uniform vec4 u_color;
uniform int u_shaded;
uniform int u_vertex_colors;

out vec4 frag_color;

void main() {
  if (u_shaded == 0) {
    frag_color = u_color;
    return;
  }
  float facing = 0.0;
  if (dot(v_normal, v_normal) > 0.0) {
    facing = abs(dot(normalize(v_normal), normalize(u_eye - v_world)));
  }
  vec3 base = u_vertex_colors != 0 ? v_color.rgb : u_color.rgb;
  frag_color = vec4(base * (0.25 + 0.75 * facing), u_color.a);
}
