// found by fuzz/viewer_messages_fuzz.cc: a frame message whose header is not JSON
// throws the documented penumbra::Error, not nlohmann's parse_error.

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/viewer/viewer_messages.h"

namespace penumbra {
namespace {

TEST(FrameMessageFuzzFinding, AHeaderThatIsNotJsonThrowsError) {
  const std::string m("\x03\x00\x00\x00{x}payload", 14);
  try {
    UnpackFrameMessage(m);
    FAIL() << "a header '{x}' was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame message: the header is not JSON"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra
