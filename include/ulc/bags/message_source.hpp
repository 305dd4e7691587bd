// MessageSource: what every recording reader offers (ROS 1 bag, MCAP, rosbag2 SQLite), so the
// layers above (point-cloud decoding, `ulc inspect`, the frame source) never see the container.
//
// A reader lists its topics once when opened, then streams the messages of the topics asked
// for through a cursor, in receive-time order, holding a bounded part of the file in memory (one
// chunk, or the few chunks whose times overlap). A message's bytes stay valid only until the
// cursor moves on: a caller that keeps a message copies or decodes it.
//
// Errors are ulc::io::IoError naming the file, the byte offset and the problem.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace ulc::bags {

/// How a message's bytes are serialised: ROS 1 (little endian, packed) or CDR (ROS 2, XCDR1).
enum class Serialization { ros1, cdr };

struct TopicInfo {
  std::string name;  ///< "/velodyne_points"
  /// The message type as the file stores it: "sensor_msgs/PointCloud2" (ROS 1) or
  /// "sensor_msgs/msg/PointCloud2" (ROS 2).
  std::string type;
  Serialization serialization = Serialization::ros1;
  std::uint64_t message_count = 0;
  std::int64_t first_time_ns = 0;  ///< receive time of the first message; 0 when none
  std::int64_t last_time_ns = 0;   ///< receive time of the last message; 0 when none
  std::size_t connections = 1;     ///< ROS 1 connections / MCAP channels that carry the topic
};

/// One message, valid only during the visitor's call.
struct MessageView {
  std::size_t topic = 0;     ///< index into MessageSource::topics()
  std::int64_t time_ns = 0;  ///< receive (log) time, nanoseconds since the Unix epoch
  const unsigned char* data = nullptr;
  std::size_t size = 0;
  const std::string* file = nullptr;  ///< the file it came from (a split bag has several)
  /// Where the message is: its byte offset in `file` when stored uncompressed, else the offset of
  /// the compressed chunk that holds it. Decoders cite it in their errors.
  std::uint64_t offset = 0;
};

/// Receive times [begin_ns, end_ns).
struct TimeWindow {
  std::int64_t begin_ns = std::numeric_limits<std::int64_t>::min();
  std::int64_t end_ns = std::numeric_limits<std::int64_t>::max();
  bool contains(std::int64_t t) const { return t >= begin_ns && t < end_ns; }
};

/// Pulls the messages of a selection one at a time.
class MessageCursor {
 public:
  virtual ~MessageCursor() = default;
  /// The next message, or false at the end. `out` (and the bytes it points to) stays valid until
  /// the next call to next() or the cursor's destruction.
  virtual bool next(MessageView& out) = 0;
};

/// Returns false to stop the reading early.
using MessageVisitor = std::function<bool(const MessageView&)>;

class MessageSource {
 public:
  virtual ~MessageSource() = default;

  /// Every topic of the recording, in a stable order (by name), with its message count.
  virtual const std::vector<TopicInfo>& topics() const = 0;

  /// What the reader had to work around (an unindexed bag read by a linear scan, ...).
  virtual std::vector<std::string> warnings() const { return {}; }

  /// The messages of the topics `selected` (indexes into topics()) whose receive time lies in
  /// `window`, in receive-time order; messages with equal times come in file order. The source
  /// must outlive the cursor; several cursors may be open at once.
  virtual std::unique_ptr<MessageCursor> cursor(const std::vector<std::size_t>& selected,
                                                TimeWindow window) const = 0;

  /// Visits what cursor(selected, window) yields; `visit` returns false to stop early.
  void read(const std::vector<std::size_t>& selected, TimeWindow window,
            const MessageVisitor& visit) const {
    const auto c = cursor(selected, window);
    MessageView m;
    while (c->next(m))
      if (!visit(m)) return;
  }
};

}  // namespace ulc::bags
