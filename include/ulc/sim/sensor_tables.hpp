// Published LiDAR angle tables, embedded from ../shared/reference/elevation_tables_deg.json.
//
// Conventions this header owns:
//   - Degrees. Elevation is the angle above the sensor's x-y plane (positive up); azimuth
//     offsets are per-laser corrections added to the head's azimuth (positive counter-
//     clockwise seen from above, i.e. towards +y).
//   - Arrays are in laser-id order where the source gives it (that order is also the firing
//     order the sensor models use); each cites its source key in the facts file verbatim.
//   - Tables that the facts file does not hold (OS0-128, RS-Helios) are generated in
//     sensor_catalog.hpp from the figures of ../shared/reference/sensors.md.
#pragma once

#include <array>

namespace ulc::sim::tables {

// Source key: "VLP-16 (ros-drivers/velodyne velodyne_pointcloud/params/VLP16db.yaml, laser_id
// order)"
inline constexpr std::array<double, 16> kVlp16Elevation = {
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0};

// Source key: "HDL-32E (velodyne_pointcloud/params/32db.yaml, laser_id order)"
inline constexpr std::array<double, 32> kHdl32eElevation = {
    -30.67, -9.33,  -29.33, -8.0,   -28.0,  -6.67, -26.67, -5.33,  -25.33, -4.0,   -24.0,
    -2.67,  -22.67, -1.33,  -21.33, 0.0,    -20.0, 1.33,   -18.67, 2.67,   -17.33, 4.0,
    -16.0,  5.33,   -14.67, 6.67,   -13.33, 8.0,   -12.0,  9.33,   -10.67, 10.67};

// Source key: "VLP-32C (velodyne_pointcloud/params/VeloView-VLP-32C.yaml, laser_id order)"
inline constexpr std::array<double, 32> kVlp32cElevation = {
    -25.0,  -1.0,   -1.667, -15.639, -11.31, 0.0,    -0.667, -8.843, -7.254, 0.333,  -0.333,
    -6.148, -5.333, 1.333,  0.667,   -4.0,   -4.667, 1.667,  1.0,    -3.667, -3.333, 3.333,
    2.333,  -2.667, -3.0,   7.0,     4.667,  -2.333, -2.0,   15.0,   10.333, -1.333};

// Source key: "VLP-32C azimuth offsets deg (same file, rot_correction)"
inline constexpr std::array<double, 32> kVlp32cAzimuthOffset = {
    -1.4, 4.2, -1.4, 1.4, -1.4, 1.4, -4.2, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -4.2, 1.4,
    -1.4, 4.2, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4, -1.4, 1.4, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4};

// Source key: "HDL-64E sorted (velodyne_pointcloud/params/64e_utexas.yaml, one unit's calibration)"
inline constexpr std::array<double, 64> kHdl64eElevation = {
    -24.711, -24.276, -23.763, -23.25,  -22.738, -22.226, -21.715, -21.204, -20.693, -20.183,
    -19.673, -19.163, -18.558, -18.144, -17.634, -17.125, -16.615, -16.106, -15.596, -15.087,
    -14.577, -14.067, -13.557, -13.047, -12.536, -12.025, -11.514, -11.002, -10.49,  -9.977,
    -9.464,  -8.95,   -8.521,  -8.18,   -7.839,  -7.499,  -7.158,  -6.818,  -6.478,  -6.138,
    -5.798,  -5.458,  -5.118,  -4.778,  -4.439,  -4.099,  -3.759,  -3.42,   -3.08,   -2.741,
    -2.401,  -2.061,  -1.722,  -1.382,  -1.042,  -0.702,  -0.362,  -0.022,  0.318,   0.658,
    0.999,   1.339,   1.68,    2.021};

// Source key: "Ouster OS1-64 Gen1 nominal (ouster-lidar/ouster-sdk ouster_core/src/sensor_info.cpp
// GEN1_ALTITUDE_ANGLES)"
inline constexpr std::array<double, 64> kOs1_64Elevation = {
    16.611,  16.084,  15.557,  15.029,  14.502,  13.975,  13.447, 12.92,   12.393,  11.865,
    11.338,  10.811,  10.283,  9.756,   9.229,   8.701,   8.174,  7.646,   7.119,   6.592,
    6.064,   5.537,   5.01,    4.482,   3.955,   3.428,   2.9,    2.373,   1.846,   1.318,
    0.791,   0.264,   -0.264,  -0.791,  -1.318,  -1.846,  -2.373, -2.9,    -3.428,  -3.955,
    -4.482,  -5.01,   -5.537,  -6.064,  -6.592,  -7.119,  -7.646, -8.174,  -8.701,  -9.229,
    -9.756,  -10.283, -10.811, -11.338, -11.865, -12.393, -12.92, -13.447, -13.975, -14.502,
    -15.029, -15.557, -16.084, -16.611};

// Source key: "Ouster OS1-64 Gen1 azimuth offsets (GEN1_AZIMUTH_ANGLES, repeating)"
inline constexpr std::array<double, 4> kOs1_64AzimuthOffset = {3.164, 1.055, -1.055, -3.164};

// Source key: "RS-Bpearl (isaac-sim/IsaacLab patterns_cfg.py BpearlPatternCfg; angle above sensor
// plane, 0-90 deg hemisphere)"
inline constexpr std::array<double, 32> kBpearlElevation = {
    89.5, 86.6875, 83.875, 81.0625, 78.25, 75.4375, 72.625, 69.8125,
    67.0, 64.1875, 61.375, 58.5625, 55.75, 52.9375, 50.125, 47.3125,
    44.5, 41.6875, 38.875, 36.0625, 33.25, 30.4375, 27.625, 24.8125,
    22.0, 19.1875, 16.375, 13.5625, 10.75, 7.9375,  5.125,  2.3125};

// Source key: "Hesai Pandar64 (HesaiTechnology/HesaiLidar_General_SDK
// src/PandarGeneralRaw/src/pandarGeneral_internal.cc pandarGeneral_elev_angle_map)"
inline constexpr std::array<double, 64> kPandar64Elevation = {
    14.882, 11.032, 8.059,  5.057,   3.04,    2.028,   1.86,   1.688,   1.522,  1.351,  1.184,
    1.013,  0.846,  0.675,  0.508,   0.337,   0.169,   0.0,    -0.169,  -0.337, -0.508, -0.675,
    -0.845, -1.013, -1.184, -1.351,  -1.522,  -1.688,  -1.86,  -2.028,  -2.198, -2.365, -2.536,
    -2.7,   -2.873, -3.04,  -3.21,   -3.375,  -3.548,  -3.712, -3.884,  -4.05,  -4.221, -4.385,
    -4.558, -4.72,  -4.892, -5.057,  -5.229,  -5.391,  -5.565, -5.726,  -5.898, -6.061, -7.063,
    -8.059, -9.06,  -9.885, -11.032, -12.006, -12.974, -13.93, -18.889, -24.897};

// Source key: "Hesai Pandar64 azimuth offsets (same file
// pandarGeneral_horizatal_azimuth_offset_map)"
inline constexpr std::array<double, 64> kPandar64AzimuthOffset = {
    -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, 1.042,  3.125,  5.208,  -5.208, -3.125,
    -1.042, 1.042,  3.125,  5.208,  -5.208, -3.125, -1.042, 1.042,  3.125,  5.208,  -5.208,
    -3.125, -1.042, 1.042,  3.125,  5.208,  -5.208, -3.125, -1.042, 1.042,  3.125,  5.208,
    -5.208, -3.125, -1.042, 1.042,  3.125,  5.208,  -5.208, -3.125, -1.042, 1.042,  3.125,
    5.208,  -5.208, -3.125, -1.042, 1.042,  3.125,  5.208,  -5.208, -3.125, -1.042, -1.042,
    -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, -1.042};
}  // namespace ulc::sim::tables
