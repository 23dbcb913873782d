#include "penumbra/runlog/run_log_reader.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/runlog/run_log_codec.h"

namespace penumbra {

using namespace runlog_codec;

namespace {

std::string VersionList() {
  std::string s;
  for (uint32_t v : kRunLogReadableVersions) s += (s.empty() ? "" : ", ") + std::to_string(v);
  return s;
}

std::string StepsOf(const ChunkHeader& h) {
  if (h.kind == RunLogChunkKind::kHeader || h.record_count == 0) return "";
  return h.first_step == h.last_step ? fmt::format(", step {}", h.first_step)
                                     : fmt::format(", steps {}..{}", h.first_step, h.last_step);
}

}  // namespace

struct RunLogReader::Impl {
  std::string path;
  RunLogReadMode mode = RunLogReadMode::kStrict;
  InputFile file;  // a regular file (core/input_file.h)
  uint64_t file_size = 0;
  RunLogHeader header;
  std::vector<RunLogChunkInfo> chunks;
  std::vector<uint32_t> codecs;     // by position in chunks
  std::vector<size_t> step_chunks;  // positions in chunks of the steps chunks
  bool complete = false;
  std::optional<std::string> damage;
  int64_t num_steps = 0, first_step = -1, last_step = -1;

  // step cursor
  size_t step_chunk = 0;  // position in step_chunks
  std::vector<StepRecord> steps;
  size_t step_pos = 0;
  bool steps_loaded = false;

  // record cursor
  size_t record_chunk = 1;  // position in chunks (0 = header)
  std::vector<RunLogRecord> records;
  size_t record_pos = 0;

  // reads `n` bytes at `offset`; false when the file is shorter
  bool ReadAt(uint64_t offset, uint64_t n, std::string* out) {
    if (offset > file_size || n > file_size - offset) return false;
    out->resize(n);
    uint64_t done = 0;
    while (done < n) {
      const ssize_t got =
          ::pread(file.fd.get(), out->data() + done, n - done, static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got < 0)
        throw RunLogError(fmt::format("{}: cannot be read: {}", path, std::strerror(errno)));
      if (got == 0) return false;  // the file shrank since it was opened
      done += static_cast<uint64_t>(got);
    }
    return true;
  }

  std::string ChunkName(const RunLogChunkInfo& c) const {
    ChunkHeader h;
    h.kind = c.kind;
    h.record_count = c.record_count;
    h.first_step = c.first_step;
    h.last_step = c.last_step;
    return fmt::format("chunk {} ({}{})", c.index, RunLogChunkKindName(c.kind), StepsOf(h));
  }

  // the raw body of chunks[pos], checked again against its CRC
  std::string Body(size_t pos) {
    const RunLogChunkInfo& c = chunks[pos];
    std::string stored;
    if (!ReadAt(c.file_offset + kChunkHeaderBytes, c.compressed_size + kChunkTrailerBytes, &stored))
      throw RunLogError(
          fmt::format("{}: {} can no longer be read (the file shrank)", path, ChunkName(c)));
    uint32_t crc;
    std::memcpy(&crc, stored.data() + c.compressed_size, 4);
    stored.resize(c.compressed_size);
    if (Crc32(stored.data(), stored.size()) != crc)
      throw RunLogError(fmt::format("{}: CRC mismatch in {} (the file changed since it was opened)",
                                    path, ChunkName(c)));
    if (codecs[pos] == kCodecNone) return stored;
    try {
      return ZstdDecompress(stored, c.raw_size);
    } catch (const RunLogError& e) {
      throw RunLogError(fmt::format("{}: {}: {}", path, ChunkName(c), e.what()));
    }
  }

