// Boundary bridges: one more window BA across each boundary of the hierarchy's top layer.
//
// Conventions this header owns:
//   - The top layer's windows share no member, so no BA ties one top-layer submap to the next
//     (hierarchy.hpp). A bridge is a window of the same size w over the top layer's members
//     (the submaps the top layer's windows were made of), centred on the boundary: members
//     [b - w/2, b - w/2 + w) for the boundary before member b, clamped to the layer. Its BA
//     (window_ba.hpp, the hierarchy's options) starts from the poses the hierarchy left, so
//     across the boundary from the odometry's step between the two anchors.
//   - A usable bridge yields one factor per member on the far side of the boundary (index >=
//     b): from the bridge's first member's anchor to that member's anchor, the BA's relative pose
//     and its marginal information, as every window's factor (hierarchy_detail::
//     marginal_information). The near-side members' factors are left out: their windows already
//     gave them, from the same points. Bridges never move the hierarchy's poses; the pose graph
//     weighs them with the rest.
//   - Why (docs/experiments/boundary_bridges.md): tied only by a
//     registration of two whole top submaps or by the odometry's step, a boundary passed on the
//     step's tilt error to the rest of the drive (60 s 64-32, seed 1: 0.15 deg at frame 125, 39
//     cm of height by the end); a BA over the members on both sides ties the two submaps as
//     firmly as the windows inside them.
//   - bridged[m] says whether the boundary between top-layer submaps m and m + 1 got a bridge.
//     Bridges run as TBB tasks, one slot each, and are appended in boundary order: the same
//     results for any number of threads. Nothing here throws or prints.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/hierarchy.hpp"

namespace hots {

struct BoundaryBridges {
  std::vector<bool> bridged;  ///< per top-layer boundary
  std::vector<HierarchyFactor> factors;
  std::size_t windows = 0;  ///< bridge BAs run
  std::size_t planes = 0;
};

/// Bridges over the boundaries of `h`'s top layer (see the header comment). `frames` are the
/// clouds build_hierarchy was given, `options` its options.
template <typename S>
BoundaryBridges boundary_bridges(const HierarchyResult<S>& h,
                                 const std::vector<std::vector<ulc::Vec3<S>>>& frames,
                                 const HierarchyOptions& options) {
  using Cloud = std::vector<ulc::Vec3<S>>;
  BoundaryBridges out;
  if (h.members.size() < 2 || h.members.back().size() < 2 || options.window < 2) return out;
  const auto& top = h.members.back();
  const auto& layer = h.members[h.members.size() - 2];  // the top layer's members
  const bool members_are_frames = h.members.size() == 2;
  const std::size_t w = options.window;
  out.bridged.assign(top.size() - 1, false);
  struct Slot {
    std::vector<HierarchyFactor> factors;
    bool ran = false;
    std::size_t planes = 0;
  };
  std::vector<Slot> slots(out.bridged.size());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, slots.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t m = r.begin(); m != r.end(); ++m) {
          // The boundary sits before the member that starts top submap m + 1.
          const auto at = std::find_if(layer.begin(), layer.end(), [&](const auto& member) {
            return member.begin == top[m + 1].begin;
          });
          if (at == layer.end()) continue;
          const std::size_t b = static_cast<std::size_t>(at - layer.begin());
          const std::size_t first = b - std::min(b, w / 2);
          const std::size_t last = std::min(first + w, layer.size());
          std::vector<const Cloud*> clouds;
          std::vector<Isometry3d> poses;
          for (std::size_t k = first; k < last; ++k) {
            clouds.push_back(members_are_frames ? &frames[layer[k].begin] : &layer[k].cloud);
            poses.push_back(h.poses[layer[k].begin]);
          }
          if (clouds.size() < 2 || b <= first) continue;
          Slot& s = slots[m];
          s.ran = true;
          const WindowBaResult ba = window_ba(clouds, poses, options.ba);
          if (!(ba.ok() || ba.status == WindowBaStatus::not_converged)) continue;
          const auto information = hierarchy_detail::marginal_information(ba, options.min_sigma);
          if (information.size() + 1 != clouds.size()) continue;
          s.planes = ba.planes;
          for (std::size_t k = b; k < last; ++k) {
            HierarchyFactor f;
            f.from = layer[first].begin;
            f.to = layer[k].begin;
            f.measured = ba.poses[0].inverse() * ba.poses[k - first];
            f.information = information[k - first - 1];
            f.layer = static_cast<int>(h.members.size()) - 2;
            s.factors.push_back(f);
          }
        }
      });
  for (std::size_t m = 0; m < slots.size(); ++m) {
    out.windows += slots[m].ran ? 1 : 0;
    out.planes += slots[m].planes;
    out.bridged[m] = !slots[m].factors.empty();
    out.factors.insert(out.factors.end(), slots[m].factors.begin(), slots[m].factors.end());
  }
  return out;
}

}  // namespace hots
