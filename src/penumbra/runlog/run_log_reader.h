#pragma once
// reads a run log (runlog/run_log_format.h, docs/run-log.md). Open reads the header and scans
// every chunk header and CRC once, building an index (chunk -> kind, steps, offset), so that
// SeekStep jumps to the chunk holding a step. a damaged or cut log (a recorder killed by
// SIGKILL, a flipped byte) is either refused (strict mode) or read up to its last complete,
// CRC-valid chunk (recovery mode); damage() says where and why, e.g.
//   "log ends at chunk 12 (step 2815): chunk 13 is cut off (file ends 4130 bytes into it)".
//
// not thread-safe: one reader per thread.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/runlog/run_log_format.h"

namespace penumbra {

/// how a reader treats damage.
enum class RunLogReadMode {
  /// any damage (truncation, CRC mismatch, missing end chunk) throws RunLogError naming the
  /// chunk index.
  kStrict,
  /// the log is read up to the last complete, CRC-valid chunk; damage() describes the rest
  /// (the reader logs nothing: its user warns with damage(), as replay does).
  kRecover,
};

/// a run log opened for reading.
class RunLogReader {
 public:
  /// opens `path`: checks the magic and the format version, reads the header chunk and
  /// indexes every chunk after it (verifying each chunk's CRC).
  /// @throws RunLogError naming the file: not a run log (bad magic), a format version this
  ///         build does not read (the message names the versions it reads and the Penumbra
  ///         version that wrote the log), a missing or truncated header or header chunk
  ///         (in both modes: without a header nothing can be read), or, in kStrict mode, any
  ///         damage after the header (naming the chunk index and its first step).
  static RunLogReader Open(const std::string& path, RunLogReadMode mode = RunLogReadMode::kStrict);

  RunLogReader(RunLogReader&&) noexcept;
  RunLogReader& operator=(RunLogReader&&) noexcept;
  ~RunLogReader();

  /// the header (format version, versions, texts, hashes, layout, ...).
  const RunLogHeader& header() const;
  /// the file read.
  const std::string& path() const;

  /// the usable chunks in file order (header chunk first; the end chunk last if present).
  const std::vector<RunLogChunkInfo>& chunks() const;
  /// the log was closed cleanly (it has its end chunk and no damage).
  bool complete() const;
  /// in kRecover mode: "log ends at chunk N (step S): <why>" when the log is damaged or cut,
  /// else nullopt. always nullopt in kStrict mode (damage throws).
  const std::optional<std::string>& damage() const;

  /// number of step records in the usable chunks, and the first and last step (-1 if none).
  int64_t num_steps() const;
  int64_t first_step() const;
  int64_t last_step() const;

  /// positions the step cursor at the first step record with step >= `step`; returns false
  /// (cursor at the end) if there is none. decompresses only the chunk that holds it.
  /// @throws RunLogError when a chunk cannot be decompressed or decoded (naming its index).
  bool SeekStep(int64_t step);
  /// the step record at the cursor, moving the cursor on; false at the end of the steps.
  /// starts at the first step record after Open.
  /// @throws RunLogError as SeekStep.
  bool NextStep(StepRecord* out);

  /// every record of every usable chunk in file order (steps, events and sensor records of
  /// each chunk in the order they were written), independent of the step cursor. restarts at
  /// the first chunk after RewindRecords().
  /// @throws RunLogError as SeekStep.
  bool NextRecord(RunLogRecord* out);
  void RewindRecords();

  /// the event records with from_step <= step <= to_step, ordered by step (stable).
  /// @throws RunLogError as SeekStep.
  std::vector<EventRecord> Events(int64_t from_step = INT64_MIN, int64_t to_step = INT64_MAX);
  /// the sensor records with from_step <= step <= to_step, ordered by step (stable).
  /// @throws RunLogError as SeekStep.
  std::vector<SensorRecord> SensorRecords(int64_t from_step = INT64_MIN,
                                          int64_t to_step = INT64_MAX);

 private:
  struct Impl;
  explicit RunLogReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
