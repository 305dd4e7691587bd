// Writes the fuzz seed corpora: make_seeds <folder> fills <folder>/<target>/ with a few small
// valid inputs per fuzz target, made by ULC's own writers plus a few hand-written files that
// use what the writers never emit (PCD COUNT > 1 and organised clouds, PLY lists before the
// vertices, JSON escapes, ...). The output is committed as tests/fuzz/corpus/; run this only to
// regenerate it.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ulc/bags/cloud_encoding.hpp"
#include "ulc/bags/mcap_writer.hpp"
#include "ulc/bags/ros1_bag_writer.hpp"
#include "ulc/bags/rosbag2_sqlite_writer.hpp"
#include "ulc/core/point_cloud.hpp"
#include "ulc/io/file_bytes.hpp"
#include "ulc/io/ground_truth.hpp"
#include "ulc/io/io.hpp"
#include "ulc/io/result_file.hpp"

namespace {

namespace fs = std::filesystem;
using ulc::bags::PointTimeStyle;
using ulc::bags::Serialization;
using Bytes = std::vector<unsigned char>;

constexpr std::int64_t kStampNs = 1700000000000000000;  // 2023-11-14, as a driver would stamp
constexpr std::int64_t kPeriodNs = 100000000;           // 10 Hz

/// Four points, intensities and per-point times (seconds after the stamp, or absolute).
ulc::io::DecodedCloud small_cloud(bool with_time, double time_base = 0.0) {
  ulc::io::DecodedCloud c;
  c.points = {{1.0, 2.0, 0.5}, {-3.25, 0.125, 1.0}, {10.0, -7.5, -1.5}, {0.0, 0.0, 42.0}};
  c.intensities = {0.0, 12.5, 255.0, 3.0};
  if (with_time) c.times = {time_base, time_base + 0.025, time_base + 0.05, time_base + 0.075};
  return c;
}

ulc::PointCloud<double> small_point_cloud(bool with_time, double time_base = 0.0) {
  return ulc::io::to_cloud<ulc::PointCloud<double>>(small_cloud(with_time, time_base));
}

void save(const fs::path& path, const Bytes& bytes) {
  fs::create_directories(path.parent_path());
  ulc::io::write_file_bytes(path, bytes);
}

void save_text(const fs::path& path, const std::string& text) {
  save(path, Bytes(text.begin(), text.end()));
}

void pcd_seeds(const fs::path& dir) {
  using ulc::io::PcdEncoding;
  const auto cloud = small_point_cloud(true);
  save(dir / "binary.pcd", ulc::io::encode_pcd(cloud, PcdEncoding::binary));
  save(dir / "ascii.pcd", ulc::io::encode_pcd(cloud, PcdEncoding::ascii));
  save(dir / "compressed.pcd", ulc::io::encode_pcd(cloud, PcdEncoding::binary_compressed));
  save(dir / "absolute_time.pcd",
       ulc::io::encode_pcd(small_point_cloud(true, 1700000000.0), PcdEncoding::binary));
  save(dir / "xyz_only.pcd", ulc::io::encode_pcd(small_point_cloud(false), PcdEncoding::binary));
  // An organised 2 x 2 cloud with a missing return, COUNT > 1, integer and double fields.
  save_text(dir / "organised.pcd",
            "# .PCD v0.7 - Point Cloud Data file format\n"
            "VERSION 0.7\n"
            "FIELDS x y z rgb normal_x time ring\n"
            "SIZE 4 4 8 4 4 8 2\n"
            "TYPE F F F U F F U\n"
            "COUNT 1 1 1 1 3 1 1\n"
            "WIDTH 2\n"
            "HEIGHT 2\n"
            "VIEWPOINT 0 0 0 1 0 0 0\n"
            "POINTS 4\n"
            "DATA ascii\n"
            "1 2 3 4278190335 0 0 1 0.001 0\n"
            "nan nan nan 0 0 0 1 0.002 1\n"
            "-1.5e2 2e-3 3 255 0.5 0.5 0 0.003 2\n"
            "4 5 6 0 1 0 0 0.004 3\n");
  save_text(dir / "columns_integer_time.pcd",
            "COLUMNS x y z intensity t\n"
            "SIZE 4 4 4 1 4\n"
            "TYPE F F F U U\n"
            "WIDTH 2\n"
            "DATA ascii\n"
            "1 2 3 200 1000\n"
            "4 5 6 17 2000\n");
}

void ply_seeds(const fs::path& dir) {
  using ulc::io::PlyFormat;
  const auto cloud = small_point_cloud(true);
  save(dir / "binary_le.ply", ulc::io::encode_ply(cloud, PlyFormat::binary_little_endian));
  save(dir / "binary_be.ply", ulc::io::encode_ply(cloud, PlyFormat::binary_big_endian));
  save(dir / "ascii.ply", ulc::io::encode_ply(cloud, PlyFormat::ascii));
  save(dir / "absolute_time.ply",
       ulc::io::encode_ply(small_point_cloud(true, 1700000000.0), PlyFormat::binary_little_endian));
  // A face element with a list property before the vertices, other type names.
  save_text(dir / "faces_first.ply",
            "ply\n"
            "format ascii 1.0\n"
            "comment hand written\n"
            "obj_info fuzz seed\n"
            "element face 2\n"
            "property list uchar int vertex_indices\n"
            "element vertex 3\n"
            "property double x\n"
            "property float32 y\n"
            "property float z\n"
            "property uchar intensity\n"
            "property uint32 offset_time\n"
            "element edge 1\n"
            "property int vertex1\n"
            "end_header\n"
            "3 0 1 2\n"
            "0\n"
            "1.5 2 3 10 100\n"
            "nan 0 0 20 200\n"
            "-4 5e1 6 30 300\n"
            "0\n");
  const std::string header =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "element face 1\n"
      "property list uint8 uint16 vertex_indices\n"
      "element vertex 1\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property short timestamp\n"
      "end_header\n";
  Bytes bytes(header.begin(), header.end());
  const unsigned char body[] = {2, 0, 0,   1,  0,  // face: 2 items of uint16
                                0, 0, 128, 63,     // x = 1.0f
                                0, 0, 0,   64,     // y = 2.0f
                                0, 0, 64,  64,     // z = 3.0f
                                7, 0};             // timestamp = 7
  bytes.insert(bytes.end(), std::begin(body), std::end(body));
  save(dir / "binary_list.ply", bytes);
}

void kitti_seeds(const fs::path& dir) {
  save(dir / "four_points.bin", ulc::io::encode_kitti_bin(small_point_cloud(false)));
  ulc::io::DecodedCloud with_nan = small_cloud(false);
  with_nan.points[1].x() = std::numeric_limits<double>::quiet_NaN();
  save(dir / "nan_point.bin",
       ulc::io::encode_kitti_bin(ulc::io::to_cloud<ulc::PointCloud<float>>(with_nan)));
}

void timestamps_seeds(const fs::path& dir) {
  save_text(dir / "relative.txt", "0.0\n0.1\n0.2\n0.30000000000000004\n");
  save_text(dir / "unix.txt", "1645000000.123456789\n1645000000.223456789\n1645000000.323\n");
  save_text(dir / "crlf_trailing_blank.txt", "1e-1\r\n2E-1\r\n  3.5e+0  \r\n\r\n\n");
  save_text(dir / "no_final_newline.txt", "-0.05\n+0.05\n.15");
  // The first line doubles as a frame file stem: Unix nanoseconds.
  save_text(dir / "nanosecond_stem.txt", "1645000000123456789\n");
  // Every line a frame file stem: pcl_ros's sec.unpadded-nanosec names, out of name order.
  save_text(dir / "pcl_ros_stems.txt",
            "1645000000.52300000\n1645000000.152300000\n1645000000.252300000\n"
            "1645000000.352300000\n");
  save_text(dir / "milliseconds.txt", "0\n100\n200\n300\n");
  save_text(dir / "backwards.txt", "0.1\n0.2\n0.15\n");
}

ulc::io::PairResult pair_result(const std::string& base, const std::string& target) {
  ulc::io::PairResult r;
  r.base = base;
  r.target = target;
  r.success = true;
  r.status = "ok";
  r.T_base_target.linear() = ulc::rotation_from_rpy(0.01, -0.02, 1.5);
  r.T_base_target.translation() = Eigen::Vector3d(1.25, -0.5, 0.75);
  r.time_offset_s = 0.0125;
  r.covariance_6x6 = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  r.stages["terra"]["iterations"] = 12;
  r.timing_s["total"] = 3.5;
  return r;
}

void json_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  ulc::io::PairResult routed = pair_result("top", "rear");
  routed.via = "left";
  routed.direct_status = "degenerate";
  routed.direct_reason = "translation along x is unobservable";
  ulc::io::PairResult failed;
  failed.base = "top";
  failed.target = "right";
  failed.reason = "no overlap";
  ulc::io::CycleResult cycle;
  cycle.lidars = {"top", "left", "rear"};
  cycle.status = "ok";
  cycle.rotation_deg = 0.05;
  cycle.translation_m = 0.002;
  ulc::io::write_result_file((dir / "result.json").string(),
                             {pair_result("top", "left"), routed, failed}, {cycle});
  ulc::io::write_result_file((dir / "initial_pair.json").string(), {pair_result("base", "target")});

