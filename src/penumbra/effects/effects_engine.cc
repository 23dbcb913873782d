#include "penumbra/effects/effects_engine.h"

#include "penumbra/core/rng.h"

namespace penumbra {

namespace {

// FNV-1a of the effect name: random streams stay put when effects are reordered.
uint64_t NameHash(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace

EffectsEngine::EffectsEngine(const std::vector<EffectConfig>& effects, uint64_t seed,
                             const SceneDescription& scene)
    : effects_(effects), num_scene_lights_(scene.lights.size()) {
  ValidateEffectsOrThrow(effects_);
  for (size_t i = 0; i < effects_.size(); ++i) {
    const EffectConfig& e = effects_[i];
    const EffectBindContext ctx{
        .scene = scene,
        .effects = effects_,
        .index = i,
        .key = HashKeys(seed, NameHash(e.name), static_cast<uint64_t>(e.type().index)),
        .key_prefix = "effects[" + std::to_string(i) + "]",
        .who = "effect '" + e.name + "' (" + e.type_name() + "): "};
    instances_.push_back(BindEffect(e, ctx));
    scales_scene_lights_ = scales_scene_lights_ || instances_.back()->ScalesSceneLights();
  }
}

EffectsEngine::~EffectsEngine() = default;

ThreadPool* EffectsEngine::Pool() {
  if (!pool_) pool_ = std::make_unique<ThreadPool>(0);
  return pool_.get();
}

std::shared_ptr<const EffectsFrame> EffectsEngine::Evaluate(double t,
                                                            const Eigen::Vector3d& viewer_W,
                                                            const std::vector<Pose>* X_WB) {
  auto frame = std::make_shared<EffectsFrame>();
  frame->time_sec = t;
  if (scales_scene_lights_) frame->light_intensity_scale.assign(num_scene_lights_, 1.0f);
  EffectEvalContext ctx;
  ctx.time_sec = t;
  ctx.viewer_W = viewer_W;
  ctx.X_WB = X_WB;
  ctx.pool = [this] { return Pool(); };
  for (size_t i = 0; i < instances_.size(); ++i) {
    ctx.weight = effects_[i].Weight(t);
    instances_[i]->Evaluate(ctx, frame.get());
  }
  return frame;
}

}  // namespace penumbra
