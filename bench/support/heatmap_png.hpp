// A success-rate heat map as PNG, for the robustness tables of the benchmarks: one cell per
// (row, column) value in [0, 100], red (0) through yellow to green (100), the value written in
// the cell, row and column labels along the left and bottom edges. Digits, '.', '-', '%' only
// (a 3x5 pixel font): the axis names go in the caption of the document that shows the picture.
// One translation unit per benchmark, so stb's implementation is compiled static here.
#pragma once

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ulc_bench {

struct Heatmap {
  std::vector<std::string> row_labels;      ///< top to bottom
  std::vector<std::string> column_labels;   ///< left to right
  std::vector<std::vector<double>> values;  ///< [row][column], percent; < 0: no data
};

namespace heatmap_detail {

/// 3x5 glyphs, one row of 3 bits per line, top line first.
inline const std::array<std::uint8_t, 5>* glyph(char c) {
  static const std::array<std::uint8_t, 5> digits[10] = {
      {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
      {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}};
  static const std::array<std::uint8_t, 5> dot = {0, 0, 0, 0, 2}, minus = {0, 0, 7, 0, 0},
                                           percent = {5, 1, 2, 4, 5};
  if (c >= '0' && c <= '9') return &digits[c - '0'];
  if (c == '.') return &dot;
  if (c == '-') return &minus;
  if (c == '%') return &percent;
  return nullptr;
}

struct Canvas {
  int width, height;
  std::vector<std::uint8_t> rgb;
  Canvas(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, 255) {}
  void rect(int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> c) {
    for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
      for (int x = std::max(0, x0); x < std::min(width, x1); ++x)
        for (int k = 0; k < 3; ++k) rgb[(static_cast<std::size_t>(y) * width + x) * 3 + k] = c[k];
  }
  /// Text centred on (cx, cy), `scale` pixels per font dot.
  void text(int cx, int cy, const std::string& s, int scale) {
    const int w = static_cast<int>(s.size()) * 4 * scale - scale;
    int x = cx - w / 2;
    const int y = cy - 5 * scale / 2;
    for (char ch : s) {
      if (const auto* g = glyph(ch))
        for (int r = 0; r < 5; ++r)
          for (int b = 0; b < 3; ++b)
            if ((*g)[r] >> (2 - b) & 1)
              rect(x + b * scale, y + r * scale, x + (b + 1) * scale, y + (r + 1) * scale,
                   {0, 0, 0});
      x += 4 * scale;
    }
  }
};

inline std::array<std::uint8_t, 3> colour(double percent) {
  if (percent < 0) return {200, 200, 200};
  const double t = std::clamp(percent / 100.0, 0.0, 1.0);
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
      canvas.rect(x0 + 1, y0 + 1, x0 + kCell - 1, y0 + kCell - 1, heatmap_detail::colour(v));
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
  return stbi_write_png(path.c_str(), canvas.width, canvas.height, 3, canvas.rgb.data(),
                        canvas.width * 3) != 0;
}

}  // namespace ulc_bench
