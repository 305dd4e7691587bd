// The multi-LiDAR simulator (namespace ulc::sim): a procedural town (or a degenerate highway or
// tunnel), a vehicle driving through it in continuous time, and real sensor models ray cast at
// every point's own instant, with exact ground truth. Convenience include of everything except
// the dataset writer (dataset_writer.hpp), which does I/O and may throw ulc::io::IoError.
//
// Typical use:
//
//   auto spec = ulc::sim::scenario("64-32");                // std::nullopt for unknown names
//   ulc::sim::SimulationOptions options;                    // seconds, seed, rate_hz, ...
//   options.seconds = 20;
//   // In memory (frames in result.dataset.lidars[i].frames):
//   ulc::sim::SimulationResult r = ulc::sim::simulate(*spec, options);
//   // Or streamed to a dataset folder (docs/design.md layout), bounded memory:
//   r = ulc::sim::simulate_to_directory("out/64-32", *spec, options, progress);
//
// Map of the headers (each states the conventions it owns at its top):
//   scenario.hpp        LidarMount, ScenarioSpec, scenario_names(), scenario(name), pair_truths,
//                       set_clock_offset, set_rate, check_scenario
//   simulate.hpp        SimulationOptions, Dataset, Simulator (frame by frame), simulate()
//   dataset_writer.hpp  write_dataset(dir, dataset), DatasetWriter, simulate_to_directory()
//   sensor_catalog.hpp  sensor_model(name), sensor_model_names()
//   sensor_model.hpp    SpinningLidar, RisleyLidar, MemsLidar, RangeModel, FieldOfView
//   sensor_tables.hpp   published elevation / azimuth tables
//   trajectory.hpp      MotionSpec, VehicleTrajectory (pose at any t), PoseTable
//   world.hpp           SceneKind, World, build_world(); town.hpp, degenerate_scenes.hpp,
//                       scene_parts.hpp, ground.hpp build it; traffic.hpp moves cars in it
//   scene.hpp, bvh.hpp, primitives.hpp   geometry and closest-hit ray casting
//   raycast.hpp         one frame: rays -> noisy, motion-distorted points
//   vehicle.hpp         the ego body that blocks returns
//   random.hpp          counter-based random numbers (determinism for any thread count)
#pragma once

#include "ulc/sim/scenario.hpp"
#include "ulc/sim/sensor_catalog.hpp"
#include "ulc/sim/simulate.hpp"
#include "ulc/sim/trajectory.hpp"
#include "ulc/sim/world.hpp"
