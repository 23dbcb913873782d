#pragma once
// run.json (output/run_manifest.h) as a pipeline sink (pipeline/sink.h): written once, when the
// loop has ended, after the sinks registered before it have finished (register it last), with
// the run's first error.

#include <functional>
#include <string>

#include "penumbra/output/run_manifest.h"
#include "penumbra/pipeline/sink.h"

namespace penumbra {

/// writes DIR/run.json when the loop ends.
class ManifestSink : public Sink {
 public:
  /// SinkStage::kManifest: last: run.json is written after every other sink finished.
  SinkStage stage() const override { return SinkStage::kManifest; }
  /// `describe` fills the manifest from the finished run (frames, timings, ...) on the loop
  /// thread in OnFinish; the sink sets RunManifest::error from LoopFinish::error.
  ManifestSink(std::string output_dir, std::function<RunManifest(const LoopFinish&)> describe);

  /// never wants a snapshot.
  SnapshotContent Wants(int64_t, double) override { return SnapshotContent::kNone; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}
  /// writes run.json. when it cannot be written after the run already failed, the write error
  /// is only logged (the first error is the one reported).
  /// @throws Error naming the path if it cannot be written and the run had no error before.
  void OnFinish(const LoopFinish& finish) override;

 private:
  std::string output_dir_;
  std::function<RunManifest(const LoopFinish&)> describe_;
};

}  // namespace penumbra
