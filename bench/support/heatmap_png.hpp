// A heat map as PNG, for the robustness tables of the benchmarks: one cell per (row, column)
// value, red (at red_at) through yellow to green (at green_at; by default a success rate, 0 to
// 100), the value rounded to an integer written in the cell, row and column labels along the
// left and bottom edges. Digits, '.', '-', '%' only
// (a 3x5 pixel font): the axis names go in the caption of the document that shows the picture.
// The canvas, the font and stb come from png_canvas.hpp.
#pragma once

#include "support/png_canvas.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ulc_bench {

struct Heatmap {
  std::vector<std::string> row_labels;      ///< top to bottom
  std::vector<std::string> column_labels;   ///< left to right
  std::vector<std::vector<double>> values;  ///< [row][column]; < 0: no data
  double red_at = 0.0;                      ///< the value drawn red (an error: its bad end)
  double green_at = 100.0;                  ///< the value drawn green
};

namespace heatmap_detail {

using png_canvas::Canvas;

/// The colour of `value` on the map's scale (grey: no data).
inline std::array<std::uint8_t, 3> colour(double value, double red_at, double green_at) {
  if (value < 0) return {200, 200, 200};
  const double t = std::clamp((value - red_at) / (green_at - red_at), 0.0, 1.0);
  const double r = t < 0.5 ? 1.0 : 2.0 * (1.0 - t);
  const double g = t < 0.5 ? 2.0 * t : 1.0;
  return {static_cast<std::uint8_t>(80 + 170 * r), static_cast<std::uint8_t>(80 + 170 * g), 90};
}

}  // namespace heatmap_detail

/// Writes the map; false when the file cannot be written.
inline bool write_heatmap_png(const std::string& path, const Heatmap& map) {
  constexpr int kCell = 64, kMargin = 56, kScale = 3;
  const int rows = static_cast<int>(map.values.size());
  const int cols = rows ? static_cast<int>(map.values[0].size()) : 0;
  heatmap_detail::Canvas canvas(kMargin + cols * kCell + 8, rows * kCell + kMargin);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double v = c < static_cast<int>(map.values[r].size()) ? map.values[r][c] : -1.0;
      const int x0 = kMargin + c * kCell, y0 = r * kCell;
      canvas.rect(x0 + 1, y0 + 1, x0 + kCell - 1, y0 + kCell - 1,
                  heatmap_detail::colour(v, map.red_at, map.green_at));
      if (v >= 0)
        canvas.text(x0 + kCell / 2, y0 + kCell / 2, std::to_string(static_cast<int>(v + 0.5)),
                    kScale);
    }
    if (r < static_cast<int>(map.row_labels.size()))
      canvas.text(kMargin / 2, r * kCell + kCell / 2, map.row_labels[r], kScale - 1);
  }
  for (int c = 0; c < cols && c < static_cast<int>(map.column_labels.size()); ++c)
    canvas.text(kMargin + c * kCell + kCell / 2, rows * kCell + kMargin / 2, map.column_labels[c],
                kScale - 1);
  return canvas.write_png(path);
}

}  // namespace ulc_bench
