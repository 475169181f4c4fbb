#include <gtest/gtest.h>

#include <cmath>

#include "core/analysis/colormap.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_colormap {

using namespace accelviz;

namespace {

void expect_rgb(const glm::vec3& c, float r, float g, float b) {
  EXPECT_NEAR(c.x, r, 1e-6f);
  EXPECT_NEAR(c.y, g, 1e-6f);
  EXPECT_NEAR(c.z, b, 1e-6f);
}

/// Relative luminance of sRGB-encoded values (decode, then Rec. 709 weights).
float luminance(const glm::vec3& srgb) {
  auto lin = [](float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); };
  return 0.2126f * lin(srgb.x) + 0.7152f * lin(srgb.y) + 0.0722f * lin(srgb.z);
}

}  // namespace

TEST(ColorMap, EndpointsMatchPublishedTables) {
  // matplotlib _cm_listed.py (viridis, inferno) and Google's turbo_srgb_floats.
  expect_rgb(colormap(ColorMap::viridis, 0.0f), 0.267004f, 0.004874f, 0.329415f);
  expect_rgb(colormap(ColorMap::viridis, 1.0f), 0.993248f, 0.906157f, 0.143936f);
  expect_rgb(colormap(ColorMap::inferno, 0.0f), 0.001462f, 0.000466f, 0.013866f);
  expect_rgb(colormap(ColorMap::inferno, 1.0f), 0.988362f, 0.998364f, 0.644924f);
  expect_rgb(colormap(ColorMap::turbo, 0.0f), 0.18995f, 0.07176f, 0.23217f);
  expect_rgb(colormap(ColorMap::turbo, 1.0f), 0.47960f, 0.01583f, 0.01055f);
  // An interior entry: viridis[128] sits at t = 128/255.
  expect_rgb(colormap(ColorMap::viridis, 128.0f / 255.0f), 0.127568f, 0.566949f, 0.550556f);
}

TEST(ColorMap, TablesHave256Entries) {
  EXPECT_EQ(colormap_table(ColorMap::viridis).size(), 256u);
  EXPECT_EQ(colormap_table(ColorMap::inferno).size(), 256u);
  EXPECT_EQ(colormap_table(ColorMap::turbo).size(), 256u);
  EXPECT_TRUE(colormap_table(ColorMap::diverging).empty());
}

TEST(ColorMap, ClampsOutOfRangeAndNaN) {
  EXPECT_EQ(colormap(ColorMap::viridis, -3.0f), colormap(ColorMap::viridis, 0.0f));
  EXPECT_EQ(colormap(ColorMap::viridis, 7.0f), colormap(ColorMap::viridis, 1.0f));
  EXPECT_EQ(colormap(ColorMap::inferno, std::nanf("")), colormap(ColorMap::inferno, 0.0f));
}

TEST(ColorMap, InterpolatesBetweenEntries) {
  const glm::vec3 a = colormap(ColorMap::turbo, 10.0f / 255.0f);
  const glm::vec3 b = colormap(ColorMap::turbo, 11.0f / 255.0f);
  const glm::vec3 mid = colormap(ColorMap::turbo, 10.5f / 255.0f);
  EXPECT_NEAR(mid.x, 0.5f * (a.x + b.x), 1e-5f);
  EXPECT_NEAR(mid.y, 0.5f * (a.y + b.y), 1e-5f);
  EXPECT_NEAR(mid.z, 0.5f * (a.z + b.z), 1e-5f);
}

TEST(ColorMap, ViridisAndInfernoLuminanceIsMonotone) {
  for (ColorMap m : {ColorMap::viridis, ColorMap::inferno}) {
    const auto table = colormap_table(m);
    float prev = -1.0f;
    for (std::size_t i = 0; i < table.size(); ++i) {
      const float y = luminance({table[i][0], table[i][1], table[i][2]});
      EXPECT_GT(y, prev) << colormap_name(m) << " entry " << i;
      prev = y;
    }
  }
}

TEST(ColorMap, DivergingIsWhiteInTheMiddle) {
  expect_rgb(colormap(ColorMap::diverging, 0.5f), 1.0f, 1.0f, 1.0f);
  const glm::vec3 lo = colormap(ColorMap::diverging, 0.0f), hi = colormap(ColorMap::diverging, 1.0f);
  EXPECT_GT(lo.z, lo.x);  // blue end
  EXPECT_GT(hi.x, hi.z);  // red end
}

TEST(ColorMap, NamesRoundTrip) {
  for (ColorMap m : {ColorMap::viridis, ColorMap::inferno, ColorMap::turbo, ColorMap::diverging})
    EXPECT_EQ(parse_colormap(colormap_name(m)), m);
  EXPECT_FALSE(parse_colormap("jet").has_value());
}
}  // namespace unity_test_colormap
