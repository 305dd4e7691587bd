// Rosbag2Sqlite: one rosbag2 SQLite file (.db3) as a MessageSource.
//
// rosbag2's sqlite3 storage keeps two tables that every schema version shares:
//   topics(id, name, type, serialization_format, offered_qos_profiles, ...)
//   messages(id, topic_id, timestamp, data)   + index timestamp_idx ON messages(timestamp)
// Later versions add columns (type_description_hash) and tables (schema, metadata,
// message_definitions); only the columns above are read, so every version opens.
//
// The file is opened read-only. By default with the URI parameter immutable=1, which tells SQLite
// the file cannot change: no locks, no -shm or -wal access. That is what makes bags on read-only
// folders and media open even in WAL mode (which otherwise needs the -shm file), and it never
// writes beside the bag (a plain read-only open of a WAL database by a user allowed to write
// updates the -shm file). It would ignore a -wal file holding committed messages, so when a
// non-empty -wal lies beside the file the plain read-only open is used instead; if that fails
// the immutable open is the fallback and warnings() says the -wal messages are missing. A bag
// still being recorded is not a supported input (immutable assumes nothing changes).
//
// Every SQLite error (not a database, malformed image, missing table) becomes an io::IoError
// naming the file; errors while stepping through messages name the last message id read.
#pragma once

#include <sqlite3.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ulc/bags/file_reader.hpp"
#include "ulc/bags/message_source.hpp"
#include "ulc/io/io_error.hpp"

namespace ulc::bags {

/// Small RAII helpers around the SQLite C API, shared by the reader and the writer.
namespace sqlite_detail {

struct DatabaseCloser {
  // close_v2 defers the close until the last statement is finalised, so destruction order
  // between a connection and its statements cannot leak or crash.
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
using Database = std::unique_ptr<sqlite3, DatabaseCloser>;

struct StatementFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

/// SQLite's message for the last error on `db` (or a generic one when there is no handle).
inline std::string message_of(sqlite3* db) {
  return db != nullptr ? std::string(sqlite3_errmsg(db)) : std::string("out of memory");
}

/// Opens `uri` (a file name or a file: URI) with `flags`; IoError naming `file` on failure.
inline Database open_database(const std::string& file, const std::string& uri, int flags) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(uri.c_str(), &raw, flags, nullptr);
  Database db(raw);
  if (rc != SQLITE_OK) throw io::IoError(file, "", message_of(raw));
  sqlite3_extended_result_codes(raw, 1);
  return db;
}

inline Statement prepare(sqlite3* db, const std::string& file, const std::string& sql) {
  sqlite3_stmt* raw = nullptr;
  const int rc = sqlite3_prepare_v2(db, sql.c_str(), static_cast<int>(sql.size()), &raw, nullptr);
  Statement statement(raw);
  if (rc != SQLITE_OK) throw io::IoError(file, "", message_of(db));
  return statement;
}

/// Runs SQL that returns no rows (pragmas, BEGIN/COMMIT, CREATE TABLE).
inline void execute(sqlite3* db, const std::string& file, const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string reason = error != nullptr ? error : message_of(db);
    sqlite3_free(error);
    throw io::IoError(file, "", reason);
  }
}

/// A text column, "" when NULL.
inline std::string text_column(sqlite3_stmt* s, int column) {
  const unsigned char* text = sqlite3_column_text(s, column);
  if (text == nullptr) return {};
  return std::string(reinterpret_cast<const char*>(text),
                     static_cast<std::size_t>(sqlite3_column_bytes(s, column)));
}

/// What a column of SQLite type `type` (SQLITE_INTEGER, ...) holds, for error messages.
inline const char* type_name(int type) {
  switch (type) {
    case SQLITE_INTEGER:
      return "an integer";
    case SQLITE_FLOAT:
      return "a real number";
    case SQLITE_TEXT:
      return "text";
    case SQLITE_BLOB:
      return "a blob";
    default:
      return "NULL";
  }
}

/// "file:<path>?immutable=1" with the URI's reserved characters ('%', '?', '#') escaped.
inline std::string immutable_uri(const std::string& path) {
  std::string uri = "file:";
  for (const char c : path) {
    if (c == '%')
      uri += "%25";
    else if (c == '?')
      uri += "%3f";
    else if (c == '#')
      uri += "%23";
    else
      uri += c;
  }
  return uri + "?immutable=1";
}

}  // namespace sqlite_detail

class Rosbag2Sqlite : public MessageSource {
 public:
  explicit Rosbag2Sqlite(const std::filesystem::path& db3_file) : file_(db3_file.string()) {
    check_sqlite_header(db3_file);
    open_connection(db3_file);
    load_topics();
    check_time_index();
  }

