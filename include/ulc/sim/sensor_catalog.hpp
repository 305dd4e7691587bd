// The catalogue of sensor models, built from ../shared/reference/sensors.md and the angle
// tables in sensor_tables.hpp.
//
// Conventions this header owns:
//   - Model names are the vendors' short names: VLP-16, HDL-32E, HDL-64E, VLP-32C, OS1-64,
//     OS0-128, RS-Helios, RS-Bpearl, Pandar64, Mid-40, Horizon, Avia, Tele-15, RS-M1.
//   - Figures the facts file gives are used as given (channels, angles, firing cycles, point
//     rates, ranges, noise). Where it gives none, the choice is marked "assumed" below and
//     kept close to the datasheet class of the device.
//   - Livox Horizon and Tele-15 have no published prism parameters: they use two-prism
//     rosettes with incommensurate frequencies, scaled (per axis) so the pattern just fills the
//     published field of view, as the facts file suggests. Avia uses its three published
//     prisms with deviations (n - 1) * wedge, scaled likewise.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ulc/sim/sensor_model.hpp"
#include "ulc/sim/sensor_tables.hpp"

namespace ulc::sim {

namespace detail {

template <std::size_t N>
std::vector<double> to_vector(const std::array<double, N>& a) {
  return std::vector<double>(a.begin(), a.end());
}

inline std::vector<double> uniform_table(double lo, double hi, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = lo + (hi - lo) * i / (n - 1);
  return v;
}

inline std::vector<int> sequential_slots(std::size_t n, std::size_t per_slot = 1,
                                         std::size_t modulo = 0) {
  std::vector<int> s(n);
  for (std::size_t i = 0; i < n; ++i) s[i] = static_cast<int>(modulo ? i % modulo : i / per_slot);
  return s;
}

inline RangeModel range_model(double min_range, double max_range, double sigma, double resolution) {
  RangeModel r;
  r.min_range = min_range;
  r.max_range = max_range;
  r.range_sigma = sigma;
  r.range_resolution = resolution;
  return r;
}

inline SensorModel spinning(const std::string& name, SpinningLidar s, RangeModel range,
                            double housing_radius, double housing_height) {
  s.finalize();
  return SensorModel{name, std::move(s), range,
                     Vec3d(housing_radius, housing_radius, 0.5 * housing_height)};
}

inline SensorModel risley(const std::string& name, RisleyLidar r, RangeModel range,
                          double fov_h_deg, double fov_v_deg, const Vec3d& housing_size) {
  double ch_az = 0.0, ch_el = 0.0;
  for (const auto& c : r.channels) {
    ch_az = std::max(ch_az, std::abs(c.azimuth_deg));
    ch_el = std::max(ch_el, std::abs(c.elevation_deg));
  }
  const double a = r.amplitude_sum();
  if (r.circular) {
    r.scale_az = r.scale_el = 0.5 * fov_h_deg / a;
  } else {
    r.scale_az = (0.5 * fov_h_deg - ch_az) / a;
    r.scale_el = (0.5 * fov_v_deg - ch_el) / a;
  }
  return SensorModel{name, std::move(r), range, 0.5 * housing_size};
}

}  // namespace detail

inline std::vector<std::string> sensor_model_names() {
  return {"VLP-16",    "HDL-32E",  "HDL-64E", "VLP-32C", "OS1-64", "OS0-128", "RS-Helios",
          "RS-Bpearl", "Pandar64", "Mid-40",  "Horizon", "Avia",   "Tele-15", "RS-M1"};
}

/// The model of that name, or nothing for an unknown name.
inline std::optional<SensorModel> sensor_model(const std::string& name) {
  using detail::range_model;
  using detail::sequential_slots;
  using detail::to_vector;
  namespace t = tables;
  if (name == "VLP-16") {  // 16 lasers fired one by one, 2.304 us apart, 55.296 us cycle
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kVlp16Elevation);
    s.firing_slot = sequential_slots(16);
    s.slot_dt = 2.304e-6;
    s.cycle_s = 55.296e-6;
    return detail::spinning(name, s, range_model(0.5, 100.0, 0.03, 0.002), 0.0515, 0.072);
  }
  if (name == "HDL-32E") {  // 32 lasers one by one, 1.152 us apart, 46.08 us cycle (~695k pts/s)
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kHdl32eElevation);
    s.firing_slot = sequential_slots(32);
    s.slot_dt = 1.152e-6;
    s.cycle_s = 46.08e-6;
    return detail::spinning(name, s, range_model(1.0, 100.0, 0.02, 0.002), 0.043, 0.145);
  }
  if (name == "HDL-64E") {  // upper and lower blocks fire together: 32 slots, 48 us (~1.3M pts/s)
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kHdl64eElevation);
    s.firing_slot = sequential_slots(64, 1, 32);
    s.slot_dt = 1.5e-6;
    s.cycle_s = 48e-6;
    return detail::spinning(name, s, range_model(0.9, 120.0, 0.02, 0.002), 0.1015, 0.28);
  }
  if (name == "VLP-32C") {  // lasers fire in pairs: 16 slots of 2.304 us (~600k pts/s)
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kVlp32cElevation);
    s.azimuth_offset_deg = to_vector(t::kVlp32cAzimuthOffset);
    s.firing_slot = sequential_slots(32, 2);
    s.slot_dt = 2.304e-6;
    s.cycle_s = 55.296e-6;
    return detail::spinning(name, s, range_model(0.5, 200.0, 0.03, 0.004), 0.052, 0.087);
  }
  if (name == "OS1-64" || name == "OS0-128") {  // 1024 columns, all beams of a column at once
    const bool os1 = name == "OS1-64";
    SpinningLidar s;
    s.elevation_deg =
        os1 ? to_vector(t::kOs1_64Elevation) : detail::uniform_table(45.0, -45.0, 128);
    for (std::size_t i = 0; i < s.elevation_deg.size(); ++i)  // OS0 offsets: assumed as OS1's
      s.azimuth_offset_deg.push_back(t::kOs1_64AzimuthOffset[i % 4]);
    s.fixed_columns = 1024;
    s.beam_origin_radius = os1 ? 0.012 : 0.028;
    const RangeModel r = os1 ? range_model(0.3, 120.0, 0.03, 0.001)
                             : range_model(0.3, 50.0, 0.03, 0.001);  // noise assumed
    return detail::spinning(name, s, r, 0.043, 0.074);
  }
  if (name == "RS-Helios") {  // variant 1615: -16..+15 deg; uniform 1 deg spacing assumed
    SpinningLidar s;
    s.elevation_deg = detail::uniform_table(-16.0, 15.0, 32);
    s.firing_slot = sequential_slots(32);
    s.slot_dt = 1.55e-6;
    s.cycle_s = 55.5e-6;
    return detail::spinning(name, s, range_model(0.2, 150.0, 0.02, 0.005), 0.05,
                            0.1);  // noise assumed
  }
  if (name == "RS-Bpearl") {  // hemisphere above the sensor plane; ~30 m on dark targets
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kBpearlElevation);
    s.firing_slot = sequential_slots(32);
    s.slot_dt = 1.55e-6;
    s.cycle_s = 55.5e-6;
    RangeModel r = range_model(0.1, 100.0, 0.02, 0.005);  // noise assumed
    r.reference_reflectivity = 0.9;  // 100 m only on bright targets, ~30 m at 10 %
    return detail::spinning(name, s, r, 0.05, 0.11);
  }
  if (name == "Pandar64") {
    SpinningLidar s;
    s.elevation_deg = to_vector(t::kPandar64Elevation);
    s.azimuth_offset_deg = to_vector(t::kPandar64AzimuthOffset);
    s.firing_slot = sequential_slots(64);
    s.slot_dt = 0.8e-6;
    s.cycle_s = 55.56e-6;
    return detail::spinning(name, s, range_model(0.3, 200.0, 0.02, 0.004), 0.058, 0.117);
  }
  if (name == "Mid-40") {  // two prisms at 7294 and 4664 rpm, opposite senses: 38.4 deg circle
    RisleyLidar r;
    r.prisms = {{9.73, 121.567}, {9.56, -77.733}};
    r.channel_rate_hz = 100000.0;
    r.circular = true;
    return detail::risley(name, r, range_model(1.0, 260.0, 0.02, 0.002), 38.4, 38.4,
                          Vec3d(0.088, 0.069, 0.076));
  }
  if (name == "Horizon") {  // 6 lines stacked in elevation, 40 kHz each (240k pts/s)
    RisleyLidar r;
    r.prisms = {{1.0, 137.03}, {0.9, -97.61}};
    r.channels = {{0.0, -2.5}, {0.0, -1.5}, {0.0, -0.5}, {0.0, 0.5}, {0.0, 1.5}, {0.0, 2.5}};
    r.channel_rate_hz = 40000.0;
    return detail::risley(name, r, range_model(0.5, 260.0, 0.02, 0.002), 81.7, 25.1,
                          Vec3d(0.077, 0.115, 0.084));
  }
  if (name == "Avia") {  // three prisms, deviations (1.51 - 1) * wedge; 6 channels at 40 kHz
    RisleyLidar r;
    r.prisms = {{0.51 * 30.89, -131.5463}, {0.51 * 29.77, 40.8032}, {0.51 * 3.14, 213.1611}};
    r.channels = {{-2.99, 0.0}, {-1.86, 0.0}, {-0.62, 0.0}, {0.62, 0.0}, {1.86, 0.0}, {3.04, 0.0}};
    r.channel_rate_hz = 40000.0;
    return detail::risley(name, r, range_model(1.0, 450.0, 0.02, 0.002), 70.4, 77.2,
                          Vec3d(0.091, 0.061, 0.064));
  }
  if (name == "Tele-15") {
    RisleyLidar r;
    r.prisms = {{1.0, 163.71}, {0.92, -111.29}};
    r.channel_rate_hz = 240000.0;
    return detail::risley(name, r, range_model(1.0, 500.0, 0.02, 0.002), 14.5, 16.2,
                          Vec3d(0.112, 0.101, 0.138));
  }
  if (name == "RS-M1") {  // 5 lasers, 120 x 25 deg, ~790k pts/s, 126 lines per 0.1 s
    MemsLidar m;
    return SensorModel{name, m, range_model(0.5, 200.0, 0.02, 0.005), Vec3d(0.055, 0.055, 0.025)};
  }
  return std::nullopt;
}

}  // namespace ulc::sim
