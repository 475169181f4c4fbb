#pragma once
// Shared by the tests in tests/gl: an OSMesa GL 4.5 core context per test,
// a renderer on it, small synthetic scenes, and pixel helpers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/triangle.h"
#include "tests/support/temp_dir.h"
#include "ui/gl/osmesa_context.h"
#include "ui/render/image.h"
#include "ui/render/renderer.h"

namespace accelviz::test {

/// Image sizes stay small: llvmpipe on two cores draws them in milliseconds.
inline constexpr int kWidth = 128;
inline constexpr int kHeight = 96;

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = std::make_unique<OsMesaContext>(kWidth, kHeight);
    renderer_ = std::make_unique<Renderer>();
  }
  void TearDown() override {
    renderer_.reset();  // GL objects go while their context is alive
    context_.reset();
  }

  Rgba8Image draw(const RenderView& view, int width = kWidth, int height = kHeight) {
    renderer_->render(view, width, height);
    return renderer_->read_pixels();
  }

  std::unique_ptr<OsMesaContext> context_;
  std::unique_ptr<Renderer> renderer_;
};

/// A camera at `eye` looking at `target`, world +Y up.
inline Camera look_from(const glm::vec3& eye, const glm::vec3& target, float yfov = 0.8f) {
  Camera c;
  c.position = eye;
  c.forward = glm::normalize(target - eye);
  const glm::vec3 right = glm::normalize(glm::cross(c.forward, glm::vec3(0.0f, 1.0f, 0.0f)));
  c.up = glm::cross(right, c.forward);
  c.yfov = yfov;
  return c;
}

/// Two triangles making the square [x0,x1]×[y0,y1] at height z (facing +z).
inline void add_quad_xy(std::vector<Triangle>& out, float x0, float y0, float x1, float y1, float z) {
  out.push_back({{x0, y0, z}, {x1, y0, z}, {x1, y1, z}});
  out.push_back({{x0, y0, z}, {x1, y1, z}, {x0, y1, z}});
}

/// The 12 triangles of a box.
inline void add_box(std::vector<Triangle>& out, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  for (const auto& f : faces) {
    out.push_back({c[f[0]], c[f[1]], c[f[2]]});
    out.push_back({c[f[0]], c[f[2]], c[f[3]]});
  }
}

inline glm::u8vec4 to_rgba8(const glm::vec3& c) {
  auto q = [](float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  return {q(c.x), q(c.y), q(c.z), 255};
}

/// The pixel containing continuous image point p (as project_to_pixel
/// returns); throws std::out_of_range outside the image, so a test that
/// looks off-screen fails instead of reading past the pixels.
inline glm::u8vec4 pixel_at(const Rgba8Image& img, glm::vec2 p) {
  const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) {
    throw std::out_of_range("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the image");
  }
  return img.at(x, y);
}

/// Largest per-channel difference (RGB) between two colours.
inline int channel_diff(glm::u8vec4 a, glm::u8vec4 b) {
  int d = 0;
  for (int i = 0; i < 3; ++i) d = std::max(d, std::abs(int(a[i]) - int(b[i])));
  return d;
}

inline std::string describe(glm::u8vec4 c) {
  // Appended piecewise: GCC 12 warns (-Wrestrict, a known false positive) on "(" + std::string.
  std::string s = "(";
  s += std::to_string(c.x);
  s += ',';
  s += std::to_string(c.y);
  s += ',';
  s += std::to_string(c.z);
  s += ')';
  return s;
}

/// A fresh empty directory under the system temp dir, removed by the destructor.
using test_support::TempDir;

}  // namespace accelviz::test
