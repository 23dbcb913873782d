#include "penumbra/ros/mcap_writer.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/output_path_policy.h"

namespace penumbra {

namespace {

// record opcodes (spec "Records")
enum Op : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// little-endian serialisation of record fields
struct Bytes {
  std::string b;
  void U8(uint8_t v) { b.push_back(static_cast<char>(v)); }
  template <typename T>
  void Le(T v) {
    for (size_t i = 0; i < sizeof(T); ++i) b.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  void U16(uint16_t v) { Le(v); }
  void U32(uint32_t v) { Le(v); }
  void U64(uint64_t v) { Le(v); }
  // String and Bytes: uint32 length prefix
  void Str(std::string_view s) {
    U32(static_cast<uint32_t>(s.size()));
    b.append(s);
  }
  void Map(const McapKeyValues& m) {
    Bytes body;
    for (const auto& [k, v] : m) {
      body.Str(k);
      body.Str(v);
    }
    Str(body.b);
  }
  // opcode, uint64 content length, content
  void Record(uint8_t op, std::string_view content) {
    U8(op);
    U64(content.size());
    b.append(content);
  }
};

void CheckSize(std::string_view what, size_t n, size_t max) {
  if (n > max)
    throw Error("MCAP " + std::string(what) + " of " + std::to_string(n) +
                " bytes; expected at most " + std::to_string(max));
}

uint32_t Crc(uint32_t crc, const void* data, size_t n) {
  const auto* p = static_cast<const Bytef*>(data);
  while (n > 0) {
    const uInt step = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = static_cast<uint32_t>(crc32(crc, p, step));
    p += step;
    n -= step;
  }
  return crc;
}

struct ChunkIndexEntry {
  uint64_t start_time = 0, end_time = 0;
  uint64_t chunk_offset = 0, chunk_length = 0;
  std::map<uint16_t, uint64_t> index_offsets;
  uint64_t index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0, uncompressed_size = 0;
};

struct ChannelInfo {
  std::string topic;
  uint64_t count = 0;
  uint32_t sequence = 0;
};

}  // namespace

struct McapWriter::Impl {
  McapWriterOptions options;
  std::string shown;
  UniqueFd fd;
  bool open = false;
  bool abandoned = false;

  std::string out;        // bytes not yet written to the file
  uint64_t position = 0;  // file offset of the end of `out`
  // CRC of the data section (from the magic up to DataEnd) and of the summary
  uint32_t data_crc = 0;
  bool in_data = true;

  std::vector<std::string> schema_records;   // content of each Schema record (id = index + 1)
  std::vector<std::string> channel_records;  // content of each Channel record
  std::vector<ChannelInfo> channels;
  std::vector<std::pair<uint64_t, uint64_t>> metadata_at;  // offset, length of each Metadata
  std::vector<std::string> metadata_names;
  std::vector<ChunkIndexEntry> chunk_indexes;

  // the open chunk
  std::string chunk;
  uint64_t chunk_start = 0, chunk_end = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_messages;

  uint64_t message_count = 0;
  uint64_t start_time = 0, end_time = 0;

  [[noreturn]] void Fail(const std::string& what, int err) {
    abandoned = true;
    open = false;
    throw Error("cannot write the MCAP file " + shown + ": " + what +
                (err != 0 ? std::string(": ") + std::strerror(err) : ""));
  }

  void CheckOpen(const std::string& doing) const {
    if (!open)
      throw Error("cannot " + doing + " in the MCAP file " + shown +
                  (abandoned ? ": an earlier write failed" : ": it is closed"));
  }

  void WriteOut() {
    size_t done = 0;
    while (done < out.size()) {
      const ssize_t n = ::write(fd.get(), out.data() + done, out.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        Fail("writing " + std::to_string(out.size() - done) + " bytes", errno);
      }
      if (n == 0) Fail("the write made no progress", ENOSPC);
      done += static_cast<size_t>(n);
    }
    out.clear();
  }

  // appends bytes to the file (through `out`) and the running CRCs
  void Emit(std::string_view bytes) {
    if (in_data) data_crc = Crc(data_crc, bytes.data(), bytes.size());
    out.append(bytes);
    position += bytes.size();
    if (out.size() >= (size_t{1} << 20)) WriteOut();
  }

