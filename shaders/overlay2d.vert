#version 450 core
// Screen-space overlay (colour legend): positions in pixels, origin at the
// top-left corner, y down, like image rows.
layout(location = 0) in vec2 a_pixel;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in vec4 a_color;
layout(location = 3) in float a_mode;  // 0 solid colour, 1 colour-map gradient (uv.y = t), 2 glyph

uniform vec2 u_viewport;

out vec2 v_uv;
out vec4 v_color;
flat out int v_mode;

void main() {
  v_uv = a_uv;
  v_color = a_color;
  v_mode = int(a_mode + 0.5);
  gl_Position = vec4(a_pixel.x / u_viewport.x * 2.0 - 1.0, 1.0 - a_pixel.y / u_viewport.y * 2.0, 0.0, 1.0);
}
