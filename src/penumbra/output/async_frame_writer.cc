#include "penumbra/output/async_frame_writer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>

#include "penumbra/core/error.h"

namespace penumbra {

void AsyncFrameWriterOptions::ValidateOrThrow() const {
  if (queue_capacity < 1) {
    throw ConfigError("", 0, "output.queue_capacity",
                      fmt::format("got {}; expected >= 1", queue_capacity));
  }
  if (num_threads < 0 || num_threads > 8) {
    throw ConfigError("", 0, "output.writer_threads",
                      fmt::format("got {}; expected 1..8, or 0 for half the cores", num_threads));
  }
  png.ValidateOrThrow();
}

int AsyncFrameWriterOptions::ResolvedThreads() const {
  if (num_threads > 0) return num_threads;
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(cores / 2, 2, 8);
}

AsyncFrameWriter::AsyncFrameWriter(std::string output_dir, AsyncFrameWriterOptions options)
    : output_dir_(std::move(output_dir)), options_(std::move(options)) {
  options_.ValidateOrThrow();
  const int threads = options_.ResolvedThreads();
  workers_.reserve(threads);
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

AsyncFrameWriter::~AsyncFrameWriter() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_work_.notify_all();
  for (std::thread& t : workers_) t.join();
  if (error_) {
    try {
      std::rethrow_exception(error_);
    } catch (const std::exception& e) {
      spdlog::error("frame writer: unreported write error: {}", e.what());
    } catch (...) {
      spdlog::error("frame writer: unreported write error of unknown type");
    }
  }
}

void AsyncFrameWriter::AddCamera(const std::string& camera, const CameraIntrinsics& intrinsics,
                                 const CameraOutputs& outputs) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (cameras_.count(camera) != 0) {
      throw Error("frame writer: camera '" + camera + "' is already registered");
    }
  }
  auto state = std::make_unique<CameraState>();
  state->writer =
      std::make_unique<CameraWriter>(output_dir_, camera, intrinsics, outputs, options_.png);
  if (options_.on_image) state->writer->set_on_image(options_.on_image);
  std::lock_guard<std::mutex> lock(mu_);
  cameras_.emplace(camera, std::move(state));
}

void AsyncFrameWriter::Submit(CameraFrame frame) {
  std::unique_lock<std::mutex> lock(mu_);
  cv_space_.wait(lock, [&] { return outstanding_ < options_.queue_capacity || error_; });
  RethrowPendingError();
  auto it = cameras_.find(frame.camera);
  if (it == cameras_.end()) {
    throw Error("frame writer: frame of unregistered camera '" + frame.camera + "'");
  }
  CameraState* cam = it->second.get();
  if (frame.index <= cam->last_submitted_index) {
    throw Error(fmt::format(
        "frame writer: camera '{}' frame {} submitted after frame {}; expected increasing indices",
        frame.camera, frame.index, cam->last_submitted_index));
  }
  cam->last_submitted_index = frame.index;
  queue_.push_back(Job{cam, cam->next_submit_seq++, std::move(frame)});
  ++outstanding_;
  lock.unlock();
  cv_work_.notify_one();
}

void AsyncFrameWriter::Flush() {
  std::unique_lock<std::mutex> lock(mu_);
  cv_idle_.wait(lock, [&] { return outstanding_ == 0; });
  RethrowPendingError();
}

std::map<std::string, int64_t> AsyncFrameWriter::FramesWritten() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::map<std::string, int64_t> out;
  for (const auto& [name, cam] : cameras_) out[name] = cam->writer->frames_written();
  return out;
}

PngWriteTimes AsyncFrameWriter::PngTimes() const {
  std::lock_guard<std::mutex> lock(mu_);
  PngWriteTimes sum;
  for (const auto& [name, cam] : cameras_) {
    const PngWriteTimes t = cam->writer->png_times();
    sum.encode_sec += t.encode_sec;
    sum.write_sec += t.write_sec;
  }
  return sum;
}

void AsyncFrameWriter::WorkerLoop() {
  std::unique_lock<std::mutex> lock(mu_);
  while (true) {
    cv_work_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stop_ and drained
    Job job = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();

    std::exception_ptr failure;
    try {
      job.camera->writer->WriteImages(job.frame);
    } catch (...) {
      failure = std::current_exception();
    }
    // keep only what the frames.csv row needs; the images go back to the caller, or are freed
    CameraFrame images = TakeImages(&job.frame);
    if (options_.on_written) options_.on_written(std::move(images));

    lock.lock();
    if (failure) {
      RecordError(failure);
      job.camera->finished.emplace(job.seq, std::nullopt);
    } else {
      job.camera->finished.emplace(job.seq, std::move(job.frame));
    }
    AppendFinishedRows(job.camera);
    --outstanding_;
    cv_space_.notify_one();
    if (outstanding_ == 0) cv_idle_.notify_all();
  }
}

void AsyncFrameWriter::AppendFinishedRows(CameraState* cam) {
  for (auto it = cam->finished.begin();
       it != cam->finished.end() && it->first == cam->next_append_seq;
       it = cam->finished.erase(it)) {
    ++cam->next_append_seq;
    if (!it->second) continue;
    try {
      cam->writer->AppendPose(*it->second);
    } catch (...) {
      RecordError(std::current_exception());
    }
  }
}

void AsyncFrameWriter::RecordError(std::exception_ptr e) {
  if (options_.on_error) options_.on_error(e);
  if (!error_) error_ = e;
  cv_space_.notify_all();
}

void AsyncFrameWriter::RethrowPendingError() {
  if (error_) {
    std::exception_ptr e = error_;
    error_ = nullptr;
    std::rethrow_exception(e);
  }
}

}  // namespace penumbra
