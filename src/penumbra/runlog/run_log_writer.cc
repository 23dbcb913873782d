#include "penumbra/runlog/run_log_writer.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "penumbra/core/bounded_queue.h"
#include "penumbra/runlog/run_log_codec.h"

namespace penumbra {

using namespace runlog_codec;

namespace {

// a chunk handed to the writer thread: its header (index and sizes are set there) and raw body
struct PendingChunk {
  ChunkHeader header;
  std::string raw;
};

// records of one kind gathered into the next chunk
struct OpenChunk {
  explicit OpenChunk(RunLogChunkKind k) : kind(k) {}
  RunLogChunkKind kind;
  std::string body;
  uint32_t count = 0;
  int64_t first_step = 0;
  int64_t last_step = 0;

  void Note(int64_t step) {
    if (count == 0 || step < first_step) first_step = step;
    if (count == 0 || step > last_step) last_step = step;
    ++count;
  }
  // the chunk to write, leaving this one empty
  PendingChunk Take() {
    PendingChunk p;
    p.header.kind = kind;
    p.header.record_count = count;
    p.header.first_step = count ? first_step : 0;
    p.header.last_step = count ? last_step : 0;
    p.raw = std::move(body);
    body.clear();
    count = 0;
    return p;
  }
};

}  // namespace

void RunLogWriterOptions::ValidateOrThrow() const {
  if (chunk_steps < 1)
    throw ConfigError("", 0, "record.chunk_steps",
                      fmt::format("{} is not a step count; expected >= 1", chunk_steps));
  if (chunk_bytes < 1) throw ConfigError("", 0, "record.chunk_bytes", "0; expected >= 1");
  if (chunk_bytes > runlog_codec::kMaxChunkBodyBytes / 2)
    throw ConfigError("", 0, "record.chunk_bytes",
                      fmt::format("{}; expected at most {} (docs/run-log.md \"Limits\")",
                                  chunk_bytes, runlog_codec::kMaxChunkBodyBytes / 2));
  if (zstd_level < 1 || zstd_level > 19)
    throw ConfigError("", 0, "record.zstd_level", fmt::format("{}; expected 1 to 19", zstd_level));
  if (max_pending_chunks < 1)
    throw ConfigError("", 0, "record.max_pending_chunks", "0; expected >= 1");
}

struct RunLogWriter::Impl {
  std::string path;
  RunLogHeader header;
  RunLogWriterOptions options;
  int fd = -1;

  // the loop thread's steps chunk
  OpenChunk steps{RunLogChunkKind::kSteps};
  StepRecord prev;
  bool has_prev = false;
  int64_t last_step = -1;
  int64_t first_step = -1;

  // events and sensor records, from any thread
  std::mutex records_mu;
  OpenChunk events{RunLogChunkKind::kEvents};
  OpenChunk sensors{RunLogChunkKind::kSensors};

  BoundedQueue<PendingChunk> queue;
  std::thread thread;
  uint64_t next_index = 1;  // writer thread only (0 is the header chunk)

  std::atomic<bool> failed{false};
  std::mutex error_mu;
  std::string error;
  bool closed = false;

  std::atomic<int64_t> n_steps{0}, n_events{0}, n_sensors{0}, n_chunks{0};
  std::atomic<uint64_t> file_bytes{0};

  explicit Impl(size_t capacity) : queue(capacity) {}

  void Fail(const std::string& what) {
    std::lock_guard<std::mutex> lock(error_mu);
    if (error.empty()) error = what;
    failed = true;
  }
  void ThrowIfFailed() {
    if (!failed) return;
    std::lock_guard<std::mutex> lock(error_mu);
    throw RunLogError(error);
  }

  // writes all of `data` (called on the constructor's thread, then only the writer thread)
  bool WriteAll(std::string_view data) {
    size_t done = 0;
    while (done < data.size()) {
      const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        Fail(fmt::format("run log {}: write failed after {} bytes: {}", path,
                         file_bytes.load() + done, std::strerror(errno)));
        return false;
      }
      done += static_cast<size_t>(n);
    }
    file_bytes += data.size();
    return true;
  }

