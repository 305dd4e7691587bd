// The `ulc` command under test (its path comes from tests/CMakeLists.txt).
#pragma once

#include <string>

namespace ulc_test {

inline const std::string kUlc = ULC_APP_PATH;

}  // namespace ulc_test
