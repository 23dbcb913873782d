// `penumbra replay` as users run it (the real binary in a child process), on logs recorded by
// `penumbra run --record`: the acceptance test of replay. a 20 s default-world recording
// resimulates bit-exact and replays its frames byte for byte; under --adversity major the camera
// trajectory (frames.csv) stays and the images change, also in a world whose agents pushed the
// robot; an override changes a camera's resolution and adds one, both along the logged path.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::RunPenumbra;

const fs::path kWorlds = fs::path(PENUMBRA_SOURCE_DIR) / "worlds";

// `text` with every occurrence of `from` replaced; fails the test when there is none
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  for (; at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// frames.csv rows by frame index (without the header)
std::map<int64_t, std::string> FramesCsv(const fs::path& camera_dir) {
  std::map<int64_t, std::string> rows;
  std::istringstream in(ReadAll(camera_dir / "frames.csv"));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "frame,time_sec,x,y,z,qw,qx,qy,qz");
  while (std::getline(in, line)) rows[std::stoll(line.substr(0, line.find(',')))] = line;
  return rows;
}

// the same frames along the same trajectory under other conditions: the frame indices match and
// each frame's stamp (its mid-exposure time) lies within a shutter time of the other's; a real
// camera (a named profile) meters its shutter time on its own image, so darker conditions
// expose longer and stamp later within the frame
void ExpectSameFramesOtherExposure(const fs::path& a, const fs::path& b) {
  const std::map<int64_t, std::string> ra = FramesCsv(a), rb = FramesCsv(b);
  ASSERT_EQ(ra.size(), rb.size());
  for (const auto& [frame, row] : ra) {
    ASSERT_TRUE(rb.count(frame)) << frame;
    const auto time_of = [](const std::string& r) {
      const size_t c = r.find(',');
      return std::stod(r.substr(c + 1, r.find(',', c + 1) - c - 1));
    };
    EXPECT_NEAR(time_of(row), time_of(rb.at(frame)), 1.0 / 30) << frame;
  }
}

std::string Png(const fs::path& camera_dir, const std::string& kind, int64_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06lld.png", static_cast<long long>(frame));
  return ReadAll(camera_dir / kind / name);
}

// width and height of a PNG (IHDR, big endian)
std::pair<int, int> PngSize(const std::string& png) {
  if (png.size() < 24) return {0, 0};
  const auto be32 = [&](size_t at) {
    return (static_cast<uint8_t>(png[at]) << 24) | (static_cast<uint8_t>(png[at + 1]) << 16) |
           (static_cast<uint8_t>(png[at + 2]) << 8) | static_cast<uint8_t>(png[at + 3]);
  };
  return {static_cast<int>(be32(16)), static_cast<int>(be32(20))};
}

// a frames.csv row's numbers
std::vector<double> Numbers(const std::string& row) {
  std::vector<double> v;
  std::istringstream in(row);
  for (std::string x; std::getline(in, x, ',');) v.push_back(std::stod(x));
  return v;
}