  void EmitRecord(uint8_t op, std::string_view content) {
    Bytes head;
    head.U8(op);
    head.U64(content.size());
    Emit(head.b);
    Emit(content);
  }

  void AddToChunk(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
                  std::span<const uint8_t> data) {
    ChannelInfo& ch = channels[channel_id - 1];
    if (chunk.empty()) {
      chunk_start = log_time;
      chunk_end = log_time;
    }
    chunk_start = std::min(chunk_start, log_time);
    chunk_end = std::max(chunk_end, log_time);
    chunk_messages[channel_id].emplace_back(log_time, chunk.size());
    Bytes head;
    head.U8(kMessage);
    head.U64(2 + 4 + 8 + 8 + data.size());
    head.U16(channel_id);
    head.U32(++ch.sequence);
    head.U64(log_time);
    head.U64(publish_time);
    chunk.append(head.b);
    chunk.append(reinterpret_cast<const char*>(data.data()), data.size());
    ++ch.count;
    if (message_count == 0) {
      start_time = log_time;
      end_time = log_time;
    }
    start_time = std::min(start_time, log_time);
    end_time = std::max(end_time, log_time);
    ++message_count;
    if (chunk.size() >= options.chunk_bytes) FlushChunk();
  }

  void FlushChunk() {
    if (chunk.empty()) return;
    ChunkIndexEntry idx;
    idx.start_time = chunk_start;
    idx.end_time = chunk_end;
    idx.uncompressed_size = chunk.size();
    const uint32_t crc = Crc(0, chunk.data(), chunk.size());
    std::string compressed;
    std::string_view records = chunk;
    if (options.compression == McapCompression::kZstd) {
      idx.compression = "zstd";
      compressed.resize(ZSTD_compressBound(chunk.size()));
      const size_t n = ZSTD_compress(compressed.data(), compressed.size(), chunk.data(),
                                     chunk.size(), options.zstd_level);
      if (ZSTD_isError(n)) Fail(std::string("zstd: ") + ZSTD_getErrorName(n), 0);
      compressed.resize(n);
      records = compressed;
    }
    idx.compressed_size = records.size();
    Bytes head;
    head.U64(idx.start_time);
    head.U64(idx.end_time);
    head.U64(idx.uncompressed_size);
    head.U32(crc);
    head.Str(idx.compression);
    head.U64(records.size());
    idx.chunk_offset = position;
    Bytes op;
    op.U8(kChunk);
    op.U64(head.b.size() + records.size());
    Emit(op.b);
    Emit(head.b);
    Emit(records);
    idx.chunk_length = position - idx.chunk_offset;
    const uint64_t index_start = position;
    for (const auto& [channel_id, entries] : chunk_messages) {
      Bytes r;
      r.U16(channel_id);
      r.U32(static_cast<uint32_t>(entries.size() * 16));
      for (const auto& [t, offset] : entries) {
        r.U64(t);
        r.U64(offset);
      }
      idx.index_offsets[channel_id] = position;
      EmitRecord(kMessageIndex, r.b);
    }
    idx.index_length = position - index_start;
    chunk_indexes.push_back(std::move(idx));
    chunk.clear();
    chunk_messages.clear();
  }

