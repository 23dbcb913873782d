// the order of a SimLoop's sinks follows their stage (pipeline/sink.h SinkStage), not the order
// of the AddSink calls; sinks of one stage keep their registration order.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "penumbra/pipeline/sim_loop.h"

namespace penumbra {
namespace {

// three steps of 0.1 s
class StageTestSource : public Source {
 public:
  int64_t step() const override { return step_; }
  double time_sec() const override { return 0.1 * static_cast<double>(step_); }
  std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent) override {
    auto s = std::make_shared<WorldSnapshot>();
    s->step = step_;
    s->time_sec = time_sec();
    return s;
  }
  bool Advance() override {
    if (step_ == 2) return false;
    ++step_;
    return true;
  }

 private:
  int64_t step_ = 0;
};

// appends "<call>:<name>" to a shared log for every call the loop makes
class StageLogSink : public Sink {
 public:
  StageLogSink(std::string name, SinkStage stage, std::vector<std::string>* log)
      : name_(std::move(name)), stage_(stage), log_(log) {}
  SinkStage stage() const override { return stage_; }
  const std::string& name() const { return name_; }
  void OnStart(const LoopStart&) override { log_->push_back("start:" + name_); }
  SnapshotContent Wants(int64_t, double) override {
    log_->push_back("wants:" + name_);
    return SnapshotContent::kState;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override {
    log_->push_back("snapshot" + std::to_string(s->step) + ":" + name_);
  }
  void OnFinish(const LoopFinish&) override { log_->push_back("finish:" + name_); }

 private:
  std::string name_;
  SinkStage stage_;
  std::vector<std::string>* log_;
};

// the calls of one kind ("start", "wants", "snapshot1", "finish") in the order they were made
std::vector<std::string> CallsOf(const std::vector<std::string>& log, const std::string& call) {
  std::vector<std::string> names;
  for (const std::string& entry : log)
    if (entry.rfind(call + ":", 0) == 0) names.push_back(entry.substr(call.size() + 1));
  return names;
}

TEST(SinkStageTest, TheLoopCallsSinksInStageOrderWhateverTheRegistrationOrder) {
  std::vector<std::string> log;
  // registered backwards: run.json first, the live changes last; two output sinks a, b
  StageLogSink manifest("manifest", SinkStage::kManifest, &log);
  StageLogSink bridge("bridge", SinkStage::kBridges, &log);
  StageLogSink control("control", SinkStage::kRunControl, &log);
  StageLogSink recorder("recorder", SinkStage::kRecording, &log);
  StageLogSink output_a("output_a", SinkStage::kOutputs, &log);
  StageLogSink output_b("output_b", SinkStage::kOutputs, &log);
  StageLogSink live("live", SinkStage::kLiveChanges, &log);
  StageTestSource source;
  SimLoopOptions options;
  options.end_time_sec = 10;
  SimLoop loop(&source, options);
  for (Sink* s :
       std::vector<Sink*>{&manifest, &bridge, &control, &recorder, &output_a, &output_b, &live})
    loop.AddSink(s);

  const std::vector<std::string> expected = {"live",    "output_a", "output_b", "recorder",
                                             "control", "bridge",   "manifest"};
  std::vector<std::string> ordered;
  for (const Sink* s : loop.OrderedSinks())
    ordered.push_back(static_cast<const StageLogSink*>(s)->name());
  EXPECT_EQ(ordered, expected);

  const LoopFinish finish = loop.Run();
  ASSERT_FALSE(finish.error);
  EXPECT_EQ(CallsOf(log, "start"), expected);
  for (const char* call : {"snapshot0", "snapshot1", "snapshot2", "finish"})
    EXPECT_EQ(CallsOf(log, call), expected) << call;
  // Wants: three steps, each in stage order
  std::vector<std::string> wants3;
  for (int i = 0; i < 3; ++i) wants3.insert(wants3.end(), expected.begin(), expected.end());
  EXPECT_EQ(CallsOf(log, "wants"), wants3);
}

TEST(SinkStageTest, ASinkThatDeclaresNoStageIsAnOutputAndTheStagesHaveNames) {
  std::vector<std::string> log;
  StageLogSink probe("probe", SinkStage::kOutputs, &log);
  EXPECT_EQ(probe.Sink::stage(), SinkStage::kOutputs);
  EXPECT_STREQ(SinkStageName(SinkStage::kLiveChanges), "live_changes");
  EXPECT_STREQ(SinkStageName(SinkStage::kOutputs), "outputs");
  EXPECT_STREQ(SinkStageName(SinkStage::kRecording), "recording");
  EXPECT_STREQ(SinkStageName(SinkStage::kRunControl), "run_control");
  EXPECT_STREQ(SinkStageName(SinkStage::kBridges), "bridges");
  EXPECT_STREQ(SinkStageName(SinkStage::kManifest), "manifest");
}

}  // namespace
}  // namespace penumbra
