// with the real binary: a recorded run log whose first steps chunk declares a stored
// size of 2^64 - 4 (the chunk scan's size + CRC sum wrapped and `replay`, `replay --resimulate`
// and `export` died of SIGSEGV) or 3.2 GB of content in a 14-byte zstd frame (the reader
// allocated it before zstd found the frame short) is refused with a message and without
// growing; `penumbra eval` refuses /dev/zero and coordinates of 1e308 with file:line.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"

extern char** environ;

namespace penumbra {
namespace {

namespace fs = std::filesystem;
namespace input_codec = runlog_codec;
using testing::ReadAll;
using testing::RunPenumbra;

constexpr char kBoundsBallMjcf[] = R"(<mujoco model="ball">
  <option timestep="0.001"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="ball" pos="0 0 1"><freejoint/><geom type="sphere" size="0.2"/></body>
  </worldbody>
</mujoco>)";

// the exit code (128 + signal if killed) and peak RSS (KiB) of the binary run with `args`
struct BoundsRun {
  int exit_code = -1;
  long max_rss_kib = 0;
  std::string err;
};
BoundsRun BoundsRunMeasured(const std::vector<std::string>& args, const fs::path& dir) {
  std::vector<std::string> argv_s = {PENUMBRA_BINARY};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string err_path = (dir / "bounds_stderr.txt").string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  BoundsRun r;
  if (posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) return r;
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  struct rusage usage {};
  wait4(pid, &status, 0, &usage);
  r.exit_code = WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
  r.max_rss_kib = usage.ru_maxrss;
  r.err = ReadAll(err_path);
  return r;
}

class InputBoundsTest : public ::testing::Test {
 protected:
  // a 0.6 s recording of a falling ball (600 steps: three steps chunks)
  void SetUp() override {
    tmp_.Write("ball.xml", kBoundsBallMjcf);
    const std::string world = tmp_.Write(
        "w.yaml",
        "seed: 3\nduration_sec: 0.6\nmodels: [{name: scene, file: ball.xml}]\n"
        "mjcf_cameras: {enabled: false}\n"
        "cameras:\n  - {name: cam, attach: world, pose: {xyz: [-3, 0, 1.5], rpy_deg: [0, 20, "
        "0]}, width: 32, height: 24, rate_hz: 20, outputs: [rgb]}\n");
    log_ = (tmp_.path() / "run.plog").string();
    const auto r =
        RunPenumbra({"run", world, "--out", (tmp_.path() / "run").string(), "-q", "--record", log_},
                    tmp_.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    bytes_ = ReadAll(log_);
    RunLogReader reader = RunLogReader::Open(log_);
    for (const RunLogChunkInfo& c : reader.chunks())
      if (c.kind == RunLogChunkKind::kSteps) {
        steps_ = c;
        break;
      }
    ASSERT_EQ(steps_.kind, RunLogChunkKind::kSteps);
    ASSERT_EQ(input_codec::DecodeChunkHeader(
                  reinterpret_cast<const uint8_t*>(bytes_.data() + steps_.file_offset), &header_),
              "");
  }

  // the log with the first steps chunk's header replaced by `h` and, if given, its body
  std::string Patched(const input_codec::ChunkHeader& h, const std::string* body = nullptr) const {
    if (!body) {
      std::string b = bytes_;
      b.replace(steps_.file_offset, input_codec::kChunkHeaderBytes,
                input_codec::EncodeChunkHeader(h));
      return b;
    }
    std::string chunk = input_codec::EncodeChunkHeader(h) + *body;
    input_codec::PutU32(&chunk, input_codec::Crc32(body->data(), body->size()));
    const uint64_t end = steps_.file_offset + input_codec::kChunkHeaderBytes +
                         steps_.compressed_size + input_codec::kChunkTrailerBytes;
    return bytes_.substr(0, steps_.file_offset) + chunk + bytes_.substr(end);
  }

  void WriteLog(const std::string& path, const std::string& bytes) const {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }

  testing::TempDir tmp_;
  std::string log_, bytes_;
  RunLogChunkInfo steps_;
  input_codec::ChunkHeader header_;
};

TEST_F(InputBoundsTest, AChunkOf2Pow64Minus4BytesIsRefusedByReplayResimulateAndExport) {
  input_codec::ChunkHeader h = header_;
  h.stored_size = UINT64_MAX - 3;
  const std::string bad = (tmp_.path() / "bad.plog").string();
  WriteLog(bad, Patched(h));
  const std::vector<std::vector<std::string>> commands = {
      {"replay", bad, "--out", (tmp_.path() / "replayed").string(), "-q"},
      {"replay", bad, "--resimulate"},
      {"export", bad, "--format", "tum", "--out", (tmp_.path() / "tum").string()},
  };
  for (const std::vector<std::string>& args : commands) {
    const BoundsRun r = BoundsRunMeasured(args, tmp_.path());
    EXPECT_LT(r.exit_code, 128) << args[0] << " " << args[2] << " was killed by signal "
                                << r.exit_code - 128 << "\n"
                                << r.err;
    EXPECT_NE(r.err.find("chunk 1 (at byte " + std::to_string(steps_.file_offset) +
                         ") is damaged: stored size 18446744073709551612 bytes is above the "
                         "format's maximum chunk body"),
              std::string::npos)
        << args[0] << " " << args[2] << ":\n"
        << r.err;
  }
}

TEST_F(InputBoundsTest, ADeclaredUncompressedSizeOf3Point2GBIsRefusedBeforeAllocating) {
  // a 14-byte zstd frame that declares 3.2 GB (one last RLE block of 1 byte)
  const uint64_t declared = 3'200'000'000ull;
  std::string frame("\x28\xb5\x2f\xfd\xe0", 5);
  input_codec::PutU64(&frame, declared);
  frame += std::string("\x0b\x00\x00\x00", 4);
  input_codec::ChunkHeader h = header_;
  h.codec = input_codec::kCodecZstd;
  h.raw_size = declared;
  h.stored_size = frame.size();
  const std::string bad = (tmp_.path() / "bomb.plog").string();
  WriteLog(bad, Patched(h, &frame));
  const BoundsRun r = BoundsRunMeasured(
      {"replay", bad, "--out", (tmp_.path() / "replayed").string(), "-q"}, tmp_.path());
  EXPECT_LT(r.exit_code, 128) << r.err;
  EXPECT_NE(r.err.find("uncompressed size 3200000000 bytes is above the format's maximum chunk "
                       "body of 268435456 bytes"),
            std::string::npos)
      << r.err;
  // the replay of this tiny world stays far below the 3.2 GB the frame declares
  EXPECT_LT(r.max_rss_kib, 1024 * 1024) << "peak RSS " << r.max_rss_kib << " KiB\n" << r.err;
}

TEST_F(InputBoundsTest, EvalRefusesDevZeroAndCoordinatesOf1e308WithFileAndLine) {
  const std::string gt =
      tmp_.Write("gt.txt", "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n");
  const std::string est =
      tmp_.Write("est.txt", "1 0 0 0 0 0 0 1\n2 1e308 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n");
  BoundsRun r = BoundsRunMeasured({"eval", "ate", gt, est}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(est + ":2: field 2 (tx) 1e+308 is beyond +-1e+06 m"), std::string::npos)
      << r.err;
  r = BoundsRunMeasured({"eval", "rpe", "/dev/zero", est}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // a device is no TUM file: refused when opened, before a byte is read
  EXPECT_NE(r.err.find("/dev/zero: TUM trajectory file is not a regular file (a character "
                       "device); expected a regular file"),
            std::string::npos)
      << r.err;
  EXPECT_LT(r.max_rss_kib, 512 * 1024) << "peak RSS " << r.max_rss_kib << " KiB";
}

}  // namespace
}  // namespace penumbra
