// PB_HOST_DEVICE (core/host_device.h): empty in plain C++, so a marked function is an ordinary
// (and constexpr-capable) C++ function.

#include "penumbra/core/host_device.h"

#include <gtest/gtest.h>

#include <string_view>

namespace penumbra {
namespace {

#define PB_HOST_DEVICE_TEST_STR2(x) #x
#define PB_HOST_DEVICE_TEST_STR(x) PB_HOST_DEVICE_TEST_STR2(x)

PB_HOST_DEVICE constexpr float HostDeviceTestLerp(float a, float b, float t) {
  return a + (b - a) * t;
}

TEST(HostDevice, MacroIsEmptyInPlainCpp) {
  // the expansion of the macro, as text: nothing outside nvcc
  EXPECT_EQ(std::string_view(PB_HOST_DEVICE_TEST_STR(PB_HOST_DEVICE)), "");
}

TEST(HostDevice, MarkedFunctionIsAnOrdinaryConstexprFunction) {
  static_assert(HostDeviceTestLerp(1.0f, 3.0f, 0.5f) == 2.0f);
  volatile float t = 0.25f;
  EXPECT_EQ(HostDeviceTestLerp(0.0f, 8.0f, t), 2.0f);
}

}  // namespace
}  // namespace penumbra