// the default world as bundled (20 s, the trot-gait quadruped in the furnished room), its
// `front` camera at 160 x 120 so that the 200 frames of the recording render quickly
TEST(ReplayRunTest, DefaultWorldResimulatesBitExactAndReplaysTheRecordedFramesByteForByte) {
  testing::TempDir tmp;
  std::string text = ReadAll(kWorlds / "default.yaml");
  text = Replace(text, "    width: 640\n    height: 480\n", "    width: 160\n    height: 120\n");
  text = Replace(text, "file: models/", "file: " + (kWorlds / "models").string() + "/");
  const std::string world = tmp.Write("default.yaml", text);
  const std::string log = (tmp.path() / "default.plog").string();
  const fs::path run = tmp.path() / "run";
  auto r = RunPenumbra({"run", world, "--out", run.string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // physics again, every step checked against the log
  r = RunPenumbra({"replay", log, "--resimulate"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "bit-exact (10001 steps)\n") << r.err;
  r = RunPenumbra({"replay", log, "--resimulate", "ctrl"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "bit-exact (10001 steps)\n") << r.err;

  // the recorded conditions over the last 2 s: the run's frames 180..200, byte for byte
  const fs::path same = tmp.path() / "same";
  r = RunPenumbra({"replay", log, "--out", same.string(), "-q", "--from", "18", "--to", "20"},
                  tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::map<int64_t, std::string> recorded = FramesCsv(run / "front");
  const std::map<int64_t, std::string> replayed = FramesCsv(same / "front");
  ASSERT_EQ(recorded.size(), 201u);
  ASSERT_EQ(replayed.size(), 21u);
  EXPECT_EQ(replayed.begin()->first, 180);
  for (const auto& [frame, row] : replayed) {
    EXPECT_EQ(row, recorded.at(frame));
    for (const char* kind : {"rgb", "depth", "segmentation"}) {
      const std::string png = Png(same / "front", kind, frame);
      ASSERT_FALSE(png.empty()) << kind << " " << frame;
      EXPECT_TRUE(png == Png(run / "front", kind, frame)) << kind << " frame " << frame;
    }
  }
  const std::string manifest = ReadAll(same / "run.json");
  EXPECT_NE(manifest.find("\"replay\""), std::string::npos);
  EXPECT_NE(manifest.find("\"first_step\": 9000"), std::string::npos) << manifest;

  // major adversity: the same camera trajectory, other images
  const fs::path major = tmp.path() / "major";
  r = RunPenumbra({"replay", log, "--out", major.string(), "-q", "--from", "18", "--to", "20",
                   "--adversity", "major"},
                  tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ExpectSameFramesOtherExposure(major / "front", same / "front");
  int differ = 0;
  for (const auto& [frame, row] : replayed)
    differ += Png(major / "front", "rgb", frame) != Png(same / "front", "rgb", frame);
  EXPECT_EQ(differ, 21);
  EXPECT_NE(ReadAll(major / "run.json").find("\"adversity\": \"major"), std::string::npos);
}

// the crowd world's rover among walking people and a forklift, 4 s: the agents push the robot
// (a contact between an agent geom and a rover geom in the recorded ground truth); replayed
// under major adversity the rover's camera follows the same path
TEST(ReplayRunTest, AgentsThatTouchedTheRobotStayOnTheLogUnderMajorAdversity) {
  testing::TempDir tmp;
  std::string text = ReadAll(kWorlds / "effects" / "crowd.yaml");
  text = Replace(text, "file: ../models/", "file: " + (kWorlds / "models").string() + "/");
  text = Replace(text, "duration_sec: 10", "duration_sec: 4");
  text = Replace(text, "width: 640, height: 480", "width: 64, height: 48");
  text += "sensors:\n  - {name: truth, type: ground_truth, rate_hz: 100, contacts: true}\n";
  const std::string world = tmp.Write("crowd.yaml", text);
  const std::string log = (tmp.path() / "crowd.plog").string();
  const fs::path run = tmp.path() / "run";
  auto r = RunPenumbra({"run", world, "--out", run.string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // which bodies are the agents' and the rover's (composed.xml names them)
  const std::string composed = ReadAll(run / "composed.xml");
  std::vector<std::string> bodies;  // by body index; 0 = world
  bodies.push_back("world");
  for (size_t at = composed.find("<body"); at != std::string::npos;
       at = composed.find("<body", at + 1)) {
    if (composed[at + 5] != ' ' && composed[at + 5] != '>') continue;
    const std::string tag = composed.substr(at, composed.find('>', at) - at);
    const size_t name = tag.find(" name=\"");
    bodies.push_back(
        name == std::string::npos ? "" : tag.substr(name + 7, tag.find('"', name + 7) - name - 7));
  }
  const auto is_agent = [&](int b) {
    return b > 0 && b < static_cast<int>(bodies.size()) && bodies[b].find("agents/") == 0;
  };
  const auto is_rover = [&](int b) {
    return b > 0 && b < static_cast<int>(bodies.size()) && bodies[b].find("rover/") == 0;
  };
  int touches = 0;
  std::istringstream contacts(ReadAll(run / "ground_truth" / "truth_contacts.csv"));
  std::string line;
  std::getline(contacts, line);
  ASSERT_EQ(line.find("sample,time_sec,geom1,geom2,body1,body2"), 0u) << line;
  while (std::getline(contacts, line)) {
    const std::vector<double> v = Numbers(line);
    const int b1 = static_cast<int>(v[4]), b2 = static_cast<int>(v[5]);
    touches += (is_agent(b1) && is_rover(b2)) || (is_agent(b2) && is_rover(b1));
  }
  EXPECT_GT(touches, 0) << "no agent touched the rover in the recorded run";

  r = RunPenumbra({"replay", log, "--resimulate"}, tmp.path());
  EXPECT_EQ(r.out, "bit-exact (2001 steps)\n") << r.err;

  const fs::path major = tmp.path() / "major";
  r = RunPenumbra({"replay", log, "--out", major.string(), "-q", "--adversity", "major"},
                  tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ExpectSameFramesOtherExposure(major / "front", run / "front");
  ExpectSameFramesOtherExposure(major / "overview", run / "overview");
  int differ = 0, frames = 0;
  for (const auto& [frame, row] : FramesCsv(run / "front")) {
    ++frames;
    differ += Png(major / "front", "rgb", frame) != Png(run / "front", "rgb", frame);
  }
  EXPECT_EQ(frames, 41);
  EXPECT_EQ(differ, frames);
  // the robot's trajectory is the log's
  EXPECT_EQ(ReadAll(major / "trajectory.csv"), ReadAll(run / "trajectory.csv"));
}

// a ball thrown across a floor, a camera riding on it: the replay renders that camera at another
// resolution and a second one on the same body looking back, both along the logged path
TEST(ReplayRunTest, AnOverrideChangesAResolutionAndAddsACameraAlongTheLoggedPath) {
  testing::TempDir tmp;
  tmp.Write("ball.xml", R"(<mujoco model="ball"><option timestep="0.002"/><worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="ball" pos="0 0 1"><freejoint name="j"/><geom type="sphere" size="0.2"/></body>
    </worldbody><keyframe><key name="throw" qpos="0 0 1 1 0 0 0" qvel="1.5 0.5 2 0 3 1"/></keyframe></mujoco>)");
  const std::string world = tmp.Write(
      "w.yaml",
      "duration_sec: 1\n"
      "models: [{name: s, file: ball.xml, initial_keyframe: throw}]\n"
      "mjcf_cameras: {enabled: false}\n"
      "lights: [{name: sun, type: sun, direction: [0.3, 0.2, -1], illuminance_lux: 50000}]\n"
      "cameras:\n"
      "  - {name: cam, attach: s/ball, width: 32, height: 24, rate_hz: 20}\n");
  const std::string log = (tmp.path() / "ball.plog").string();
  const fs::path run = tmp.path() / "run";
  auto r = RunPenumbra({"run", world, "--out", run.string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const std::string rig =
      tmp.Write("rig/rig.yaml",
                "cameras:\n"
                "  - {name: cam, attach: s/ball, width: 64, height: 48, rate_hz: 20}\n"
                "  - {name: back, attach: s/ball, pose: {rpy_deg: [0, 0, 180]}, width: 40,\n"
                "     height: 30, rate_hz: 10, outputs: [rgb, depth]}\n");
  const fs::path out = tmp.path() / "replayed";
  r = RunPenumbra({"replay", log, "--out", out.string(), "-q", "--world", rig}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // cam: the recorded poses, at the new size
  const std::map<int64_t, std::string> recorded = FramesCsv(run / "cam");
  const std::map<int64_t, std::string> cam = FramesCsv(out / "cam");
  ASSERT_EQ(recorded.size(), 21u);
  EXPECT_EQ(cam, recorded);
  for (const auto& [frame, row] : cam)
    EXPECT_EQ(PngSize(Png(out / "cam", "rgb", frame)), std::make_pair(64, 48));
  EXPECT_EQ(PngSize(Png(run / "cam", "rgb", 0)), std::make_pair(32, 24));
  // back: every other frame time of cam, at the same place (same body, same origin), another
  // orientation, 40 x 30
  const std::map<int64_t, std::string> back = FramesCsv(out / "back");
  ASSERT_EQ(back.size(), 11u);
  double travelled = 0;
  for (const auto& [frame, row] : back) {
    const std::vector<double> b = Numbers(row), c = Numbers(cam.at(2 * frame));
    EXPECT_EQ(b[1], c[1]);                                                      // time
    for (int k = 2; k < 5; ++k) EXPECT_EQ(b[k], c[k]) << "frame " << frame;     // position
    EXPECT_TRUE(b[5] != c[5] || b[6] != c[6] || b[7] != c[7] || b[8] != c[8]);  // turned
    EXPECT_EQ(PngSize(Png(out / "back", "rgb", frame)), std::make_pair(40, 30));
    EXPECT_EQ(PngSize(Png(out / "back", "depth", frame)), std::make_pair(40, 30));
    travelled = std::max(travelled, std::abs(b[2]));
  }
  EXPECT_GT(travelled, 0.5);  // the ball moved along x: the poses are the logged path's
  const std::string manifest = ReadAll(out / "run.json");
  EXPECT_NE(manifest.find("\"override_keys\": [\n      \"cameras\"\n    ]"), std::string::npos)
      << manifest;

  // --cameras: only `back` is rendered, with the same frames as beside `cam`
  const fs::path only = tmp.path() / "only_back";
  r = RunPenumbra(
      {"replay", log, "--out", only.string(), "-q", "--world", rig, "--cameras", "back"},
      tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(only / "cam"));
  EXPECT_EQ(ReadAll(only / "camera_info.json").find("\"cam\""), std::string::npos);
  EXPECT_EQ(ReadAll(only / "back" / "frames.csv"), ReadAll(out / "back" / "frames.csv"));
  for (const auto& [frame, row] : back)
    EXPECT_TRUE(Png(only / "back", "rgb", frame) == Png(out / "back", "rgb", frame)) << frame;
}

TEST(ReplayRunTest, BadOptionsAndOverridesAreRefusedNamingThem) {
  testing::TempDir tmp;
  tmp.Write("ball.xml", R"(<mujoco><worldbody><geom type="plane" size="2 2 0.1"/>
    <body pos="0 0 1"><freejoint/><geom type="sphere" size="0.1"/></body></worldbody></mujoco>)");
  const std::string world = tmp.Write("w.yaml",
                                      "duration_sec: 0.2\nmodels: [{name: s, file: ball.xml}]\n"
                                      "cameras: [{name: cam, width: 16, height: 12, rate_hz: 10}]\n"
                                      "mjcf_cameras: {enabled: false}\n");
  const std::string log = (tmp.path() / "b.plog").string();
  auto r = RunPenumbra(
      {"run", world, "--out", (tmp.path() / "run").string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const std::string physics =
      tmp.Write("physics.yaml", "sky: {type: uniform}\nphysics: {timestep_sec: 0.001}\n");
  const fs::path out = tmp.path() / "o";
  r = RunPenumbra({"replay", log, "--out", out.string(), "--world", physics}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(physics + ":2: physics: changes the recorded physics"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));  // nothing left behind

  r = RunPenumbra({"replay", log, "--out", out.string(), "--cameras", "cam,nope"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--cameras: no camera named 'nope'; expected some of: cam"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));

  r = RunPenumbra({"replay", log, "--out", out.string(), "--from", "0.15", "--to", "0.1"},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--from"), std::string::npos) << r.err;
  r = RunPenumbra({"replay", log, "--resimulate", "--cameras", "cam"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--cameras: does not apply to --resimulate"), std::string::npos) << r.err;
  r = RunPenumbra({"replay", log, "--resimulate", "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--force: needs --out DIR"), std::string::npos) << r.err;
  // --resimulate --out: the verdict on stdout, run.json beside; the log's folder is refused
  r = RunPenumbra({"replay", log, "--resimulate", "--out", out.string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "bit-exact (101 steps)\n");
  EXPECT_NE(ReadAll(out / "run.json").find("\"verdict\": \"bit-exact (101 steps)\""),
            std::string::npos);
  fs::remove_all(out);
  r = RunPenumbra({"replay", log, "--resimulate", "--out", tmp.str(), "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("holds the log being replayed"), std::string::npos) << r.err;
  // the output folder of the recording holds the log: --force would remove it
  r = RunPenumbra({"replay", log, "--out", tmp.str(), "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("holds the log being replayed"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(log));
  r = RunPenumbra({"replay", world, "--out", out.string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(world), std::string::npos) << r.err;
}

// a log cut short (as by SIGKILL of the recorder) replays up to its last complete chunk, with a
// warning naming where it ends, also in run.json
TEST(ReplayRunTest, ACutLogReplaysToItsLastCompleteChunk) {
  testing::TempDir tmp;
  tmp.Write("ball.xml", R"(<mujoco><worldbody><geom type="plane" size="2 2 0.1"/>
    <body pos="0 0 1"><freejoint/><geom type="sphere" size="0.1"/></body></worldbody></mujoco>)");
  const std::string world =
      tmp.Write("w.yaml",
                "duration_sec: 2\nmodels: [{name: s, file: ball.xml}]\n"
                "cameras: [{name: cam, pose: {xyz: [-2, 0, 0.5]}, width: 16, height: 12, "
                "rate_hz: 10}]\nmjcf_cameras: {enabled: false}\n");
  const std::string log = (tmp.path() / "b.plog").string();
  const fs::path run = tmp.path() / "run";
  auto r = RunPenumbra({"run", world, "--out", run.string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // the last 40 % of the file gone: the steps of its last chunks with it
  fs::resize_file(log, fs::file_size(log) * 6 / 10);
  const fs::path out = tmp.path() / "cut";
  r = RunPenumbra({"replay", log, "--out", out.string(), "-q"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("log ends at chunk "), std::string::npos) << r.err;
  const std::map<int64_t, std::string> recorded = FramesCsv(run / "cam");
  const std::map<int64_t, std::string> replayed = FramesCsv(out / "cam");
  ASSERT_EQ(recorded.size(), 21u);
  ASSERT_GT(replayed.size(), 0u);
  EXPECT_LT(replayed.size(), recorded.size());
  for (const auto& [frame, row] : replayed) {
    EXPECT_EQ(row, recorded.at(frame));
    EXPECT_TRUE(Png(out / "cam", "rgb", frame) == Png(run / "cam", "rgb", frame)) << frame;
  }
  const std::string manifest = ReadAll(out / "run.json");
  EXPECT_NE(manifest.find("log ends at chunk "), std::string::npos) << manifest;
}

// a log with one flipped byte in a steps chunk is damaged, never "bit-exact": the
// verdict names the chunk and its steps and the exit status is 1
TEST(ReplayRunTest, ResimulateOfALogWithAFlippedStepByteReportsTheDamageAndFails) {
  testing::TempDir tmp;
  tmp.Write("ball.xml", R"(<mujoco><worldbody><geom type="plane" size="2 2 0.1"/>
    <body pos="0 0 1"><freejoint/><geom type="sphere" size="0.1"/></body></worldbody></mujoco>)");
  const std::string world = tmp.Write("w.yaml",
                                      "duration_sec: 1.2\nmodels: [{name: s, file: ball.xml}]\n"
                                      "cameras: [{name: cam, width: 16, height: 12, rate_hz: 5}]\n"
                                      "mjcf_cameras: {enabled: false}\n");
  const std::string log = (tmp.path() / "b.plog").string();
  auto r = RunPenumbra(
      {"run", world, "--out", (tmp.path() / "run").string(), "-q", "--record", log}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunPenumbra({"replay", log, "--resimulate"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  ASSERT_EQ(r.out, "bit-exact (601 steps)\n");

  // one byte in the middle of the second steps chunk (steps 256..511)
  uint64_t at = 0;
  {
    RunLogReader reader = RunLogReader::Open(log);
    int steps_chunks = 0;
    for (const RunLogChunkInfo& c : reader.chunks())
      if (c.kind == RunLogChunkKind::kSteps && ++steps_chunks == 2)
        at = c.file_offset + runlog_codec::kChunkHeaderBytes + c.compressed_size / 2;
    ASSERT_GE(steps_chunks, 2);
  }
  {
    std::fstream f(log, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(at));
    char b = 0;
    f.read(&b, 1);
    b = static_cast<char>(b ^ 0x01);
    f.seekp(static_cast<std::streamoff>(at));
    f.write(&b, 1);
  }
  for (const char* mode : {"", "ctrl"}) {
    std::vector<std::string> args = {"replay", log, "--resimulate"};
    if (*mode) args.push_back(mode);
    r = RunPenumbra(args, tmp.path());
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_EQ(r.out.find("bit-exact ("), std::string::npos) << r.out;
    EXPECT_EQ(r.out.rfind("damaged log, not verified past step 255: log ends at chunk ", 0), 0u)
        << r.out;
    EXPECT_NE(r.out.find("CRC mismatch in chunk "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("steps 256..511"), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace penumbra