  // compresses a chunk (stored raw where zstd does not make it smaller) and writes it
  void WriteChunk(PendingChunk& c, uint64_t index) {
    ChunkHeader h = c.header;
    h.index = index;
    h.raw_size = c.raw.size();
    // a reader refuses a larger chunk (docs/run-log.md "Limits")
    const uint64_t cap =
        h.kind == RunLogChunkKind::kHeader ? kMaxHeaderChunkBytes : kMaxChunkBodyBytes;
    if (h.raw_size > cap)
      throw RunLogError(fmt::format(
          "a {} chunk of {} bytes is above the format's maximum of {} bytes (docs/run-log.md "
          "\"Limits\"); record fewer or smaller sensor outputs",
          RunLogChunkKindName(h.kind), h.raw_size, cap));
    std::string stored;
    if (!c.raw.empty()) stored = ZstdCompress(c.raw, options.zstd_level);
    if (c.raw.empty() || stored.size() >= c.raw.size()) {
      h.codec = kCodecNone;
      stored = std::move(c.raw);
    } else {
      h.codec = kCodecZstd;
    }
    h.stored_size = stored.size();
    std::string out = EncodeChunkHeader(h);
    out.reserve(out.size() + stored.size() + kChunkTrailerBytes);
    out += stored;
    PutU32(&out, Crc32(stored.data(), stored.size()));
    if (WriteAll(out)) ++n_chunks;
  }

  void Run() {
    while (std::optional<PendingChunk> c = queue.Pop()) {
      if (failed) continue;
      try {
        WriteChunk(*c, next_index++);
      } catch (const std::exception& e) {
        Fail(fmt::format("run log {}: {}", path, e.what()));
      }
    }
  }

  // hands the open steps chunk and the events and sensor records gathered so far to the
  // writer thread (loop thread)
  void FlushSteps() {
    if (steps.count > 0) queue.Push(steps.Take());
    has_prev = false;
    std::lock_guard<std::mutex> lock(records_mu);
    if (events.count > 0) queue.Push(events.Take());
    if (sensors.count > 0) queue.Push(sensors.Take());
  }
};

namespace {

// the writer never writes what the reader refuses (docs/run-log.md "Limits"): checked before the
// file is opened or written
void ThrowIfUnreadable(const std::string& path, const RunLogHeader& header) {
  std::string bad = CheckHeader(header);
  if (bad.empty() && StepRecordMemoryBytes(header.layout) > kMaxChunkDecodedBytes / 2)
    bad = fmt::format(
        "one step of this model takes {} bytes, more than a run log chunk may hold "
        "(docs/run-log.md \"Limits\")",
        StepRecordMemoryBytes(header.layout));
  if (!bad.empty()) throw RunLogError(fmt::format("run log {}: {}", path, bad));
}

}  // namespace

RunLogWriter::RunLogWriter(const std::string& path, const RunLogHeader& header,
                           const RunLogWriterOptions& options) {
  options.ValidateOrThrow();
  ThrowIfUnreadable(path, header);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw RunLogError(fmt::format("run log {}: cannot be created: {}", path, std::strerror(errno)));
  Start(fd, path, header, options);
}

RunLogWriter::RunLogWriter(UniqueFd fd, const std::string& name, const RunLogHeader& header,
                           const RunLogWriterOptions& options) {
  options.ValidateOrThrow();  // fd closes itself if this throws
  ThrowIfUnreadable(name, header);
  Start(fd.release(), name, header, options);
}

void RunLogWriter::Start(int fd, const std::string& path, const RunLogHeader& header,
                         const RunLogWriterOptions& options) {
  impl_ = std::make_unique<Impl>(options.max_pending_chunks);
  Impl& m = *impl_;
  m.path = path;
  m.header = header;
  m.header.format_version = kRunLogFormatVersion;
  m.options = options;
  m.fd = fd;
  // preamble and header chunk, before any step
  PendingChunk head;
  head.header.kind = RunLogChunkKind::kHeader;
  head.header.record_count = 1;
  head.raw = HeaderToJson(m.header);
  if (m.WriteAll(EncodePreamble(kRunLogFormatVersion))) {
    try {
      m.WriteChunk(head, 0);
    } catch (const std::exception& e) {
      m.Fail(fmt::format("run log {}: {}", path, e.what()));
    }
  }
  if (m.failed) {
    ::close(m.fd);
    m.closed = true;
    m.ThrowIfFailed();
  }
  m.thread = std::thread([&m] { m.Run(); });
}

RunLogWriter::~RunLogWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

void RunLogWriter::Append(const StepRecord& r) {
  Impl& m = *impl_;
  if (m.closed) throw RunLogError(fmt::format("run log {}: Append after Close", m.path));
  m.ThrowIfFailed();
  if (r.step <= m.last_step)
    throw RunLogError(fmt::format("run log {}: step {} appended after step {}; steps must increase",
                                  m.path, r.step, m.last_step));
  const RunLogLayout& l = m.header.layout;
  const StateDims dims = l.dims();
  ForEachStateField(
      [&](const StateFieldInfo& f, const auto& v) {
        if (static_cast<int64_t>(v.size()) != StateFieldSize(f, dims))
          throw RunLogError(
              fmt::format("run log {}: step {}: {} has {} entries; the header's layout says {}",
                          m.path, r.step, f.name, v.size(), StateFieldSize(f, dims)));
      },
      r);
  EncodeStep(r, m.has_prev ? &m.prev : nullptr, &m.steps.body);
  m.steps.Note(r.step);
  m.prev = r;  // same sizes every step: the vectors' storage is reused
  m.has_prev = true;
  if (m.first_step < 0) m.first_step = r.step;
  m.last_step = r.step;
  ++m.n_steps;
  // a chunk also closes at half the decoded size a reader accepts (docs/run-log.md "Limits")
  if (m.steps.count >= static_cast<uint32_t>(m.options.chunk_steps) ||
      m.steps.body.size() >= m.options.chunk_bytes ||
      (m.steps.count + 1) * StepRecordMemoryBytes(l) > kMaxChunkDecodedBytes / 2)
    m.FlushSteps();
}

void RunLogWriter::RecordEvent(const EventRecord& e) {
  Impl& m = *impl_;
  m.ThrowIfFailed();
  std::lock_guard<std::mutex> lock(m.records_mu);
  if (m.closed) throw RunLogError(fmt::format("run log {}: RecordEvent after Close", m.path));
  EncodeEvent(e, &m.events.body);
  m.events.Note(e.step);
  ++m.n_events;
  if (m.events.body.size() >= m.options.chunk_bytes) m.queue.Push(m.events.Take());
}

void RunLogWriter::RecordEvent(int64_t step, double time_sec, const std::string& kind,
                               const std::string& payload_json) {
  RecordEvent(EventRecord{step, time_sec, kind, payload_json});
}

void RunLogWriter::RecordSensor(const SensorRecord& s) {
  Impl& m = *impl_;
  m.ThrowIfFailed();
  std::lock_guard<std::mutex> lock(m.records_mu);
  if (m.closed) throw RunLogError(fmt::format("run log {}: RecordSensor after Close", m.path));
  EncodeSensor(s, &m.sensors.body);
  m.sensors.Note(s.step);
  ++m.n_sensors;
  if (m.sensors.body.size() >= m.options.chunk_bytes) m.queue.Push(m.sensors.Take());
}

void RunLogWriter::Close() {
  Impl& m = *impl_;
  {
    std::lock_guard<std::mutex> lock(m.records_mu);
    if (m.closed) return;
  }
  m.FlushSteps();
  {
    std::lock_guard<std::mutex> lock(m.records_mu);
    m.closed = true;
  }
  // the end chunk: the log was closed cleanly; its body sums the log up
  PendingChunk end;
  end.header.kind = RunLogChunkKind::kEnd;
  end.header.first_step = m.first_step < 0 ? 0 : m.first_step;
  end.header.last_step = m.last_step < 0 ? 0 : m.last_step;
  end.raw = nlohmann::json{{"steps", m.n_steps.load()},
                           {"events", m.n_events.load()},
                           {"sensor_records", m.n_sensors.load()},
                           {"first_step", m.first_step},
                           {"last_step", m.last_step}}
                .dump();
  m.queue.Push(std::move(end));
  m.queue.Close();
  if (m.thread.joinable()) m.thread.join();
  if (::close(m.fd) != 0)
    m.Fail(fmt::format("run log {}: closing failed: {}", m.path, std::strerror(errno)));
  m.ThrowIfFailed();
}

RunLogWriterStats RunLogWriter::stats() const {
  const Impl& m = *impl_;
  RunLogWriterStats s;
  s.steps = m.n_steps;
  s.events = m.n_events;
  s.sensor_records = m.n_sensors;
  s.chunks = m.n_chunks;
  s.file_bytes = m.file_bytes;
  s.first_step = m.first_step;
  s.last_step = m.last_step;
  return s;
}

const std::string& RunLogWriter::path() const { return impl_->path; }

}  // namespace penumbra
