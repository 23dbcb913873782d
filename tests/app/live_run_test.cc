// live controls in a whole `penumbra run` (run/runner.h RunOptions::on_live): a recording
// started and stopped from another thread while the run goes on is a complete log that
// `penumbra replay` renders from its first step with the live run's images, byte for byte,
// including the live fog changes made before and during it; the run's own --record log holds
// the changes as events and its replay reproduces them too.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <thread>

#include "common/temp_dir.h"
#include "penumbra/live/live_control.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/replay/resimulate.h"
#include "penumbra/run/runner.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
const fs::path kWorlds = fs::path(PENUMBRA_SOURCE_DIR) / "worlds";

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// rgb PNGs of camera `front` by frame index
std::map<int, std::string> Frames(const fs::path& run) {
  std::map<int, std::string> out;
  for (const auto& e : fs::directory_iterator(run / "front" / "rgb"))
    out[std::stoi(e.path().stem().string())] = Bytes(e.path());
  return out;
}

// waits (on the bridge's side) until the loop has reached `step`
void WaitForStep(const LiveControl& live, int64_t step) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (live.step() < step && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

TEST(LiveRunTest, AMidRunRecordingReplaysFromItsFirstStepWithTheLiveRunsImages) {
  testing::TempDir tmp;
  // the default world with its camera at 40 x 30, rgb only, in a file (a replay rebuilds the
  // world from the text the log holds)
  std::string text = Bytes(kWorlds / "default.yaml");
  const auto replace = [&text](const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("    width: 640\n    height: 480\n", "    width: 40\n    height: 30\n");
  replace("outputs: [rgb, depth, segmentation]", "outputs: [rgb]");
  for (size_t at = text.find("file: models/"); at != std::string::npos;
       at = text.find("file: models/", at + 1))
    text.replace(at, 13, "file: " + (kWorlds / "models").string() + "/");
  const WorldConfig world = LoadWorldFile(tmp.Write("default.yaml", text));
  ASSERT_EQ(world.cameras.size(), 1u);
  ASSERT_EQ(world.cameras[0].width, 40);
  const fs::path run = tmp.path() / "run";
  const std::string full_log = (tmp.path() / "full.plog").string();
  // a live recording is a new file inside the run's output folder, named relative to it
  const std::string live_log = (run / "live.plog").string();
  // paced to wall-clock time, and stopped (as by Ctrl-C) once the bridge thread is done: the
  // run lasts about a second and the bridge never talks to a run that has ended
  std::atomic<int> stop{0};
  RunOptions options;
  options.out_dir = run.string();
  options.progress = false;
  options.realtime = true;
  options.duration_sec = 30;
  options.stop_request = &stop;
  options.record_file = full_log;
  options.command_line = {"penumbra", "run", "default.yaml"};
  LiveRecording recording;
  std::string bridge_error;
  std::thread bridge;
  options.on_live = [&](LiveControl& live) {
    bridge = std::thread([&live, &recording, &bridge_error, &stop] {
      try {
        WaitForStep(live, 80);
        live.effects().SetEffect("fog", {{"mor_m", 2.0}});  // before the recording
        WaitForStep(live, 160);
        live.recorder().StartRecording("live.plog", false);
        WaitForStep(live, 300);
        live.effects().SetEffect("fog", {{"mor_m", 0.8}});  // during it
        WaitForStep(live, 440);
        recording = live.recorder().StopRecording();
        WaitForStep(live, 520);
      } catch (const std::exception& e) {
        bridge_error = e.what();
      }
      stop = 1;
    });
  };
  RunSummary summary;
  try {
    summary = RunWorld(world, options);
  } catch (...) {
    stop = 1;
    if (bridge.joinable()) bridge.join();
    throw;
  }
  bridge.join();
  ASSERT_EQ(bridge_error, "");
  EXPECT_TRUE(summary.interrupted);
  ASSERT_GE(summary.physics_steps, 520);

  // the live log: complete, from a step after the start to one before the end
  EXPECT_EQ(recording.path, "live.plog");
  EXPECT_EQ(recording.file, live_log);
  EXPECT_GT(recording.bytes, 0u);
  ASSERT_GE(recording.first_step, 160);
  // the stop came once the loop reached step 440: the recorder had appended 439 at least
  ASSERT_GE(recording.last_step, 439);
  EXPECT_LT(recording.last_step, summary.physics_steps);
  EXPECT_EQ(recording.steps, recording.last_step - recording.first_step + 1);
  {
    RunLogReader log = RunLogReader::Open(live_log);  // strict: the end chunk is there
    EXPECT_TRUE(log.complete());
    EXPECT_EQ(log.first_step(), recording.first_step);
    EXPECT_EQ(log.last_step(), recording.last_step);
    // the change before the recording at its first step, the one during it at its own step
    const std::vector<EventRecord> events = log.Events();
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].kind, "live");
    EXPECT_EQ(events[0].step, recording.first_step);
    EXPECT_NE(events[0].payload.find("\"applied_at_step\""), std::string::npos);
    EXPECT_NE(events[0].payload.find("\"mor_m\":2.0"), std::string::npos) << events[0].payload;
    EXPECT_GT(events[1].step, 300);
    EXPECT_NE(events[1].payload.find("\"mor_m\":0.8"), std::string::npos) << events[1].payload;
    // the run's own log has both at the steps they applied
    RunLogReader full = RunLogReader::Open(full_log);
    const std::vector<EventRecord> all = full.Events();
    ASSERT_EQ(all.size(), 2u);
    EXPECT_GT(all[0].step, 80);
    EXPECT_LT(all[0].step, recording.first_step);
    EXPECT_EQ(all[1].step, events[1].step);
  }

  // the live run's frames (10 Hz: one every 50 steps)
  const std::map<int, std::string> live_frames = Frames(run);
  ASSERT_GE(live_frames.size(), 11u);

  // replays of both logs give the live run's frames byte for byte, fog included
  for (const std::string& log : {live_log, full_log}) {
    ReplayOptions ro;
    ro.log_path = log;
    ro.out_dir = (tmp.path() / fs::path(log).stem()).string();
    ro.progress = false;
    const ReplaySummary rs = ReplayLog(ro);
    const std::map<int, std::string> replayed = Frames(ro.out_dir);
    if (log == live_log) {
      EXPECT_EQ(rs.first_step, recording.first_step);
      EXPECT_EQ(rs.last_step, recording.last_step);
      ASSERT_FALSE(replayed.empty());
      EXPECT_EQ(replayed.begin()->first, static_cast<int>((recording.first_step + 49) / 50));
      EXPECT_EQ(replayed.rbegin()->first, static_cast<int>(recording.last_step / 50));
    } else {
      EXPECT_EQ(replayed.size(), live_frames.size());
    }
    for (const auto& [frame, png] : replayed)
      EXPECT_TRUE(png == live_frames.at(frame)) << log << " frame " << frame;
  }
  // and the fog made a difference: a replay without the live changes differs after them
  ReplayOptions clear;
  clear.log_path = full_log;
  clear.out_dir = (tmp.path() / "clear").string();
  clear.progress = false;
  clear.adversity = "none";
  const ReplaySummary cs = ReplayLog(clear);
  EXPECT_FALSE(cs.warnings.empty());
  const std::map<int, std::string> clear_frames = Frames(clear.out_dir);
  EXPECT_TRUE(clear_frames.at(0) == live_frames.at(0));
  EXPECT_FALSE(clear_frames.at(10) == live_frames.at(10));
}

