// bench_covariance: is the covariance the pipeline reports honest?
//
//   bench_covariance [--scenarios 64-32,32-16,horizon-tele,64-horizon,32-avia,64-tele,
//                                 ring-5x16,side-bpearl] [--seconds 10] [--runs 10]
//                    [--first-run 0] [--estimate-offset] [--parked [--parked-seconds 0.1]]
//                    [--threads 2] [--json]
//
// Per scenario and run (seed = run + 1) the drive is simulated and every pair of its ground truth
// (base -> each target: one for the paper's pairs, one per target for a rig) is calibrated by
// the default pipeline (TERRA, JEEP, HOTS; no initial guess). The clocks are told to agree
// (CalibrateOptions::time_offset_s = the true offset, zero on these rigs: HOTS's known-offset
// path) unless --estimate-offset, which lets HOTS estimate and check the offset (a 10 s drive
// then usually fails with time_offset_untrusted: no covariance to check). --parked: the vehicle
// stands still and one frame per LiDAR is calibrated (HOTS is skipped: JEEP's covariance).
//
// For each success with a covariance Sigma (PairCalibration::covariance_6x6, [rho; phi], left):
//   xi = log(T_true T_est^-1)  (the 6-D error, the left perturbation that takes T_est to T_true),
//   d^2 = xi^T Sigma^-1 xi     (squared Mahalanobis distance; chi-square with 6 dof if honest),
//   inside 3-sigma:  d^2 <= 20.06, the chi-square(6) quantile at 99.73 % (the probability of
//                    |x| <= 3 sigma in one dimension carried to six),
//   normalised error e = sqrt(d^2 / 6)  (about 1 for an honest covariance: its median is
//                    sqrt(5.35 / 6) = 0.94; far below 1 means inflated sigmas).
// Per scenario: runs (pairs calibrated), successes, false successes (ok but beyond 1 deg or
// 10 cm: must be 0), results the covariance did not vouch for (status uncertain) and how many of
// those were within 1 deg / 10 cm anyway, successes with a covariance, coverage (%)
// within 3-sigma, the median e, and the median rotation / translation errors; then an overall
// row. The bar: coverage >= 95 %, median e >= 0.3.
#include <tbb/task_arena.h>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "pipeline/calibrate.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/angles.hpp"
#include "ulc/core/lie.hpp"
#include "ulc/core/mahalanobis.hpp"
#include "ulc/core/pose_error.hpp"
#include "ulc/core/small_sample.hpp"
#include "ulc/sim/simulate.hpp"

namespace {

using ulc::Isometry3d;
using ulc_bench::Cell;

struct Config {
  std::vector<std::string> scenarios{"64-32",   "32-16",   "horizon-tele", "64-horizon",
                                     "32-avia", "64-tele", "ring-5x16",    "side-bpearl"};
  double seconds = 10.0;
  std::size_t runs = 10;
  std::size_t first_run = 0;
  bool estimate_offset = false;
  bool parked = false;
  double parked_seconds = 0.1;  ///< the parked recording's length: 0.1 s is one frame per LiDAR
  int threads = 2;
  ulc_bench::Options bench;
};

/// One calibrated pair: its errors and d^2 (negative: no covariance).
struct Outcome {
  bool success = false;
  bool uncertain = false;  ///< status uncertain: the covariance did not vouch (confidence.hpp)
  bool right = false;      ///< within the paper's success threshold (1 deg, 10 cm)
  double d2 = -1.0;
  double rotation_deg = 0.0, translation_m = 0.0;
};

ulc::sim::Dataset simulate(const std::string& scenario, std::uint64_t seed, const Config& c) {
  ulc::sim::SimulationOptions o;
  o.seed = seed;
  o.seconds = c.parked ? c.parked_seconds : c.seconds;
  if (c.parked) o.static_at_s = 5.0;
  const auto spec = ulc::sim::scenario(scenario);
  if (!spec) return {};
  return ulc::sim::simulate(*spec, o).dataset;
}

/// ", free space 0.283 (385 judged), through 0.04 (1200 rays)" for a parked answer the check
/// judged (pipeline/free_space.hpp).
std::string free_space_note(const ulc::PairCalibration& r) {
  if (!r.jeep || !r.jeep->free_space) return "";
  const ulc::FreeSpaceVerdict& v = *r.jeep->free_space;
  std::ostringstream s;
  s << ", free space " << v.share() << " (" << v.judged << " judged), through " << v.through_share()
    << " (" << v.rays_judged << " rays)";
  return s.str();
}

/// ", two-way gap 1.2 cm / 0.031 deg" when JEEP met both directions halfway (jeep/two_way.hpp).
std::string two_way_note(const ulc::PairCalibration& r) {
  if (!r.jeep || !r.jeep->two_way) return "";
  std::ostringstream s;
  s << ", two-way gap " << 100.0 * r.jeep->two_way_gap_translation << " cm / "
    << r.jeep->two_way_gap_rotation * ulc::kDegPerRad << " deg";
  return s.str();
}

Outcome calibrate(const ulc::sim::Dataset& d, const ulc::sim::PairTruth& truth, const Config& c) {
  const auto* a = d.find(truth.base);
  const auto* b = d.find(truth.target);
  Outcome out;
  if (!a || !b) return out;
  ulc::CalibrateOptions o;
  if (!c.estimate_offset) o.time_offset_s = truth.time_offset_s;
  const ulc::PairCalibration r =
      ulc::calibrate_pair(a->frames, a->timestamps, b->frames, b->timestamps, o);
  const auto e = ulc::pose_error(truth.T_base_target, r.T_base_target);
  out.success = r.success;
  out.uncertain = r.status == ulc::CalibrateStatus::uncertain;
  out.right = ulc::is_calibration_success(e);
  out.rotation_deg = e.rotation_deg;
  out.translation_m = e.translation_m;
  if (r.success && r.covariance_6x6) {
    const ulc::Vec6d xi = ulc::se3_log(Isometry3d(truth.T_base_target * r.T_base_target.inverse()));
    out.d2 = ulc::mahalanobis_sq(xi, *r.covariance_6x6).value_or(-1.0);
  }
  if (!c.bench.json)
    std::cerr << "  " << d.scenario << " seed " << d.seed << " " << truth.target << ": "
              << ulc::to_string(r.status) << ", " << e.rotation_deg << " deg, "
              << 100.0 * e.translation_m
              << " cm, e = " << (out.d2 >= 0.0 ? std::sqrt(out.d2 / 6.0) : -1.0) << ", 3 sigma "
              << (r.covariance_6x6 ? 300.0 * std::sqrt(r.covariance_6x6->topLeftCorner<3, 3>()
                                                           .selfadjointView<Eigen::Lower>()
                                                           .eigenvalues()
                                                           .maxCoeff())
                                   : -1.0)
              << " cm" << free_space_note(r) << two_way_note(r) << "\n";
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return ulc_bench::median_of_sorted(v);
}

struct Tally {
  std::size_t runs = 0, successes = 0, false_successes = 0, with_covariance = 0, inside = 0;
  std::size_t uncertain = 0, uncertain_right = 0;
  std::vector<double> normalised, rotation_deg, translation_cm;

