// Sensor models: firing rates and steps from the facts file, firing-order times spanning one
// sweep, field of view, random phases, and the non-repetitive growth of Livox coverage.
#include <catch2/catch.hpp>
#include <cmath>
#include <set>

#include "ulc/sim/sensor_catalog.hpp"

using namespace ulc::sim;
using ulc::Vec3d;

namespace {

constexpr double kDeg = M_PI / 180.0;

Vec3d dir_of(const SensorRay& r) {
  return Vec3d(std::cos(r.elevation) * std::cos(r.azimuth),
               std::cos(r.elevation) * std::sin(r.azimuth), std::sin(r.elevation));
}

SensorModel model(const std::string& name) {
  auto m = sensor_model(name);
  REQUIRE(m);
  if (auto* r = std::get_if<RisleyLidar>(&m->pattern)) r->set_session(7);
  return *m;
}

}  // namespace

TEST_CASE("catalogue: every listed model exists, unknown names do not", "[sim][sensors]") {
  for (const auto& name : sensor_model_names()) {
    INFO(name);
    CHECK(sensor_model(name).has_value());
  }
  CHECK_FALSE(sensor_model("VLP-17").has_value());
  CHECK(sensor_model_names().size() == 14);
}

TEST_CASE("point rates match the facts file at 10 Hz", "[sim][sensors]") {
  // Points per second from ../shared/reference/sensors.md (the ~ figures), within 5 %.
  const std::vector<std::pair<std::string, double>> rates = {
      {"VLP-16", 300e3},    {"HDL-32E", 695e3},   {"HDL-64E", 1.3e6},   {"VLP-32C", 600e3},
      {"RS-Helios", 576e3}, {"RS-Bpearl", 576e3}, {"Pandar64", 1.15e6}, {"Mid-40", 100e3},
      {"Horizon", 240e3},   {"Avia", 240e3},      {"Tele-15", 240e3},   {"RS-M1", 790e3}};
  for (const auto& [name, rate] : rates) {
    INFO(name);
    const SensorModel m = model(name);
    const double per_second = static_cast<double>(m.setup(10.0, 0.0, 1, 1).rays) * 10.0;
    CHECK(per_second == Approx(rate).epsilon(0.05));
  }
}

TEST_CASE("spinning models: horizontal step, real elevation tables, one revolution",
          "[sim][sensors]") {
  const std::vector<std::pair<std::string, double>> steps = {
      {"VLP-16", 0.2},    {"HDL-64E", 0.17}, {"VLP-32C", 0.2},
      {"OS1-64", 0.35},   {"OS0-128", 0.35}, {"RS-Helios", 0.2},
      {"RS-Bpearl", 0.2}, {"Pandar64", 0.2}, {"HDL-32E", 0.16}};
  for (const auto& [name, step_deg] : steps) {
    INFO(name);
    const SensorModel m = model(name);
    const auto& s = std::get<SpinningLidar>(m.pattern);
    const FrameSetup f = m.setup(10.0, 0.0, 3, 1);
    const std::size_t lasers = s.lasers();
    REQUIRE(f.rays % lasers == 0);
    const std::size_t columns = f.rays / lasers;
    CHECK(360.0 / columns == Approx(step_deg).epsilon(0.05));
    // The first laser of consecutive columns advances by one step, clockwise.
    const SensorRay a = m.ray(0, f), b = m.ray(lasers, f);
    const double step = 360.0 * 10.0 * s.column_dt(10.0);  // the head turns during one cycle
    CHECK(step == Approx(360.0 / columns).epsilon(0.01));
    CHECK((a.azimuth - b.azimuth) / kDeg == Approx(step).epsilon(1e-9));
    // The rays of a column use exactly the table's elevations.
    std::multiset<double> table(s.elevation_deg.begin(), s.elevation_deg.end()), seen;
    for (std::size_t i = 0; i < lasers; ++i)
      seen.insert(std::round(m.ray(i, f).elevation / kDeg * 1e6) / 1e6);
    std::multiset<double> rounded;
    for (double e : table) rounded.insert(std::round(e * 1e6) / 1e6);
    CHECK(seen == rounded);
    // The frame covers one revolution in one period.
    const SensorRay last = m.ray(f.rays - 1, f);
    CHECK(last.time < 0.1);
    CHECK(last.time > 0.095);
    const SensorRay last_column = m.ray(f.rays - lasers, f);  // same laser as `a`
    CHECK((a.azimuth - last_column.azimuth) / kDeg == Approx((columns - 1) * step).epsilon(1e-9));
  }
  // The tables are the published ones (spot checks against the facts file).
  const SensorModel hdl64_model = model("HDL-64E"), vlp32_model = model("VLP-32C");
  const auto& hdl64 = std::get<SpinningLidar>(hdl64_model.pattern);
  CHECK(hdl64.elevation_deg.front() == -24.711);
  CHECK(hdl64.elevation_deg.back() == 2.021);
  const auto& vlp32 = std::get<SpinningLidar>(vlp32_model.pattern);
  CHECK(vlp32.azimuth_offset_deg[1] == 4.2);
  CHECK(vlp32.elevation_deg[29] == 15.0);
}

