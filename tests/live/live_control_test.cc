// live changes of a running world (live/live_effects.h, live_control.h): a change requested
// during step k applies from step k + 1 on, in every frame after and in none before; bad
// requests are refused naming the field before anything changes; the NPCs of the preset a run
// started with move onto the new preset's paths or park, and no more can be added.

#include "penumbra/live/live_control.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>

#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/core/error.h"
#include "penumbra/output/png_io.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/run/run_outputs.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
const fs::path kWorlds = fs::path(PENUMBRA_SOURCE_DIR) / "worlds";

// calls `at` on the loop thread at step `step` (after the live effects' turn at that step)
class StepHook : public Sink {
 public:
  StepHook(int64_t step, std::function<void()> at) : step_(step), at_(std::move(at)) {}
  SnapshotContent Wants(int64_t step, double) override {
    if (step == step_) at_();
    return SnapshotContent::kNone;
  }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}

 private:
  int64_t step_;
  std::function<void()> at_;
};

// the default world with its front camera at 48 x 36, 10 Hz, for `duration` s
WorldConfig SmallDefaultWorld(const fs::path& out, double duration) {
  WorldConfig w = LoadWorldFile((kWorlds / "default.yaml").string());
  w.duration_sec = duration;
  w.output_dir = out.string();
  fs::create_directories(out);
  w.cameras.resize(1);
  w.cameras[0].width = 48;
  w.cameras[0].height = 36;
  w.cameras[0].outputs = CameraOutputs{ImageKind::kRgb};
  return w;
}

// runs `world` through the run's sinks with live controls; `request` (may be empty) runs on
// the loop thread at step `at_step`. returns the rgb PNGs' paths by frame index.
std::map<int, fs::path> RunWithChange(const WorldConfig& world, int64_t at_step,
                                      const std::function<void(LiveControl&)>& request) {
  Session session(world);
  LiveControl live(session, "test", world.output_dir);
  RunOutputsOptions oo;
  oo.end_time_sec = world.duration_sec;
  RunOutputs outputs(session, world, world.output_dir, oo);
  PhysicsSource physics(&session.sim());
  SimLoopOptions lo;
  lo.end_time_sec = world.duration_sec;
  SimLoop loop(&physics, lo);
  StepHook hook(at_step, [&] {
    if (request) request(live);
  });
  live.AddTo(&loop);
  loop.AddSink(&hook);
  outputs.AddTo(&loop);
  const LoopFinish f = loop.Run();
  if (f.error) std::rethrow_exception(f.error);
  std::map<int, fs::path> frames;
  for (const auto& e : fs::directory_iterator(fs::path(world.output_dir) / "front" / "rgb"))
    frames[std::stoi(e.path().stem().string())] = e.path();
  return frames;
}

// standard deviation of the luma of an 8-bit rgb PNG
double LumaStddev(const fs::path& png) {
  const PngImage img = ReadPng(png.string());
  double sum = 0, sum2 = 0;
  const int n = img.width * img.height;
  for (int i = 0; i < n; ++i) {
    const double y = 0.2126 * img.samples[3 * i] + 0.7152 * img.samples[3 * i + 1] +
                     0.0722 * img.samples[3 * i + 2];
    sum += y;
    sum2 += y * y;
  }
  const double mean = sum / n;
  return std::sqrt(std::max(0.0, sum2 / n - mean * mean));
}

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(LiveControlTest, AFogChangeAtStepKChangesTheFramesAfterKAndNoneBefore) {
  testing::TempDir tmp;
  // 0.6 s: frames 0..6 at steps 0, 50, ..., 300; the fog is asked for during step 120, so it
  // shows from step 121: frames 3..6 change, frames 0..2 do not
  const auto clear = RunWithChange(SmallDefaultWorld(tmp.path() / "clear", 0.6), 120, nullptr);
  const auto foggy =
      RunWithChange(SmallDefaultWorld(tmp.path() / "foggy", 0.6), 120, [](LiveControl& live) {
        live.effects().SetEffect("fog", {{"mor_m", 1.5}});
        EXPECT_EQ(live.effects().pending(), 1u);
      });
  ASSERT_EQ(clear.size(), 7u);
  ASSERT_EQ(foggy.size(), 7u);
  for (int i = 0; i <= 2; ++i)
    EXPECT_TRUE(Bytes(clear.at(i)) == Bytes(foggy.at(i))) << "frame " << i << " before the change";
  for (int i = 3; i <= 6; ++i) {
    const double c = LumaStddev(clear.at(i)), f = LumaStddev(foggy.at(i));
    EXPECT_LT(f, 0.6 * c) << "frame " << i << ": contrast " << f << " in fog, " << c << " clear";
  }
}