  void add(const Outcome& o, double limit) {
    ++runs;
    uncertain += o.uncertain ? 1 : 0;
    uncertain_right += o.uncertain && o.right ? 1 : 0;
    if (!o.success) return;
    ++successes;
    false_successes += o.right ? 0 : 1;
    rotation_deg.push_back(o.rotation_deg);
    translation_cm.push_back(100.0 * o.translation_m);
    if (o.d2 < 0.0) return;
    ++with_covariance;
    inside += o.d2 <= limit ? 1 : 0;
    normalised.push_back(std::sqrt(o.d2 / 6.0));
  }
  void add(const Tally& t) {
    runs += t.runs;
    successes += t.successes;
    false_successes += t.false_successes;
    uncertain += t.uncertain;
    uncertain_right += t.uncertain_right;
    with_covariance += t.with_covariance;
    inside += t.inside;
    normalised.insert(normalised.end(), t.normalised.begin(), t.normalised.end());
    rotation_deg.insert(rotation_deg.end(), t.rotation_deg.begin(), t.rotation_deg.end());
    translation_cm.insert(translation_cm.end(), t.translation_cm.begin(), t.translation_cm.end());
  }
  std::vector<Cell> row(const std::string& name) const {
    const auto integer = [](std::size_t n) { return Cell::integer(static_cast<long long>(n)); };
    const Cell coverage =
        with_covariance
            ? Cell::num(100.0 * static_cast<double>(inside) / static_cast<double>(with_covariance),
                        1)
            : Cell("-");
    const auto med = [](const std::vector<double>& v, int digits) {
      return v.empty() ? Cell("-") : Cell::num(median(v), digits);
    };
    return {name,
            integer(runs),
            integer(successes),
            integer(false_successes),
            integer(uncertain),
            integer(uncertain_right),
            integer(with_covariance),
            coverage,
            med(normalised, 3),
            med(rotation_deg, 4),
            med(translation_cm, 3)};
  }
};

void bench(const Config& c) {
  const double limit = ulc::chi_square_quantile(ulc::kThreeSigmaLevel, 6);
  ulc_bench::Table table({"scenario", "runs", "successes", "false_successes", "uncertain",
                          "uncertain_right", "with_covariance", "coverage_3sigma_pct",
                          "median_normalised_error", "median_e_rot_deg", "median_e_trans_cm"});
  Tally all;
  tbb::task_arena arena(c.threads);
  for (const auto& scenario : c.scenarios) {
    Tally t;
    for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run) {
      arena.execute([&] {
        const ulc::sim::Dataset d = simulate(scenario, run + 1, c);
        if (d.lidars.size() < 2) {
          std::cerr << "bench_covariance: cannot simulate scenario '" << scenario << "'\n";
          std::exit(2);
        }
        for (const auto& truth : d.pairs) t.add(calibrate(d, truth, c), limit);
      });
    }
    table.add_row(t.row(scenario));
    all.add(t);
  }
  table.add_row(all.row("all"));
  ulc_bench::emit(std::cout, table, c.bench.json, "covariance", 1,
                  {{"seconds", Cell::num(c.parked ? c.parked_seconds : c.seconds, 1)},
                   {"runs", Cell::integer(static_cast<long long>(c.runs))},
                   {"first_run", Cell::integer(static_cast<long long>(c.first_run))},
                   {"offset", c.estimate_offset ? "estimated" : "known"},
                   {"parked", c.parked ? "yes" : "no"},
                   {"threads", Cell::integer(c.threads)}},
                  {{"chi2_6_99.73", Cell::num(limit, 2)}});
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app("Coverage of the reported covariance over simulated runs", "bench_covariance");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--scenarios", c.scenarios, "scenarios")->delimiter(',')->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated drive (default 10)")->type_name("S");
  app.add_option("--runs", c.runs, "runs per scenario (default 10)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  app.add_flag("--estimate-offset", c.estimate_offset,
               "let HOTS estimate the clock offset (default: told the true one)");
  app.add_flag("--parked", c.parked, "one frame per LiDAR of a parked rig (JEEP's covariance)");
  app.add_option("--parked-seconds", c.parked_seconds, "the parked recording's length (s)");
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
