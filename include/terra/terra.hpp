// Convenience include: all of TERRA (rotation initialisation) and the scancontext* baseline.
#pragma once

#include "terra/descriptor.hpp"
#include "terra/distance.hpp"
#include "terra/kdtree_lookup.hpp"
#include "terra/lattice.hpp"
#include "terra/plane_fit.hpp"
#include "terra/profile.hpp"
#include "terra/random_rotation.hpp"
#include "terra/rotate.hpp"
#include "terra/rotation_grid.hpp"
#include "terra/scan_context.hpp"
#include "terra/search.hpp"
