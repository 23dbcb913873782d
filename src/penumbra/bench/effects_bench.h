#pragma once
// the adversity part of `penumbra bench render`: frames/s of the world's first camera at
// 640x480 under the bundled presets none, minor and major (bench/preset_scene.h).

#include "penumbra/bench/bench.h"

namespace penumbra {

/// prints one line per preset: frames/s, ms/frame and Mrays/s of the renderer with the
/// preset's EffectsFrame, its process CPU time per frame (all threads) and the frame rate that
/// gives on 2 idle cores (2 / CPU s per frame: perfect scaling, a bound for a loaded machine),
/// and the effects evaluation time per frame (timed separately: in a
/// run it happens on the physics thread, alongside rendering). the world moves between
/// frames (1/30 s of physics per frame after 1 s of warm-up).
void BenchRenderAdversity(const RenderBenchOptions& options);

}  // namespace penumbra
