// A planar driving path of straight lines and circular arcs, parametrised by arc length.
//
// Conventions this header owns:
//   - Heading is the angle of the direction of travel from the world x axis (counter-
//     clockwise, radians); curvature is dheading/ds (positive: turning left).
//   - at(s) is exact (closed form per segment), continuous in position and heading; before 0
//     it clamps, beyond length() it continues straight along the final heading.
//   - Corners are filleted: add a corner point and a radius, and the path turns on the arc
//     tangent to both legs (fillet_polyline).
//   - averaged(s, L) is the path's moving average over [s - L/2, s + L/2] (exact, from the
//     closed-form integral of the position; before 0 the path is extended straight back): its
//     heading is that of the chord between the ends of that stretch, so its curvature ramps in
//     over L where a line meets an arc instead of stepping (a clothoid-like transition), and on
//     an arc of radius R it runs about L^2 / (24 R) inside the arc.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace ulc::sim {

struct PathPoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double heading = 0.0;
  double curvature = 0.0;
};

class Path2d {
 public:
  Path2d() = default;
  Path2d(const Eigen::Vector2d& start, double heading) : end_{start, heading, 0.0} {}

  /// Straight ahead by `length` metres.
  void add_line(double length) { add_segment(length, 0.0); }
  /// An arc of the given radius turning by `sweep` radians (positive: left).
  void add_arc(double radius, double sweep) {
    if (sweep == 0.0 || radius <= 0.0) return;
    add_segment(radius * std::abs(sweep), (sweep > 0 ? 1.0 : -1.0) / radius);
  }

  double length() const { return segments_.empty() ? 0.0 : segments_.back().s1(); }
  bool empty() const { return segments_.empty(); }
  /// Where the path currently ends (the start of the next segment).
  const PathPoint& end() const { return end_; }

  /// See offset_path().
  Path2d offset(double offset) const {
    const PathPoint p0 = at(0.0);
    Path2d out(p0.position + offset * Eigen::Vector2d(-std::sin(p0.heading), std::cos(p0.heading)),
               p0.heading);
    for (const Segment& seg : segments_) {
      if (seg.curvature == 0.0) {
        out.add_line(seg.length);
      } else {
        const double radius = 1.0 / std::abs(seg.curvature);
        out.add_arc(radius - (seg.curvature > 0.0 ? offset : -offset), seg.curvature * seg.length);
      }
    }
    return out;
  }

  /// Integral of the position from 0 to s (m^2); before 0 the path is taken straight back
  /// along its start heading (as in averaged(), unlike at(), which clamps there).
  Eigen::Vector2d position_integral(double s) const {
    const PathPoint p0 = at(0.0);
    if (segments_.empty()) return s * p0.position;
    if (s <= 0.0)
      return s * p0.position +
             0.5 * s * s * Eigen::Vector2d(std::cos(p0.heading), std::sin(p0.heading));
    if (s >= length()) {
      const double u = s - length();
      const Segment& last = segments_.back();
      const Eigen::Vector2d d(std::cos(end_.heading), std::sin(end_.heading));
      return last.integral0 + last.integral(last.length) + u * end_.position + 0.5 * u * u * d;
    }
    auto it = std::upper_bound(segments_.begin(), segments_.end(), s,
                               [](double v, const Segment& seg) { return v < seg.s0; });
    const Segment& seg = *(it - 1);
    return seg.integral0 + seg.integral(s - seg.s0);
  }

  /// The moving average of the path over `window` metres centred on s (see the conventions):
  /// position, the chord's heading (unwrapped next to at(s).heading) and its rate of change per
  /// metre of s, as curvature.
  PathPoint averaged(double s, double window) const {
    const PathPoint here = at(s);
    if (!(window > 0.0)) return here;
    const PathPoint a = extended_at(s - 0.5 * window), b = extended_at(s + 0.5 * window);
    const Eigen::Vector2d chord = b.position - a.position;
    PathPoint out;
    out.position =
        (position_integral(s + 0.5 * window) - position_integral(s - 0.5 * window)) / window;
    const double n2 = chord.squaredNorm();
    if (!(n2 > 1e-18)) return here;
    out.heading = here.heading + std::remainder(std::atan2(chord.y(), chord.x()) - here.heading,
                                                6.283185307179586);
    // d chord / ds = tangent(s + L/2) - tangent(s - L/2).
    const Eigen::Vector2d dchord = Eigen::Vector2d(std::cos(b.heading), std::sin(b.heading)) -
                                   Eigen::Vector2d(std::cos(a.heading), std::sin(a.heading));
    out.curvature = (chord.x() * dchord.y() - chord.y() * dchord.x()) / n2;
    return out;
  }

