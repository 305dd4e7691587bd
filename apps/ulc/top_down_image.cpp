#include "top_down_image.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBIW_WINDOWS_UTF8
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "ulc/io/atomic_file.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::app {
namespace {

// 5x7 glyphs, one byte per row (low 5 bits), for the characters labels need.
struct Glyph {
  char c;
  std::uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {14, 17, 19, 21, 25, 17, 14}}, {'1', {4, 12, 4, 4, 4, 4, 14}},
    {'2', {14, 17, 1, 2, 4, 8, 31}},     {'3', {30, 1, 1, 14, 1, 1, 30}},
    {'4', {2, 6, 10, 18, 31, 2, 2}},     {'5', {31, 16, 30, 1, 1, 17, 14}},
    {'6', {6, 8, 16, 30, 17, 17, 14}},   {'7', {31, 1, 2, 4, 8, 8, 8}},
    {'8', {14, 17, 17, 14, 17, 17, 14}}, {'9', {14, 17, 17, 15, 1, 2, 12}},
    {'A', {14, 17, 17, 31, 17, 17, 17}}, {'B', {30, 17, 17, 30, 17, 17, 30}},
    {'C', {14, 17, 16, 16, 16, 17, 14}}, {'D', {28, 18, 17, 17, 17, 18, 28}},
    {'E', {31, 16, 16, 30, 16, 16, 31}}, {'F', {31, 16, 16, 30, 16, 16, 16}},
    {'G', {14, 17, 16, 23, 17, 17, 15}}, {'H', {17, 17, 17, 31, 17, 17, 17}},
    {'I', {14, 4, 4, 4, 4, 4, 14}},      {'J', {7, 2, 2, 2, 2, 18, 12}},
    {'K', {17, 18, 20, 24, 20, 18, 17}}, {'L', {16, 16, 16, 16, 16, 16, 31}},
    {'M', {17, 27, 21, 21, 17, 17, 17}}, {'N', {17, 17, 25, 21, 19, 17, 17}},
    {'O', {14, 17, 17, 17, 17, 17, 14}}, {'P', {30, 17, 17, 30, 16, 16, 16}},
    {'Q', {14, 17, 17, 17, 21, 18, 13}}, {'R', {30, 17, 17, 30, 20, 18, 17}},
    {'S', {15, 16, 16, 14, 1, 1, 30}},   {'T', {31, 4, 4, 4, 4, 4, 4}},
    {'U', {17, 17, 17, 17, 17, 17, 14}}, {'V', {17, 17, 17, 17, 17, 10, 4}},
    {'W', {17, 17, 17, 21, 21, 21, 10}}, {'X', {17, 17, 10, 4, 10, 17, 17}},
    {'Y', {17, 17, 10, 4, 4, 4, 4}},     {'Z', {31, 1, 2, 4, 8, 16, 31}},
    {'-', {0, 0, 0, 31, 0, 0, 0}},       {'.', {0, 0, 0, 0, 0, 12, 12}},
    {':', {0, 12, 12, 0, 12, 12, 0}},    {'/', {1, 1, 2, 4, 8, 16, 16}},
    {'(', {2, 4, 8, 8, 8, 4, 2}},        {')', {8, 4, 2, 2, 2, 4, 8}},
    {'+', {0, 4, 4, 31, 4, 4, 0}},       {'_', {0, 0, 0, 0, 0, 0, 31}},
    {'<', {2, 4, 8, 16, 8, 4, 2}},       {'>', {8, 4, 2, 1, 2, 4, 8}},
    {',', {0, 0, 0, 0, 12, 4, 8}},       {'=', {0, 0, 31, 0, 31, 0, 0}},
};

const Glyph* glyph(char c) {
  const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kFont)
    if (g.c == u) return &g;
  return nullptr;
}

}  // namespace

Rgb palette(std::size_t i) {
  static constexpr Rgb kColours[] = {{255, 80, 80},  {80, 200, 255},  {120, 255, 120},
                                     {255, 210, 60}, {230, 120, 255}, {255, 150, 60},
                                     {60, 255, 220}, {240, 240, 240}};
  return kColours[i % (sizeof(kColours) / sizeof(kColours[0]))];
}

Image::Image(int width, int height, Rgb background)
    : width_(width), height_(height), rgb_(static_cast<std::size_t>(width) * height * 3) {
  for (std::size_t i = 0; i < rgb_.size(); i += 3)
    std::copy(background.begin(), background.end(), rgb_.begin() + static_cast<long>(i));
}

void Image::blend(int x, int y, Rgb c, float alpha) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  std::uint8_t* p = &rgb_[(static_cast<std::size_t>(y) * width_ + x) * 3];
  for (int k = 0; k < 3; ++k)
    p[k] = static_cast<std::uint8_t>(std::lround(p[k] * (1.0f - alpha) + c[k] * alpha));
}

void Image::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(0, y0); y < std::min(height_, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(width_, x1); ++x) blend(x, y, c, 1.0f);
}

void Image::text(int x, int y, const std::string& s, Rgb c, int scale) {
  for (char ch : s) {
    if (const Glyph* g = glyph(ch)) {
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (g->rows[row] & (1u << (4 - col)))
            fill_rect(x + col * scale, y + row * scale, x + (col + 1) * scale,
                      y + (row + 1) * scale, c);
    }
    x += 6 * scale;
  }
}

void Image::write_png(const std::string& path) const {
  io::AtomicFile file(path);  // never a half-written picture
  if (!stbi_write_png(file.temporary().c_str(), width_, height_, 3, rgb_.data(), width_ * 3))
    throw io::IoError(path, "", "cannot write PNG file");
  file.commit();
}

void draw_points(Image& image, const std::array<int, 4>& area, const View& view,
                 const std::vector<Eigen::Vector3f>& points, Rgb colour, float alpha) {
  const auto [x0, y0, w, h] = area;
  for (const Eigen::Vector3f& p : points) {
    const double u = (p[view.horizontal_axis] - view.centre.x()) / view.metres_per_pixel;
    const double v = (p[view.vertical_axis] - view.centre.y()) / view.metres_per_pixel;
    const int px = x0 + w / 2 + static_cast<int>(std::floor(u));
    const int py = y0 + h / 2 - static_cast<int>(std::floor(v));
    if (px >= x0 && px < x0 + w && py >= y0 && py < y0 + h) image.blend(px, py, colour, alpha);
  }
}

void draw_frame_labels(Image& image, const std::array<int, 4>& area, const View& view,
                       const std::string& title) {
  const auto [x0, y0, w, h] = area;
  image.text(x0 + 8, y0 + 8, title, {230, 230, 230});
  // A 10 m scale bar in the lower left.
  const int bar = static_cast<int>(std::lround(10.0 / view.metres_per_pixel));
  image.fill_rect(x0 + 10, y0 + h - 16, x0 + 10 + bar, y0 + h - 12, {230, 230, 230});
  image.text(x0 + 14 + bar, y0 + h - 22, "10 M", {230, 230, 230});
}

}  // namespace ulc::app
