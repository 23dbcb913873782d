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
  e.params = RainParams{};
  return e;
}

EffectConfig NoiseSmoke() {
  EffectConfig e;
  e.name = "smoke";
  e.params = SmokeParams{};
  e.region = BoxRegion{{-2, -2, 0}, {2, 2, 2}};
  return e;
}

EffectConfig Plume(bool fire, int resolution) {
  EffectConfig e;
  e.name = "plume";
  e.region = BoxRegion{{-1, -1, 0}, {1, 1, 2}};
  PlumeEmitter em;
  em.position_W = {0, 0, 0.3};
  FluidParams* fluid;
  if (fire) {
    fluid = &e.params.emplace<FireParams>().fluid;
    em.temperature_k = 1500;
  } else {
    SmokeParams& s = e.params.emplace<SmokeParams>();
    s.mode = SmokeParams::Mode::kPlume;
    s.wind_m_s.setZero();
    fluid = &s.fluid;
  }
  FluidParams& f = *fluid;
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
  const bool fire = state.range(0) != 0;
  const int resolution = static_cast<int>(state.range(1));
  for (auto _ : state) {
    EffectsEngine engine({Plume(fire, resolution)}, 1, SceneDescription{});
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