TEST(LiveControlTest, BadRequestsAreRefusedNamingTheFieldAndChangeNothing) {
  const WorldConfig world = LoadWorldFile((kWorlds / "effects" / "fog.yaml").string());
  SessionOptions o;
  o.build_renderer = false;
  Session session(world, o);
  LiveControl live(session, "test", ::testing::TempDir());
  LiveEffects& fx = live.effects();
  const auto refused = [&](const std::function<void()>& call, const std::string& key,
                           const std::string& words) {
    try {
      call();
      ADD_FAILURE() << "accepted; expected an error on " << key;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused([&] { fx.SetAdversity("foggiest"); }, "adversity", "expected one of: none, minor, major");
  refused([&] { fx.SetAdversity("/nonexistent/presets.yaml"); }, "preset", "is absolute");
  // the preset the world started without has no NPC bodies
  refused([&] { fx.SetAdversity("major"); }, "npcs", "cannot add bodies");
  refused([&] { fx.SetEffect("npcs", {{"people", 1}}); }, "npcs", "cannot add bodies");
  // the world's own effect `fog`: world-file keys, checked as the world file's
  refused(
      [&] {
        fx.SetEffect("fog", {{"mor_m", "thick"}});
      },
      "effects.fog.mor_m", "expected a number");
  refused([&] { fx.SetEffect("fog", {{"mor_m", -2}}); }, "effects.fog.mor_m",
          "expected [0.001, 1e+05]");
  refused(
      [&] {
        fx.SetEffect("fog", {{"visibility", 3}});
      },
      "effects.fog.visibility", "unknown key 'visibility'");
  refused([&] { fx.SetEffect("fog", {{"type", "rain"}}); }, "effects.fog.type", "keeps its type");
  // preset blocks: the preset file's keys and ranges
  refused(
      [&] {
        fx.SetEffect("rain", {{"rate_mm_h", 900}});
      },
      "rain.rate_mm_h", "expected (0, 500] mm/h");
  refused([&] { fx.SetEffect("smoke", {{"coverage", 0.5}}); }, "smoke.sigma_t_per_m", "");
  refused([&] { fx.SetEffect("lights", {{"scale", 2}}); }, "lights.scale", "expected [0, 1]");
  refused(
      [&] {
        fx.SetEffect("adversity_fog", {{"mor_m", 3}});
      },
      "effects.adversity_fog", "planned from the adversity preset");
  // new effects need a type; removals need an effect
  refused([&] { fx.SetEffect("haze", {{"mor_m", 5}}); }, "effects.haze.type", "missing");
  refused(
      [&] {
        fx.SetEffect("haze", {{"type", "mist"}});
      },
      "effects.haze.type", "unknown value 'mist'");
  refused([&] { fx.SetEffect("haze", nullptr); }, "effects.haze", "no such effect");
  refused([&] { fx.SetEffect("fog", 3); }, "effects.fog", "expected an object or null");
  refused(
      [&] {
        fx.SetEffect("dimmer", {{"type", "light_event"}, {"light", "no_such_lamp"}});
      },
      "effects.dimmer.light", "no_such_lamp");
  EXPECT_EQ(fx.pending(), 0u);
  EXPECT_EQ(session.effects().effects().size(), 1u);

  // valid ones queue, and apply (in order) at the next step boundary
  fx.SetEffect("fog", {{"sigma_t_per_m", 0.8}});
  fx.SetEffect("drizzle", {{"type", "rain"}, {"rate_mm_h", 3}});
  fx.SetEffect("lights", {{"scale", 0.5}});
  EXPECT_EQ(fx.pending(), 3u);
  EXPECT_EQ(session.effects().effects().size(), 1u);  // nothing applied yet
  fx.Wants(0, 0.0);
  EXPECT_EQ(fx.pending(), 0u);
  const std::vector<EffectConfig>& e = session.effects().effects();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].name, "fog");
  EXPECT_EQ(*e[0].Get<FogParams>().extinction.sigma_t_per_m, 0.8);
  EXPECT_FALSE(e[0].Get<FogParams>().extinction.mor_m);
  EXPECT_EQ(e[1].name, "drizzle");
  EXPECT_EQ(e[1].Get<RainParams>().rate_mm_h, 3);
  EXPECT_EQ(e[2].name, "adversity_dim");
  EXPECT_EQ(e[2].Get<LightEventParams>().min_scale, 0.5);
  // removals
  fx.SetEffect("drizzle", nullptr);
  fx.SetEffect("lights", nullptr);
  fx.SetAdversity("none");
  fx.Wants(1, 0.002);
  ASSERT_EQ(session.effects().effects().size(), 1u);
  EXPECT_EQ(session.effects().effects()[0].name, "fog");
}