  /// at(s), but before 0 straight back along the start heading instead of clamped.
  PathPoint extended_at(double s) const {
    if (s >= 0.0 || segments_.empty()) return at(s);
    PathPoint p = at(0.0);
    p.position += s * Eigen::Vector2d(std::cos(p.heading), std::sin(p.heading));
    p.curvature = 0.0;
    return p;
  }

  PathPoint at(double s) const {
    if (segments_.empty()) return end_;
    s = std::max(s, 0.0);
    if (s >= length()) {
      PathPoint p = end_;
      p.position += (s - length()) * Eigen::Vector2d(std::cos(p.heading), std::sin(p.heading));
      p.curvature = 0.0;
      return p;
    }
    // Last segment starting at or before s.
    auto it = std::upper_bound(segments_.begin(), segments_.end(), s,
                               [](double v, const Segment& seg) { return v < seg.s0; });
    const Segment& seg = *(it - 1);
    return seg.eval(s - seg.s0);
  }

 private:
  struct Segment {
    double s0;
    double length;
    double curvature;
    PathPoint start;
    Eigen::Vector2d integral0 = Eigen::Vector2d::Zero();  ///< position integral from 0 to s0
    double s1() const { return s0 + length; }
    /// Integral of the position over the first u metres of this segment.
    Eigen::Vector2d integral(double u) const {
      const double h0 = start.heading;
      const double c0 = std::cos(h0), s0h = std::sin(h0);
      if (curvature == 0.0) return u * start.position + 0.5 * u * u * Eigen::Vector2d(c0, s0h);
      const double k = curvature, h = h0 + k * u;
      return u * start.position +
             Eigen::Vector2d((c0 - std::cos(h)) / k - u * s0h, u * c0 - (std::sin(h) - s0h) / k) /
                 k;
    }
    PathPoint eval(double u) const {
      PathPoint p;
      p.curvature = curvature;
      const double h0 = start.heading;
      if (curvature == 0.0) {
        p.heading = h0;
        p.position = start.position + u * Eigen::Vector2d(std::cos(h0), std::sin(h0));
      } else {
        const double h = h0 + curvature * u;
        p.heading = h;
        p.position =
            start.position +
            Eigen::Vector2d(std::sin(h) - std::sin(h0), std::cos(h0) - std::cos(h)) / curvature;
      }
      return p;
    }
  };

  void add_segment(double length, double curvature) {
    if (!(length > 0.0)) return;
    Segment seg{this->length(), length, curvature, end_};
    seg.start.curvature = curvature;
    seg.integral0 = segments_.empty()
                        ? Eigen::Vector2d::Zero().eval()
                        : Eigen::Vector2d(segments_.back().integral0 +
                                          segments_.back().integral(segments_.back().length));
    segments_.push_back(seg);
    end_ = seg.eval(length);
    end_.curvature = 0.0;
  }

  std::vector<Segment> segments_;
  PathPoint end_;
};

/// One corner of a polyline to be filleted: the turn happens at `point` with `radius`.
struct PathCorner {
  Eigen::Vector2d point;
  double radius;
};

/// A path from `start` through filleted corners to `finish`. Each leg must be long enough for
/// the tangent lengths of the fillets at its ends (the caller's road geometry guarantees it).
inline Path2d fillet_polyline(const Eigen::Vector2d& start, const std::vector<PathCorner>& corners,
                              const Eigen::Vector2d& finish) {
  std::vector<Eigen::Vector2d> pts;
  pts.push_back(start);
  for (const PathCorner& c : corners) pts.push_back(c.point);
  pts.push_back(finish);
  const Eigen::Vector2d d0 = (pts[1] - pts[0]).normalized();
  Path2d path(start, std::atan2(d0.y(), d0.x()));
  Eigen::Vector2d cursor = start;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Eigen::Vector2d din = (pts[k + 1] - pts[k]).normalized();
    const Eigen::Vector2d dout = (pts[k + 2] - pts[k + 1]).normalized();
    const double turn = std::atan2(din.x() * dout.y() - din.y() * dout.x(), din.dot(dout));
    const double tangent = corners[k].radius * std::tan(std::abs(turn) / 2.0);
    const Eigen::Vector2d arc_start = pts[k + 1] - tangent * din;
    path.add_line((arc_start - cursor).norm());
    path.add_arc(corners[k].radius, turn);
    cursor = pts[k + 1] + tangent * dout;
  }
  path.add_line((finish - cursor).norm());
  return path;
}

/// The same path shifted sideways by `offset` metres (positive: left), segment by segment: a
/// line stays a line of the same length, an arc of radius R turning by the same angle becomes
/// one of radius R - offset (turning left) or R + offset (turning right). The offset must be
/// smaller than every such radius.
inline Path2d offset_path(const Path2d& center, double offset) {
  return center.offset(offset);
}

}  // namespace ulc::sim
