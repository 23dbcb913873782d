#pragma once
// writes a run log (runlog/run_log_format.h, docs/run-log.md). the caller's thread (the
// physics loop's) only copies records into an in-memory chunk; full chunks go to the writer's
// own thread, which compresses (zstd) and writes them. a chunk is complete on disk once
// written, so a process killed at any time leaves a log readable up to its last complete
// chunk (runlog/run_log_reader.h recovery mode).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "penumbra/core/output_path_policy.h"
#include "penumbra/runlog/run_log_format.h"

namespace penumbra {

/// settings of a RunLogWriter.
struct RunLogWriterOptions {
  /// a steps chunk is closed after this many step records (>= 1) ...
  int chunk_steps = 256;
  /// ... or once its raw body reaches this many bytes (1 to 128 MiB), whichever comes first
  /// (or at half the decoded size a reader accepts, docs/run-log.md "Limits"). events
  /// and sensor records pending at that point are written as chunks of their own at the same
  /// time, so a killed process loses at most the records since the last steps chunk.
  size_t chunk_bytes = size_t{1} << 20;
  /// zstd compression level (1..19).
  int zstd_level = 1;
  /// chunks waiting for the writer thread before Append blocks (back-pressure), >= 1.
  size_t max_pending_chunks = 16;

  /// @throws ConfigError naming the field when a value is outside its range.
  void ValidateOrThrow() const;
};

/// what a writer has written so far.
struct RunLogWriterStats {
  int64_t steps = 0;           ///< step records appended
  int64_t events = 0;          ///< event records
  int64_t sensor_records = 0;  ///< sensor records
  int64_t chunks = 0;          ///< chunks written to the file (header and end included)
  uint64_t file_bytes = 0;     ///< bytes written to the file
  int64_t first_step = -1;     ///< first and last step appended (-1 before the first)
  int64_t last_step = -1;
};

/// writes one run log. Append is called from one thread (the loop's); RecordEvent and
/// RecordSensor from any thread. errors of the writer thread (disk full, ...) are kept and
/// thrown by the next Append / RecordEvent / RecordSensor and by Close.
class RunLogWriter {
 public:
  /// creates (truncates) `path` and writes the magic, the format version and the header
  /// chunk synchronously; starts the writer thread. the header's format_version is set to
  /// kRunLogFormatVersion.
  /// @throws RunLogError naming the file when it cannot be created or written; ConfigError
  ///         from options.ValidateOrThrow.
  RunLogWriter(const std::string& path, const RunLogHeader& header,
               const RunLogWriterOptions& options = {});
  /// as above, into a file the caller created (e.g. core/output_path_policy.h's
  /// OpenNewFileInside); the writer owns `fd` from here on and closes it, also when this
  /// throws. `name` stands for the file in stats, path() and every error message.
  RunLogWriter(UniqueFd fd, const std::string& name, const RunLogHeader& header,
               const RunLogWriterOptions& options = {});
  /// Close() if not closed (errors are then logged, not thrown).
  ~RunLogWriter();
  RunLogWriter(const RunLogWriter&) = delete;
  RunLogWriter& operator=(const RunLogWriter&) = delete;

  /// adds the state at one step. steps must increase from call to call, and the vector sizes
  /// must match the header's layout. cheap: the record is encoded (XOR with the previous
  /// record of the chunk) into the open chunk's buffer; a full chunk is handed to the writer
  /// thread (blocking only while max_pending_chunks wait).
  /// @throws RunLogError for a step not after the previous one, a size that does not match
  ///         the layout (naming the field), a closed writer, or an earlier writer-thread error.
  void Append(const StepRecord& record);

  /// adds an event (thread-safe). its step should be one already appended or the next.
  /// @throws RunLogError for a closed writer or an earlier writer-thread error.
  void RecordEvent(const EventRecord& event);
  /// as RecordEvent, from its parts.
  void RecordEvent(int64_t step, double time_sec, const std::string& kind,
                   const std::string& payload_json);

  /// adds a sensor output (thread-safe).
  /// @throws RunLogError as RecordEvent.
  void RecordSensor(const SensorRecord& record);

  /// writes every pending record, then the end chunk, and closes the file; waits for the
  /// writer thread. idempotent.
  /// @throws RunLogError with the first error of the writer thread (or of closing the file).
  void Close();

  /// what has been handed to the writer so far (file_bytes: what reached the file).
  RunLogWriterStats stats() const;
  /// the file being written.
  const std::string& path() const;

 private:
  void Start(int fd, const std::string& name, const RunLogHeader& header,
             const RunLogWriterOptions& options);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
