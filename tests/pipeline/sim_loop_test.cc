#include "penumbra/pipeline/sim_loop.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a source that counts steps of 0.01 s; qpos[0] = step. `fail_at` makes Advance throw there,
// `last` makes it end there.
class CountingSource : public Source {
 public:
  int64_t step() const override { return step_; }
  double time_sec() const override { return 0.01 * static_cast<double>(step_); }
  std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent content) override {
    contents.push_back(content);
    auto s = std::make_shared<WorldSnapshot>();
    s->step = step_;
    s->time_sec = time_sec();
    s->qpos = {static_cast<double>(step_)};
    return s;
  }
  bool Advance() override {
    if (step_ == fail_at) throw PhysicsError("diverged at step " + std::to_string(step_));
    if (step_ == last) return false;
    ++step_;
    if (step_ == stop_at && stop) stop->store(1);
    return true;
  }

  int64_t fail_at = -1;
  int64_t last = -1;
  int64_t stop_at = -1;
  std::atomic<int>* stop = nullptr;
  std::vector<SnapshotContent> contents;

 private:
  int64_t step_ = 0;
};

// records what it is given; wants `content` every `every` steps; throws at `throw_at`.
class RecordingSink : public Sink {
 public:
  explicit RecordingSink(int every = 1, SnapshotContent content = SnapshotContent::kState)
      : every_(every), content_(content) {}
  void OnStart(const LoopStart& s) override {
    start = s;
    started_on = std::this_thread::get_id();
  }
  SnapshotContent Wants(int64_t step, double) override {
    wanted.push_back(step);
    return step % every_ == 0 ? content_ : SnapshotContent::kNone;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override {
    if (s->step == throw_at) throw Error("sink failed at step " + std::to_string(s->step));
    steps.push_back(s->step);
  }
  void OnFinish(const LoopFinish& f) override {
    finish = f;
    ++finishes;
  }

  int64_t throw_at = -1;
  LoopStart start;
  std::thread::id started_on;
  std::vector<int64_t> wanted, steps;
  LoopFinish finish;
  int finishes = 0;

 private:
  int every_;
  SnapshotContent content_;
};

std::string Message(std::exception_ptr e) { return e ? ErrorMessage(e) : ""; }

TEST(SimLoopTest, EverySinkGetsEverySnapshotInStepOrderOnTheLoopThread) {
  CountingSource source;
  RecordingSink every(1), fifth(5, SnapshotContent::kFull);
  SimLoopOptions o;
  o.end_time_sec = 0.2;  // steps 0..20
  SimLoop loop(&source, o);
  loop.AddSink(&every);
  loop.AddSink(&fifth);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kEndTime);
  EXPECT_EQ(f.step, 20);
  EXPECT_FALSE(f.error);
  std::vector<int64_t> all;
  for (int64_t i = 0; i <= 20; ++i) all.push_back(i);
  EXPECT_EQ(every.wanted, all);
  // a sink gets the snapshots other sinks asked for too
  EXPECT_EQ(every.steps, all);
  EXPECT_EQ(fifth.steps, all);
  // the richest content asked for at a step is the one taken
  ASSERT_EQ(source.contents.size(), 21u);
  for (size_t i = 0; i < source.contents.size(); ++i)
    EXPECT_EQ(source.contents[i], i % 5 == 0 ? SnapshotContent::kFull : SnapshotContent::kState)
        << i;
  EXPECT_NE(every.started_on, std::this_thread::get_id());
  EXPECT_EQ(every.finishes, 1);
  EXPECT_EQ(every.finish.reason, LoopEndReason::kEndTime);
}

TEST(SimLoopTest, NoSnapshotIsTakenWhenNoSinkWantsOne) {
  CountingSource source;
  RecordingSink sparse(7);
  SimLoopOptions o;
  o.end_time_sec = 0.2;
  SimLoop loop(&source, o);
  loop.AddSink(&sparse);
  loop.Run();
  EXPECT_EQ(sparse.steps, (std::vector<int64_t>{0, 7, 14}));
  EXPECT_EQ(source.contents.size(), 3u);
}

