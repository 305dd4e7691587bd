// Compiled with -fno-exceptions: every algorithm header must build this way (DESIGN.md).
// Add each new algorithm header here.
#include "ulc/core/cloud.hpp"
