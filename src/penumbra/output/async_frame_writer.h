#pragma once
// writes camera frames on background threads so that rendering is not blocked by
// PNG encoding and disk writes. frames wait in a bounded queue (Submit blocks when
// it is full, which bounds memory); frames.csv rows are appended in submission
// order per camera even when several frames are encoded at once.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "penumbra/output/camera_frame.h"
#include "penumbra/output/camera_writer.h"
#include "penumbra/output/png_io.h"

namespace penumbra {

/// queue and thread settings of AsyncFrameWriter.
struct AsyncFrameWriterOptions {
  /// frames submitted but not yet written (queued or being encoded) before Submit blocks.
  int queue_capacity = 8;
  /// encoder/writer threads, 1..8; 0 = ResolvedThreads's default (half the machine's cores,
  /// 2 to 8): with a GPU renderer PNG encoding is most of a run's work (about 20 ms a 640x480
  /// rgb+depth frame on one thread, docs/gpu.md "Where a run's time goes"). the files do not
  /// depend on the count.
  int num_threads = 0;
  /// num_threads, or for 0 half of std::thread::hardware_concurrency() clamped to 2..8.
  int ResolvedThreads() const;
  PngEncodeOptions png;
  /// called with each write error as it happens, on the worker thread (with the writer's
  /// lock held: do not call back into the writer), before Submit/Flush rethrow it; lets a
  /// caller order it against errors of other threads. may be empty.
  std::function<void(std::exception_ptr)> on_error;
  /// receives every image file written (output/camera_frame.h), on the worker threads; may
  /// be empty.
  CameraImageCallback on_image;
  /// receives each frame back after its files were written (or failed), with its images, on
  /// the worker thread and without the writer's lock, so that the caller can reuse the image
  /// buffers (sinks/frame_buffer_pool.h); must not throw. may be empty (the images are freed).
  std::function<void(CameraFrame&& frame)> on_written;

  /// @throws ConfigError for a capacity < 1 or a thread count outside 0..8.
  void ValidateOrThrow() const;
};

/// background writer of the camera files described in camera_writer.h.
///
/// errors: a failure while writing a frame (unwritable folder, full disk, bad image) is
/// captured on the worker thread and rethrown by the next Submit or Flush (each error is
/// rethrown once; the first one wins). the failed frame gets no frames.csv row; frames
/// written before and after it are kept. the destructor drains the queue and logs an
/// error that was never rethrown.
class AsyncFrameWriter {
 public:
  /// starts the worker threads; files go to DIR/<camera>/ (see camera_writer.h).
  /// @throws ConfigError for bad options.
  explicit AsyncFrameWriter(std::string output_dir, AsyncFrameWriterOptions options = {});
  /// drains every submitted frame, then stops the threads. never throws.
  ~AsyncFrameWriter();

  AsyncFrameWriter(const AsyncFrameWriter&) = delete;
  AsyncFrameWriter& operator=(const AsyncFrameWriter&) = delete;

  /// registers a camera: creates its folders, intrinsics.json and the frames.csv header now
  /// (synchronously).
  /// @throws ConfigError for a bad name; Error if it is already registered or a file cannot be
  ///         created.
  void AddCamera(const std::string& camera, const CameraIntrinsics& intrinsics,
                 const CameraOutputs& outputs);

  /// queues a frame for writing; blocks while queue_capacity frames are outstanding.
  /// @throws Error for an unregistered camera or a frame index not greater than the last one
  ///         submitted for that camera (the frame is not queued), or the first unreported
  ///         write error of an earlier frame (the frame is not queued either).
  void Submit(CameraFrame frame);

  /// blocks until every submitted frame is written (or failed).
  /// @throws Error the first unreported write error.
  void Flush();

  /// frames.csv rows written per camera so far (sorted by camera name).
  std::map<std::string, int64_t> FramesWritten() const;

  /// the PNG encoding and file writing of every camera's images so far, s (summed over the
  /// worker threads, which run beside the caller's).
  PngWriteTimes PngTimes() const;

 private:
  struct CameraState {
    std::unique_ptr<CameraWriter> writer;
    uint64_t next_submit_seq = 0;
    uint64_t next_append_seq = 0;
    int64_t last_submitted_index = -1;
    /// finished frames waiting for their turn in frames.csv (images dropped);
    /// nullopt = the frame failed and gets no row.
    std::map<uint64_t, std::optional<CameraFrame>> finished;
  };
  struct Job {
    CameraState* camera;
    uint64_t seq;
    CameraFrame frame;
  };

  void WorkerLoop();
  /// appends the finished rows of `cam` that are next in order; mu_ held.
  void AppendFinishedRows(CameraState* cam);
  /// records the first unreported error; mu_ held.
  void RecordError(std::exception_ptr e);
  /// rethrows and clears the unreported error, if any; mu_ held.
  void RethrowPendingError();

  std::string output_dir_;
  AsyncFrameWriterOptions options_;
  mutable std::mutex mu_;
  std::condition_variable cv_work_, cv_space_, cv_idle_;
  std::deque<Job> queue_;
  int outstanding_ = 0;  ///< queued + being written
  bool stop_ = false;
  std::exception_ptr error_;
  std::map<std::string, std::unique_ptr<CameraState>> cameras_;
  std::vector<std::thread> workers_;
};

}  // namespace penumbra
