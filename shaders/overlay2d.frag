#version 450 core
in vec2 v_uv;
in vec4 v_color;
flat in int v_mode;

uniform sampler1D u_lut;   // the heatmap's colour map; mode 1 maps uv.y = t through it
uniform sampler2D u_font;  // R8 glyph atlas, texel rows top-down

out vec4 frag_color;

void main() {
  if (v_mode == 1) {
    frag_color = vec4(texture(u_lut, (clamp(v_uv.y, 0.0, 1.0) * 255.0 + 0.5) / 256.0).rgb, 1.0);
  } else if (v_mode == 2) {
    float coverage = texture(u_font, v_uv).r;
    if (coverage < 0.5) discard;
    frag_color = v_color;
  } else {
    frag_color = v_color;
  }
}
