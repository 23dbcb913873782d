// every length a run log declares is checked before it is added to, read or
// allocated: a chunk whose stored size is 2^64 - 4 (which wrapped the size + CRC sum and
// crashed the chunk scan), a declared uncompressed size of 3.2 GB (which the reader allocated
// before zstd found the frame short), a record count of 2^32 - 1 and a zero-encoded field of
// 2^32 - 1 entries in a few bytes, a header whose layout is negative or points outside qpos.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/runlog/run_log_writer.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
namespace bounds_codec = runlog_codec;

RunLogHeader BoundsHeader() {
  RunLogHeader h;
  h.penumbra_version = "0.1.0";
  h.mujoco_version = "2.2.2";
  h.composed_mjcf = "<mujoco/>";
  h.timestep_sec = 0.002;
  RunLogLayout& l = h.layout;
  l.nq = 2;
  l.nv = 2;
  l.nbody = 2;
  l.joints = {{"a", "hinge", 0, 1, 0, 1}, {"b", "slide", 1, 1, 1, 1}};
  l.body_names = {"world", "b"};
  return h;
}

StepRecord BoundsStep(int64_t step) {
  StepRecord r;
  r.step = step;
  r.time_sec = step * 0.002;
  r.qpos = {std::sin(step * 0.1), 0.5};
  r.qvel = {std::cos(step * 0.1), 0.0};
  r.qacc_warmstart = {0.0, 1.0};
  r.qfrc_applied = {0.0, 0.0};
  r.xfrc_applied.assign(12, 0.0);
  return r;
}

// a closed log of 40 steps in chunks of 10
std::string BoundsWriteLog(const testing::TempDir& tmp) {
  const std::string path = (tmp.path() / "run.plog").string();
  RunLogWriterOptions o;
  o.chunk_steps = 10;
  RunLogWriter w(path, BoundsHeader(), o);
  for (int s = 0; s < 40; ++s) w.Append(BoundsStep(s));
  w.Close();
  return path;
}

