#include "ui/render/legend_pass.h"

#include "core/analysis/heatmap.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace accelviz {
namespace {

// The font's geometry (core/analysis/heatmap.h): 5×7 glyphs above the
// baseline, 9 rows with the descenders.
constexpr int kGlyphW = kFontGlyphW, kGlyphH = kFontGlyphH, kGlyphRows = kFontGlyphRows;
// Atlas: printable ASCII 32..126 in one row of 6×10 cells.
constexpr int kFirstChar = 32, kLastChar = 126, kCellW = kFontAdvance, kCellH = kGlyphRows + 1;
constexpr int kAtlasW = (kLastChar - kFirstChar + 1) * kCellW;

struct OverlayVertex {
  glm::vec2 pixel;
  glm::vec2 uv;
  glm::vec4 color;
  float mode;  // 0 solid, 1 gradient, 2 glyph (see overlay2d.frag)
};

const glm::vec4 kPanel{24 / 255.0f, 24 / 255.0f, 24 / 255.0f, 0.85f};
const glm::vec4 kInk{235 / 255.0f, 235 / 255.0f, 235 / 255.0f, 1.0f};

void add_rect(std::vector<OverlayVertex>& out, float x0, float y0, float x1, float y1, glm::vec2 uv0, glm::vec2 uv1,
              const glm::vec4& color, float mode) {
  const OverlayVertex a{{x0, y0}, {uv0.x, uv0.y}, color, mode};
  const OverlayVertex b{{x1, y0}, {uv1.x, uv0.y}, color, mode};
  const OverlayVertex c{{x1, y1}, {uv1.x, uv1.y}, color, mode};
  const OverlayVertex d{{x0, y1}, {uv0.x, uv1.y}, color, mode};
  out.insert(out.end(), {a, b, c, a, c, d});
}

}  // namespace

LegendLayout layout_legend(int width, int height, const glm::vec2& range, std::string_view title, bool whole,
                           bool above_top, bool below_bottom) {
  LegendLayout L;
  // Proportions (glyph scale, padding, bar width) and ticks (legend_ticks) follow core's
  // CPU legend (colorize), so both read alike.
  const int s = std::max(width, height) >= 480 ? 2 : 1;
  const int pad = 4 * s, glyph_h = kGlyphH * s, bar_w = 10 * s, tick = 3 * s;
  L.scale = s;

  const std::vector<double> ticks = legend_ticks(range.x, range.y, whole);
  const std::vector<std::string> numbers = legend_labels(ticks, above_top, below_bottom);
  int widest = 0;
  for (const std::string& n : numbers) widest = std::max(widest, text_width(n, s));
  const int panel_w = std::max(pad + tick + bar_w + pad + widest + pad, text_width(title, s) + 2 * pad);
  const int header = pad + glyph_h + pad + glyph_h / 2;  // title, then half a glyph so the top number fits
  const int footer = glyph_h / 2 + pad;
  const int bar_len = std::min(200 * s, height - 2 * pad - header - footer);
  if (bar_len < 4 * glyph_h || panel_w + 2 * pad > width) return L;  // no room: no legend

  L.visible = true;
  L.panel = {width - pad - panel_w, pad, width - pad, pad + header + bar_len + footer};
  const int bar_x0 = L.panel.x0 + pad + tick;
  const int bar_top = L.panel.y0 + header;
  L.bar = {bar_x0, bar_top, bar_x0 + bar_w, bar_top + bar_len};
  L.labels.push_back({std::string(title), L.panel.x0 + pad, L.panel.y0 + pad});
  const double span = static_cast<double>(range.y) - range.x;
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    // Tick k sits on the row of its value in the range: the bottom row is the
    // low end. Ticks stick out on the bar's left: on the right, next to the
    // numbers, they would read as minus signs.
    const double f = span > 0.0 ? (ticks[k] - range.x) / span : 0.0;
    const int y = L.bar.y1 - 1 - static_cast<int>(std::lround((bar_len - 1) * f));
    L.ticks.push_back({L.bar.x0 - tick, y, L.bar.x0, y + s});
    L.labels.push_back({numbers[k], L.bar.x1 + pad, y - glyph_h / 2});
  }
  return L;
}

