// A line plot as PNG, for curves the benchmarks compute (HOTS's spread against the clock
// offset): one or more series of (x, y) points joined by lines, each in its own colour, x and y
// axes with tick labels at round values (1, 2 or 5 times a power of ten) and light grid lines,
// and vertical marker lines (a truth, an estimate) labelled with their x value above the plot.
// Digits, '.', '-', '%' only (png_canvas.hpp's 3x5 font): series and marker names and the axis
// names go in the caption of the document that shows the picture. Non-finite points are
// skipped; the axes span every finite point and every finite marker.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "support/png_canvas.hpp"

namespace ulc_bench {

struct CurveSeries {
  std::string name;                               ///< for the caption only
  std::vector<std::pair<double, double>> points;  ///< (x, y), drawn in this order
};

struct CurveMarker {
  std::string name;  ///< for the caption only
  double x = 0.0;
  bool dashed = false;  ///< tells two markers apart where they overlap
};

struct CurvePlot {
  std::vector<CurveSeries> series;       ///< coloured by index: blue, orange, purple, grey, ...
  std::vector<CurveMarker> markers;      ///< coloured by index: green, red, black, ...
  int width = 640, height = 400;         ///< pixels
  int x_decimals = -1, y_decimals = -1;  ///< tick label decimals; < 0: from the tick step
};

namespace curve_detail {

using png_canvas::Rgb;

inline Rgb series_colour(std::size_t i) {
  static const Rgb palette[] = {{31, 90, 180}, {230, 120, 20}, {130, 60, 160}, {110, 110, 110}};
  return palette[i % 4];
}

inline Rgb marker_colour(std::size_t i) {
  static const Rgb palette[] = {{20, 150, 60}, {210, 30, 30}, {0, 0, 0}};
  return palette[i % 3];
}

/// Round tick step for a range: 1, 2 or 5 times a power of ten, about `count` steps.
inline double tick_step(double range, int count) {
  const double raw = range / count;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

/// An axis from lo to hi widened to whole tick steps.
struct Axis {
  double lo = 0.0, hi = 1.0, step = 0.5;
  int decimals = 1;
  Axis(double min, double max, int count, int fixed_decimals) {
    if (!(max > min)) {  // one value: a unit span around it
      const double half = min != 0.0 ? 0.1 * std::abs(min) : 0.5;
      min -= half;
      max += half;
    }
    step = tick_step(max - min, count);
    lo = std::floor(min / step + 1e-9) * step;
    hi = std::ceil(max / step - 1e-9) * step;
    decimals = fixed_decimals >= 0
                   ? fixed_decimals
                   : std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  }
  int ticks() const { return static_cast<int>(std::lround((hi - lo) / step)); }
  double tick(int k) const { return lo + k * step; }
  /// `extra` decimals beyond the ticks' (markers lie between ticks).
  std::string label(double v, int extra = 0) const {
    if (std::abs(v) < 1e-9 * step) v = 0.0;  // no "-0"
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals + extra, v);
    return buffer;
  }
};

}  // namespace curve_detail

/// Writes the plot; false, and nothing written, when no series has two finite points or the
/// file cannot be written.
inline bool write_curve_png(const std::string& path, const CurvePlot& plot) {
  namespace d = curve_detail;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x_min = kInf, x_max = -kInf, y_min = kInf, y_max = -kInf;
  bool drawable = false;
  for (const auto& s : plot.series) {
    std::size_t finite = 0;
    for (const auto& [x, y] : s.points) {
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      ++finite;
      x_min = std::min(x_min, x);
      x_max = std::max(x_max, x);
      y_min = std::min(y_min, y);
      y_max = std::max(y_max, y);
    }
    drawable = drawable || finite >= 2;
  }
  if (!drawable || plot.width < 160 || plot.height < 120) return false;
  for (const auto& m : plot.markers)
    if (std::isfinite(m.x)) {
      x_min = std::min(x_min, m.x);
      x_max = std::max(x_max, m.x);
    }

  constexpr int kScale = 2, kLine = 14;  // font scale; marker label row height
  const int markers = static_cast<int>(plot.markers.size());
  const int left = 72, right = plot.width - 24, top = 16 + kLine * markers,
            bottom = plot.height - 36;
  const d::Axis ax(x_min, x_max, std::max(2, (right - left) / 80), plot.x_decimals);
  const d::Axis ay(y_min, y_max, std::max(2, (bottom - top) / 60), plot.y_decimals);
  const auto px = [&](double x) { return left + (x - ax.lo) / (ax.hi - ax.lo) * (right - left); };
  const auto py = [&](double y) { return bottom - (y - ay.lo) / (ay.hi - ay.lo) * (bottom - top); };

  png_canvas::Canvas canvas(plot.width, plot.height);
  const png_canvas::Rgb grid = {225, 225, 225}, black = {0, 0, 0};
  for (int k = 0; k <= ax.ticks(); ++k) {
    const double x = px(ax.tick(k));
    canvas.line(x, top, x, bottom, grid);
    canvas.line(x, bottom, x, bottom + 5, black);
    canvas.text(static_cast<int>(std::lround(x)), bottom + 18, ax.label(ax.tick(k)), kScale);
  }
  for (int k = 0; k <= ay.ticks(); ++k) {
    const double y = py(ay.tick(k));
    canvas.line(left, y, right, y, grid);
    canvas.line(left - 5, y, left, y, black);
    const std::string label = ay.label(ay.tick(k));
    canvas.text(left - 10 - png_canvas::text_width(label, kScale) / 2,
                static_cast<int>(std::lround(y)), label, kScale);
  }
  canvas.line(left, top, left, bottom, black);
  canvas.line(left, bottom, right, bottom, black);

  for (int i = 0; i < markers; ++i) {
    const auto& m = plot.markers[static_cast<std::size_t>(i)];
    if (!std::isfinite(m.x)) continue;
    const auto colour = d::marker_colour(static_cast<std::size_t>(i));
    const double x = px(m.x);
    canvas.line(x, top, x, bottom, colour, 2, m.dashed ? 6 : 0);
    // Labels in rows above the plot, so that close markers do not overwrite each other.
    canvas.text(static_cast<int>(std::lround(x)), 10 + kLine * i, ax.label(m.x, 1), kScale, colour);
  }

  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const auto colour = d::series_colour(i);
    bool have_previous = false;
    double x0 = 0.0, y0 = 0.0;
    for (const auto& [x, y] : plot.series[i].points) {
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      const double x1 = px(x), y1 = py(y);
      if (have_previous) canvas.line(x0, y0, x1, y1, colour, 2);
      canvas.rect(static_cast<int>(std::lround(x1)) - 2, static_cast<int>(std::lround(y1)) - 2,
                  static_cast<int>(std::lround(x1)) + 3, static_cast<int>(std::lround(y1)) + 3,
                  colour);
      x0 = x1;
      y0 = y1;
      have_previous = true;
    }
  }
  return canvas.write_png(path);
}

}  // namespace ulc_bench
