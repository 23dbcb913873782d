// start_recording through the one command layer (command/command_dispatcher.h), as the ZeroMQ
// bridge, the viewer and ROS reach it: the path is a new .plog inside the run's output folder
// (core/output_path_policy.h). a path outside it (absolute or with ".."), through a symbolic
// link or over an existing file is refused with a message naming the path and the rule, and
// nothing is created or changed anywhere; a plain relative name records a run log.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_control.h"
#include "penumbra/command/run_description.h"
#include "penumbra/live/live_control.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/runlog/run_log_format.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string RecordingPendulum() {
  return "<mujoco>\n"
         "  <worldbody><body name=\"arm\" pos=\"0 0 1\">\n"
         "    <joint name=\"hinge\" type=\"hinge\" axis=\"0 1 0\" damping=\"0.1\"/>\n"
         "    <geom type=\"capsule\" fromto=\"0 0 0 0 0 -0.5\" size=\"0.02\"/>\n"
         "  </body></worldbody>\n"
         "</mujoco>\n";
}

// a paused (lockstep) live loop with live controls whose output folder is `out`
class RecordingLoop {
 public:
  RecordingLoop(const std::string& world_file, const fs::path& out) {
    SessionOptions so;
    so.build_renderer = false;
    session_ = std::make_unique<Session>(LoadWorldFile(world_file), so);
    live_ = std::make_unique<LiveControl>(*session_, "test", out);
    RunControlOptions co;
    co.start_paused = true;
    control_ = std::make_unique<RunControl>(&session_->sim(), co);
    dispatcher_ = std::make_unique<CommandDispatcher>(*session_, session_->world(), control_.get(),
                                                      DescribeRun(*session_, session_->world()),
                                                      true, live_.get());
    PhysicsSourceOptions po;
    po.before_step = [this](Simulation& sim) { return control_->BeforeStep(sim); };
    source_ = std::make_unique<PhysicsSource>(&session_->sim(), po);
    SimLoopOptions lo;
    lo.end_time_sec = 1.0;
    lo.stop_request = control_->stop_flag();
    loop_ = std::make_unique<SimLoop>(source_.get(), lo);
    live_->AddTo(loop_.get());
    loop_->AddSink(control_.get());
    loop_->Start();
  }
  ~RecordingLoop() {
    control_->RequestStop();
    loop_->Wait();
  }
  json Call(const json& request) { return dispatcher_->Call(request); }

 private:
  std::unique_ptr<Session> session_;
  std::unique_ptr<LiveControl> live_;
  std::unique_ptr<RunControl> control_;
  std::unique_ptr<CommandDispatcher> dispatcher_;
  std::unique_ptr<PhysicsSource> source_;
  std::unique_ptr<SimLoop> loop_;
};

// every entry under `dir` (links not followed), relative, sorted
std::vector<std::string> RecordingTree(const fs::path& dir) {
  std::vector<std::string> out;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator();
       ++it)
    out.push_back(it->path().lexically_relative(dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

// start_recording of `path` is refused as bad_field "path" with `words` in its message, and
// the next request works
void ExpectPathRefused(RecordingLoop& loop, const std::string& path, const std::string& words) {
  const json r = loop.Call({{"cmd", "start_recording"}, {"path", path}, {"id", 1}});
  ASSERT_FALSE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("error").at("code"), "bad_field") << r.dump();
  EXPECT_EQ(r.at("error").at("field"), "path") << r.dump();
  const std::string message = r.at("error").at("message");
  EXPECT_NE(message.find("output path '" + path + "'"), std::string::npos) << message;
  EXPECT_NE(message.find(words), std::string::npos) << message;
  EXPECT_TRUE(loop.Call({{"cmd", "get_state"}}).at("ok").get<bool>());
  // a refused start left no recording behind
  EXPECT_EQ(loop.Call({{"cmd", "stop_recording"}}).at("error").at("code"), "conflict");
}

TEST(RecordingPathTest, StartRecordingWritesOnlyNewFilesInsideTheOutputFolder) {
  penumbra::testing::TempDir tmp;
  tmp.Write("pendulum.xml", RecordingPendulum());
  const std::string world =
      tmp.Write("world.yaml", "seed: 4\nmodels:\n  - {name: a, file: pendulum.xml}\n");
  const fs::path out = tmp.path() / "out", outside = tmp.path() / "outside";
  fs::create_directories(out);
  fs::create_directories(outside);
  tmp.Write("outside/victim.plog", "precious");
  tmp.Write("out/old.plog", "an earlier recording");
  fs::create_directory_symlink(outside, out / "escape");
  RecordingLoop loop(world, out);

  ExpectPathRefused(loop, (outside / "abs.plog").string(), "is absolute");
  ExpectPathRefused(loop, "../outside/dotdot.plog", "'..' component");
  ExpectPathRefused(loop, "escape/link.plog", "'escape' is a symbolic link");
  ExpectPathRefused(loop, "escape/victim.plog", "'escape' is a symbolic link");
  ExpectPathRefused(loop, "old.plog", "already exists");
  ExpectPathRefused(loop, "notes.txt", "does not end in .plog");
  // nothing was created or changed outside, nor inside
  EXPECT_EQ(RecordingTree(outside), std::vector<std::string>{"victim.plog"});
  EXPECT_EQ(testing::ReadAll(outside / "victim.plog"), "precious");
  EXPECT_EQ(testing::ReadAll(out / "old.plog"), "an earlier recording");
  EXPECT_EQ(RecordingTree(out), (std::vector<std::string>{"escape", "old.plog"}));

  // a plain relative name: a run log in the output folder, named relative to it in replies
  json r = loop.Call({{"cmd", "start_recording"}, {"path", "live.plog"}});
  ASSERT_TRUE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("path"), "live.plog");
  // a second start while recording is a conflict that names the relative path only
  r = loop.Call({{"cmd", "start_recording"}, {"path", "other.plog"}});
  EXPECT_EQ(r.at("error").at("code"), "conflict") << r.dump();
  EXPECT_EQ(r.at("error").at("message").get<std::string>().find(tmp.str()), std::string::npos)
      << r.dump();
  EXPECT_FALSE(fs::exists(out / "other.plog"));
  ASSERT_TRUE(loop.Call({{"cmd", "step"}, {"n", 3}}).at("ok").get<bool>());
  r = loop.Call({{"cmd", "stop_recording"}});
  ASSERT_TRUE(r.at("ok").get<bool>()) << r.dump();
  EXPECT_EQ(r.at("path"), "live.plog");
  // the three steps and the boundary the recording started at
  EXPECT_GE(r.at("steps").get<int64_t>(), 3);
  EXPECT_EQ(r.at("steps").get<int64_t>(),
            r.at("last_step").get<int64_t>() - r.at("first_step").get<int64_t>() + 1);
  const std::string log = testing::ReadAll(out / "live.plog");
  ASSERT_GE(log.size(), kRunLogMagic.size());
  EXPECT_EQ(log.substr(0, kRunLogMagic.size()),
            std::string(kRunLogMagic.begin(), kRunLogMagic.end()));
  EXPECT_EQ(r.at("bytes").get<uint64_t>(), log.size());
  // the same name again: refused, the log kept
  ExpectPathRefused(loop, "live.plog", "already exists");
  EXPECT_EQ(testing::ReadAll(out / "live.plog"), log);
}

// set_effect's vdb_smoke `file` from a client: an existing regular .vdb inside the world file's
// folder, reached without following a link; anything else is refused as bad_field
// "params.file" naming the path as given and the rule, in the same words whether or not a file
// exists outside (an absolute path was read, and its error told what was there)
TEST(RecordingPathTest, SetEffectReadsVdbFilesOnlyInsideTheWorldFilesFolder) {
  penumbra::testing::TempDir tmp, outside;
  tmp.Write("pendulum.xml", RecordingPendulum());
  const std::string world =
      tmp.Write("world.yaml", "seed: 4\nmodels:\n  - {name: a, file: pendulum.xml}\n");
  outside.Write("real.vdb", "not a grid");
  fs::create_symlink(outside.path() / "real.vdb", tmp.path() / "link.vdb");
  fs::create_directory_symlink(outside.path(), tmp.path() / "escape");
  fs::create_directory(tmp.path() / "folder.vdb");
  RecordingLoop loop(world, tmp.path() / "out");
  auto refused = [&](const std::string& path, const std::string& words) {
    const json r = loop.Call({{"cmd", "set_effect"},
                              {"effect", "plume"},
                              {"params", {{"type", "vdb_smoke"}, {"file", path}}}});
    EXPECT_FALSE(r.at("ok").get<bool>()) << r.dump();
    if (r.at("ok").get<bool>()) return std::string();
    EXPECT_EQ(r.at("error").at("code"), "bad_field") << r.dump();
    EXPECT_EQ(r.at("error").at("field"), "params.file") << r.dump();
    std::string message = r.at("error").at("message");
    EXPECT_NE(message.find("file '" + path + "': " + words), std::string::npos) << message;
    EXPECT_NE(message.find("the world file's folder"), std::string::npos) << message;
    EXPECT_TRUE(loop.Call({{"cmd", "get_state"}}).at("ok").get<bool>());
    message.erase(message.find(path), path.size());
    return message;
  };
  // an existing and a missing file outside get the same answer
  EXPECT_EQ(refused((outside.path() / "real.vdb").string(), "is absolute"),
            refused((outside.path() / "none.vdb").string(), "is absolute"));
  refused("/etc/passwd.vdb", "is absolute");
  refused("../x/real.vdb", "has a '..' component");
  refused("link.vdb", "is a symbolic link");
  refused("escape/real.vdb", "folder 'escape' is a symbolic link");
  refused("missing.vdb", "does not exist");
  refused("folder.vdb", "is not a regular file");
  refused("notes.txt", "does not end in .vdb");
}

}  // namespace
}  // namespace penumbra
