// libFuzzer target: the run log reader (runlog/run_log_reader.h) on arbitrary file bytes, in
// both read modes, reading every record, seeking and listing events and sensor records. the
// documented failure is RunLogError; any other exception, a crash or a sanitizer report is a
// finding. docs/fuzzing.md.

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <string>

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
  const std::string path = file.Write(data, size);
  ReadEverything(path, penumbra::RunLogReadMode::kStrict);
  ReadEverything(path, penumbra::RunLogReadMode::kRecover);
  return 0;
}
