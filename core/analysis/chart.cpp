// Chart drawing on the CPU: map data to a plot rectangle, draw the grid and
// axes first, then lines (Bresenham), markers and labels on top, then the
// legend. Integer pixel maths throughout; scale 1 glyphs for ticks and labels,
// scale 2 for the title.
#include "core/analysis/chart.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/analysis/label_placement.h"

namespace accelviz {

namespace {

const glm::u8vec3 kWhite{255, 255, 255}, kAxis{40, 40, 40}, kGrid{225, 225, 225}, kText{20, 20, 20};

void put(RgbImage& img, int x, int y, glm::u8vec3 c) {
  if (x >= 0 && y >= 0 && x < img.width && y < img.height) img.set(x, y, c);
}

void line(RgbImage& img, int x0, int y0, int x1, int y1, glm::u8vec3 c) {
  // Bresenham: exact integer steps, no gaps at any slope.
  const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
  const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (int guard = 0; guard < 100000; ++guard) {
    put(img, x0, y0, c);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) { err += dy; x0 += sx; }
    if (e2 <= dx) { err += dx; y0 += sy; }
  }
}

/// Axis range with a margin; log axes work in log10 space.
struct Axis {
  double lo = 0, hi = 1;
  bool log = false;
  double map(double v) const {
    const double t = log ? std::log10(v) : v;
    return (t - lo) / (hi - lo);
  }
};

Axis make_axis(std::vector<double> values, bool log, bool from_zero) {
  Axis a;
  a.log = log;
  if (values.empty()) return a;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values) {
    const double t = log ? std::log10(v) : v;
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  if (!log && from_zero && lo > 0) lo = 0;
  if (hi - lo <= 0) {
    const double pad = std::abs(hi) > 0 ? std::abs(hi) * 0.1 : 1.0;
    lo -= pad;
    hi += pad;
  } else {
    const double pad = (hi - lo) * 0.06;
    if (!(!log && from_zero && lo == 0)) lo -= pad;
    hi += pad;
  }
  a.lo = lo;
  a.hi = hi;
  return a;
}

std::vector<double> axis_ticks(const Axis& a) {
  if (!a.log) return nice_ticks(a.lo, a.hi, 6);
  std::vector<double> t;  // decades, in value space
  for (double e = std::ceil(a.lo); e <= std::floor(a.hi) + 1e-9; e += 1) t.push_back(std::pow(10.0, e));
  if (t.size() < 2) {  // less than a decade: fall back to linear ticks inside it
    t.clear();
    for (double v : nice_ticks(std::pow(10.0, a.lo), std::pow(10.0, a.hi), 5))
      if (v > 0) t.push_back(v);
  }
  return t;
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> out;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return out;
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) { step = m * mag; break; }
  // Integer multiples of the step (no accumulated rounding from repeated adds).
  const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last; k += 1) out.push_back(k == 0 ? 0.0 : k * step);
  return out;
}