  // refuses a record count that the body cannot hold or whose decoded records would take more
  // than kMaxChunkDecodedBytes, before anything is allocated for them
  void CheckRecordCount(size_t pos, uint64_t body_bytes, uint64_t min_record_bytes,
                        uint64_t record_memory_bytes) const {
    const RunLogChunkInfo& c = chunks[pos];
    if (c.record_count > body_bytes / min_record_bytes)
      throw RunLogError(fmt::format(
          "{}: {} at byte {}: {} records declared; its {}-byte body holds at most {} of at least "
          "{} bytes each",
          path, ChunkName(c), c.file_offset, c.record_count, body_bytes,
          body_bytes / min_record_bytes, min_record_bytes));
    if (c.record_count > kMaxChunkDecodedBytes / record_memory_bytes)
      throw RunLogError(fmt::format(
          "{}: {} at byte {}: {} records of {} bytes each would take more than the format's "
          "maximum of {} bytes decoded per chunk (docs/run-log.md \"Limits\")",
          path, ChunkName(c), c.file_offset, c.record_count, record_memory_bytes,
          kMaxChunkDecodedBytes));
  }

  std::vector<StepRecord> DecodeSteps(size_t pos) {
    const std::string body = Body(pos);
    CheckRecordCount(pos, body.size(), MinStepRecordBytes(header.format_version),
                     StepRecordMemoryBytes(header.layout));
    BodyReader in(body, fmt::format("{}: {}", path, ChunkName(chunks[pos])));
    std::vector<StepRecord> out(chunks[pos].record_count);
    for (size_t i = 0; i < out.size(); ++i)
      DecodeStep(&in, i ? &out[i - 1] : nullptr, &out[i], &header.layout, header.format_version);
    if (!in.done()) in.Fail("bytes left after the last record");
    return out;
  }

  std::vector<RunLogRecord> DecodeRecords(size_t pos) {
    const RunLogChunkInfo& c = chunks[pos];
    std::vector<RunLogRecord> out;
    if (c.kind == RunLogChunkKind::kSteps) {
      for (StepRecord& s : DecodeSteps(pos)) out.emplace_back(std::move(s));
      return out;
    }
    if (c.kind != RunLogChunkKind::kEvents && c.kind != RunLogChunkKind::kSensors) return out;
    const std::string body = Body(pos);
    // a decoded event or sensor record takes its strings' bytes plus the record itself
    const bool events = c.kind == RunLogChunkKind::kEvents;
    CheckRecordCount(pos, body.size(), events ? kMinEventRecordBytes : kMinSensorRecordBytes,
                     sizeof(RunLogRecord));
    BodyReader in(body, fmt::format("{}: {}", path, ChunkName(c)));
    out.reserve(c.record_count);
    for (uint32_t i = 0; i < c.record_count; ++i) {
      if (c.kind == RunLogChunkKind::kEvents)
        out.emplace_back(DecodeEvent(&in));
      else
        out.emplace_back(DecodeSensor(&in));
    }
    if (!in.done()) in.Fail("bytes left after the last record");
    return out;
  }

