// Calibrating from PCD folders with the library: two LiDARs' frame folders in, the extrinsic
// out as the result file `ulc calibrate` writes (docs/design.md). The command does the same with
// more options; this is what to copy into your own tool.
//
//   example_calibrate_folders BASE_DIR TARGET_DIR [result.json]
//   example_calibrate_folders                      (simulates a 3 s 64-32 drive first)
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/calibrate.hpp"
#include "ulc/io/result_entry.hpp"
#include "ulc/io/result_file.hpp"
#include "ulc/io/sequence.hpp"
#include "ulc/sim/dataset_writer.hpp"
#include "ulc/sim/sim.hpp"

namespace {

struct Frames {
  std::vector<ulc::PointCloud<float>> clouds;
  std::vector<double> times;  // the LiDAR's own clock
};

Frames load_first(const ulc::io::Sequence& sequence, std::size_t count) {
  Frames f;
  for (std::size_t i = 0; i < sequence.size() && i < count; ++i) {
    auto frame = sequence.load_frame<ulc::PointCloud<float>>(i);
    f.clouds.push_back(std::move(frame.cloud));
    f.times.push_back(frame.timestamp);
  }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::string base_dir, target_dir, output = "result.json";
  if (argc >= 3) {
    base_dir = argv[1];
    target_dir = argv[2];
    if (argc >= 4) output = argv[3];
  } else {
    const fs::path dir = fs::temp_directory_path() / "ulc_example_64-32";
    ulc::sim::SimulationOptions options;
    options.seconds = 3.0;
    const auto run = ulc::sim::simulate_to_directory(dir, *ulc::sim::scenario("64-32"), options);
    if (!run.ok()) {
      std::fprintf(stderr, "simulation failed: %s\n", run.reason.c_str());
      return 1;
    }
    base_dir = (dir / "lidar64").string();
    target_dir = (dir / "lidar32").string();
    output = (dir / "result.json").string();
  }
  try {
    const ulc::io::Sequence base(base_dir), target(target_dir);
    ulc::CalibrateOptions options;  // the paper's defaults
    // TERRA (no guess) then JEEP on the first frames; add ulc::Stage::hots for a long drive.
    options.stages = {ulc::Stage::terra, ulc::Stage::jeep};
    // Without HOTS nobody estimates the clocks' offset: the simulator's are synchronised.
    // Otherwise leave it unset and give JEEP enough frames for the clock check
    // (pipeline/vouch.hpp), or add HOTS.
    options.time_offset_s = 0.0;
    options.progress = [](const std::string& stage, double fraction) {
      if (fraction == 1.0) std::fprintf(stderr, "%s done\n", stage.c_str());
    };
    const Frames a = load_first(base, options.tuning.jeep.frames + 2);
    const Frames b = load_first(target, options.tuning.jeep.frames + 2);
    const ulc::PairCalibration c =
        ulc::calibrate_pair(a.clouds, a.times, b.clouds, b.times, options);
    const ulc::io::PairResult entry = ulc::io::to_pair_result(c, base.name(), target.name());
    ulc::io::write_result_file(output, {entry});
    const Eigen::Vector3d t = c.T_base_target.translation();
    std::printf("%s <- %s: %s %s\n  translation %.4f %.4f %.4f m\n  wrote %s\n",
                base.name().c_str(), target.name().c_str(), c.success ? "ok" : "FAILED",
                c.reason.c_str(), t.x(), t.y(), t.z(), output.c_str());
    return c.success ? 0 : 1;
  } catch (const std::exception& e) {  // unreadable folders and files: ulc::io::IoError
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
