// bench_trust: does HOTS tell a right extrinsic from a wrong one JEEP accepted or handed over?
//
//   bench_trust [--scenarios 64-tele,horizon-tele,64-32] [--seconds 20] [--runs 2]
//               [--first-run 0] [--threads 2] [--json]
//
// TERRA's failure mode on a narrow-FoV pair is a wrong rotation, often the street's
// forward/backward symmetry (a yaw of about 180 deg), with zero translation. This bench makes
// such starts on purpose: per scenario and run (seed = run + 1), JEEP (K = 5, the pipeline's
// options) starts from the true rotation, from the paper's disturbance (5 deg about a random
// axis, 2 m), and from the true rotation turned by 10, 20, 45, 90 and 166 deg of yaw, each with
// zero translation. Where JEEP accepts, or fails in a way the pipeline hands to HOTS (rejected,
// not settled: CalibrateOptions::tuning.hypotheses.hots_judges_jeep), the pipeline's odometry and
// HOTS run with the cross-link trust rule switched off (RefineOptions::min_cross_link_ratio = 0) so
// that every start shows what HOTS would have returned; the table gives the cross links agreeing
// with the start, kept, and attempted (cross_links.hpp), the verdict the default rule would give
// (confirmed / unconfirmed; "in reach": the counts of its second look, the links kept by their
// inlier ratio over b's points within a's reach; a start that look confirms is refined again
// with the default rule, since its links then enter the graph), and the truth (right: HOTS's
// extrinsic within the paper's success threshold, 1 deg and 10 cm). The figure of merit: the
// largest agreeing share among wrong results against the smallest among right ones (the rule's
// margin), printed after the table.
#include <tbb/task_arena.h>
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "../tests/jeep/jeep_test_util.hpp"
#include "hots/hots.hpp"
#include "odometry/run_odometry.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/pipeline.hpp"
#include "support/bench_util.hpp"
#include "ulc/core/pose_error.hpp"