// a client's preset file (set_adversity) is read from inside the world file's folder only:
// an absolute path, "..", a symbolic link or a non-YAML file is refused naming the rule, and
// no refusal quotes the file's content; a preset file inside the folder still works
TEST(LiveControlTest, ClientPresetFilesStayInsideTheWorldFolderAndAreNotQuoted) {
  penumbra::testing::TempDir tmp;
  WorldConfig world = LoadWorldFile((kWorlds / "effects" / "fog.yaml").string());
  world.file = (tmp.path() / "world" / "fog.yaml").string();  // the folder presets come from
  fs::create_directories(tmp.path() / "world" / "presets");
  const std::string secret = tmp.Write("outside/secret.yaml", "api_token: SECRET-TOKEN\n");
  const std::string notes = tmp.Write("outside/notes.txt", "one line of SECRET-TEXT\n");
  tmp.Write("world/presets/smoky.yaml",
            "presets:\n  smoky:\n    fog: {mor_m: 4}\n    lights: {scale: 0.4}\n");
  tmp.Write("world/bad.yaml", "presets:\n  p:\n    fog: {mor_m: SECRET-VALUE}\n");
  tmp.Write("world/text.yaml", "one line of SECRET-TEXT\n");
  fs::create_symlink(secret, tmp.path() / "world" / "link.yaml");
  fs::create_symlink(notes, tmp.path() / "world" / "notes.yaml");
  fs::create_symlink(tmp.path() / "outside", tmp.path() / "world" / "out");
  SessionOptions o;
  o.build_renderer = false;
  Session session(world, o);
  LiveControl live(session, "test", tmp.path());
  LiveEffects& fx = live.effects();
  const auto refused = [&](const std::string& spec, const std::string& words) {
    try {
      fx.SetAdversity(spec);
      ADD_FAILURE() << spec << ": accepted; expected a refusal";
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_EQ(e.key(), "preset") << m;
      EXPECT_NE(m.find(words), std::string::npos) << spec << ": " << m;
      EXPECT_EQ(m.find("SECRET"), std::string::npos) << spec << ": " << m;
      EXPECT_EQ(m.find("api_token"), std::string::npos) << spec << ": " << m;
      EXPECT_EQ(m.find((tmp.path() / "world").string()), std::string::npos) << spec << ": " << m;
    }
  };
  refused(secret, "is absolute");
  refused(secret + "#p", "is absolute");
  refused("../outside/secret.yaml", "'..' component");
  refused("presets/../../outside/secret.yaml", "'..' component");
  refused("link.yaml", "is a symbolic link");
  refused("notes.yaml", "is a symbolic link");
  refused("out/secret.yaml", "'out' is a symbolic link");
  refused("bad.yaml", "line 3: not a valid adversity preset file");
  refused("text.yaml#x", "line 1: not a valid adversity preset file");
  refused("presets/smoky.yaml#other", "unknown preset 'other' in 'presets/smoky.yaml'");
  EXPECT_EQ(fx.pending(), 0u);

  // a preset file inside the folder, named relative to it
  fx.SetAdversity("presets/smoky.yaml#smoky");
  fx.SetAdversity("presets/smoky.yaml");  // its only preset
  EXPECT_EQ(fx.pending(), 2u);
  fx.Wants(0, 0.0);
  ASSERT_TRUE(session.effects().preset());
  EXPECT_EQ(session.effects().preset()->name, "smoky");
  EXPECT_EQ(*session.effects().preset()->fog_mor_m, 4.0);
}

