// The results of ulc/core/observability.hpp (which holds the conventions), apart from its
// eigen-solver, so that a file that only holds or reports them (ulc::PairCalibration) stays
// light.
#pragma once

#include <string>
#include <vector>

#include "ulc/core/types.hpp"

namespace ulc {

/// One direction of the extrinsic the data leave free.
struct UnobservableDirection {
  Vec6d vector = Vec6d::Zero();  ///< unit [t; S phi], base-frame axes, turn about the centre
  double share = 0.0;            ///< its information over the best-pinned direction's
  std::string words;             ///< "translation along x of the base frame is unobservable: ..."
};

/// The observability of an extrinsic in one problem.
struct Observability {
  double weakest_share = 0.0;    ///< smallest eigenvalue of H' over the largest (0: none)
  Vec6d shares = Vec6d::Zero();  ///< every eigenvalue of H' over the largest, ascending
  Vec3d centre = Vec3d::Zero();  ///< of the points, base frame
  double length = 0.0;           ///< their RMS distance from it, m
  std::vector<UnobservableDirection> unobservable;  ///< weakest first
  bool degenerate() const { return !unobservable.empty(); }
};

}  // namespace ulc
