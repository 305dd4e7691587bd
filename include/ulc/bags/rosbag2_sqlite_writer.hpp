// Rosbag2SqliteWriter: writes a rosbag2 sqlite3 bag, either one .db3 file or a bag folder
// (`<folder name>_0.db3`, `_1.db3`, ... plus the metadata.yaml rosbag2 writes), so ULC can record
// what `ros2 bag play` reads and tests can make bags of any shape.
//
// The tables are rosbag2's (the layout without a `schema` table, which every rosbag2 release
// reads): topics(id, name, type, serialization_format, offered_qos_profiles),
// messages(id, topic_id, timestamp, data) and the index timestamp_idx. Messages are inserted in
// transactions of up to kBatchBytes, so writing gigabytes costs a few dozen commits; the journal
// lives in memory and nothing is synced (a crash mid-write loses the file, not other data).
//
// With split_bytes > 0 (folder only) a new `_N.db3` file starts once the current one holds about
// that many message bytes; each file lists every topic added so far, as rosbag2's splits do.
#pragma once

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "ulc/bags/limits.hpp"
#include "ulc/bags/message_span.hpp"
#include "ulc/bags/rosbag2_sqlite.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

class Rosbag2SqliteWriter {
 public:
  /// Message bytes per transaction.
  static constexpr std::uint64_t kBatchBytes = std::uint64_t{32} << 20;

  /// `path` ending in .db3: that one file (replaced if present). Otherwise a bag folder to create
  /// (it may exist but must be empty). `split_bytes` > 0 splits a folder's files at about that
  /// many message bytes.
  explicit Rosbag2SqliteWriter(const std::filesystem::path& path, std::uint64_t split_bytes = 0)
      : split_bytes_(split_bytes) {
    if (path.extension() == ".db3") {
      if (split_bytes != 0)
        throw io::IoError(path.string(), "", "splitting needs a bag folder, not a .db3 file");
      std::error_code ec;
      std::filesystem::remove(path, ec);
      open_file(path);
    } else {
      folder_ = path.lexically_normal();
      if (folder_.filename().empty()) folder_ = folder_.parent_path();
      create_folder();
      open_file(folder_ / file_name(0));
    }
  }
  Rosbag2SqliteWriter(const Rosbag2SqliteWriter&) = delete;
  Rosbag2SqliteWriter& operator=(const Rosbag2SqliteWriter&) = delete;
  ~Rosbag2SqliteWriter() {
    try {
      close();
    } catch (...) {  // a destructor must not throw; call close() to see errors
    }
  }

  /// Registers a topic (again: the same id when name, type and format agree) and returns its id.
  std::int64_t add_topic(const std::string& name, const std::string& type,
                         const std::string& serialization_format = "cdr") {
    require_open();
    for (std::size_t i = 0; i < topics_.size(); ++i) {
      if (topics_[i].name != name) continue;
      if (topics_[i].type != type || topics_[i].format != serialization_format)
        throw std::invalid_argument("Rosbag2SqliteWriter: topic " + name +
                                    " was added with another type or serialization format");
      return static_cast<std::int64_t>(i + 1);
    }
    topics_.push_back(Topic{name, type, serialization_format, {}});
    insert_topic(topics_.size() - 1);
    return static_cast<std::int64_t>(topics_.size());
  }

  /// Appends one message; `data` may be null when `size` is 0. Any order of times is fine.
  void write(std::int64_t topic, std::int64_t time_ns, const unsigned char* data,
             std::size_t size) {
    require_open();
    if (topic < 1 || static_cast<std::size_t>(topic) > topics_.size())
      throw std::invalid_argument("Rosbag2SqliteWriter: unknown topic id " + std::to_string(topic));
    if (size > kMaxRecordBytes)
      throw io::IoError(
          current_.path.string(), "",
          "a message of " + std::to_string(size) + " bytes is larger than the 1 GiB limit");
    // Split before the message that would go past the limit, so no file is left empty.
    if (split_bytes_ != 0 && current_bytes_ >= split_bytes_) start_next_file();
    if (!in_transaction_) begin();
    insert_message(topic, time_ns, data, size);
    topics_[static_cast<std::size_t>(topic - 1)].stats.add(time_ns);
    current_.stats.add(time_ns);
    batch_bytes_ += size;
    current_bytes_ += size;
    if (batch_bytes_ >= kBatchBytes) commit();
  }

