// PCD v0.7: read (ascii, binary, binary_compressed) and write. See pcd_read.hpp, pcd_write.hpp.
#pragma once

#include "ulc/io/pcd_read.hpp"
#include "ulc/io/pcd_write.hpp"
