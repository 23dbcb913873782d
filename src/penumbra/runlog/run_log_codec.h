#pragma once
// the byte-level pieces of the run log format shared by the writer and the reader
// (docs/run-log.md): the preamble, the 64-byte chunk header, record bodies, CRC32 and zstd.
// every integer and double is little-endian; doubles are IEEE 754 binary64 bit patterns.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/runlog/run_log_format.h"

namespace penumbra::runlog_codec {

static_assert(std::endian::native == std::endian::little,
              "the run log codec writes the host's bytes; it assumes a little-endian host");

/// bytes of the preamble: magic (8), format version (u32), reserved (u32, 0).
inline constexpr size_t kPreambleBytes = 16;
/// bytes of a chunk header; its last 4 are the CRC32 of the first 60.
inline constexpr size_t kChunkHeaderBytes = 64;
/// bytes of the CRC32 that follows each chunk body.
inline constexpr size_t kChunkTrailerBytes = 4;
/// the 4 bytes that open every chunk header.
inline constexpr char kChunkMagic[4] = {'P', 'C', 'H', 'K'};
/// body codecs.
inline constexpr uint32_t kCodecNone = 0;
inline constexpr uint32_t kCodecZstd = 1;
/// field encodings of a step record (docs/run-log.md "Steps chunk").
inline constexpr uint8_t kFieldZero = 0;   ///< n entries, all +0.0 (or 0); no data follows
inline constexpr uint8_t kFieldXor = 1;    ///< n words, each XORed with the previous record's
inline constexpr uint8_t kFieldPlain = 2;  ///< n words as they are

// limits of the format (docs/run-log.md "Limits"). every length read from a log is checked
// against the bytes left in the file and against these caps before anything is allocated;
// the writer never writes a log that breaks them.

/// most bytes a chunk body may have, stored or decompressed (256 MiB). a chunk header that
/// declares more is damaged.
inline constexpr uint64_t kMaxChunkBodyBytes = uint64_t{256} << 20;
/// most bytes the header chunk's JSON may have after decompression (64 MiB).
inline constexpr uint64_t kMaxHeaderChunkBytes = uint64_t{64} << 20;
/// most JSON values (objects, arrays, numbers, strings, ...) and nesting depth of the header
/// chunk's JSON.
inline constexpr uint64_t kMaxHeaderJsonValues = uint64_t{4} << 20;
inline constexpr int kMaxHeaderJsonDepth = 32;
/// most entries of any layout count (nq, nv, na, nu, nuserdata, num_controllers) and most
/// bodies and mocap bodies (4,194,304; a MuJoCo model has thousands at most).
inline constexpr int kMaxLayoutEntries = 1 << 22;
/// most memory the decoded records of one chunk may take (512 MiB): a steps chunk's record
/// count times StepRecordMemoryBytes(layout). the writer closes steps chunks at half of it.
inline constexpr uint64_t kMaxChunkDecodedBytes = uint64_t{512} << 20;
/// bytes of the smallest record of each kind in a body (all strings and fields empty); a
/// step record's depend on the fields of the log's format version (RunLogStateShapeOf).
constexpr uint64_t MinStepRecordBytes(uint32_t format_version) {
  return 16 + uint64_t(RunLogStateShapeOf(format_version).fields) * 5;
}
inline constexpr uint64_t kMinEventRecordBytes = 16 + 4 + 8;
inline constexpr uint64_t kMinSensorRecordBytes = 16 + 4 + 4 + 8;

/// bytes one decoded step record of `layout` takes in memory (the record and its vectors'
/// entries); layout counts must be within [0, kMaxLayoutEntries] (no overflow).
uint64_t StepRecordMemoryBytes(const RunLogLayout& layout);
/// checks a layout read from a log or given to the writer: every count within
/// [0, kMaxLayoutEntries], every joint's qpos and qvel span inside nq and nv. returns "" or
/// the problem ("layout.nq is -3; expected 0 to 4194304").
std::string CheckLayout(const RunLogLayout& layout);
/// checks a header read from a log or given to the writer, the one validation of its values
/// that every reader (replay, replay --resimulate, export) relies on: timestep_sec within
/// [kMinTimestepSec, kMaxTimestepSec] (scene/scene_limits.h, the range of a world file's
/// physics.timestep_sec), then the layout (CheckLayout). returns "" or the problem naming the
/// field and the expected range ("timestep_sec is 0 s; expected a physics timestep in
/// [1e-06, 0.1] s").
std::string CheckHeader(const RunLogHeader& header);

/// a chunk header as stored (RunLogChunkInfo less the file offset, plus the codec).
struct ChunkHeader {
  RunLogChunkKind kind = RunLogChunkKind::kSteps;
  uint64_t index = 0;
  uint32_t record_count = 0;
  uint32_t codec = kCodecNone;
  int64_t first_step = 0;
  int64_t last_step = 0;
  uint64_t raw_size = 0;
  uint64_t stored_size = 0;
};

/// the 16-byte preamble for `version`.
std::string EncodePreamble(uint32_t version);
/// the 64-byte header of `h` (with its CRC).
std::string EncodeChunkHeader(const ChunkHeader& h);
/// parses 64 bytes; returns "" and fills `out`, or the reason they are not a valid chunk
/// header ("bad chunk magic", "header CRC mismatch", "unknown chunk kind 9", a raw or stored
/// size above kMaxChunkBodyBytes (kMaxHeaderChunkBytes for the header chunk), ...).
std::string DecodeChunkHeader(const uint8_t* bytes, ChunkHeader* out);

/// CRC-32 (ISO-HDLC, zlib crc32) of `n` bytes.
uint32_t Crc32(const void* data, size_t n);

/// zstd at `level`. @throws RunLogError with zstd's message.
std::string ZstdCompress(std::string_view raw, int level);
/// zstd decompression of a frame whose content is `raw_size` bytes (at most
/// kMaxChunkBodyBytes). the frame's own content size, where it declares one, must equal
/// `raw_size`; nothing larger than `raw_size` is allocated.
/// @throws RunLogError when the data is not such a frame or `raw_size` is above the cap.
std::string ZstdDecompress(std::string_view stored, uint64_t raw_size);

/// appends little-endian values to a buffer.
inline void PutU8(std::string* b, uint8_t v) { b->push_back(static_cast<char>(v)); }
inline void PutU32(std::string* b, uint32_t v) { b->append(reinterpret_cast<const char*>(&v), 4); }
inline void PutU64(std::string* b, uint64_t v) { b->append(reinterpret_cast<const char*>(&v), 8); }
inline void PutI64(std::string* b, int64_t v) { b->append(reinterpret_cast<const char*>(&v), 8); }
inline void PutF64(std::string* b, double v) { b->append(reinterpret_cast<const char*>(&v), 8); }
/// u32 length, then the bytes.
inline void PutString(std::string* b, std::string_view s) {
  PutU32(b, static_cast<uint32_t>(s.size()));
  b->append(s.data(), s.size());
}
/// u64 length, then the bytes.
inline void PutBlob(std::string* b, std::string_view s) {
  PutU64(b, s.size());
  b->append(s.data(), s.size());
}

/// reads little-endian values from a body; every read past the end throws RunLogError with
/// `what` and the offset.
class BodyReader {
 public:
  BodyReader(std::string_view data, std::string what) : data_(data), what_(std::move(what)) {}
  bool done() const { return pos_ == data_.size(); }
  size_t pos() const { return pos_; }
  uint8_t U8() { return Take<uint8_t>(); }
  uint32_t U32() { return Take<uint32_t>(); }
  uint64_t U64() { return Take<uint64_t>(); }
  int64_t I64() { return Take<int64_t>(); }
  double F64() { return Take<double>(); }
  std::string_view Bytes(uint64_t n);
  std::string String() { return std::string(Bytes(U32())); }
  std::string Blob() { return std::string(Bytes(U64())); }
  /// throws RunLogError "<what>: <problem> at byte <pos>".
  [[noreturn]] void Fail(const std::string& problem) const;