  ulc::io::GroundTruth gt;
  gt.lidars.push_back({"top", "VLP-16", Eigen::Isometry3d::Identity()});
  gt.lidars.push_back({"left", "OS1-64", pair_result("top", "left").T_base_target});
  gt.pairs.push_back({"top", "left", pair_result("top", "left").T_base_target, 0.01});
  ulc::io::write_ground_truth((dir / "ground_truth.json").string(), gt);

  save_text(dir / "escapes.json",
            "{\"s\": \"a\\\"b\\\\c\\/d\\b\\f\\n\\r\\t\\u00e9\\ud83d\\ude00\", \"n\": [-0, 1e-7, "
            "-2.5E+3, 123456789012345678], \"t\": true, \"f\": false, \"z\": null, \"o\": {}}\n");
  save_text(dir / "initial_numbers.txt", "0.1, -0.2 0.3 1.5 -2 90\n");
}

/// The messages of the recording seeds: two PointCloud2 frames and one Livox frame per stream.
struct SeedMessage {
  bool livox;
  std::int64_t time_ns;
  Bytes bytes;
};

std::vector<SeedMessage> seed_messages(Serialization serialization) {
  std::vector<SeedMessage> out;
  for (int k = 0; k < 2; ++k) {
    const std::int64_t t = kStampNs + k * kPeriodNs;
    out.push_back({false, t,
                   ulc::bags::encode_pointcloud2(small_cloud(true), t, "velodyne", serialization,
                                                 PointTimeStyle::velodyne_time)});
  }
  const auto livox = ulc::bags::livox_message(small_cloud(true), kStampNs + 50000000, "livox");
  out.push_back({true, kStampNs + 50000000, ulc::bags::write_livox_custom(livox, serialization)});
  return out;
}