namespace {

using ulc::Isometry3d;
using ulc_bench::Cell;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Config {
  std::vector<std::string> scenarios{"64-tele", "horizon-tele", "64-32"};
  double seconds = 20.0;
  std::size_t runs = 2;
  std::size_t first_run = 0;
  int threads = 2;
  ulc_bench::Options bench;
};

struct Start {
  std::string name;
  Isometry3d initial;
};

/// The cross-link statistics as the default trust rule judges them: the links HOTS kept with
/// the rule off, and, where the rule would take its second look within a's reach
/// (hots/refine_steps.hpp), the links that look keeps (hots::select_links on the
/// registrations' records).
hots::RefineStatistics judged_as_by_default(hots::RefineStatistics st,
                                            const hots::RefineOptions& defaults) {
  namespace hd = hots::hots_detail;
  st.link_verdict = hd::judge_links(st, defaults);
  if (!hd::second_look_within_reach(st, defaults)) return st;
  std::vector<hots::LinkRegistration> registrations;
  for (const auto& r : st.cross_link_records) {
    hots::LinkRegistration reg;
    reg.converged = r.converged;
    reg.inlier_ratio = r.inlier_ratio;
    reg.inlier_ratio_in_reach = r.inlier_ratio_in_reach;
    reg.link.moved_rad = r.moved_rad;
    reg.link.moved_m = r.moved_m;
    registrations.push_back(reg);
  }
  hots::CrossLinkStats counts;
  st.cross_links = hots::select_links(registrations, defaults.links, true, counts).size();
  st.cross_links_agreeing = counts.agreeing;
  st.links_judged_within_reach = true;
  st.link_verdict = hd::judge_links(st, defaults);
  return st;
}

std::vector<Start> starts(const Isometry3d& truth, std::size_t run) {
  std::vector<Start> out;
  Isometry3d rotation_only = Isometry3d::Identity();
  rotation_only.linear() = truth.linear();
  out.push_back({"true rotation", rotation_only});
  std::mt19937_64 rng(1000003ULL * (run + 1));
  out.push_back({"5 deg, 2 m", jeep_test::disturbed(truth, rng, 5.0 * kDeg, 2.0)});
  for (const double yaw : {10.0, 20.0, 45.0, 90.0, 166.0}) {
    Isometry3d s = Isometry3d::Identity();
    s.linear() =
        Eigen::AngleAxisd(yaw * kDeg, ulc::Vec3d::UnitZ()).toRotationMatrix() * truth.linear();
    out.push_back({"yaw " + std::to_string(static_cast<int>(yaw)) + " deg", s});
  }
  return out;
}

struct Margin {
  double wrong_max = -1.0, right_min = 2.0;  ///< agreeing shares; sentinels: none seen
  std::size_t wrong = 0, right = 0, wrong_confirmed = 0, right_unconfirmed = 0;
};

void bench(const Config& c) {
  ulc_bench::Table table({"scenario", "seed", "start", "jeep", "jeep_e_rot_deg", "jeep_e_trans_cm",
                          "hots", "e_rot_deg", "e_trans_cm", "links_agree_kept_tried", "agree_pct",
                          "rule", "truth"});
  Margin m;
  tbb::task_arena arena(c.threads);
  for (const auto& scenario : c.scenarios) {
    for (std::size_t run = c.first_run; run < c.first_run + c.runs; ++run) {
      jeep_test::DriveSpec spec;
      spec.scenario = scenario;
      spec.seconds = c.seconds;
      spec.seed = run + 1;
      const ulc::sim::Dataset d = arena.execute([&] { return jeep_test::simulate(spec); });
      if (d.lidars.size() < 2) {
        std::cerr << "bench_trust: cannot simulate scenario '" << scenario << "'\n";
        std::exit(2);
      }
      const auto& a = d.lidars[0];
      const auto& b = d.lidars[1];
      const Isometry3d truth = d.pairs.at(0).T_base_target;
      for (const Start& s : starts(truth, run)) {
        arena.execute([&] {
          ulc::CalibrateOptions o;
          o.stages = {ulc::Stage::jeep};
          o.initial = s.initial;
          // HOTS, run next, estimates the clock offset: JEEP's own result need not vouch for one.
          o.tuning.vouch.enabled = false;
          const auto j = ulc::calibrate_pair(a.frames, a.timestamps, b.frames, b.timestamps, o);
          const auto je = ulc::pose_error(truth, j.jeep ? j.jeep->extrinsic : s.initial);
          std::vector<Cell> row{scenario,
                                Cell::integer(static_cast<long long>(run + 1)),
                                s.name,
                                ulc::to_string(j.status),
                                Cell::num(je.rotation_deg, 3),
                                Cell::num(100.0 * je.translation_m, 2)};
          // As the pipeline does (CalibrateOptions::tuning.hypotheses.hots_judges_jeep): a JEEP
          // that was rejected or did not settle hands its extrinsic to HOTS.
          if (!j.success && !(j.jeep && ulc::calibrate_detail::hots_can_judge(*j.jeep))) {
            for (int k = 0; k < 7; ++k) row.push_back("-");
            table.add_row(row);
            return;
          }
          const Isometry3d C = j.jeep->extrinsic;
          const auto odo = odometry::run_odometry(a.frames, a.timestamps, b.frames, b.timestamps, C,
                                                  o.tuning.odometry);
          if (!ulc::calibrate_detail::odometry_usable(odo)) {
            row.push_back(std::string("odometry_") + odometry::to_string(odo.status));
            for (int k = 0; k < 6; ++k) row.push_back("-");
            table.add_row(row);
            return;
          }
          hots::RefineOptions ho = o.tuning.hots;
          ho.min_cross_link_ratio = 0.0;  // what HOTS would return without the rule
          const auto refine = [&](const hots::RefineOptions& options) {
            return hots::refine(ulc::make_sequence(a.frames, a.timestamps, odo.poses_a),
                                ulc::make_sequence(b.frames, b.timestamps, odo.poses_b), C,
                                options);
          };
          auto h = refine(ho);
          auto st = judged_as_by_default(h.statistics, o.tuning.hots);
          // Confirmed by the second look, HOTS refines with that look's links in its graph: the
          // rule-off run above had only the plain rule's. What it returns is the default run's.
          if (st.links_judged_within_reach && hots::confirms(st.link_verdict)) {
            h = refine(o.tuning.hots);
            st = h.statistics;
          }
          const auto he = ulc::pose_error(truth, h.extrinsic);
          const double share = st.cross_links_attempted
                                   ? static_cast<double>(st.cross_links_agreeing) /
                                         static_cast<double>(st.cross_links_attempted)
                                   : 0.0;
          const bool confirmed = hots::confirms(st.link_verdict);
          const bool right = ulc::is_calibration_success(he);
          (right ? m.right : m.wrong) += 1;
          if (right) {
            m.right_min = std::min(m.right_min, share);
            m.right_unconfirmed += confirmed ? 0 : 1;
          } else {
            m.wrong_max = std::max(m.wrong_max, share);
            m.wrong_confirmed += confirmed ? 1 : 0;
          }
          row.insert(
              row.end(),
              {hots::to_string(h.status), Cell::num(he.rotation_deg, 3),
               Cell::num(100.0 * he.translation_m, 2),
               std::to_string(st.cross_links_agreeing) + "/" + std::to_string(st.cross_links) +
                   "/" + std::to_string(st.cross_links_attempted) +
                   (st.links_judged_within_reach ? " in reach" : ""),
               Cell::num(100.0 * share, 1), confirmed ? "confirmed" : "unconfirmed",
               right ? "right" : "wrong"});
          table.add_row(row);
          if (!c.bench.json)
            std::cerr << "  " << scenario << " seed " << run + 1 << " " << s.name << ": "
                      << hots::to_string(h.status) << ", " << he.rotation_deg << " deg, "
                      << 100.0 * he.translation_m << " cm, links agreeing/kept/tried "
                      << st.cross_links_agreeing << "/" << st.cross_links << "/"
                      << st.cross_links_attempted << "\n";
        });
      }
    }
  }
  const hots::RefineOptions defaults;
  const auto pct = [](double v, bool seen) { return seen ? Cell::num(100.0 * v, 1) : Cell("-"); };
  const std::vector<std::pair<std::string, Cell>> notes{
      {"rule", "agreeing >= max(" + std::to_string(defaults.min_cross_links) + ", " +
                   Cell::num(100.0 * defaults.min_cross_link_ratio, 1).text + " % of attempted)"},
      {"wrong_results", Cell::integer(static_cast<long long>(m.wrong))},
      {"right_results", Cell::integer(static_cast<long long>(m.right))},
      {"wrong_max_agree_pct", pct(m.wrong_max, m.wrong > 0)},
      {"right_min_agree_pct", pct(m.right_min, m.right > 0)},
      {"wrong_confirmed", Cell::integer(static_cast<long long>(m.wrong_confirmed))},
      {"right_unconfirmed", Cell::integer(static_cast<long long>(m.right_unconfirmed))}};
  ulc_bench::emit(std::cout, table, c.bench.json, "trust", 1,
                  {{"seconds", Cell::num(c.seconds, 1)},
                   {"runs", Cell::integer(static_cast<long long>(c.runs))},
                   {"threads", Cell::integer(c.threads)}},
                  notes);
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  CLI::App app(
      "JEEP and HOTS from right and wrong starts: does the cross-link rule tell them "
      "apart",
      "bench_trust");
  ulc_bench::add_options(app, c.bench);
  app.add_option("--scenarios", c.scenarios, "scenarios")->delimiter(',')->type_name("A,B,...");
  app.add_option("--seconds", c.seconds, "simulated drive")->type_name("S");
  app.add_option("--runs", c.runs, "runs per scenario")->type_name("N")->check(CLI::PositiveNumber);
  ulc_bench::add_first_run_option(app, c.first_run);
  ulc_bench::add_threads_option(app, c.threads);
  CLI11_PARSE(app, argc, argv);
  bench(c);
  return 0;
}
