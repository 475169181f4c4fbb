// Chart drawing: nice ticks, and pixels where the data say they should be.
#include <gtest/gtest.h>

#include "core/analysis/chart.h"
#include "core/analysis/label_placement.h"

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

TEST(Chart, LabelsOfNearbyPointsDoNotCoverEachOther) {
  // Two points 0.4 apart (about 8 pixels): without placement B's label would
  // be drawn over A's (a "WWWW" label is some 60 pixels). A's pixels are the same whether B is drawn or
  // not, but for a pixel or two where B's leader line (point to label) crosses A's.
  const ChartSeries a{"", {0, 5, 10}, {0, 5, 10}, {"", "WWWW", ""}, {200, 0, 0}, false, true, 3};
  const ChartSeries b{"", {5.4}, {5}, {"WWWW"}, {0, 0, 200}, false, true, 3};
  ChartOptions o;
  o.width = 300;
  o.height = 200;
  const int alone = count_color(draw_chart(o, {a}), {200, 0, 0});
  const RgbImage both = draw_chart(o, {a, b});
  EXPECT_GE(count_color(both, {200, 0, 0}), alone - 2);
  EXPECT_GT(count_color(both, {0, 0, 200}), 49);  // B's marker and its label, placed elsewhere
}

TEST(Chart, TheLegendTakesACornerThatCoversNoPoint) {
  // A point in the top right corner, where the legend goes by default: the
  // legend moves, so the marker (7x7) and the legend's swatch (8x5) are whole.
  const ChartSeries s{"a series", {0, 10}, {0, 10}, {}, {200, 0, 0}, false, true, 3};
  ChartOptions o;
  o.width = 300;
  o.height = 200;
  EXPECT_EQ(count_color(draw_chart(o, {s}), {200, 0, 0}), 2 * 49 + 40);
}

TEST(LabelPlacement, EachLabelTakesTheFirstFreeSpotOrIsLeftOut) {
  LabelLayout layout;
  layout.gap = 2.0f;
  layout.marker = 3.0f;
  layout.bounds = {0, 0, 100, 100};
  // Right-above of its point when free: x = 50 + 3 + 2, y = 50 - 5 - 10.
  std::vector<LabelRequest> r = {{50, 50, 20, 10}};
  auto spots = place_point_labels(r, layout);
  ASSERT_TRUE(spots[0]);
  EXPECT_FLOAT_EQ(spots[0]->x0, 55.0f);
  EXPECT_FLOAT_EQ(spots[0]->y0, 35.0f);
  EXPECT_FLOAT_EQ(spots[0]->x1, 75.0f);

  // Seven labels at one point: the four corners, then right and left of it (centred above and below
  // would cover a corner's label), the seventh left out; no two overlap.
  r.assign(7, LabelRequest{50, 50, 20, 10});
  spots = place_point_labels(r, layout);
  int placed = 0;
  for (std::size_t i = 0; i < spots.size(); ++i) {
    placed += spots[i].has_value();
    for (std::size_t k = 0; k < i; ++k)
      if (spots[i] && spots[k]) {
        EXPECT_FALSE(spots[i]->overlaps(*spots[k])) << i << " " << k;
      }
  }
  EXPECT_EQ(placed, 6);
  EXPECT_FLOAT_EQ(spots[4]->y0, 45.0f);  // right, centred on the point's row
  EXPECT_FLOAT_EQ(spots[5]->x1, 45.0f);  // left
  EXPECT_FALSE(spots[6]);

  // Priority: the last request first, so it gets the first spot.
  const std::vector<std::size_t> last_first = {1, 0};
  r = {{50, 50, 20, 10}, {50, 50, 20, 10}};
  spots = place_point_labels(r, layout, last_first);
  EXPECT_FLOAT_EQ(spots[1]->y0, 35.0f);
  EXPECT_FLOAT_EQ(spots[0]->y0, 55.0f);  // right-below

  // At the right edge the label goes left; the bounds' top sends it below.
  r = {{95, 5, 20, 10}};
  spots = place_point_labels(r, layout);
  ASSERT_TRUE(spots[0]);
  EXPECT_FLOAT_EQ(spots[0]->x1, 90.0f);
  EXPECT_FLOAT_EQ(spots[0]->y0, 10.0f);

  // Another point's marker and a taken rectangle (a legend) block spots.
  const LabelRect legend{54, 30, 80, 46};
  layout.taken = std::span<const LabelRect>(&legend, 1);
  r = {{50, 50, 20, 10}, {45, 58, 0, 0}};  // the second: a point without a label, below-left of the first
  spots = place_point_labels(r, layout);
  ASSERT_TRUE(spots[0]);
  EXPECT_FLOAT_EQ(spots[0]->x0, 55.0f);  // right-below: right-above is the legend's
  EXPECT_FLOAT_EQ(spots[0]->y0, 55.0f);
  EXPECT_FALSE(spots[1]);                  // size 0: no label
  r = {{50, 50, 20, 10}, {60, 60, 0, 0}};  // a marker right-below
  spots = place_point_labels(r, layout);
  ASSERT_TRUE(spots[0]);
  EXPECT_FLOAT_EQ(spots[0]->x1, 45.0f);  // left-above
  EXPECT_FLOAT_EQ(spots[0]->y0, 35.0f);
}

}  // namespace
}  // namespace accelviz::unity_test_chart
