#pragma once
// an MCAP file writer (MCAP format major version 0, https://mcap.dev/spec): the container of
// ROS 2 bags (rosbag2's default storage since Iron) that `ros2 bag`, Foxglove and the `mcap`
// tools read. pure C++ (zlib for CRC-32, zstd for chunk compression); nothing ROS-specific:
// the profile, schemas and channels are the caller's (ros/ros2/rosbag2_writer.h).
//
// layout written:
//   magic, Header, the data section (Schema, Channel and Metadata records as they are added;
//   Chunk records of Message records, each followed by one MessageIndex record per channel in
//   it), DataEnd (with the CRC-32 of everything before it), the summary section (every Schema,
//   Channel, one Statistics, every ChunkIndex and MetadataIndex), a SummaryOffset record per
//   group of the summary, Footer (with the CRC-32 of the summary, the summary offsets and the
//   footer's own fields), magic. every Chunk has the CRC-32 of its uncompressed records.
//   all integers little endian, as the spec says.
//
// a failed write (a full disk) throws Error with the system's reason; the file is then
// abandoned (no further record is written; every later call throws) and the caller removes it.

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace penumbra {

/// how Chunk records are compressed (the spec's "" and "zstd").
enum class McapCompression { kNone, kZstd };

/// a Channel's or Metadata record's key-value pairs (written in key order).
using McapKeyValues = std::map<std::string, std::string>;

/// options of a McapWriter.
struct McapWriterOptions {
  std::string profile{};             ///< Header profile, e.g. "ros2" ("" = none)
  std::string library = "penumbra";  ///< Header library
  McapCompression compression = McapCompression::kZstd;
  size_t chunk_bytes = size_t{4} << 20;  ///< a chunk is written once its records reach this
  int zstd_level = 1;                    ///< zstd compression level (1 = fastest)
};

/// the largest message payload accepted, in bytes (a 4K float image is 33 MB).
inline constexpr size_t kMcapMaxMessageBytes = size_t{1} << 30;
/// the largest schema data or metadata value, in bytes.
inline constexpr size_t kMcapMaxSchemaBytes = size_t{16} << 20;
/// the largest name, topic, encoding or key, in bytes.
inline constexpr size_t kMcapMaxNameBytes = size_t{64} << 10;

/// writes one MCAP file, chunked and indexed.
class McapWriter {
 public:
  /// creates `path` (O_CREAT | O_EXCL | O_NOFOLLOW: it must not exist) and writes the magic and
  /// the Header. messages name the file `shown_path` ("" = `path`).
  /// @throws Error naming the file and the system's reason if it cannot be created or written,
  ///         or if options.chunk_bytes is 0 or above 1 GiB.
  McapWriter(const std::string& path, McapWriterOptions options,
             const std::string& shown_path = "");
  /// finishes the file (Close) unless it was closed or abandoned; logs an error and never
  /// throws.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// adds a Schema record (e.g. name "sensor_msgs/msg/Image", encoding "ros2msg", data the
  /// message definition). @returns its id (1, 2, ...).
  /// @throws Error if a size exceeds the bounds above, past 65535 schemas, or the write fails.
  uint16_t AddSchema(std::string_view name, std::string_view encoding, std::string_view data);

  /// adds a Channel record: `topic` with messages in `message_encoding` (e.g. "cdr") described
  /// by schema `schema_id` (0 = none). @returns its id (1, 2, ...).
  /// @throws Error for an unknown schema id, sizes above the bounds, past 65535 channels, or a
  ///         failed write.
  uint16_t AddChannel(uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                      const McapKeyValues& metadata);

  /// adds a Message record on `channel_id` with `data` as its payload. log_time is when it was
  /// recorded, publish_time when it was published (ns; ROS 2 bags: since the epoch, or sim
  /// time). each channel's messages get sequence numbers 1, 2, .... messages need not come in
  /// time order (readers order them by the indexes).
  /// @throws Error for an unknown channel, a payload above kMcapMaxMessageBytes, or a failed
  ///         write (naming the channel's topic and the system's reason).
  void WriteMessage(uint16_t channel_id, uint64_t log_time_ns, uint64_t publish_time_ns,
                    std::span<const uint8_t> data);

  /// adds a Metadata record `name` (indexed in the summary), e.g. rosbag2's "rosbag2".
  /// @throws Error for sizes above the bounds or a failed write.
  void AddMetadata(std::string_view name, const McapKeyValues& metadata);

  /// writes the last chunk, DataEnd, the summary and the Footer, syncs and closes the file.
  /// does nothing when already closed.
  /// @throws Error naming the file and the system's reason (the file is then abandoned).
  void Close();

  /// messages written so far.
  uint64_t messages() const;
  /// messages written so far on `channel_id` (0 for an unknown id).
  uint64_t messages(uint16_t channel_id) const;
  /// the smallest and largest log time written (both 0 before the first message).
  uint64_t message_start_time() const;
  uint64_t message_end_time() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