TEST(LiveControlTest, NpcsOfTheStartingPresetMoveOrParkAndTheRestStayBitExact) {
  const WorldConfig world = LoadWorldFile((kWorlds / "effects" / "adversity_major.yaml").string());
  SessionOptions o;
  o.build_renderer = false;
  Session live_session(world, o), same_session(world, o);
  const std::vector<std::string>& npcs = live_session.effects().agent_bodies();
  ASSERT_EQ(npcs.size(), 4u);  // major: four people (its forklift has no drivable area here)
  LiveControl live(live_session, "test", ::testing::TempDir());
  // re-placing the same preset gives the same plan: nothing moves
  live.effects().SetAdversity("major");
  live.effects().Wants(0, 0.0);
  EXPECT_EQ(live_session.effects().EffectLabels(), same_session.effects().EffectLabels());
  // more people than the run has bodies: refused
  EXPECT_THROW(live.effects().SetEffect("npcs", {{"people", 5}}), ConfigError);

  Simulation& a = live_session.sim();
  Simulation& b = same_session.sim();
  for (int i = 0; i < 100; ++i) {
    a.Step();
    b.Step();
  }
  // during step 100: one person stays, the others park
  live.effects().SetEffect("npcs", {{"people", 1}, {"vehicles", 0}});
  live.effects().Wants(a.step_count(), a.time());
  const SimState sa = a.GetState(), sb = b.GetState();
  const std::vector<std::string> mocap = a.MocapBodyNames();
  for (size_t m = 0; m < mocap.size(); ++m) {
    const double za = sa.mocap_pos[3 * m + 2], zb = sb.mocap_pos[3 * m + 2];
    if (IsAgentBodyOf(mocap[m], "adversity_person0")) {  // its root and limbs
      EXPECT_EQ(za, zb) << mocap[m];
      EXPECT_EQ(sa.mocap_pos[3 * m], sb.mocap_pos[3 * m]) << mocap[m];
    } else {
      // parked 100 m down, standing: a person's pelvis without the walking cycle's drop
      // (< 6 cm), its limbs at rest instead of mid-stride
      EXPECT_NEAR(za, zb - 100.0, 0.2) << mocap[m] << " parked";
      EXPECT_LT(za, -90.0) << mocap[m];
    }
  }
  EXPECT_EQ(sa.qpos, sb.qpos);  // the change is at a step boundary: the state is the same
  EXPECT_EQ(live_session.effects().agents().size(), 1u);
}

// what the viewer's controls show: the preset as requested, its name, whether a
// block was changed since, and a count of accepted changes; a refused change leaves it
TEST(LiveControlTest, RequestedAdversityFollowsEveryAcceptedChange) {
  const WorldConfig world = LoadWorldFile((kWorlds / "effects" / "fog.yaml").string());
  SessionOptions o;
  o.build_renderer = false;
  o.reserve_live_npcs = true;
  Session session(world, o);
  LiveControl live(session, "test", ::testing::TempDir());
  LiveEffects& fx = live.effects();
  RequestedAdversity r = fx.requested_adversity();
  EXPECT_EQ(r.name, "none");
  EXPECT_FALSE(r.edited);
  EXPECT_EQ(r.changes, 0);
  EXPECT_TRUE(!r.preset || r.preset->empty());

  fx.SetAdversity("major");
  r = fx.requested_adversity();
  EXPECT_EQ(r.name, "major");
  EXPECT_FALSE(r.edited);
  EXPECT_EQ(r.changes, 1);
  ASSERT_TRUE(r.preset);
  EXPECT_EQ(r.preset->fog_mor_m, 12.0);
  EXPECT_EQ(r.preset->npc_people, 4);
  EXPECT_EQ(r.preset->light_scale, 0.25);

  fx.SetEffect("fog", {{"mor_m", 40}});  // the world's own effect: not the preset's block
  EXPECT_FALSE(fx.requested_adversity().edited);
  fx.SetEffect("rain", {{"rate_mm_h", 5}});
  r = fx.requested_adversity();
  EXPECT_EQ(r.name, "major");
  EXPECT_TRUE(r.edited);
  EXPECT_EQ(r.changes, 3);
  EXPECT_EQ(r.preset->rain_rate_mm_h, 5.0);
  EXPECT_EQ(r.preset->fog_mor_m, 12.0);

  EXPECT_THROW(fx.SetEffect("lights", {{"scale", 2}}), ConfigError);
  EXPECT_EQ(fx.requested_adversity().changes, 3);

  fx.SetAdversity("none");
  r = fx.requested_adversity();
  EXPECT_EQ(r.name, "none");
  EXPECT_FALSE(r.edited);
  EXPECT_EQ(r.changes, 4);
  EXPECT_TRUE(!r.preset || r.preset->empty());
}

}  // namespace
}  // namespace penumbra
