#include "penumbra/output/manifest_sink.h"

#include <spdlog/spdlog.h>

#include "penumbra/pipeline/first_error.h"

namespace penumbra {

ManifestSink::ManifestSink(std::string output_dir,
                           std::function<RunManifest(const LoopFinish&)> describe)
    : output_dir_(std::move(output_dir)), describe_(std::move(describe)) {}

void ManifestSink::OnFinish(const LoopFinish& finish) {
  RunManifest manifest = describe_(finish);
  if (finish.error) manifest.error = ErrorMessage(finish.error);
  try {
    WriteRunManifest(output_dir_, manifest);
  } catch (...) {
    // on a full disk run.json fails too; the error that came first is the one reported
    if (!finish.error) throw;
    spdlog::warn("after the first error, also: {}", ErrorMessage(std::current_exception()));
  }
}

}  // namespace penumbra
