// render.backend selection (render/backends/renderer_factory.h): auto takes the CUDA backend
// only when a CUDA device is present, and cuda without one is a ConfigError naming the key.
// on a machine with a device these run there too (the other branch of each test).

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cpu/embree_renderer.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

// the process's first CUDA call (InitRuntime, here through ProbeDevice) sets the module loading
// mode only while it starts the runtime: the environment after it is the one before, so child
// processes do not inherit EAGER (and a mode the user named stays).
TEST(CudaModuleLoading, TheFirstCudaCallLeavesTheEnvironmentAsItWas) {
#if !defined(PENUMBRA_WITH_CUDA)
  GTEST_SKIP()
      << "built without the CUDA backend (PENUMBRA_CUDA=OFF or no nvcc): no runtime to start";
#else
  const char* before = std::getenv("CUDA_MODULE_LOADING");
  const std::string want = before ? before : "(unset)";
  std::string name, why;
  const bool device = cuda::ProbeDevice(&name, &why);
  const char* after = std::getenv("CUDA_MODULE_LOADING");
  std::printf("device %s; CUDA_MODULE_LOADING before %s, after %s\n",
              device ? name.c_str() : why.c_str(), want.c_str(), after ? after : "(unset)");
  EXPECT_EQ(after ? std::string(after) : std::string("(unset)"), want);
#endif
}

TEST(CudaBackendSelection, AutoIsCudaExactlyWhenADeviceIsPresent) {
  const CudaDeviceStatus s = ProbeCudaDevice();
  EXPECT_EQ(s.available, s.why.empty());
  EXPECT_EQ(ResolveBackend(RenderSettings::Backend::kAuto),
            s.available ? RenderSettings::Backend::kCuda : RenderSettings::Backend::kEmbree);
  EXPECT_EQ(ResolveBackend(RenderSettings::Backend::kEmbree), RenderSettings::Backend::kEmbree);
  EXPECT_EQ(ResolveBackend(RenderSettings::Backend::kCuda), RenderSettings::Backend::kCuda);
  const SceneDescription scene = testing::EmptyScene();
  RenderSettings settings;
  settings.threads = 1;
  const std::unique_ptr<Renderer> r = MakeRenderer(scene, settings);  // auto, the default
  EXPECT_EQ(dynamic_cast<EmbreeRenderer*>(r.get()) != nullptr, !s.available);
}

TEST(CudaBackendSelection, CudaWithoutADeviceIsAConfigErrorNamingTheKey) {
  if (ProbeCudaDevice().available) GTEST_SKIP() << "a CUDA device is present";
  const SceneDescription scene = testing::EmptyScene();
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kCuda;
  try {
    MakeRenderer(scene, settings);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "render.backend");
    EXPECT_NE(std::string(e.what()).find("cuda needs a CUDA device"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(MakeRayQuery(scene, RenderSettings::Backend::kCuda), ConfigError);
}

}  // namespace
}  // namespace penumbra
