#include "calibration_report.hpp"

#include <algorithm>
#include <array>

#include "top_down_image.hpp"

namespace ulc::app {

void write_calibration_report(const std::string& png, const std::vector<ReportCloud>& clouds,
                              double view_radius_m) {
  constexpr int kPanel = 700, kSide = 220, kLegend = 36;
  Image image(2 * kPanel, kPanel + kSide + kLegend, {18, 18, 22});
  const double mpp = 2.0 * view_radius_m / kPanel;
  const View top_view{0, 1, Eigen::Vector2d(0, 0), mpp};
  const View side_view{0, 2, Eigen::Vector2d(0, 2.0), mpp};
  for (int column = 0; column < 2; ++column) {
    const bool after = column == 1;
    const std::array<int, 4> top{column * kPanel, 0, kPanel, kPanel};
    const std::array<int, 4> side{column * kPanel, kPanel, kPanel, kSide};
    for (std::size_t i = 0; i < clouds.size(); ++i) {
      const Eigen::Isometry3f T = (after ? clouds[i].after : clouds[i].before).cast<float>();
      std::vector<Eigen::Vector3f> moved;
      moved.reserve(clouds[i].points.size());
      for (const auto& p : clouds[i].points) moved.push_back(T * p);
      draw_points(image, top, top_view, moved, palette(i), 0.45f);
      draw_points(image, side, side_view, moved, palette(i), 0.3f);
    }
    draw_frame_labels(image, top, top_view,
                      after ? "after calibration, top view (base frame)"
                            : "before (initial guess), top view (base frame)");
    draw_frame_labels(image, side, side_view, "side view (x right, z up)");
  }
  image.fill_rect(kPanel - 1, 0, kPanel + 1, kPanel + kSide, {90, 90, 90});
  image.fill_rect(0, kPanel, 2 * kPanel, kPanel + 2, {90, 90, 90});
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    const int x = 10 + 230 * static_cast<int>(i % 6);
    const int y = kPanel + kSide + 10;
    image.fill_rect(x, y, x + 16, y + 16, palette(i));
    image.text(x + 22, y + 2, clouds[i].name.substr(0, 16) + (i == 0 ? " (base)" : ""),
               {220, 220, 220});
  }
  image.write_png(png);
}

}  // namespace ulc::app