  void Finish() {
    FlushChunk();
    // DataEnd holds the CRC of the data section before it
    Bytes rec;
    rec.U8(kDataEnd);
    rec.U64(4);
    rec.U32(data_crc);
    in_data = false;
    Emit(rec.b);

    const uint64_t summary_start = position;
    uint32_t summary_crc = 0;
    std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> groups;
    auto emit_summary = [&](uint8_t op, std::string_view content) {
      Bytes r;
      r.Record(op, content);
      summary_crc = Crc(summary_crc, r.b.data(), r.b.size());
      Emit(r.b);
    };
    auto group = [&](uint8_t op, const std::vector<std::string>& contents) {
      if (contents.empty()) return;
      const uint64_t start = position;
      for (const std::string& c : contents) emit_summary(op, c);
      groups.emplace_back(op, start, position - start);
    };
    group(kSchema, schema_records);
    group(kChannel, channel_records);
    {
      Bytes s;
      s.U64(message_count);
      s.U16(static_cast<uint16_t>(schema_records.size()));
      s.U32(static_cast<uint32_t>(channel_records.size()));
      s.U32(0);  // attachments
      s.U32(static_cast<uint32_t>(metadata_at.size()));
      s.U32(static_cast<uint32_t>(chunk_indexes.size()));
      s.U64(start_time);
      s.U64(end_time);
      Bytes counts;
      for (size_t i = 0; i < channels.size(); ++i) {
        counts.U16(static_cast<uint16_t>(i + 1));
        counts.U64(channels[i].count);
      }
      s.Str(counts.b);
      group(kStatistics, {s.b});
    }
    std::vector<std::string> chunk_index_records;
    for (const ChunkIndexEntry& c : chunk_indexes) {
      Bytes r;
      r.U64(c.start_time);
      r.U64(c.end_time);
      r.U64(c.chunk_offset);
      r.U64(c.chunk_length);
      Bytes offsets;
      for (const auto& [channel_id, offset] : c.index_offsets) {
        offsets.U16(channel_id);
        offsets.U64(offset);
      }
      r.Str(offsets.b);
      r.U64(c.index_length);
      r.Str(c.compression);
      r.U64(c.compressed_size);
      r.U64(c.uncompressed_size);
      chunk_index_records.push_back(std::move(r.b));
    }
    group(kChunkIndex, chunk_index_records);
    std::vector<std::string> metadata_index_records;
    for (size_t i = 0; i < metadata_at.size(); ++i) {
      Bytes r;
      r.U64(metadata_at[i].first);
      r.U64(metadata_at[i].second);
      r.Str(metadata_names[i]);
      metadata_index_records.push_back(std::move(r.b));
    }
    group(kMetadataIndex, metadata_index_records);

    const uint64_t summary_offset_start = position;
    for (const auto& [op, start, length] : groups) {
      Bytes r;
      r.U8(op);
      r.U64(start);
      r.U64(length);
      emit_summary(kSummaryOffset, r.b);
    }
    Bytes footer;
    footer.U8(kFooter);
    footer.U64(8 + 8 + 4);
    footer.U64(summary_start);
    footer.U64(summary_offset_start);
    summary_crc = Crc(summary_crc, footer.b.data(), footer.b.size());
    footer.U32(summary_crc);
    Emit(footer.b);
    Emit(std::string_view(reinterpret_cast<const char*>(kMagic), sizeof(kMagic)));
    WriteOut();
    if (::fsync(fd.get()) != 0 && errno != EINVAL && errno != EROFS) Fail("fsync", errno);
    const int raw = fd.release();
    if (::close(raw) != 0 && errno != EINTR) Fail("close", errno);
  }
};

McapWriter::McapWriter(const std::string& path, McapWriterOptions options,
                       const std::string& shown_path)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.shown = shown_path.empty() ? path : shown_path;
  if (options.chunk_bytes == 0 || options.chunk_bytes > (size_t{1} << 30))
    throw Error("MCAP chunk size of " + std::to_string(options.chunk_bytes) +
                " bytes; expected 1 byte to 1 GiB");
  CheckSize("profile", options.profile.size(), kMcapMaxNameBytes);
  CheckSize("library", options.library.size(), kMcapMaxNameBytes);
  m.options = std::move(options);
  m.fd = UniqueFd(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666));
  if (m.fd.get() < 0)
    throw Error("cannot create the MCAP file " + m.shown + ": " + std::strerror(errno));
  m.open = true;
  m.Emit(std::string_view(reinterpret_cast<const char*>(kMagic), sizeof(kMagic)));
  Bytes h;
  h.Str(m.options.profile);
  h.Str(m.options.library);
  m.EmitRecord(kHeader, h.b);
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

uint16_t McapWriter::AddSchema(std::string_view name, std::string_view encoding,
                               std::string_view data) {
  Impl& m = *impl_;
  m.CheckOpen("add a schema");
  CheckSize("schema name", name.size(), kMcapMaxNameBytes);
  CheckSize("schema encoding", encoding.size(), kMcapMaxNameBytes);
  CheckSize("schema data", data.size(), kMcapMaxSchemaBytes);
  if (m.schema_records.size() >= std::numeric_limits<uint16_t>::max())
    throw Error("MCAP file " + m.shown + ": more than 65535 schemas");
  const auto id = static_cast<uint16_t>(m.schema_records.size() + 1);
  Bytes r;
  r.U16(id);
  r.Str(name);
  r.Str(encoding);
  r.Str(data);
  m.EmitRecord(kSchema, r.b);
  m.schema_records.push_back(std::move(r.b));
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, std::string_view topic,
                                std::string_view message_encoding, const McapKeyValues& metadata) {
  Impl& m = *impl_;
  m.CheckOpen("add a channel");
  if (schema_id > m.schema_records.size())
    throw Error("MCAP channel " + std::string(topic) + ": schema id " + std::to_string(schema_id) +
                " was not added; expected 0 (none) or 1 to " +
                std::to_string(m.schema_records.size()));
  CheckSize("topic", topic.size(), kMcapMaxNameBytes);
  CheckSize("message encoding", message_encoding.size(), kMcapMaxNameBytes);
  size_t metadata_bytes = 0;
  for (const auto& [k, v] : metadata) {
    CheckSize("channel metadata key", k.size(), kMcapMaxNameBytes);
    metadata_bytes += 8 + k.size() + v.size();
  }
  CheckSize("channel metadata", metadata_bytes, kMcapMaxSchemaBytes);
  if (m.channels.size() >= std::numeric_limits<uint16_t>::max())
    throw Error("MCAP file " + m.shown + ": more than 65535 channels");
  const auto id = static_cast<uint16_t>(m.channels.size() + 1);
  Bytes r;
  r.U16(id);
  r.U16(schema_id);
  r.Str(topic);
  r.Str(message_encoding);
  r.Map(metadata);
  m.EmitRecord(kChannel, r.b);
  m.channel_records.push_back(std::move(r.b));
  m.channels.push_back({std::string(topic), 0, 0});
  return id;
}

void McapWriter::WriteMessage(uint16_t channel_id, uint64_t log_time_ns, uint64_t publish_time_ns,
                              std::span<const uint8_t> data) {
  Impl& m = *impl_;
  if (channel_id == 0 || channel_id > m.channels.size())
    throw Error("MCAP file " + m.shown + ": channel id " + std::to_string(channel_id) +
                " was not added");
  m.CheckOpen("write a message on " + m.channels[channel_id - 1].topic);
  CheckSize("message on " + m.channels[channel_id - 1].topic, data.size(), kMcapMaxMessageBytes);
  try {
    m.AddToChunk(channel_id, log_time_ns, publish_time_ns, data);
  } catch (const std::bad_alloc&) {
    m.Fail("out of memory for a message on " + m.channels[channel_id - 1].topic, ENOMEM);
  }
}

void McapWriter::AddMetadata(std::string_view name, const McapKeyValues& metadata) {
  Impl& m = *impl_;
  m.CheckOpen("add metadata");
  CheckSize("metadata name", name.size(), kMcapMaxNameBytes);
  size_t bytes = 0;
  for (const auto& [k, v] : metadata) {
    CheckSize("metadata key", k.size(), kMcapMaxNameBytes);
    bytes += 8 + k.size() + v.size();
  }
  CheckSize("metadata", bytes, kMcapMaxSchemaBytes);
  Bytes r;
  r.Str(name);
  r.Map(metadata);
  const uint64_t at = m.position;
  m.EmitRecord(kMetadata, r.b);
  m.metadata_at.emplace_back(at, m.position - at);
  m.metadata_names.emplace_back(name);
}

void McapWriter::Close() {
  if (!impl_ || !impl_->open) return;
  impl_->Finish();
  impl_->open = false;
}

uint64_t McapWriter::messages() const { return impl_->message_count; }
uint64_t McapWriter::messages(uint16_t channel_id) const {
  if (channel_id == 0 || channel_id > impl_->channels.size()) return 0;
  return impl_->channels[channel_id - 1].count;
}
uint64_t McapWriter::message_start_time() const { return impl_->start_time; }
uint64_t McapWriter::message_end_time() const { return impl_->end_time; }

}  // namespace penumbra
