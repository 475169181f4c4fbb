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
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const int x = px(s.x[i]), y = py(s.y[i]);
      if (s.points)
        for (int dy = -s.marker; dy <= s.marker; ++dy)
          for (int dx = -s.marker; dx <= s.marker; ++dx) put(img, x + dx, y + dy, s.color);
      if (i < s.labels.size() && !s.labels[i].empty())
        draw_text(img, x + s.marker + 3, y - s.marker - 8, s.labels[i], s.color, 1);
    }
  }

  // ---- legend, top right ----
  int ly = top + 4;
  for (const ChartSeries& s : series) {
    if (s.name.empty()) continue;
    const int w = text_width(s.name, 1);
    const int x = right - w - 16;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = 0; dx < 8; ++dx) put(img, x + dx, ly + 3 + dy, s.color);
    draw_text(img, x + 12, ly, s.name, kText, 1);
    ly += 12;
  }
  return img;
}

}  // namespace accelviz
