// through `penumbra run`: absurd but finite inputs exit 2 with a
// message that names the file and key (or the MJCF geom / camera) instead of aborting in Embree
// (SIGABRT), hanging, or dying of std::bad_alloc. each run goes through RunCli in a child process
// with an alarm, so a regression that hangs fails the test instead of stalling the suite.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/app/cli.h"
#include "penumbra/core/error.h"
#include "penumbra/run/runner.h"
#include "penumbra/world/run_budget.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

constexpr char kBall[] = R"(<mujoco model="ball">
  <option timestep="TIMESTEP"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="ball" pos="BALLPOS">
      <freejoint/>
      <geom name="ball" type="sphere" size="RADIUS"/>
    </body>
    <camera name="eye" pos="0 -3 1" xyaxes="1 0 0 0 0.3 1" fovy="FOVY"/>
  </worldbody>
</mujoco>
)";

std::string Ball(const std::string& timestep = "0.005", const std::string& radius = "0.2",
                 const std::string& pos = "0 0 1", const std::string& fovy = "45") {
  std::string s = kBall;
  const auto put = [&](const std::string& key, const std::string& v) {
    s.replace(s.find(key), key.size(), v);
  };
  put("TIMESTEP", timestep);
  put("RADIUS", radius);
  put("BALLPOS", pos);
  put("FOVY", fovy);
  return s;
}

struct CliResult {
  int code = -1;       // exit code, or -signal
  std::string output;  // stdout and stderr
};

// runs `penumbra run <target> --out <dir>/out --quiet <extra>` in a child process that is killed
// after 60 s (a hang fails the test with code -SIGALRM); address_space_bytes > 0 limits the
// child's address space (RLIMIT_AS).
CliResult RunChild(const penumbra::testing::TempDir& dir, const std::string& target,
                   std::vector<std::string> extra = {}, rlim_t address_space_bytes = 0) {
  const std::string log = (dir.path() / "cli.log").string();
  std::vector<std::string> args = {"penumbra",         "run",    target, "--out",
                                   dir.str() + "/out", "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(60);
    if (address_space_bytes > 0) {
      const rlimit limit{address_space_bytes, address_space_bytes};
      if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(98);
    }
    FILE* f = std::freopen(log.c_str(), "w", stdout);
    if (f == nullptr || dup2(fileno(stdout), 2) < 0) _exit(99);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    const int code = RunCli(static_cast<int>(argv.size()), argv.data());
    std::fflush(stdout);
    _exit(code);
  }
  CliResult r;
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  std::stringstream ss;
  ss << std::ifstream(log).rdbuf();
  r.output = ss.str();
  return r;
}

void ExpectExit2(const CliResult& r, const std::string& text) {
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(text), std::string::npos) << "expected '" << text << "' in:\n"
                                                    << r.output;
}

std::string World(const std::string& body) {
  return "duration_sec: 0.2\nmodels:\n  - {name: m, file: ball.xml}\n" + body;
}

TEST(LimitsRun, HugePosesAndIntrinsicsExit2) {
  penumbra::testing::TempDir dir;
  dir.Write("ball.xml", Ball());
  ExpectExit2(
      RunChild(dir, dir.Write("a.yaml",
                              "duration_sec: 0.2\nrobots:\n"
                              "  - {name: r, file: ball.xml, pose: {xyz: [1e19, 0, 0]}}\n")),
      "a.yaml:3: robots[0].pose.xyz: component 0 is 1e+19");
  ExpectExit2(
      RunChild(dir,
               dir.Write("b.yaml", World("cameras:\n  - {name: c, pose: {xyz: [0, 1e300, 1]}}\n"))),
      "cameras[0].pose.xyz: component 1 is 1e+300");
  ExpectExit2(
      RunChild(dir, dir.Write("c.yaml",
                              World("cameras:\n  - {name: c, width: 32, height: 24,\n"
                                    "     intrinsics: {fx: 30, fy: 30, cx: 1e300, cy: 12}}\n"))),
      "cameras[0].intrinsics: the horizontal field of view reaches 180 deg");
  ExpectExit2(
      RunChild(dir, dir.Write("d.yaml", World("cameras:\n  - {name: c, width: 32, height: 24,\n"
                                              "     intrinsics: {fx: 1e-300, fy: 1e-300}}\n"))),
      "cameras[0].intrinsics:");
}