// NPCs parked and brought back live change the physics from their steps: the log holds the
// changes, and resimulation applies them at the same steps and stays bit-exact
TEST(LiveRunTest, NpcChangesAreRecordedAndResimulateBitExact) {
  testing::TempDir tmp;
  WorldConfig world = LoadWorldFile((kWorlds / "effects" / "adversity_major.yaml").string());
  world.cameras.clear();
  world.mjcf_cameras.enabled = false;
  const std::string log = (tmp.path() / "npcs.plog").string();
  std::atomic<int> stop{0};
  RunOptions options;
  options.out_dir = (tmp.path() / "run").string();
  options.progress = false;
  options.realtime = true;
  options.duration_sec = 30;
  options.stop_request = &stop;
  options.record_file = log;
  std::string bridge_error;
  std::thread bridge;
  options.on_live = [&](LiveControl& live) {
    bridge = std::thread([&live, &bridge_error, &stop] {
      try {
        WaitForStep(live, 100);
        live.effects().SetEffect("npcs", {{"people", 1}, {"vehicles", 0}});
        WaitForStep(live, 250);
        live.effects().SetAdversity("major");
        WaitForStep(live, 400);
      } catch (const std::exception& e) {
        bridge_error = e.what();
      }
      stop = 1;
    });
  };
  RunSummary summary;
  try {
    summary = RunWorld(world, options);
  } catch (...) {
    stop = 1;
    if (bridge.joinable()) bridge.join();
    throw;
  }
  bridge.join();
  ASSERT_EQ(bridge_error, "");
  ASSERT_GE(summary.physics_steps, 400);
  RunLogReader reader = RunLogReader::Open(log);
  // the two live changes (the crowd's own decisions are "npc" events beside them, docs/npcs.md)
  size_t live_changes = 0;
  for (const EventRecord& e : reader.Events())
    if (e.kind != "npc") ++live_changes;
  EXPECT_EQ(live_changes, 2u);

  ResimulateOptions ro;
  ro.log_path = log;
  const ResimulateReport report = ResimulateLog(ro);
  EXPECT_FALSE(report.divergence) << report.Describe();
  EXPECT_EQ(report.steps_checked, summary.physics_steps + 1);
}

}  // namespace
}  // namespace penumbra