 private:
  template <typename T>
  T Take() {
    T v;
    std::memcpy(&v, Bytes(sizeof(T)).data(), sizeof(T));
    return v;
  }
  std::string_view data_;
  std::string what_;
  size_t pos_ = 0;
};

/// appends `r` to a steps body; `prev` is the previous record of the same chunk (null for
/// the chunk's first), against which fields of equal size are XORed.
void EncodeStep(const StepRecord& r, const StepRecord* prev, std::string* body);
/// reads one step record of a log of `format_version`, whose fields are the first ones of
/// kStateFields (RunLogStateShapeOf; the others are left empty); `prev` as for EncodeStep.
/// with a `layout`, every field must have the layout's number of entries (as the writer
/// enforces); without one, at most kMaxLayoutEntries.
/// @throws RunLogError on malformed data (naming the field, the entries found and expected).
void DecodeStep(BodyReader* in, const StepRecord* prev, StepRecord* out,
                const RunLogLayout* layout = nullptr,
                uint32_t format_version = kRunLogFormatVersion);

/// appends an event / sensor record to a body.
void EncodeEvent(const EventRecord& e, std::string* body);
void EncodeSensor(const SensorRecord& s, std::string* body);
/// reads one event / sensor record. @throws RunLogError on malformed data.
EventRecord DecodeEvent(BodyReader* in);
SensorRecord DecodeSensor(BodyReader* in);

/// the header as the JSON text of a header chunk; its layout names the dimensions of
/// h.format_version (RunLogStateShapeOf).
std::string HeaderToJson(const RunLogHeader& h);
/// parses a header chunk's JSON (at most kMaxHeaderJsonValues values nested at most
/// kMaxHeaderJsonDepth deep) and checks its layout (CheckLayout). the layout must name the
/// dimensions of its format_version; those after them count 0.
/// @throws RunLogError naming a missing or mistyped key, a bad layout or a cap exceeded.
RunLogHeader HeaderFromJson(std::string_view json);

}  // namespace penumbra::runlog_codec
