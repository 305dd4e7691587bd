// Convenience include: every point-cloud reader and writer, and dataset sequences.
#pragma once

#include "ulc/io/cloud_file.hpp"
#include "ulc/io/io_error.hpp"
#include "ulc/io/kitti_bin.hpp"
#include "ulc/io/pcd.hpp"
#include "ulc/io/ply.hpp"
#include "ulc/io/sequence.hpp"
