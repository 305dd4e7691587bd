// PLY: read (ascii, binary little / big endian) and write. See ply_read.hpp, ply_write.hpp.
#pragma once

#include "ulc/io/ply_read.hpp"
#include "ulc/io/ply_write.hpp"
