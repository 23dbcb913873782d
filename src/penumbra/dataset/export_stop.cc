#include "penumbra/dataset/export_stop.h"

#include <string>

namespace penumbra {

ExportStopped::ExportStopped(int signal)
    : Error("the export was stopped (signal " + std::to_string(signal) +
            "); its partial output was removed"),
      signal_(signal) {}

void CheckExportStop(const std::atomic<int>* stop_request) {
  if (stop_request == nullptr) return;
  const int v = stop_request->load(std::memory_order_relaxed);
  if (v != 0) throw ExportStopped(v);
}

}  // namespace penumbra
