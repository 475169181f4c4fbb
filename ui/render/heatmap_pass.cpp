#include "ui/render/heatmap_pass.h"

#include <stdexcept>
#include <string>

namespace accelviz {
namespace {

GlObject make_lut_texture(std::span<const glm::vec3> lut) {
  GlObject tex = GlObject::create_texture(GL_TEXTURE_1D);
  glTextureStorage1D(tex.id(), 1, GL_RGBA32F, 256);
  std::vector<glm::vec4> rgba;
  rgba.reserve(lut.size());
  for (const glm::vec3& c : lut) rgba.emplace_back(c, 1.0f);
  glTextureSubImage1D(tex.id(), 0, 0, 256, GL_RGBA, GL_FLOAT, rgba.data());
  glTextureParameteri(tex.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  return tex;
}

}  // namespace

std::vector<glm::vec3> colormap_lut(ColorMap map) {
  std::vector<glm::vec3> lut(256);
  for (int i = 0; i < 256; ++i) lut[i] = colormap(map, static_cast<float>(i) / 255.0f);
  return lut;
}

HeatmapPass::HeatmapPass() : vao_(GlObject::create(GlObject::Kind::vertex_array)) {
  set_lut(colormap_lut(ColorMap::viridis));
  // core's heatmap_color draws the shaded metric as grey 0.1 + 0.85·v.
  std::vector<glm::vec3> grey(256);
  for (int i = 0; i < 256; ++i) grey[i] = glm::vec3(0.1f + 0.85f * static_cast<float>(i) / 255.0f);
  grey_lut_ = make_lut_texture(grey);
  check_gl_errors("heatmap pass setup");
}

void HeatmapPass::set_lut(std::span<const glm::vec3> lut) {
  if (lut.size() != 256) {
    throw std::invalid_argument("colour-map LUT needs 256 entries, got " + std::to_string(lut.size()));
  }
  lut_ = make_lut_texture(lut);
  check_gl_errors("colour-map upload");
}

GLuint HeatmapPass::lut_texture() const {
  return metric_ == HeatMetric::shaded ? grey_lut_.id() : lut_.id();
}

void HeatmapPass::upload(const MetricImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.values.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw std::invalid_argument("metric image: " + std::to_string(image.values.size()) + " values for " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels");
  }
  if (image.width != width_ || image.height != height_ || !values_) {
    values_ = GlObject::create_texture(GL_TEXTURE_2D);
    glTextureStorage2D(values_.id(), 1, GL_R32F, image.width, image.height);
    // Nearest: a pixel shows its own value, never a blend of two metrics.
    glTextureParameteri(values_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(values_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(values_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(values_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  // Row 0 of the image goes to texel row 0; the shader flips v, so it shows at the top.
  glTextureSubImage2D(values_.id(), 0, 0, 0, image.width, image.height, GL_RED, GL_FLOAT, image.values.data());
  width_ = image.width;
  height_ = image.height;
  metric_ = image.metric;
  values_range_ = metric_value_range(image);
  check_gl_errors("heatmap upload");
}

void HeatmapPass::draw(const ShaderProgram& program, const glm::vec2& range, float opacity) const {
  if (!has_image()) return;
  program.use();
  program.set("u_values", 0);
  program.set("u_lut", 1);
  program.set("u_range", range);
  program.set("u_opacity", opacity);
  glBindTextureUnit(0, values_.id());
  glBindTextureUnit(1, lut_texture());
  glBindVertexArray(vao_.id());
  glDisable(GL_DEPTH_TEST);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace accelviz
