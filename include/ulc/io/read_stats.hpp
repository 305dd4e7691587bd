// ReadStats: what a reader found in a file, for callers that want to report or check it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ulc::io {

struct ReadStats {
  std::string format;               ///< "pcd", "ply" or "kitti_bin"
  std::string encoding;             ///< "ascii", "binary", "binary_compressed",
                                    ///< "binary_little_endian", "binary_big_endian"
  std::vector<std::string> fields;  ///< every field / vertex property, in file order
  std::string intensity_field;      ///< field read as intensity; empty when none
  std::string time_field;           ///< field read as per-point time; empty when none
  double time_scale = 1.0;          ///< seconds per unit of time_field (1e-9 for integer ns)
  std::size_t width = 0;            ///< PCD WIDTH; the point count for other formats
  std::size_t height = 0;           ///< PCD HEIGHT (> 1: organised); 1 for other formats
  std::size_t points_in_file = 0;   ///< PCD POINTS, PLY vertex count, KITTI size / 16
  std::size_t points_read = 0;      ///< points returned
  std::size_t points_dropped_nonfinite = 0;  ///< points with a NaN / Inf coordinate, dropped
};

}  // namespace ulc::io