  void ReadPreambleAndHeader();
  void ScanChunks();
};

void RunLogReader::Impl::ReadPreambleAndHeader() {
  std::string pre;
  const uint64_t have = std::min<uint64_t>(file_size, kPreambleBytes);
  ReadAt(0, have, &pre);
  const size_t magic_have = std::min<size_t>(pre.size(), kRunLogMagic.size());
  if (magic_have == 0)
    throw RunLogError(fmt::format("{}: empty file; expected a penumbra run log (.plog)", path));
  if (std::memcmp(pre.data(), kRunLogMagic.data(), magic_have) != 0)
    throw RunLogError(fmt::format(
        "{}: not a penumbra run log (.plog): the file does not start with the run log magic",
        path));
  if (file_size < kPreambleBytes)
    throw RunLogError(fmt::format(
        "{}: truncated run log header: the file has {} bytes, fewer than the {}-byte preamble",
        path, file_size, kPreambleBytes));
  uint32_t version;
  std::memcpy(&version, pre.data() + 8, 4);

  // the header chunk (chunk 0)
  auto truncated = [&](const std::string& why) {
    return RunLogError(fmt::format("{}: truncated run log header: {}", path, why));
  };
  std::string hb;
  if (!ReadAt(kPreambleBytes, kChunkHeaderBytes, &hb))
    throw truncated(fmt::format("the file ends {} bytes into the {}-byte header chunk header",
                                file_size - kPreambleBytes, kChunkHeaderBytes));
  ChunkHeader h;
  const std::string bad = DecodeChunkHeader(reinterpret_cast<const uint8_t*>(hb.data()), &h);
  const bool readable = std::find(kRunLogReadableVersions.begin(), kRunLogReadableVersions.end(),
                                  version) != kRunLogReadableVersions.end();
  std::string text;
  std::string header_error = bad;
  if (header_error.empty() && (h.kind != RunLogChunkKind::kHeader || h.index != 0))
    header_error = fmt::format("the first chunk is chunk {} of kind {}, not the header chunk",
                               h.index, RunLogChunkKindName(h.kind));
  bool cut = false;
  if (header_error.empty()) {
    // stored_size is at most kMaxHeaderChunkBytes here (DecodeChunkHeader): the sum cannot wrap
    std::string stored;
    if (!ReadAt(kPreambleBytes + kChunkHeaderBytes, h.stored_size + kChunkTrailerBytes, &stored)) {
      cut = true;
      header_error = fmt::format("the file ends {} bytes into the header chunk's {}-byte body",
                                 file_size - kPreambleBytes - kChunkHeaderBytes,
                                 h.stored_size + kChunkTrailerBytes);
    } else {
      uint32_t crc;
      std::memcpy(&crc, stored.data() + h.stored_size, 4);
      stored.resize(h.stored_size);
      if (Crc32(stored.data(), stored.size()) != crc) {
        header_error = "CRC mismatch in chunk 0 (header)";
      } else {
        try {
          text = h.codec == kCodecZstd ? ZstdDecompress(stored, h.raw_size) : stored;
        } catch (const RunLogError& e) {
          header_error = std::string("chunk 0 (header): ") + e.what();
        }
      }
    }
  }
  if (!readable) {
    // name the writer's version when its header can still be read
    std::string writer;
    if (header_error.empty()) {
      try {
        writer = fmt::format(" (written by penumbra {})", HeaderFromJson(text).penumbra_version);
      } catch (const RunLogError&) {
      }
    }
    throw RunLogError(fmt::format(
        "{}: run log format version {}{}; this penumbra ({}) reads run log format version {}: "
        "read the log with the penumbra version that wrote it or a later one that lists "
        "format {} among the versions it reads (docs/run-log.md, \"Versions\")",
        path, version, writer, PENUMBRA_VERSION, VersionList(), version));
  }
  if (!header_error.empty()) {
    if (cut) throw truncated(header_error);
    throw RunLogError(fmt::format("{}: damaged run log header: {}", path, header_error));
  }
  try {
    header = HeaderFromJson(text);
  } catch (const RunLogError& e) {
    throw RunLogError(fmt::format("{}: damaged run log header: {}", path, e.what()));
  }
  if (header.format_version != version)
    throw RunLogError(fmt::format(
        "{}: damaged run log header: the header chunk says format version {}, the preamble {}",
        path, header.format_version, version));
  RunLogChunkInfo info;
  info.kind = RunLogChunkKind::kHeader;
  info.index = 0;
  info.record_count = h.record_count;
  info.raw_size = h.raw_size;
  info.compressed_size = h.stored_size;
  info.file_offset = kPreambleBytes;
  chunks.push_back(info);
  codecs.push_back(h.codec);
}

void RunLogReader::Impl::ScanChunks() {
  uint64_t offset =
      chunks[0].file_offset + kChunkHeaderBytes + chunks[0].compressed_size + kChunkTrailerBytes;
  uint64_t expected = 1;
  bool end_seen = false;
  std::string why;
  std::string hb, body;
  while (true) {
    if (offset == file_size) {
      if (!end_seen)
        why = "the log has no end chunk: it was not closed (the recorder was killed or crashed)";
      break;
    }
    if (end_seen) {
      why = fmt::format("{} bytes follow the end chunk", file_size - offset);
      break;
    }
    if (file_size - offset < kChunkHeaderBytes) {
      why = fmt::format("chunk {} is cut off: the file ends {} bytes into its {}-byte header",
                        expected, file_size - offset, kChunkHeaderBytes);
      break;
    }
    ReadAt(offset, kChunkHeaderBytes, &hb);
    ChunkHeader h;
    const std::string bad = DecodeChunkHeader(reinterpret_cast<const uint8_t*>(hb.data()), &h);
    if (!bad.empty()) {
      why = fmt::format("chunk {} (at byte {}) is damaged: {}", expected, offset, bad);
      break;
    }
    const std::string name =
        fmt::format("chunk {} ({}{})", expected, RunLogChunkKindName(h.kind), StepsOf(h));
    if (h.index != expected) {
      why = fmt::format("the chunk at byte {} says it is chunk {}; expected chunk {}", offset,
                        h.index, expected);
      break;
    }
    if (h.kind == RunLogChunkKind::kHeader) {
      why = fmt::format("{} is a second header chunk", name);
      break;
    }
    // checked arithmetic: the declared size is compared with what is left before adding to it
    // (DecodeChunkHeader has capped it at kMaxChunkBodyBytes as well)
    const uint64_t left = file_size - offset - kChunkHeaderBytes;
    if (h.stored_size > left || kChunkTrailerBytes > left - h.stored_size) {
      why = fmt::format(
          "{} is cut off: the file ends {} bytes into its {}-byte body and CRC (chunk header at "
          "byte {})",
          name, left, h.stored_size + kChunkTrailerBytes, offset);
      break;
    }
    const uint64_t need = h.stored_size + kChunkTrailerBytes;
    ReadAt(offset + kChunkHeaderBytes, need, &body);
    uint32_t crc;
    std::memcpy(&crc, body.data() + h.stored_size, 4);
    const uint32_t computed = Crc32(body.data(), h.stored_size);
    if (crc != computed) {
      why = fmt::format("CRC mismatch in {}: stored {:08x}, computed {:08x}", name, crc, computed);
      break;
    }
    RunLogChunkInfo info;
    info.kind = h.kind;
    info.index = h.index;
    info.record_count = h.record_count;
    info.first_step = h.first_step;
    info.last_step = h.last_step;
    info.raw_size = h.raw_size;
    info.compressed_size = h.stored_size;
    info.file_offset = offset;
    chunks.push_back(info);
    codecs.push_back(h.codec);
    if (h.kind == RunLogChunkKind::kSteps && h.record_count > 0) {
      step_chunks.push_back(chunks.size() - 1);
      num_steps += h.record_count;
      if (first_step < 0) first_step = h.first_step;
      last_step = h.last_step;
    }
    if (h.kind == RunLogChunkKind::kEnd) end_seen = true;
    offset += kChunkHeaderBytes + need;
    ++expected;
  }
  complete = why.empty();
  if (complete) return;
  const std::string step = last_step >= 0 ? fmt::format("step {}", last_step) : "no step";
  const std::string msg =
      fmt::format("log ends at chunk {} ({}): {}", chunks.back().index, step, why);
  if (mode == RunLogReadMode::kStrict) throw RunLogError(fmt::format("{}: {}", path, msg));
  damage = msg;
}

RunLogReader RunLogReader::Open(const std::string& path, RunLogReadMode mode) {
  auto m = std::make_unique<Impl>();
  m->path = path;
  m->mode = mode;
  // a regular file only: a folder or /dev/zero read as an "empty file" and a FIFO blocked
  // in open() for ever
  try {
    m->file = OpenInputFile(path, "run log");
  } catch (const ConfigError& e) {
    throw RunLogError(fmt::format("{}: {} (a penumbra run log, .plog)", path, e.problem()));
  }
  m->file_size = m->file.size;
  m->ReadPreambleAndHeader();
  m->ScanChunks();
  return RunLogReader(std::move(m));
}

RunLogReader::RunLogReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RunLogReader::RunLogReader(RunLogReader&&) noexcept = default;
RunLogReader& RunLogReader::operator=(RunLogReader&&) noexcept = default;
RunLogReader::~RunLogReader() = default;

const RunLogHeader& RunLogReader::header() const { return impl_->header; }
const std::string& RunLogReader::path() const { return impl_->path; }
const std::vector<RunLogChunkInfo>& RunLogReader::chunks() const { return impl_->chunks; }
bool RunLogReader::complete() const { return impl_->complete; }
const std::optional<std::string>& RunLogReader::damage() const { return impl_->damage; }
int64_t RunLogReader::num_steps() const { return impl_->num_steps; }
int64_t RunLogReader::first_step() const { return impl_->first_step; }
int64_t RunLogReader::last_step() const { return impl_->last_step; }

bool RunLogReader::SeekStep(int64_t step) {
  Impl& m = *impl_;
  // the first steps chunk whose last step is >= step
  const auto it =
      std::lower_bound(m.step_chunks.begin(), m.step_chunks.end(), step,
                       [&](size_t pos, int64_t s) { return m.chunks[pos].last_step < s; });
  m.step_chunk = static_cast<size_t>(it - m.step_chunks.begin());
  m.steps.clear();
  m.step_pos = 0;
  m.steps_loaded = false;
  if (it == m.step_chunks.end()) return false;
  m.steps = m.DecodeSteps(*it);
  m.steps_loaded = true;
  while (m.step_pos < m.steps.size() && m.steps[m.step_pos].step < step) ++m.step_pos;
  return m.step_pos < m.steps.size();
}

bool RunLogReader::NextStep(StepRecord* out) {
  Impl& m = *impl_;
  while (true) {
    if (m.step_chunk >= m.step_chunks.size()) return false;
    if (!m.steps_loaded) {
      m.steps = m.DecodeSteps(m.step_chunks[m.step_chunk]);
      m.step_pos = 0;
      m.steps_loaded = true;
    }
    if (m.step_pos < m.steps.size()) {
      *out = std::move(m.steps[m.step_pos++]);
      return true;
    }
    ++m.step_chunk;
    m.steps_loaded = false;
  }
}

bool RunLogReader::NextRecord(RunLogRecord* out) {
  Impl& m = *impl_;
  while (true) {
    if (m.record_pos < m.records.size()) {
      *out = std::move(m.records[m.record_pos++]);
      return true;
    }
    if (m.record_chunk >= m.chunks.size()) return false;
    m.records = m.DecodeRecords(m.record_chunk++);
    m.record_pos = 0;
  }
}

void RunLogReader::RewindRecords() {
  impl_->record_chunk = 1;
  impl_->records.clear();
  impl_->record_pos = 0;
}

std::vector<EventRecord> RunLogReader::Events(int64_t from_step, int64_t to_step) {
  Impl& m = *impl_;
  std::vector<EventRecord> out;
  for (size_t pos = 1; pos < m.chunks.size(); ++pos) {
    const RunLogChunkInfo& c = m.chunks[pos];
    if (c.kind != RunLogChunkKind::kEvents || c.last_step < from_step || c.first_step > to_step)
      continue;
    for (RunLogRecord& r : m.DecodeRecords(pos)) {
      EventRecord& e = std::get<EventRecord>(r);
      if (e.step >= from_step && e.step <= to_step) out.push_back(std::move(e));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const EventRecord& a, const EventRecord& b) { return a.step < b.step; });
  return out;
}

std::vector<SensorRecord> RunLogReader::SensorRecords(int64_t from_step, int64_t to_step) {
  Impl& m = *impl_;
  std::vector<SensorRecord> out;
  for (size_t pos = 1; pos < m.chunks.size(); ++pos) {
    const RunLogChunkInfo& c = m.chunks[pos];
    if (c.kind != RunLogChunkKind::kSensors || c.last_step < from_step || c.first_step > to_step)
      continue;
    for (RunLogRecord& r : m.DecodeRecords(pos)) {
      SensorRecord& s = std::get<SensorRecord>(r);
      if (s.step >= from_step && s.step <= to_step) out.push_back(std::move(s));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const SensorRecord& a, const SensorRecord& b) { return a.step < b.step; });
  return out;
}

}  // namespace penumbra