std::string BoundsRead(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

void BoundsWrite(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string BoundsOpenError(const std::string& path) {
  try {
    RunLogReader::Open(path);
  } catch (const RunLogError& e) {
    return e.what();
  }
  return "";
}

// the first steps chunk of `bytes`: its header offset, header and body (as stored)
struct BoundsChunk {
  uint64_t offset = 0;
  bounds_codec::ChunkHeader header;
  std::string body;
};
BoundsChunk BoundsFirstSteps(const std::string& path, const std::string& bytes) {
  RunLogReader r = RunLogReader::Open(path);
  for (const RunLogChunkInfo& c : r.chunks())
    if (c.kind == RunLogChunkKind::kSteps) {
      BoundsChunk out;
      out.offset = c.file_offset;
      EXPECT_EQ(bounds_codec::DecodeChunkHeader(
                    reinterpret_cast<const uint8_t*>(bytes.data() + c.file_offset), &out.header),
                "");
      out.body = bytes.substr(c.file_offset + bounds_codec::kChunkHeaderBytes, c.compressed_size);
      return out;
    }
  ADD_FAILURE() << "no steps chunk";
  return {};
}

// `bytes` with the chunk at `c.offset` replaced by header `h` and body `body` (CRCs recomputed)
std::string BoundsReplaceChunk(const std::string& bytes, const BoundsChunk& c,
                               const bounds_codec::ChunkHeader& h, const std::string& body) {
  std::string chunk = bounds_codec::EncodeChunkHeader(h) + body;
  bounds_codec::PutU32(&chunk, bounds_codec::Crc32(body.data(), body.size()));
  const uint64_t old_end =
      c.offset + bounds_codec::kChunkHeaderBytes + c.body.size() + bounds_codec::kChunkTrailerBytes;
  return bytes.substr(0, c.offset) + chunk + bytes.substr(old_end);
}

TEST(RunLogBoundsTest, AStoredSizeOf2Pow64Minus4IsRefusedNamingFileOffsetAndChunk) {
  testing::TempDir tmp;
  const std::string path = BoundsWriteLog(tmp);
  const std::string bytes = BoundsRead(path);
  const BoundsChunk c = BoundsFirstSteps(path, bytes);
  // only the header changes (its CRC recomputed): the body and its CRC stay where they were
  bounds_codec::ChunkHeader h = c.header;
  h.stored_size = UINT64_MAX - 3;
  std::string b = bytes;
  b.replace(c.offset, bounds_codec::kChunkHeaderBytes, bounds_codec::EncodeChunkHeader(h));
  BoundsWrite(path, b);

  const std::string err = BoundsOpenError(path);
  EXPECT_NE(err.find(path + ": log ends at chunk 0"), std::string::npos) << err;
  EXPECT_NE(err.find("chunk 1 (at byte " + std::to_string(c.offset) + ") is damaged"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("stored size 18446744073709551612 bytes is above the format's maximum"),
            std::string::npos)
      << err;
  // recovery mode keeps the header chunk and says why it stopped
  RunLogReader r = RunLogReader::Open(path, RunLogReadMode::kRecover);
  EXPECT_EQ(r.chunks().size(), 1u);
  ASSERT_TRUE(r.damage());
  EXPECT_NE(r.damage()->find("18446744073709551612"), std::string::npos) << *r.damage();
  StepRecord s;
  EXPECT_FALSE(r.NextStep(&s));

  // just below the cap but beyond the file: cut off, with the sizes (no wrap-around either)
  h.stored_size = bounds_codec::kMaxChunkBodyBytes;
  b.replace(c.offset, bounds_codec::kChunkHeaderBytes, bounds_codec::EncodeChunkHeader(h));
  BoundsWrite(path, b);
  const std::string err2 = BoundsOpenError(path);
  EXPECT_NE(err2.find("is cut off: the file ends"), std::string::npos) << err2;
  EXPECT_NE(err2.find("(chunk header at byte " + std::to_string(c.offset) + ")"), std::string::npos)
      << err2;
}

TEST(RunLogBoundsTest, AHugeDeclaredUncompressedSizeIsRefusedBeforeAllocating) {
  testing::TempDir tmp;
  const std::string path = BoundsWriteLog(tmp);
  const std::string bytes = BoundsRead(path);
  const BoundsChunk c = BoundsFirstSteps(path, bytes);
  // a 14-byte zstd frame that declares 3.2 GB of content: magic, a single-segment frame
  // header with an 8-byte content size, then one last RLE block of 1 byte
  const uint64_t declared = 3'200'000'000ull;
  std::string frame("\x28\xb5\x2f\xfd\xe0", 5);
  bounds_codec::PutU64(&frame, declared);
  frame += std::string("\x0b\x00\x00\x00", 4);  // last block, RLE, 1 byte; the byte 0
  bounds_codec::ChunkHeader h = c.header;
  h.codec = bounds_codec::kCodecZstd;
  h.raw_size = declared;
  h.stored_size = frame.size();
  BoundsWrite(path, BoundsReplaceChunk(bytes, c, h, frame));

  const std::string err = BoundsOpenError(path);
  EXPECT_NE(err.find("chunk 1 (at byte " + std::to_string(c.offset) + ") is damaged: " +
                     "uncompressed size 3200000000 bytes is above the format's maximum chunk "
                     "body of 268435456 bytes"),
            std::string::npos)
      << err;
  // and a frame whose own content size is above the cap is refused before decompression even
  // where the chunk header claims a small size
  EXPECT_THROW(bounds_codec::ZstdDecompress(frame, declared), RunLogError);
  try {
    bounds_codec::ZstdDecompress(frame, 100);
    ADD_FAILURE() << "a frame of 3.2 GB decompressed into 100 bytes";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("zstd frame holds 3200000000 bytes"), std::string::npos)
        << e.what();
  }
}

TEST(RunLogBoundsTest, RecordCountsAndZeroFieldsBeyondTheBodyOrLayoutAreRefused) {
  testing::TempDir tmp;
  const std::string path = BoundsWriteLog(tmp);
  const std::string bytes = BoundsRead(path);
  const BoundsChunk c = BoundsFirstSteps(path, bytes);

  // 2^32 - 1 records declared in a body of one record (stored as is)
  std::string one;
  bounds_codec::EncodeStep(BoundsStep(0), nullptr, &one);
  bounds_codec::ChunkHeader h = c.header;
  h.codec = bounds_codec::kCodecNone;
  h.record_count = UINT32_MAX;
  h.raw_size = h.stored_size = one.size();
  h.first_step = h.last_step = 0;
  BoundsWrite(path, BoundsReplaceChunk(bytes, c, h, one));
  {
    RunLogReader r = RunLogReader::Open(path);
    StepRecord s;
    try {
      r.NextStep(&s);
      ADD_FAILURE() << "4294967295 records read from one";
    } catch (const RunLogError& e) {
      EXPECT_NE(
          std::string(e.what()).find("4294967295 records declared; its " +
                                     std::to_string(one.size()) + "-byte body holds at most 1"),
          std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }

  // one record whose qpos is "2^32 - 1 zeros" in 5 bytes
  std::string zero;
  bounds_codec::PutI64(&zero, 0);
  bounds_codec::PutF64(&zero, 0.0);
  bounds_codec::PutU8(&zero, bounds_codec::kFieldZero);
  bounds_codec::PutU32(&zero, UINT32_MAX);
  for (int f = 1; f < kNumStateFields; ++f) {
    bounds_codec::PutU8(&zero, bounds_codec::kFieldZero);
    bounds_codec::PutU32(&zero, 0);
  }
  h.record_count = 1;
  h.raw_size = h.stored_size = zero.size();
  BoundsWrite(path, BoundsReplaceChunk(bytes, c, h, zero));
  {
    RunLogReader r = RunLogReader::Open(path);
    StepRecord s;
    try {
      r.NextStep(&s);
      ADD_FAILURE() << "a qpos of 4294967295 entries decoded";
    } catch (const RunLogError& e) {
      EXPECT_NE(std::string(e.what()).find(
                    "field qpos has 4294967295 entries; the header's layout says 2"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(RunLogBoundsTest, ALayoutOutOfRangeIsRefusedByReaderAndWriter) {
  testing::TempDir tmp;
  RunLogHeader h = BoundsHeader();
  h.layout.nq = -3;
  EXPECT_EQ(bounds_codec::CheckLayout(h.layout), "layout.nq is -3; expected 0 to 4194304");
  EXPECT_THROW(RunLogWriter((tmp.path() / "a.plog").string(), h), RunLogError);
  h = BoundsHeader();
  h.layout.joints[1].qpos_adr = 5;
  EXPECT_NE(bounds_codec::CheckLayout(h.layout).find(
                "layout.joints[1] ('b'): qpos_adr 5 and qpos_width 1 are "
                "not inside nq 2"),
            std::string::npos);
  try {
    bounds_codec::HeaderFromJson(bounds_codec::HeaderToJson(h));
    ADD_FAILURE() << "a joint outside qpos was read";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("qpos_adr 5"), std::string::npos) << e.what();
  }
  // a header of nested arrays deeper than the cap, and the writer's chunk size option
  EXPECT_THROW(bounds_codec::HeaderFromJson(std::string(100, '[') + std::string(100, ']')),
               RunLogError);
  RunLogWriterOptions o;
  o.chunk_bytes = size_t{1} << 30;
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
}

// a header claiming a timestep of 0 s (or NaN, negative, above 0.1 s) is refused by the one
// header check: by the writer, and by the reader whatever reads the log (replay, --resimulate,
// export); --resimulate of such a log said "bit-exact"
TEST(RunLogBoundsTest, ATimestepOutsideTheWorldFilesRangeIsRefusedByReaderAndWriter) {
  testing::TempDir tmp;
  for (double dt : {0.0, -0.002, 0.5, std::nan("")}) {
    RunLogHeader h = BoundsHeader();
    h.timestep_sec = dt;
    EXPECT_NE(bounds_codec::CheckHeader(h).find("expected a physics timestep in [1e-06, 0.1] s"),
              std::string::npos)
        << dt;
    EXPECT_THROW(RunLogWriter((tmp.path() / "a.plog").string(), h), RunLogError) << dt;
  }
  RunLogHeader h = BoundsHeader();
  h.timestep_sec = 0;
  EXPECT_EQ(bounds_codec::CheckHeader(h),
            "timestep_sec is 0 s; expected a physics timestep in [1e-06, 0.1] s");
  try {
    bounds_codec::HeaderFromJson(bounds_codec::HeaderToJson(h));
    ADD_FAILURE() << "a timestep of 0 s was read";
  } catch (const RunLogError& e) {
    EXPECT_EQ(std::string(e.what()),
              "header chunk: timestep_sec is 0 s; expected a physics timestep in [1e-06, 0.1] s");
  }
  h.timestep_sec = 0.002;
  EXPECT_EQ(bounds_codec::CheckHeader(h), "");
}

}  // namespace
}  // namespace penumbra