  const std::string& file() const { return file_; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::vector<std::string> warnings() const override { return warnings_; }

  std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                        TimeWindow window) const override;

 private:
  class Cursor;

  /// What the reader keeps per topic name beyond TopicInfo.
  struct TopicRows {
    std::vector<std::int64_t> ids;     ///< topics.id rows carrying the name
    std::string serialization_format;  ///< as stored; only "cdr" and "ros1" can be read
    bool readable = true;
  };

  /// A clear error for files SQLite would only call "not a database": empty, short, or text.
  void check_sqlite_header(const std::filesystem::path& path) const {
    const FileReader reader(path);
    if (reader.size() == 0)
      throw io::IoError(file_, "", "empty file (0 bytes), not a SQLite database");
    static constexpr char kMagic[] = "SQLite format 3";  // 16 bytes with the terminating NUL
    constexpr std::uint64_t kHeaderBytes = 100;          // the database header (fileformat.html)
    unsigned char head[sizeof(kMagic)] = {};
    reader.read_into(0, head, std::min<std::uint64_t>(sizeof(kMagic), reader.size()), "header");
    if (std::memcmp(head, kMagic, sizeof(kMagic)) != 0)
      throw io::IoError(file_, io::at_byte(0),
                        "not a SQLite database: the file does not start with \"SQLite format 3\"");
    if (reader.size() < kHeaderBytes)
      reader.fail(reader.size(), "truncated SQLite database: the 100-byte header is incomplete");
  }

  /// Immutable unless a non-empty -wal file holds messages (see the file comment).
  void open_connection(const std::filesystem::path& path) {
    std::error_code ec;
    const auto wal_size = std::filesystem::file_size(path.string() + "-wal", ec);
    if (ec || wal_size == 0) {
      db_ = open_immutable();
      return;
    }
    try {
      db_ = sqlite_detail::open_database(file_, file_, SQLITE_OPEN_READONLY);
      sqlite_detail::execute(db_.get(), file_, "SELECT count(*) FROM sqlite_master");
    } catch (const io::IoError& e) {
      warnings_.push_back(file_ + ": could not read its -wal file (" + e.reason() +
                          "); messages recorded only there are missing");
      db_ = open_immutable();
    }
  }

  sqlite_detail::Database open_immutable() const {
    return sqlite_detail::open_database(file_, sqlite_detail::immutable_uri(file_),
                                        SQLITE_OPEN_READONLY | SQLITE_OPEN_URI);
  }

  /// One query: every topic row with its message count and first/last timestamp (topics without
  /// messages included), merged by name.
  void load_topics() {
    const auto statement = sqlite_detail::prepare(
        db_.get(), file_,
        "SELECT t.id, t.name, t.type, t.serialization_format, coalesce(s.n, 0), s.first, s.last "
        "FROM topics AS t LEFT JOIN (SELECT topic_id, count(*) AS n, min(timestamp) AS first, "
        "max(timestamp) AS last FROM messages GROUP BY topic_id) AS s ON s.topic_id = t.id "
        "ORDER BY t.id");
    std::map<std::string, std::pair<TopicInfo, TopicRows>> by_name;
    int rc;
    while ((rc = sqlite3_step(statement.get())) == SQLITE_ROW)
      add_topic_row(statement.get(), by_name);
    if (rc != SQLITE_DONE) throw io::IoError(file_, "", sqlite_detail::message_of(db_.get()));
    for (auto& [name, entry] : by_name) {
      for (const auto id : entry.second.ids) index_id(id, topics_.size());
      topics_.push_back(std::move(entry.first));
      rows_.push_back(std::move(entry.second));
    }
  }

  /// Maps topics.id `id` to topic `index`. An id on two rows (which rosbag2's primary key rules
  /// out, a damaged file does not) would hand one topic's messages out as another's.
  void index_id(std::int64_t id, std::size_t index) {
    if (!index_of_id_.emplace(id, index).second)
      throw io::IoError(file_, "topic id " + std::to_string(id),
                        "topic id " + std::to_string(id) +
                            " is listed twice in the topics table (a damaged file)");
  }

