// The pixel canvas the benchmarks' PNG pictures are drawn on (heatmap_png.hpp, curve_png.hpp):
// an RGB image, white at start, with filled rectangles, thick lines and a 3x5 pixel font that
// has digits, '.', '-' and '%' only (other characters leave a blank): axis names go in the
// caption of the document that shows the picture. Pixel (0, 0) is the top left corner.
// One translation unit per benchmark, so stb's implementation is compiled static here, once per
// translation unit however many picture headers include this one.
#pragma once

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace ulc_bench {
namespace png_canvas {

using Rgb = std::array<std::uint8_t, 3>;

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

/// Width in pixels of `s` written at `scale` pixels per font dot (one dot between glyphs).
inline int text_width(const std::string& s, int scale) {
  return s.empty() ? 0 : static_cast<int>(s.size()) * 4 * scale - scale;
}

struct Canvas {
  int width, height;
  std::vector<std::uint8_t> rgb;
  Canvas(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, 255) {}
  /// Fills [x0, x1) x [y0, y1), clipped to the canvas.
  void rect(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
      for (int x = std::max(0, x0); x < std::min(width, x1); ++x)
        for (int k = 0; k < 3; ++k) rgb[(static_cast<std::size_t>(y) * width + x) * 3 + k] = c[k];
  }
  /// A line `thickness` pixels wide from (x0, y0) to (x1, y1); with dash > 0, `dash` pixels
  /// drawn then `dash` skipped along it.
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness = 1, int dash = 0) {
    const double length = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, static_cast<int>(std::ceil(length)));
    const int lo = -(thickness - 1) / 2, hi = lo + thickness;
    for (int i = 0; i <= steps; ++i) {
      if (dash > 0 && (i / dash) % 2 == 1) continue;
      const double t = static_cast<double>(i) / steps;
      const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0)));
      const int y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
      rect(x + lo, y + lo, x + hi, y + hi, c);
    }
  }
  /// Text centred on (cx, cy), `scale` pixels per font dot.
  void text(int cx, int cy, const std::string& s, int scale, Rgb c = {0, 0, 0}) {
    int x = cx - text_width(s, scale) / 2;
    const int y = cy - 5 * scale / 2;
    for (char ch : s) {
      if (const auto* g = glyph(ch))
        for (int r = 0; r < 5; ++r)
          for (int b = 0; b < 3; ++b)
            if ((*g)[r] >> (2 - b) & 1)
              rect(x + b * scale, y + r * scale, x + (b + 1) * scale, y + (r + 1) * scale, c);
      x += 4 * scale;
    }
  }
  /// False when the file cannot be written.
  bool write_png(const std::string& path) const {
    return stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3) != 0;
  }
};

}  // namespace png_canvas
}  // namespace ulc_bench