// Short message definitions keep the seeds small; the readers do not parse them.
constexpr const char* kShortDefinition = "# fuzz seed\n";

void ros1_seed(const fs::path& path, ulc::bags::Codec codec, bool index) {
  fs::create_directories(path.parent_path());
  ulc::bags::Ros1BagWriter bag(path, ulc::bags::Ros1WriteOptions{codec, 256, index});
  const std::uint32_t points = bag.add_connection({"/velodyne_points", "sensor_msgs/PointCloud2",
                                                   "1158d486dd51d683ce2f1be655c3c181",
                                                   kShortDefinition, "/velodyne", false});
  const std::uint32_t livox = bag.add_connection(
      {"/livox/lidar", "livox_ros_driver/CustomMsg", "*", kShortDefinition, "/livox", true});
  for (const SeedMessage& m : seed_messages(Serialization::ros1))
    bag.write(m.livox ? livox : points, m.time_ns, m.bytes.data(), m.bytes.size());
  bag.close();
}

void mcap_seed(const fs::path& path, ulc::bags::Codec codec, bool chunked, bool summary) {
  fs::create_directories(path.parent_path());
  ulc::bags::McapWriteOptions options;
  options.compression = codec;
  options.chunk_bytes = 256;
  options.chunked = chunked;
  options.write_summary = summary;
  ulc::bags::McapWriter mcap(path, options);
  const auto points = mcap.add_channel(
      "/points", mcap.add_schema("sensor_msgs/msg/PointCloud2", "ros2msg", kShortDefinition),
      "cdr");
  const auto livox = mcap.add_channel(
      "/livox/lidar",
      mcap.add_schema("livox_ros_driver2/msg/CustomMsg", "ros2msg", kShortDefinition), "cdr");
  for (const SeedMessage& m : seed_messages(Serialization::cdr))
    mcap.write(m.livox ? livox : points, m.time_ns, m.time_ns, m.bytes.data(), m.bytes.size());
  mcap.close();
}