TEST(SimLoopTest, AStopRequestEndsTheLoopAtTheNextStepBoundary) {
  std::atomic<int> stop{0};
  CountingSource source;
  source.stop_at = 6;
  source.stop = &stop;
  RecordingSink sink;
  SimLoopOptions o;
  o.stop_request = &stop;
  SimLoop loop(&source, o);  // no end time: only the stop ends it
  loop.AddSink(&sink);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kStopRequested);
  EXPECT_EQ(f.step, 6);
  // the step the request was seen at is still handed over
  EXPECT_EQ(sink.steps.back(), 6);
  EXPECT_EQ(sink.finish.reason, LoopEndReason::kStopRequested);
}

TEST(SimLoopTest, AnErrorInASinkEndsTheRunAndIsReportedAfterEverySinkFinished) {
  CountingSource source;
  RecordingSink first, failing;
  failing.throw_at = 4;
  SimLoopOptions o;
  o.end_time_sec = 1.0;
  SimLoop loop(&source, o);
  loop.AddSink(&first);
  loop.AddSink(&failing);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kError);
  EXPECT_EQ(Message(f.error), "sink failed at step 4");
  EXPECT_EQ(f.step, 4);
  EXPECT_EQ(first.steps.back(), 4);
  EXPECT_EQ(failing.steps.back(), 3);
  // every sink finishes, and sees the error
  EXPECT_EQ(first.finishes, 1);
  EXPECT_EQ(Message(first.finish.error), "sink failed at step 4");
  EXPECT_EQ(Message(loop.first_error()), "sink failed at step 4");
}

TEST(SimLoopTest, AnErrorFromASinkThreadEndsTheLoopAndTheFirstErrorWins) {
  CountingSource source;
  // reports from "its own thread" at step 3, then a second error that must not replace it
  class ThreadedSink : public RecordingSink {
   public:
    void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& s) override {
      RecordingSink::OnSnapshot(s);
      if (s->step == 3) {
        std::thread t([&] { start.report_error(std::make_exception_ptr(Error("writer full"))); });
        t.join();
        start.report_error(std::make_exception_ptr(Error("second")));
      }
    }
  } sink;
  SimLoop loop(&source, SimLoopOptions{});
  loop.AddSink(&sink);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kError);
  EXPECT_EQ(f.step, 3);
  EXPECT_EQ(Message(f.error), "writer full");
  EXPECT_FALSE(loop.ReportError(std::make_exception_ptr(Error("later"))));
}

TEST(SimLoopTest, ASourceErrorEndsTheRunAndSinksStillFinish) {
  CountingSource source;
  source.fail_at = 2;
  RecordingSink sink;
  SimLoop loop(&source, SimLoopOptions{});
  loop.AddSink(&sink);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kError);
  EXPECT_EQ(Message(f.error), "diverged at step 2");
  EXPECT_EQ(sink.steps, (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(sink.finishes, 1);
}

TEST(SimLoopTest, AnErrorInOnFinishIsReportedAndLaterSinksStillFinish) {
  CountingSource source;
  class FailingFinish : public RecordingSink {
   public:
    void OnFinish(const LoopFinish& f) override {
      RecordingSink::OnFinish(f);
      throw Error("close failed");
    }
  } a;
  RecordingSink b;
  SimLoopOptions o;
  o.end_time_sec = 0.05;
  SimLoop loop(&source, o);
  loop.AddSink(&a);
  loop.AddSink(&b);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(Message(f.error), "close failed");
  EXPECT_EQ(b.finishes, 1);
}

TEST(SimLoopTest, ASourceThatEndsEndsTheLoop) {
  CountingSource source;
  source.last = 3;
  RecordingSink sink;
  SimLoop loop(&source, SimLoopOptions{});
  loop.AddSink(&sink);
  const LoopFinish f = loop.Run();
  EXPECT_EQ(f.reason, LoopEndReason::kSourceEnded);
  EXPECT_EQ(sink.steps, (std::vector<int64_t>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace penumbra