  /// Commits, closes the file and (folder) writes metadata.yaml. Idempotent.
  void close() {
    if (db_ == nullptr) return;
    close_file();
    if (!folder_.empty()) write_metadata();
  }

  /// The .db3 files written so far, in order.
  std::vector<std::filesystem::path> files() const {
    std::vector<std::filesystem::path> out;
    for (const auto& f : done_) out.push_back(f.path);
    if (db_ != nullptr) out.push_back(current_.path);
    return out;
  }

 private:
  /// Message count and time span of a topic or a file.
  using Stats = MessageSpan;
  struct Topic {
    std::string name, type, format;
    Stats stats;
  };
  struct File {
    std::filesystem::path path;
    Stats stats;
  };

  std::string file_name(std::size_t index) const {
    return folder_.filename().string() + "_" + std::to_string(index) + ".db3";
  }

  void create_folder() const {
    std::error_code ec;
    if (std::filesystem::exists(folder_, ec) && !std::filesystem::is_empty(folder_, ec))
      throw io::IoError(folder_.string(), "", "the bag folder already exists and is not empty");
    std::filesystem::create_directories(folder_, ec);
    if (ec) throw io::IoError(folder_.string(), "", "cannot create the folder: " + ec.message());
  }

  void open_file(const std::filesystem::path& path) {
    current_ = File{path, {}};
    current_bytes_ = 0;
    const std::string name = path.string();
    db_ = sqlite_detail::open_database(name, name, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    sqlite_detail::execute(db_.get(), name,
                           "PRAGMA journal_mode = MEMORY; PRAGMA synchronous = OFF;"
                           "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, "
                           "type TEXT NOT NULL, serialization_format TEXT NOT NULL, "
                           "offered_qos_profiles TEXT NOT NULL);"
                           "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT "
                           "NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
                           "CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
    insert_ = sqlite_detail::prepare(
        db_.get(), name, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?1, ?2, ?3)");
    for (std::size_t i = 0; i < topics_.size(); ++i) insert_topic(i);
  }

  void insert_topic(std::size_t index) {
    const auto s = sqlite_detail::prepare(
        db_.get(), current_.path.string(),
        "INSERT INTO topics (id, name, type, serialization_format, offered_qos_profiles) "
        "VALUES (?1, ?2, ?3, ?4, '')");
    const Topic& t = topics_[index];
    sqlite3_bind_int64(s.get(), 1, static_cast<sqlite3_int64>(index + 1));
    sqlite3_bind_text(s.get(), 2, t.name.c_str(), static_cast<int>(t.name.size()), SQLITE_STATIC);
    sqlite3_bind_text(s.get(), 3, t.type.c_str(), static_cast<int>(t.type.size()), SQLITE_STATIC);
    sqlite3_bind_text(s.get(), 4, t.format.c_str(), static_cast<int>(t.format.size()),
                      SQLITE_STATIC);
    step_done(s.get());
  }

  void insert_message(std::int64_t topic, std::int64_t time_ns, const unsigned char* data,
                      std::size_t size) {
    sqlite3_stmt* s = insert_.get();
    sqlite3_reset(s);
    sqlite3_bind_int64(s, 1, topic);
    sqlite3_bind_int64(s, 2, time_ns);
    // A null pointer would bind NULL (the column is NOT NULL): an empty message is a zero blob.
    if (size == 0)
      sqlite3_bind_zeroblob(s, 3, 0);
    else
      sqlite3_bind_blob64(s, 3, data, size, SQLITE_STATIC);
    step_done(s);
    sqlite3_clear_bindings(s);
  }

  void step_done(sqlite3_stmt* s) const {
    if (sqlite3_step(s) != SQLITE_DONE)
      throw io::IoError(current_.path.string(), "", sqlite_detail::message_of(db_.get()));
  }

  void begin() {
    sqlite_detail::execute(db_.get(), current_.path.string(), "BEGIN");
    in_transaction_ = true;
  }

  void commit() {
    if (!in_transaction_) return;
    in_transaction_ = false;
    batch_bytes_ = 0;
    sqlite_detail::execute(db_.get(), current_.path.string(), "COMMIT");
  }

  void close_file() {
    commit();
    insert_.reset();
    const int rc = sqlite3_close(db_.release());
    if (rc != SQLITE_OK)
      throw io::IoError(current_.path.string(), "",
                        "closing failed: " + std::string(sqlite3_errstr(rc)));
    done_.push_back(current_);
  }

  void start_next_file() {
    close_file();
    open_file(folder_ / file_name(done_.size()));
  }

  void require_open() const {
    if (db_ == nullptr) throw std::logic_error("Rosbag2SqliteWriter: used after close()");
  }

  /// rosbag2's metadata.yaml (version 5: per-file details under `files`).
  void write_metadata() const {
    Stats all;
    for (const auto& f : done_) all.merge(f.stats);
    YAML::Emitter out;
    out << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value
        << YAML::BeginMap;
    out << YAML::Key << "version" << YAML::Value << 5;
    out << YAML::Key << "storage_identifier" << YAML::Value << "sqlite3";
    emit_span(out, all);
    out << YAML::Key << "message_count" << YAML::Value << all.count;
    emit_topics(out);
    out << YAML::Key << "compression_format" << YAML::Value << "";
    out << YAML::Key << "compression_mode" << YAML::Value << "";
    out << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq;
    for (const auto& f : done_) out << f.path.filename().string();
    out << YAML::EndSeq;
    emit_files(out);
    out << YAML::EndMap << YAML::EndMap;
    save_text(folder_ / "metadata.yaml", std::string(out.c_str()) + "\n");
  }

  /// `duration` and `starting_time` of a span (0 and 0 when it holds no message).
  static void emit_span(YAML::Emitter& out, const Stats& s) {
    out << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds"
        << YAML::Value << (s.last_ns - s.first_ns) << YAML::EndMap;
    out << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key
        << "nanoseconds_since_epoch" << YAML::Value << s.first_ns << YAML::EndMap;
  }

  void emit_topics(YAML::Emitter& out) const {
    out << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
    for (const auto& t : topics_) {
      out << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "name" << YAML::Value << t.name;
      out << YAML::Key << "type" << YAML::Value << t.type;
      out << YAML::Key << "serialization_format" << YAML::Value << t.format;
      out << YAML::Key << "offered_qos_profiles" << YAML::Value << "";
      out << YAML::EndMap << YAML::Key << "message_count" << YAML::Value << t.stats.count
          << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }

  void emit_files(YAML::Emitter& out) const {
    out << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
    for (const auto& f : done_) {
      out << YAML::BeginMap << YAML::Key << "path" << YAML::Value << f.path.filename().string();
      emit_span(out, f.stats);
      out << YAML::Key << "message_count" << YAML::Value << f.stats.count << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }

  static void save_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file << text;
    file.close();
    if (!file) throw io::IoError(path.string(), "", "cannot write the file");
  }

  std::filesystem::path folder_;  ///< empty when writing a single .db3 file
  std::uint64_t split_bytes_ = 0;
  std::vector<Topic> topics_;  ///< topic id = index + 1
  std::vector<File> done_;     ///< closed files
  File current_;
  std::uint64_t current_bytes_ = 0;
  std::uint64_t batch_bytes_ = 0;
  bool in_transaction_ = false;
  sqlite_detail::Database db_;
  sqlite_detail::Statement insert_;
};

}  // namespace ulc::bags
