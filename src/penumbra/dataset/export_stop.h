#pragma once
// stopping an export on request (SIGINT / SIGTERM in `penumbra export`): the exporters
// (dataset/dataset_export.h, ros/rosbag_export.h) check a stop request between frames and
// messages and throw ExportStopped, after which nothing of the export is left behind.

#include <atomic>

#include "penumbra/core/error.h"

namespace penumbra {

/// an export ended early because its stop request was set; what it had written is removed.
class ExportStopped : public Error {
 public:
  /// `signal`: the request's value (the signal number for SIGINT / SIGTERM).
  explicit ExportStopped(int signal);
  int signal() const { return signal_; }

 private:
  int signal_ = 0;
};

/// @throws ExportStopped if `stop_request` (may be null) reads non-zero.
void CheckExportStop(const std::atomic<int>* stop_request);

}  // namespace penumbra
