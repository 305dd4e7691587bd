// Convenience include: the traits, the built-in cloud types and ulc::PointCloud.
#pragma once

#include "ulc/core/builtin_traits.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/core/point_traits.hpp"
