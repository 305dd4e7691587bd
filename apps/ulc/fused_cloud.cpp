#include "fused_cloud.hpp"

#include <cstdint>
#include <cstring>
#include <string>

#include "top_down_image.hpp"
#include "ulc/io/file_bytes.hpp"

namespace ulc::app {

void write_fused_cloud(const std::string& pcd, const std::vector<FusedPart>& parts) {
  std::size_t n = 0;
  for (const auto& part : parts) n += part.points.size();
  std::vector<float> record;  // x y z rgb lidar per point
  record.reserve(n * 5);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Rgb c = palette(i);
    // PCL packs 0x00RRGGBB into the bits of a float32.
    const std::uint32_t packed = std::uint32_t{c[0]} << 16 | std::uint32_t{c[1]} << 8 | c[2];
    float rgb;
    std::memcpy(&rgb, &packed, sizeof rgb);
    const Eigen::Isometry3f T = parts[i].T_base_lidar.cast<float>();
    for (const auto& p : parts[i].points) {
      const Eigen::Vector3f q = T * p;
      record.insert(record.end(), {q.x(), q.y(), q.z(), rgb, static_cast<float>(i)});
    }
  }
  std::string text =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb lidar\n"
      "SIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\nWIDTH " +
      std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) +
      "\nDATA binary\n";
  // Little-endian hosts only write this byte order; PCD binary is the host's float layout,
  // which every reader of PCD assumes to be little-endian.
  const auto* bytes = reinterpret_cast<const char*>(record.data());
  text.append(bytes, record.size() * sizeof(float));
  io::write_file_text(pcd, text);  // atomic: never half a cloud
}

}  // namespace ulc::app
