// Chart drawing: nice ticks, and pixels where the data say they should be.
#include <gtest/gtest.h>

#include "core/analysis/chart.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_chart {
namespace {

TEST(Chart, NiceTicksCoverTheRangeInOneTwoFiveSteps) {
  EXPECT_EQ(nice_ticks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  const std::vector<double> t = nice_ticks(0.3, 1.1, 4), want{0.4, 0.6, 0.8, 1.0};
  ASSERT_EQ(t.size(), want.size());
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(t[i], want[i], 1e-12);
  EXPECT_TRUE(nice_ticks(1, 1, 5).empty());
}

int count_color(const RgbImage& img, glm::u8vec3 c) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) n += img.at(x, y) == c;
  return n;
}

TEST(Chart, DrawsMarkersLinesAndLabelsInTheSeriesColour) {
  ChartSeries s{"series", {1, 2, 3}, {1, 4, 9}, {"a", "b", "c"}, {200, 0, 0}, true, true, 3};
  ChartOptions o;
  o.width = 300;
  o.height = 200;
  o.title = "squares";
  const RgbImage img = draw_chart(o, {s});
  EXPECT_EQ(img.width, 300);
  EXPECT_EQ(img.height, 200);
  // Three 7x7 markers at least, plus the lines and labels.
  EXPECT_GT(count_color(img, {200, 0, 0}), 3 * 49);
  s.lines = false;
  s.labels.clear();
  s.name.clear();
  EXPECT_EQ(count_color(draw_chart(o, {s}), {200, 0, 0}), 3 * 49);
}

TEST(Chart, RejectsBadSeries) {
  ChartOptions o;
  EXPECT_THROW(draw_chart(o, {ChartSeries{"x", {1, 2}, {1}, {}, {0, 0, 0}, true, true, 2}}), std::invalid_argument);
  o.log_x = true;
  EXPECT_THROW(draw_chart(o, {ChartSeries{"x", {0, 2}, {1, 2}, {}, {0, 0, 0}, true, true, 2}}), std::invalid_argument);
}

TEST(Chart, CategoricalAxisAndEmptyChartDraw) {
  ChartOptions o;
  o.x_categories = {"2", "4", "exact"};
  const RgbImage img = draw_chart(o, {ChartSeries{"", {0, 1, 2}, {3, 2, 1}, {}, {0, 0, 250}, true, true, 2}});
  EXPECT_GT(count_color(img, {0, 0, 250}), 0);
  EXPECT_EQ(draw_chart(ChartOptions{}, {}).width, ChartOptions{}.width);
}

}  // namespace
}  // namespace accelviz::unity_test_chart