TEST_CASE("every model: times nondecreasing in firing order, within one sweep, inside the FoV",
          "[sim][sensors]") {
  for (const auto& name : sensor_model_names()) {
    for (double rate : {10.0, 20.0}) {
      INFO(name << " at " << rate << " Hz");
      const SensorModel m = model(name);
      const FrameSetup f = m.setup(rate, 12.345, 11, 1);
      const FieldOfView fov = m.fov();
      REQUIRE(f.rays > 1000);
      double prev = -1.0;
      bool ordered = true, inside = true, unit = true;
      for (std::size_t i = 0; i < f.rays; ++i) {
        const SensorRay r = m.ray(i, f);
        ordered = ordered && r.time >= prev && r.time < 1.0 / rate;
        prev = r.time;
        inside = inside && fov.contains(dir_of(r), 1e-9);
        unit = unit && (r.dir - direction_of(r.azimuth, r.elevation)).norm() < 1e-12;
      }
      CHECK(ordered);
      CHECK(inside);
      CHECK(unit);
      CHECK(prev > 0.95 / rate);  // the sweep fills the frame period
    }
  }
}

TEST_CASE("spinning frames start at a random azimuth phase", "[sim][sensors]") {
  const SensorModel m = model("VLP-16");
  std::set<double> starts;
  for (std::uint64_t key = 0; key < 20; ++key)
    starts.insert(m.setup(10.0, 0.0, key, 1).start_azimuth);
  CHECK(starts.size() == 20);
  const double step = 2 * M_PI * 10.0 * 55.296e-6;
  CHECK(*starts.rbegin() <= M_PI);
  CHECK(*starts.begin() >= M_PI - step);
}

TEST_CASE("decimation keeps true times and every n-th column", "[sim][sensors]") {
  const SensorModel m = model("HDL-64E");
  const FrameSetup full = m.setup(10.0, 0.0, 5, 1), dec = m.setup(10.0, 0.0, 5, 4);
  CHECK(dec.rays == (full.rays / 64 + 3) / 4 * 64);
  CHECK(m.ray(64 * 3 + 5, dec).time == m.ray(64 * 12 + 5, full).time);
  CHECK(m.ray(64 * 3 + 5, dec).azimuth == m.ray(64 * 12 + 5, full).azimuth);
}

TEST_CASE("Livox patterns are non-repetitive: coverage grows with integration time",
          "[sim][sensors]") {
  // Fraction of 0.5 deg cells inside the Mid-40's 38.4 deg circle hit after 0.1, 0.2, 0.5 s.
  const SensorModel m = model("Mid-40");
  const auto& r = std::get<RisleyLidar>(m.pattern);
  auto coverage = [&](double seconds) {
    std::set<std::pair<int, int>> cells;
    const auto n = static_cast<std::size_t>(seconds * r.channel_rate_hz);
    FrameSetup f = m.setup(1.0 / seconds, 3.0, 0, 1);
    for (std::size_t i = 0; i < n; ++i) {
      const SensorRay ray = m.ray(i, f);
      cells.insert({static_cast<int>(std::floor(ray.azimuth / kDeg / 0.5)),
                    static_cast<int>(std::floor(ray.elevation / kDeg / 0.5))});
    }
    const double disc_cells = M_PI * 19.2 * 19.2 / 0.25;
    return cells.size() / disc_cells;
  };
  const double c1 = coverage(0.1), c2 = coverage(0.2), c5 = coverage(0.5);
  // The facts file: ~35 %, ~60 %, ~96 %. Our small-angle rosette should be in that class.
  CHECK(c1 > 0.2);
  CHECK(c1 < 0.5);
  CHECK(c2 > c1 + 0.1);
  CHECK(c5 > 0.85);
  // Consecutive frames sample different directions (the pattern continues, it does not restart).
  const FrameSetup f0 = m.setup(10.0, 0.0, 0, 1), f1 = m.setup(10.0, 0.1, 1, 1);
  CHECK(std::abs(m.ray(100, f0).azimuth - m.ray(100, f1).azimuth) > 1e-3);
}

TEST_CASE("MEMS raster: lasers stay in their zones, the slow axis sweeps down once per frame",
          "[sim][sensors]") {
  const SensorModel m = model("RS-M1");
  const auto& mems = std::get<MemsLidar>(m.pattern);
  const FrameSetup f = m.setup(10.0, 0.0, 0, 1);
  const std::size_t lasers = mems.zone_center_deg.size();
  double prev_el = 1e9;
  for (std::size_t i = 0; i < f.rays; i += lasers) {
    const SensorRay r = m.ray(i, f);
    REQUIRE(r.elevation <= prev_el);
    prev_el = r.elevation;
    for (std::size_t l = 0; l < lasers; ++l) {
      const SensorRay q = m.ray(i + l, f);
      REQUIRE(std::abs(q.azimuth / kDeg - mems.zone_center_deg[l]) <=
              mems.zone_half_width_deg + 1e-9);
    }
  }
  CHECK(m.ray(0, f).elevation / kDeg == Approx(12.5));
  CHECK(prev_el / kDeg < -12.0);
}
