// libFuzzer target: the run log reader (runlog/run_log_reader.h) on arbitrary file bytes, in
// both read modes, reading every record, seeking and listing events and sensor records; then
// once more with every chunk's CRCs recomputed (mutations would otherwise rarely get past the
// CRC checks into the decoding). the
// documented failure is RunLogError; any other exception, a crash or a sanitizer report is a
// finding. docs/fuzzing.md.

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <string>

#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"

namespace {

// the input as a file without touching the disk: a memfd, opened again through /proc
class MemFile {
 public:
  MemFile() : fd_(memfd_create("penumbra-fuzz-plog", MFD_CLOEXEC)) {
    if (fd_ < 0) __builtin_trap();
  }
  ~MemFile() { close(fd_); }
  std::string Write(const uint8_t* data, size_t size) {
    if (ftruncate(fd_, 0) != 0) __builtin_trap();
    size_t done = 0;
    while (done < size) {
      const ssize_t n = pwrite(fd_, data + done, size - done, static_cast<off_t>(done));
      if (n <= 0) __builtin_trap();
      done += static_cast<size_t>(n);
    }
    return "/proc/self/fd/" + std::to_string(fd_);
  }

 private:
  int fd_;
};

// `bytes` with every chunk's header CRC and body CRC recomputed where the declared sizes fit the
// input, so that mutated inputs also reach the decoding past the CRC checks
std::string WithRepairedCrcs(std::string b) {
  using namespace penumbra::runlog_codec;
  size_t off = kPreambleBytes;
  while (off <= b.size() && b.size() - off >= kChunkHeaderBytes) {
    if (std::memcmp(b.data() + off, kChunkMagic, 4) != 0) break;
    const uint32_t header_crc = Crc32(b.data() + off, 60);
    std::memcpy(b.data() + off + 60, &header_crc, 4);
    uint64_t stored = 0;
    std::memcpy(&stored, b.data() + off + 48, 8);
    const size_t left = b.size() - off - kChunkHeaderBytes;
    if (stored > left || kChunkTrailerBytes > left - stored) break;
    const uint32_t body_crc = Crc32(b.data() + off + kChunkHeaderBytes, stored);
    std::memcpy(b.data() + off + kChunkHeaderBytes + stored, &body_crc, 4);
    off += kChunkHeaderBytes + stored + kChunkTrailerBytes;
  }
  return b;
}

void ReadEverything(const std::string& path, penumbra::RunLogReadMode mode) {
  using namespace penumbra;
  try {
    RunLogReader r = RunLogReader::Open(path, mode);
    RunLogRecord record;
    while (r.NextRecord(&record)) {
    }
    StepRecord step;
    if (r.SeekStep(std::midpoint(r.first_step(), r.last_step())))
      while (r.NextStep(&step)) {
      }
    r.Events();
    r.SensorRecords();
  } catch (const RunLogError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static MemFile file;
  std::string path = file.Write(data, size);
  ReadEverything(path, penumbra::RunLogReadMode::kStrict);
  ReadEverything(path, penumbra::RunLogReadMode::kRecover);
  if (size < penumbra::runlog_codec::kPreambleBytes) return 0;
  const std::string repaired =
      WithRepairedCrcs(std::string(reinterpret_cast<const char*>(data), size));
  path = file.Write(reinterpret_cast<const uint8_t*>(repaired.data()), repaired.size());
  ReadEverything(path, penumbra::RunLogReadMode::kRecover);
  return 0;
}