void recording_seeds(const fs::path& corpus) {
  using ulc::bags::Codec;
  ros1_seed(corpus / "fuzz_ros1_bag" / "plain.bag", Codec::none, true);
  ros1_seed(corpus / "fuzz_ros1_bag" / "bz2.bag", Codec::bz2, true);
  ros1_seed(corpus / "fuzz_ros1_bag" / "lz4.bag", Codec::lz4, true);
  ros1_seed(corpus / "fuzz_ros1_bag" / "unindexed.bag", Codec::none, false);
  mcap_seed(corpus / "fuzz_mcap" / "plain.mcap", Codec::none, true, true);
  mcap_seed(corpus / "fuzz_mcap" / "zstd.mcap", Codec::zstd, true, true);
  mcap_seed(corpus / "fuzz_mcap" / "lz4.mcap", Codec::lz4, true, true);
  mcap_seed(corpus / "fuzz_mcap" / "no_summary.mcap", Codec::none, true, false);
  mcap_seed(corpus / "fuzz_mcap" / "unchunked.mcap", Codec::none, false, true);

  const fs::path db3 = corpus / "fuzz_rosbag2_sqlite" / "clouds.db3";
  fs::create_directories(db3.parent_path());
  ulc::bags::Rosbag2SqliteWriter bag(db3);
  const auto points = bag.add_topic("/points", "sensor_msgs/msg/PointCloud2", "cdr");
  const auto livox = bag.add_topic("/livox/lidar", "livox_ros_driver2/msg/CustomMsg", "cdr");
  for (const SeedMessage& m : seed_messages(Serialization::cdr))
    bag.write(m.livox ? livox : points, m.time_ns, m.bytes.data(), m.bytes.size());
  bag.close();
}

/// One cloud_message seed: the variant byte (bit 0: CDR, bit 1: Livox), then the message.
void save_message(const fs::path& path, Serialization serialization, bool livox,
                  const Bytes& message) {
  Bytes bytes{
      static_cast<unsigned char>((serialization == Serialization::cdr ? 1 : 0) | (livox ? 2 : 0))};
  bytes.insert(bytes.end(), message.begin(), message.end());
  save(path, bytes);
}

void cloud_message_seeds(const fs::path& dir) {
  using ulc::io::Endian;
  const auto cloud = small_cloud(true);
  const auto pc2 = [&](Serialization s, PointTimeStyle style, Endian order) {
    return ulc::bags::encode_pointcloud2(cloud, kStampNs, "lidar", s, style, order);
  };
  save_message(dir / "pc2_ros1_velodyne", Serialization::ros1, false,
               pc2(Serialization::ros1, PointTimeStyle::velodyne_time, Endian::little));
  save_message(dir / "pc2_cdr_ouster", Serialization::cdr, false,
               pc2(Serialization::cdr, PointTimeStyle::ouster_t, Endian::little));
  save_message(dir / "pc2_cdr_hesai_big_endian", Serialization::cdr, false,
               pc2(Serialization::cdr, PointTimeStyle::hesai_timestamp, Endian::big));
  save_message(dir / "pc2_ros1_offset_time", Serialization::ros1, false,
               pc2(Serialization::ros1, PointTimeStyle::livox_offset_time, Endian::little));
  save_message(dir / "pc2_cdr_no_time", Serialization::cdr, false,
               pc2(Serialization::cdr, PointTimeStyle::none, Endian::little));
  const auto livox = ulc::bags::livox_message(cloud, kStampNs, "livox_frame");
  save_message(dir / "livox_ros1", Serialization::ros1, true,
               ulc::bags::write_livox_custom(livox, Serialization::ros1));
  save_message(dir / "livox_cdr_big_endian", Serialization::cdr, true,
               ulc::bags::write_livox_custom(livox, Serialization::cdr, Endian::big));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds <corpus folder>\n");
    return 2;
  }
  const fs::path corpus = argv[1];
  try {
    pcd_seeds(corpus / "fuzz_pcd");
    ply_seeds(corpus / "fuzz_ply");
    kitti_seeds(corpus / "fuzz_kitti");
    timestamps_seeds(corpus / "fuzz_timestamps");
    json_seeds(corpus / "fuzz_json");
    recording_seeds(corpus);
    cloud_message_seeds(corpus / "fuzz_cloud_message");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
