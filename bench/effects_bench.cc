// cost of the effects stage (EffectsEngine::Evaluate; noise smoke voxels and particle placement run
// on its own pool of all cores, the fluids serially): rain at the default box
// (200000 drops after the max_particles cap, 5 mm/h), noise smoke on a 4 x 4 x 2 m region at
// noise_resolution 48, and one second of sim time (30 steps) of the plume and fire fluids at
// resolution 48 and 32. counters: particles per frame; fluid steps per second of CPU time.

#include <benchmark/benchmark.h>

#include "penumbra/effects/effects_engine.h"

namespace penumbra {
namespace {

EffectConfig Rain() {
  EffectConfig e;
  e.name = "rain";
  e.type = EffectType::kRain;
  return e;
}

EffectConfig NoiseSmoke() {
  EffectConfig e;
  e.name = "smoke";
  e.type = EffectType::kSmoke;
  e.region = BoxRegion{{-2, -2, 0}, {2, 2, 2}};
  return e;
}

EffectConfig Plume(EffectType type, int resolution) {
  EffectConfig e;
  e.name = "plume";
  e.type = type;
  e.region = BoxRegion{{-1, -1, 0}, {1, 1, 2}};
  PlumeEmitter em;
  em.position_W = {0, 0, 0.3};
  FluidParams& f = type == EffectType::kFire ? e.fire.fluid : e.smoke.fluid;
  if (type == EffectType::kFire) em.temperature_k = 1500;
  e.smoke.mode = SmokeParams::Mode::kPlume;
  e.smoke.wind_m_s.setZero();
  f.resolution = resolution;
  f.emitters = {em};
  return e;
}

void BM_EffectsRainFrame(benchmark::State& state) {
  EffectsEngine engine({Rain()}, 1, SceneDescription{});
  double t = 0;
  size_t n = 0;
  for (auto _ : state) {
    auto f = engine.Evaluate(t, {0, 0, 1.5});
    n = f->particles[0].position_W.size();
    t += 0.1;
  }
  state.counters["particles"] = static_cast<double>(n);
}
BENCHMARK(BM_EffectsRainFrame)->Unit(benchmark::kMillisecond);

void BM_EffectsNoiseSmokeFrame(benchmark::State& state) {
  EffectsEngine engine({NoiseSmoke()}, 1, SceneDescription{});
  double t = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(engine.Evaluate(t, {0, 0, 1.5}));
    t += 0.1;
  }
}
BENCHMARK(BM_EffectsNoiseSmokeFrame)->Unit(benchmark::kMillisecond);

// one second of sim time: 30 fluid steps plus one frame
void BM_EffectsFluidSecond(benchmark::State& state) {
  const EffectType type = state.range(0) ? EffectType::kFire : EffectType::kSmoke;
  const int resolution = static_cast<int>(state.range(1));
  for (auto _ : state) {
    EffectsEngine engine({Plume(type, resolution)}, 1, SceneDescription{});
    benchmark::DoNotOptimize(engine.Evaluate(1.0, {0, 0, 0}));
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(30.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_EffectsFluidSecond)
    ->ArgsProduct({{0, 1}, {32, 48}})
    ->ArgNames({"fire", "res"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace penumbra