LegendPass::LegendPass()
    : vao_(GlObject::create(GlObject::Kind::vertex_array)),
      vbo_(GlObject::create(GlObject::Kind::buffer)),
      font_(GlObject::create_texture(GL_TEXTURE_2D)) {
  // Rasterise every printable character once with the CPU font.
  RgbImage atlas(kAtlasW, kCellH);
  for (int c = kFirstChar; c <= kLastChar; ++c) {
    draw_text(atlas, (c - kFirstChar) * kCellW, 0, std::string(1, static_cast<char>(c)), {255, 255, 255}, 1);
  }
  std::vector<std::uint8_t> coverage(static_cast<std::size_t>(kAtlasW) * kCellH);
  for (int y = 0; y < kCellH; ++y)
    for (int x = 0; x < kAtlasW; ++x) coverage[static_cast<std::size_t>(y) * kAtlasW + x] = atlas.at(x, y).x;
  glTextureStorage2D(font_.id(), 1, GL_R8, kAtlasW, kCellH);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(font_.id(), 0, 0, 0, kAtlasW, kCellH, GL_RED, GL_UNSIGNED_BYTE, coverage.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureParameteri(font_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(font_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(font_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(font_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  const GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, vbo_.id(), 0, sizeof(OverlayVertex));
  glVertexArrayAttribFormat(vao, 0, 2, GL_FLOAT, GL_FALSE, offsetof(OverlayVertex, pixel));
  glVertexArrayAttribFormat(vao, 1, 2, GL_FLOAT, GL_FALSE, offsetof(OverlayVertex, uv));
  glVertexArrayAttribFormat(vao, 2, 4, GL_FLOAT, GL_FALSE, offsetof(OverlayVertex, color));
  glVertexArrayAttribFormat(vao, 3, 1, GL_FLOAT, GL_FALSE, offsetof(OverlayVertex, mode));
  for (GLuint a : {0u, 1u, 2u, 3u}) {
    glVertexArrayAttribBinding(vao, a, 0);
    glEnableVertexArrayAttrib(vao, a);
  }
  check_gl_errors("legend setup");
}

void LegendPass::draw(const ShaderProgram& program, const LegendLayout& L, GLuint lut_texture, int width,
                      int height) const {
  if (!L.visible) return;
  std::vector<OverlayVertex> v;
  const glm::vec2 none(0.0f);
  add_rect(v, L.panel.x0, L.panel.y0, L.panel.x1, L.panel.y1, none, none, kPanel, 0.0f);
  // Gradient: uv.y carries t, 1 on the top edge and 0 on the bottom edge.
  add_rect(v, L.bar.x0, L.bar.y0, L.bar.x1, L.bar.y1, {0.0f, 1.0f}, {0.0f, 0.0f}, kInk, 1.0f);
  for (const LegendLayout::Rect& t : L.ticks) add_rect(v, t.x0, t.y0, t.x1, t.y1, none, none, kInk, 0.0f);
  const int s = L.scale;
  for (const LegendLayout::Label& label : L.labels) {
    int x = label.x;
    for (char ch : label.text) {
      const int c = (ch >= kFirstChar && ch <= kLastChar) ? ch : ' ';
      const float u0 = static_cast<float>((c - kFirstChar) * kCellW) / kAtlasW;
      const float u1 = static_cast<float>((c - kFirstChar) * kCellW + kGlyphW) / kAtlasW;
      const float v1 = static_cast<float>(kGlyphRows) / kCellH;
      add_rect(v, x, label.y, x + kGlyphW * s, label.y + kGlyphRows * s, {u0, 0.0f}, {u1, v1}, kInk, 2.0f);
      x += kCellW * s;
    }
  }
  glNamedBufferData(vbo_.id(), static_cast<GLsizeiptr>(v.size() * sizeof(OverlayVertex)), v.data(), GL_STREAM_DRAW);

  program.use();
  program.set("u_viewport", glm::vec2(width, height));
  program.set("u_lut", 0);
  program.set("u_font", 1);
  glBindTextureUnit(0, lut_texture);
  glBindTextureUnit(1, font_.id());
  glBindVertexArray(vao_.id());
  glDisable(GL_DEPTH_TEST);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(v.size()));
  glEnable(GL_DEPTH_TEST);
}

}  // namespace accelviz