  void add_topic_row(sqlite3_stmt* s,
                     std::map<std::string, std::pair<TopicInfo, TopicRows>>& by_name) const {
    if (sqlite3_column_type(s, 0) != SQLITE_INTEGER)
      throw io::IoError(file_, "topics table",
                        std::string("a topic id is ") +
                            sqlite_detail::type_name(sqlite3_column_type(s, 0)) +
                            ", not an integer (a damaged file)");
    const std::int64_t id = sqlite3_column_int64(s, 0);
    TopicInfo row;
    row.name = sqlite_detail::text_column(s, 1);
    row.type = sqlite_detail::text_column(s, 2);
    const std::string format = sqlite_detail::text_column(s, 3);
    row.serialization = format == "ros1" ? Serialization::ros1 : Serialization::cdr;
    row.message_count = static_cast<std::uint64_t>(sqlite3_column_int64(s, 4));
    row.first_time_ns = row.message_count > 0 ? sqlite3_column_int64(s, 5) : 0;
    row.last_time_ns = row.message_count > 0 ? sqlite3_column_int64(s, 6) : 0;
    auto found = by_name.find(row.name);
    if (found == by_name.end()) {
      TopicRows rows{{id}, format, format == "cdr" || format == "ros1"};
      std::string name = row.name;
      by_name.emplace(std::move(name), std::make_pair(std::move(row), std::move(rows)));
      return;
    }
    merge_topic_row(found->second, row, id, format);
  }

  /// A second topics row with the same name (rosbag2 writes one per name; tolerated when the
  /// type and serialisation agree).
  void merge_topic_row(std::pair<TopicInfo, TopicRows>& into, const TopicInfo& row, std::int64_t id,
                       const std::string& format) const {
    TopicInfo& info = into.first;
    if (info.type != row.type || into.second.serialization_format != format)
      throw io::IoError(file_, "topic id " + std::to_string(id),
                        "topic " + row.name + " is listed twice with different types (" +
                            info.type + ", " + row.type + ")");
    if (row.message_count > 0) {
      info.first_time_ns = info.message_count > 0 ? std::min(info.first_time_ns, row.first_time_ns)
                                                  : row.first_time_ns;
      info.last_time_ns =
          info.message_count > 0 ? std::max(info.last_time_ns, row.last_time_ns) : row.last_time_ns;
    }
    info.message_count += row.message_count;
    info.connections += 1;
    into.second.ids.push_back(id);
  }

  /// Without timestamp_idx SQLite would sort whole rows, blobs included, in a temporary B-tree
  /// (as large as the bag); then the cursor sorts (timestamp, id) only and fetches each blob by id.
  void check_time_index() {
    const auto plan =
        sqlite_detail::prepare(db_.get(), file_, "EXPLAIN QUERY PLAN " + select_sql("0", true));
    while (sqlite3_step(plan.get()) == SQLITE_ROW)
      if (sqlite_detail::text_column(plan.get(), 3).find("TEMP B-TREE") != std::string::npos)
        sorted_by_index_ = false;
    if (!sorted_by_index_)
      warnings_.push_back(file_ +
                          ": the messages table has no timestamp index; messages are sorted by "
                          "SQLite and fetched one by one (slower)");
  }

  /// The cursor's query over the topic ids `id_list` ("1,4"), with or without the blob column.
  static std::string select_sql(const std::string& id_list, bool with_data) {
    return std::string("SELECT id, topic_id, timestamp") + (with_data ? ", data" : "") +
           " FROM messages WHERE topic_id IN (" + id_list +
           ") AND timestamp >= ?1 AND timestamp < ?2 ORDER BY timestamp, id";
  }

  std::string file_;
  sqlite_detail::Database db_;
  std::vector<TopicInfo> topics_;
  std::vector<TopicRows> rows_;
  std::unordered_map<std::int64_t, std::size_t> index_of_id_;
  std::vector<std::string> warnings_;
  bool sorted_by_index_ = true;
};

/// Steps one prepared statement one row at a time; the view points into SQLite's row buffer.
class Rosbag2Sqlite::Cursor : public MessageCursor {
 public:
  Cursor(const Rosbag2Sqlite& bag, const std::string& id_list, std::vector<bool> selected,
         TimeWindow window)
      : bag_(bag), selected_(std::move(selected)), window_(window) {
    const bool inline_data = bag.sorted_by_index_;
    rows_ = sqlite_detail::prepare(bag.db_.get(), bag.file_, select_sql(id_list, inline_data));
    sqlite3_bind_int64(rows_.get(), 1, window.begin_ns);
    sqlite3_bind_int64(rows_.get(), 2, window.end_ns);
    if (!inline_data)
      blob_ = sqlite_detail::prepare(bag.db_.get(), bag.file_,
                                     "SELECT data FROM messages WHERE id = ?1");
  }

