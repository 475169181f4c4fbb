#version 450 core
// A per-pixel metric (R32F, rows stored top row first) through a colour map.
// NaN marks "no value" (e.g. a pixel the metric does not cover): left
// transparent.
in vec2 v_uv;

uniform sampler2D u_values;
uniform sampler1D u_lut;     // 256 entries, linear filtering
uniform vec2 u_range;        // value mapped to 0 and to 1
uniform float u_opacity;

out vec4 frag_color;

void main() {
  // The image's first row is the top of the screen.
  float v = texture(u_values, vec2(v_uv.x, 1.0 - v_uv.y)).r;
  if (isnan(v)) discard;
  float t = clamp((v - u_range.x) / max(u_range.y - u_range.x, 1e-30), 0.0, 1.0);
  // Entry i's centre is at (i + 0.5) / 256: mapping t to [0.5, 255.5] / 256
  // makes linear filtering interpolate between neighbouring entries exactly
  // as the CPU colormap() does.
  vec3 c = texture(u_lut, (t * 255.0 + 0.5) / 256.0).rgb;
  frag_color = vec4(c, u_opacity);
}