TEST(LimitsRun, HugeMjcfGeomsAndBodiesExit2) {
  penumbra::testing::TempDir dir;
  // a sphere of 1e30 m: the auto-framed default camera used to start 1e30 m away (SIGABRT)
  const std::string big = dir.Write("big.xml", Ball("0.005", "1e30"));
  ExpectExit2(RunChild(dir, big),
              big +
                  ": geom 'big/ball': in body 'big/ball': size[0] is 1e+30 m; expected "
                  "[1e-06, 100000] m");
  // a body at 1e17 m used to exit 1 with "physics diverged at t = 0"
  const std::string far = dir.Write("far.xml", Ball("0.005", "0.2", "1e17 0 0"));
  ExpectExit2(RunChild(dir, far), "geom 'far/ball': in body 'far/ball': centre x is 1e+17 m");
}

TEST(LimitsRun, MjcfCameraFovyIsCheckedLikeWorldCameras) {
  penumbra::testing::TempDir dir;
  // MuJoCo 4 refuses 180 deg itself; 179.5 and 0.05 compile and are Penumbra's to refuse
  const std::string wide = dir.Write("wide.xml", Ball("0.005", "0.2", "0 0 1", "179.5"));
  ExpectExit2(RunChild(dir, wide),
              "MJCF camera 'wide/eye': fovy is 179.5 deg; expected [0.1, 179) deg");
  const std::string narrow = dir.Write("narrow.xml", Ball("0.005", "0.2", "0 0 1", "0.05"));
  ExpectExit2(RunChild(dir, narrow),
              "MJCF camera 'narrow/eye': fovy is 0.05 deg; expected [0.1, 179) deg");
  const std::string flat = dir.Write("flat.xml", Ball("0.005", "0.2", "0 0 1", "180"));
  ExpectExit2(RunChild(dir, flat), flat + ":9: Error: fovy too large in camera 'eye'");
}

TEST(LimitsRun, DegenerateTimestepsAndDurationsExit2InsteadOfHanging) {
  penumbra::testing::TempDir dir;
  const std::string zero = dir.Write("zero.xml", Ball("0"));
  ExpectExit2(RunChild(dir, zero, {"--duration", "0.3"}),
              zero + ": option.timestep: '0' is not a usable physics timestep");
  const std::string back = dir.Write("back.xml", Ball("-0.01"));
  ExpectExit2(RunChild(dir, back, {"--duration", "0.3"}), "option.timestep: '-0.01'");
  const std::string one = dir.Write("one.xml", Ball("1"));
  ExpectExit2(RunChild(dir, one, {"--duration", "0.3"}), "option.timestep: '1'");
  dir.Write("ball.xml", Ball());
  ExpectExit2(RunChild(dir, dir.Write("t.yaml", World("physics: {timestep_sec: 1e-300}\n"))),
              "physics.timestep_sec: got 1e-300; expected [1e-06, 0.1]");
  ExpectExit2(
      RunChild(dir,
               dir.Write("d.yaml", "duration_sec: 1e308\nmodels: [{name: m, file: ball.xml}]\n")),
      "duration_sec: got 1e+308; expected (0, 1e+06]");
  ExpectExit2(RunChild(dir, dir.Write("e.yaml", World("")), {"--duration", "1e308"}),
              "duration_sec: got 1e+308");
  // smoke plume dt 1e-9: 1e9 grid steps per simulated second
  ExpectExit2(
      RunChild(dir, dir.Write("p.yaml", World("effects:\n  - name: s\n    type: smoke\n"
                                              "    mode: plume\n"
                                              "    region: {min: [-1, -1, 0], max: [1, 1, 2]}\n"
                                              "    emitters: [{position: [0, 0, 0.2]}]\n"
                                              "    dt_sec: 1e-9\n"))),
      "dt_sec");
}

TEST(LimitsRun, LidarColumnsExit2WithTheKey) {
  penumbra::testing::TempDir dir;
  dir.Write("ball.xml", Ball());
  ExpectExit2(RunChild(dir, dir.Write("l.yaml", World("sensors:\n  - name: l\n    type: lidar\n"
                                                      "    preset: velodyne_vlp16\n"
                                                      "    columns: 1000000000\n"))),
              "l.yaml:8: sensors[0].columns: sensor 'l': got 1000000000; expected an integer in "
              "[1, 4194304]");
  // a tiny rate makes the preset's default column count huge
  ExpectExit2(RunChild(dir, dir.Write("r.yaml", World("sensors:\n  - name: l\n    type: lidar\n"
                                                      "    preset: velodyne_vlp16\n"
                                                      "    rate_hz: 1e-6\n"))),
              "expected at most 4194304 beams per scan");
}

