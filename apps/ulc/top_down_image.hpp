// Pictures a person can check by eye: clouds drawn top-down (x right, y up) or from the side
// (x right, z up), one colour per cloud, written as PNG. Used by `ulc simulate --preview`.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ulc::app {

using Rgb = std::array<std::uint8_t, 3>;

/// Distinct colours for up to eight LiDARs, then repeating.
Rgb palette(std::size_t i);

class Image {
 public:
  Image(int width, int height, Rgb background);
  int width() const { return width_; }
  int height() const { return height_; }
  /// Blends `c` into pixel (x, y) with weight `alpha` in [0, 1]; outside pixels are ignored.
  void blend(int x, int y, Rgb c, float alpha);
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
  /// Draws text in a 5x7 pixel font (digits, letters, a few signs), `scale` pixels per dot.
  void text(int x, int y, const std::string& s, Rgb c, int scale = 2);
  /// Throws ulc::io::IoError when the file cannot be written.
  void write_png(const std::string& path) const;
  const std::vector<std::uint8_t>& pixels() const { return rgb_; }

 private:
  int width_, height_;
  std::vector<std::uint8_t> rgb_;
};

/// A view of the plane spanned by two axes of the base frame (0 = x, 1 = y, 2 = z).
struct View {
  int horizontal_axis = 0;
  int vertical_axis = 1;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double metres_per_pixel = 0.1;
};

/// Projects points (already in a common frame) into `area` of the image (x0, y0, w, h).
void draw_points(Image& image, const std::array<int, 4>& area, const View& view,
                 const std::vector<Eigen::Vector3f>& points, Rgb colour, float alpha = 0.6f);

/// A scale bar and a title in the corner of an area.
void draw_frame_labels(Image& image, const std::array<int, 4>& area, const View& view,
                       const std::string& title);

}  // namespace ulc::app
