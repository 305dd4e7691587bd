// Where tests find ../shared (the real sample data) and the source tree.
#pragma once

#include <filesystem>
#include <string>

namespace ulc_test {

inline std::filesystem::path shared_dir() {
  return std::filesystem::path(ULC_SHARED_DIR);
}
inline std::filesystem::path source_dir() {
  return std::filesystem::path(ULC_SOURCE_DIR);
}

/// The real croon_0003 sample, or an empty path when ../shared is not beside the checkout.
inline std::filesystem::path croon_dir() {
  auto dir = shared_dir() / "data" / "real" / "croon_0003";
  return std::filesystem::exists(dir / "top.pcd") ? dir : std::filesystem::path();
}

/// The real bags of other people's tools (../shared/data/bags, its README says what each holds),
/// or an empty path when ../shared is not beside the checkout.
inline std::filesystem::path bags_dir() {
  auto dir = shared_dir() / "data" / "bags";
  return std::filesystem::exists(dir / "README.md") ? dir : std::filesystem::path();
}

}  // namespace ulc_test

/// Skip the rest of a TEST_CASE cleanly when a path is missing (Catch2 v2 has no SKIP).
#define ULC_SKIP_UNLESS(cond, why) \
  do {                             \
    if (!(cond)) {                 \
      WARN("skipped: " << why);    \
      return;                      \
    }                              \
  } while (0)