  bool next(MessageView& out) override {
    if (rows_ == nullptr) return false;
    const int rc = sqlite3_step(rows_.get());
    if (rc == SQLITE_DONE) {
      rows_.reset();  // finished: release the statement early
      return false;
    }
    if (rc != SQLITE_ROW) fail(sqlite_detail::message_of(bag_.db_.get()));
    last_id_ = sqlite3_column_int64(rows_.get(), 0);
    const auto topic = bag_.index_of_id_.find(sqlite3_column_int64(rows_.get(), 1));
    if (topic == bag_.index_of_id_.end()) fail("its topic_id is not in the topics table");
    if (!selected_[topic->second]) fail("its topic_id is not one asked for (a damaged file)");
    out.topic = topic->second;
    out.time_ns = sqlite3_column_int64(rows_.get(), 2);
    check_order(out.time_ns);
    out.file = &bag_.file_;
    out.offset = 0;  // SQLite pages have no meaningful byte offset; errors cite the message id
    if (blob_ == nullptr) {
      point_at_blob(rows_.get(), 3, out);
    } else {
      fetch_blob(out);
    }
    return true;
  }

 private:
  /// SQLite orders and filters by the timestamp index and returns the index's copy of the time:
  /// a damaged index can disagree with the table. What comes out must still be in time order and
  /// inside the window, or the file is damaged.
  void check_order(std::int64_t t) {
    if (!window_.contains(t))
      fail("timestamp " + std::to_string(t) +
           " outside the window asked for: the timestamp index disagrees with the messages "
           "(a damaged file)");
    if (previous_ns_ && t < *previous_ns_)
      fail("timestamp " + std::to_string(t) + " comes after " + std::to_string(*previous_ns_) +
           ": the timestamp index disagrees with the messages (a damaged file)");
    previous_ns_ = t;
  }

  /// `out` views the blob of `column`; valid until the statement steps or resets.
  void point_at_blob(sqlite3_stmt* s, int column, MessageView& out) const {
    static const unsigned char kEmpty[1] = {0};
    if (sqlite3_column_type(s, column) == SQLITE_NULL) fail("its data is NULL");
    const void* data = sqlite3_column_blob(s, column);
    const int size = sqlite3_column_bytes(s, column);
    if (data == nullptr && sqlite3_errcode(bag_.db_.get()) == SQLITE_NOMEM)
      fail("out of memory reading its data");
    out.data = size > 0 ? static_cast<const unsigned char*>(data) : kEmpty;
    out.size = static_cast<std::size_t>(size);
  }

  void fetch_blob(MessageView& out) {
    sqlite3_reset(blob_.get());
    sqlite3_bind_int64(blob_.get(), 1, *last_id_);
    const int rc = sqlite3_step(blob_.get());
    if (rc == SQLITE_DONE) fail("its row is missing when its data is read");
    if (rc != SQLITE_ROW) fail(sqlite_detail::message_of(bag_.db_.get()));
    point_at_blob(blob_.get(), 0, out);
  }

  [[noreturn]] void fail(const std::string& reason) const {
    const std::string where =
        last_id_ ? "message id " + std::to_string(*last_id_) : std::string("first message");
    throw io::IoError(bag_.file_, where, reason);
  }

  const Rosbag2Sqlite& bag_;
  std::vector<bool> selected_;  ///< per topic index: asked for
  sqlite_detail::Statement rows_;
  sqlite_detail::Statement blob_;
  std::optional<std::int64_t> last_id_;
  TimeWindow window_;
  std::optional<std::int64_t> previous_ns_;
};

namespace sqlite_detail {
/// A cursor that yields nothing (no topic selected, empty window).
class EmptyCursor : public MessageCursor {
 public:
  bool next(MessageView&) override { return false; }
};
}  // namespace sqlite_detail

inline std::unique_ptr<MessageCursor> Rosbag2Sqlite::cursor(
    const std::vector<std::size_t>& selected, TimeWindow window) const {
  std::string id_list;
  std::vector<bool> wanted(topics_.size(), false);
  for (const std::size_t index : selected) {
    if (index >= topics_.size())
      throw std::out_of_range("Rosbag2Sqlite::cursor: topic index " + std::to_string(index) +
                              " out of range (" + std::to_string(topics_.size()) + " topics)");
    const TopicRows& rows = rows_[index];
    if (!rows.readable)
      throw io::IoError(file_, "",
                        "topic " + topics_[index].name + ": serialization format \"" +
                            rows.serialization_format + "\" is not supported (only cdr and ros1)");
    for (const auto id : rows.ids) id_list += (id_list.empty() ? "" : ",") + std::to_string(id);
    wanted[index] = true;
  }
  if (id_list.empty() || window.begin_ns >= window.end_ns)
    return std::make_unique<sqlite_detail::EmptyCursor>();
  return std::make_unique<Cursor>(*this, id_list, std::move(wanted), window);
}

}  // namespace ulc::bags