RgbImage draw_chart(const ChartOptions& opts, const std::vector<ChartSeries>& series) {
  std::vector<double> xs, ys;
  for (const ChartSeries& s : series) {
    if (s.x.size() != s.y.size()) throw std::invalid_argument("chart series '" + s.name + "': x and y sizes differ");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      if ((opts.log_x && s.x[i] <= 0) || (opts.log_y && s.y[i] <= 0))
        throw std::invalid_argument("chart series '" + s.name + "': non-positive value on a log axis");
      xs.push_back(s.x[i]);
      ys.push_back(s.y[i]);
    }
  }
  const bool categorical = !opts.x_categories.empty();
  Axis ax;
  if (categorical) {
    ax.lo = -0.5;
    ax.hi = static_cast<double>(opts.x_categories.size()) - 0.5;
  } else {
    ax = make_axis(xs, opts.log_x, false);
  }
  const Axis ay = make_axis(ys, opts.log_y, opts.y_from_zero);

  RgbImage img(opts.width, opts.height, kWhite);
  // Plot rectangle: room for the title above, tick numbers and the x label below, numbers left.
  const int left = 70, right = opts.width - 20, top = opts.title.empty() ? 20 : 40, bottom = opts.height - 45;
  auto px = [&](double v) { return left + static_cast<int>(std::lround(ax.map(v) * (right - left))); };
  auto py = [&](double v) { return bottom - static_cast<int>(std::lround(ay.map(v) * (bottom - top))); };

  // ---- grid, ticks and numbers ----
  for (double t : axis_ticks(ay)) {
    const int y = py(t);
    if (y < top || y > bottom) continue;
    line(img, left, y, right, y, kGrid);
    line(img, left - 4, y, left, y, kAxis);
    const std::string s = format_tick(t);
    draw_text(img, left - 7 - text_width(s, 1), y - 3, s, kText, 1);
  }
  if (categorical) {
    for (std::size_t i = 0; i < opts.x_categories.size(); ++i) {
      const int x = px(static_cast<double>(i));
      line(img, x, top, x, bottom, kGrid);
      line(img, x, bottom, x, bottom + 4, kAxis);
      draw_text(img, x - text_width(opts.x_categories[i], 1) / 2, bottom + 8, opts.x_categories[i], kText, 1);
    }
  } else {
    for (double t : axis_ticks(ax)) {
      const int x = px(t);
      if (x < left || x > right) continue;
      line(img, x, top, x, bottom, kGrid);
      line(img, x, bottom, x, bottom + 4, kAxis);
      const std::string s = format_tick(t);
      draw_text(img, x - text_width(s, 1) / 2, bottom + 8, s, kText, 1);
    }
  }
  line(img, left, top, left, bottom, kAxis);
  line(img, left, bottom, right, bottom, kAxis);

  // ---- titles ----
  if (!opts.title.empty()) draw_text(img, left, 10, opts.title, kText, 2);
  if (!opts.x_label.empty())
    draw_text(img, (left + right) / 2 - text_width(opts.x_label, 1) / 2, bottom + 24, opts.x_label, kText, 1);
  if (!opts.y_label.empty()) draw_text(img, 4, top - 12, opts.y_label, kText, 1);

  // ---- data ----
  for (const ChartSeries& s : series) {
    bool have_prev = false;
    int prev_x = 0, prev_y = 0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        have_prev = false;
        continue;
      }
      const int x = px(s.x[i]), y = py(s.y[i]);
      if (s.lines && have_prev) line(img, prev_x, prev_y, x, y, s.color);
      have_prev = true;
      prev_x = x;
      prev_y = y;
    }
  }

  // ---- legend, top right; the points' labels where they overlap nothing ----
  int legend_w = 0, legend_rows = 0;
  for (const ChartSeries& s : series)
    if (!s.name.empty()) legend_w = std::max(legend_w, text_width(s.name, 1) + 16), ++legend_rows;
  // The legend in the first corner of the plot that covers no point: top right, top left, bottom right, bottom left.
  const int legend_h = 12 * legend_rows + 2;
  const auto covers_a_point = [&](const LabelRect& box) {
    for (const ChartSeries& s : series)
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        const float x = static_cast<float>(px(s.x[i])), y = static_cast<float>(py(s.y[i])), m = s.marker + 1.0f;
        if (box.overlaps({x - m, y - m, x + m, y + m})) return true;
      }
    return false;
  };
  const auto corner = [&](bool at_right, bool at_top) {
    const int x1 = at_right ? right : left + 4 + legend_w, y0 = at_top ? top + 2 : bottom - 4 - legend_h;
    return LabelRect{static_cast<float>(x1 - legend_w - 2), static_cast<float>(y0), static_cast<float>(x1),
                     static_cast<float>(y0 + legend_h)};
  };
  LabelRect legend_box = corner(true, true);  // also where every corner covers a point
  for (const auto& [at_right, at_top] : {std::pair{true, true}, {false, true}, {true, false}, {false, false}})
    if (!covers_a_point(corner(at_right, at_top))) {
      legend_box = corner(at_right, at_top);
      break;
    }
  std::vector<LabelRequest> requests;
  std::vector<std::pair<const ChartSeries*, std::size_t>> labelled;  // one per request: series, point
  std::vector<std::size_t> starts;                                   // each series' first request
  for (const ChartSeries& s : series) {
    starts.push_back(requests.size());
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const bool has = i < s.labels.size() && !s.labels[i].empty();
      requests.push_back({static_cast<float>(px(s.x[i])), static_cast<float>(py(s.y[i])),
                          has ? static_cast<float>(text_width(s.labels[i], 1)) : 0.0f, has ? 9.0f : 0.0f});
      labelled.emplace_back(&s, i);
    }
  }
  starts.push_back(requests.size());
  std::vector<std::size_t> priority;  // the last series' labels first: it is drawn on top (a Pareto front)
  for (std::size_t k = series.size(); k-- > 0;)
    for (std::size_t r = starts[k]; r < starts[k + 1]; ++r) priority.push_back(r);
  LabelLayout layout;
  layout.marker = 0.0f;
  for (const ChartSeries& s : series) layout.marker = std::max(layout.marker, static_cast<float>(s.marker));
  layout.bounds = {static_cast<float>(left + 1), static_cast<float>(top), static_cast<float>(right),
                   static_cast<float>(bottom)};
  if (legend_rows > 0) layout.taken = std::span<const LabelRect>(&legend_box, 1);
  const std::vector<std::optional<LabelRect>> spots = place_point_labels(requests, layout, priority);
  // Leaders first (from a point to its label's nearest corner: in a cluster, which label is whose), then
  // the markers over them, then the labels.
  for (std::size_t k = 0; k < spots.size(); ++k)
    if (spots[k]) {
      const LabelRect& b = *spots[k];
      const float cx = requests[k].x < b.x0 ? b.x0 : b.x1, cy = requests[k].y < b.y0 ? b.y0 : b.y1;
      line(img, static_cast<int>(requests[k].x), static_cast<int>(requests[k].y), static_cast<int>(cx),
           static_cast<int>(cy), labelled[k].first->color);
    }
  for (const ChartSeries& s : series)
    for (std::size_t i = 0; s.points && i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const int x = px(s.x[i]), y = py(s.y[i]);
      for (int dy = -s.marker; dy <= s.marker; ++dy)
        for (int dx = -s.marker; dx <= s.marker; ++dx) put(img, x + dx, y + dy, s.color);
    }
  for (std::size_t k = 0; k < spots.size(); ++k)
    if (spots[k]) {
      const auto& [s, i] = labelled[k];
      draw_text(img, static_cast<int>(spots[k]->x0), static_cast<int>(spots[k]->y0), s->labels[i], s->color, 1);
    }
  int ly = static_cast<int>(legend_box.y0) + 2;
  for (const ChartSeries& s : series) {
    if (s.name.empty()) continue;
    const int w = text_width(s.name, 1);
    const int x = static_cast<int>(legend_box.x1) - w - 16;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = 0; dx < 8; ++dx) put(img, x + dx, ly + 3 + dy, s.color);
    draw_text(img, x + 12, ly, s.name, kText, 1);
    ly += 12;
  }
  return img;
}

}  // namespace accelviz