// memory that runs out anyway (here: a 1 GiB address space for an 8192 x 8192 camera that the
// estimate allows on a machine with more memory) ends with a message, not a bare
// "std::bad_alloc". (a 4096 x 4096 camera needs about 340 MiB of it, so whether it ran out
// depended on how much address space the run's threads had reserved by then: it once rendered
// its frame in CI.)
TEST(LimitsRun, OutOfMemoryIsReportedClearly) {
  penumbra::testing::TempDir dir;
  dir.Write("ball.xml", Ball());
  const CliResult r =
      RunChild(dir,
               dir.Write("m.yaml",
                         "duration_sec: 0.01\nmodels: [{name: m, file: ball.xml}]\n"
                         "mjcf_cameras: {enabled: false}\n"
                         "cameras: [{name: c, pose: {xyz: [-3, 0, 1]}, width: 8192, height: 8192,\n"
                         "           rate_hz: 1}]\n"),
               {}, rlim_t{1} << 30);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("out of memory; expected smaller images"), std::string::npos) << r.output;
}

// a world with one 640 x 480 world camera and the MJCF camera of kBall.
struct Assembled {
  WorldConfig world;
  SceneDescription scene;
  Assembled() {
    world.file = "w.yaml";
    CameraSpec mjcf;
    mjcf.name = "m/eye";
    mjcf.mjcf_camera = 0;
    mjcf.intrinsics = CameraIntrinsics::FromFovy(16384, 16384, 60);
    CameraSpec cam;
    cam.name = "front";
    cam.intrinsics = CameraIntrinsics::FromFovy(640, 480, 60);
    cam.outputs[ImageKind::kDepth] = true;
    CameraConfig c;
    c.name = "front";
    world.cameras.push_back(c);
    scene.cameras = {cam, mjcf};
  }
};

TEST(RunBudget, CameraMemoryIsEstimatedAndRefusedAboveTheLimit) {
  Assembled a;
  // realtime: 42 B/px for rgb plus 7 B/px for the depth image
  EXPECT_DOUBLE_EQ(EstimateCameraMemoryBytes(a.scene.cameras[0], RenderSettings::Tier::kRealtime),
                   640.0 * 480 * 49);
  EXPECT_DOUBLE_EQ(EstimateCameraMemoryBytes(a.scene.cameras[1], RenderSettings::Tier::kPathtraced),
                   16384.0 * 16384 * 108);
  EXPECT_NO_THROW(CheckRunMemory(a.world, a.scene, 1e14));
  EXPECT_NO_THROW(CheckRunMemory(a.world, a.scene, 0));  // no limit
  try {
    CheckRunMemory(a.world, a.scene, 8e9);
    ADD_FAILURE() << "16384 x 16384 accepted with 8 GB";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "w.yaml");
    EXPECT_EQ(e.key(), "mjcf_cameras.width");
    EXPECT_NE(std::string(e.what()).find("camera 'm/eye' at 16384 x 16384 needs about 11.3 GB "
                                         "(~42 bytes per pixel)"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("more than the 8.0 GB of memory available"),
              std::string::npos)
        << e.what();
  }
  try {
    CheckRunMemory(a.world, a.scene, 1e7);
    ADD_FAILURE() << "640 x 480 accepted with 10 MB";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "cameras[0].width") << e.what();
  }
  EXPECT_GT(PhysicalMemoryBytes(), 1e8);
}

TEST(RunBudget, AbsurdWorkIsDescribed) {
  Assembled a;
  a.scene.cameras[0].rate_hz = 10;
  a.scene.cameras.pop_back();
  a.world.duration_sec = 10;
  RunWork w = EstimateRunWork(a.world, a.scene, 0.002);
  EXPECT_EQ(w.physics_steps, 5000);
  EXPECT_EQ(w.camera_frames, 101);
  EXPECT_EQ(w.image_bytes, 101 * 640.0 * 480 * 5);  // rgb 3 + depth 2 bytes per pixel
  EXPECT_FALSE(DescribeRunWork(w));
  a.world.duration_sec = 1e5;
  w = EstimateRunWork(a.world, a.scene, 1e-4);
  const auto text = DescribeRunWork(w);
  ASSERT_TRUE(text);
  EXPECT_EQ(text->rfind("this run will take ~1e+09 physics steps and 1e+06 frames (~1536.0 GB of "
                        "images)",
                        0),
            0u)
      << *text;
}

TEST(LimitsRun, TimestepLongerThanTheDurationStopsAfterOneStep) {
  penumbra::testing::TempDir dir;
  dir.Write("ball.xml", Ball());
  WorldConfig world = LoadWorldFile(
      dir.Write("w.yaml",
                "duration_sec: 0.05\nphysics: {timestep_sec: 0.1}\n"
                "models: [{name: m, file: ball.xml}]\nmjcf_cameras: {enabled: false}\n"));
  RunOptions o;
  o.out_dir = dir.str() + "/out";
  o.progress = false;
  const RunSummary s = RunWorld(world, o);
  EXPECT_EQ(s.physics_steps, 1);
  EXPECT_DOUBLE_EQ(s.sim_time_sec, 0.1);
}

}  // namespace
}  // namespace penumbra
