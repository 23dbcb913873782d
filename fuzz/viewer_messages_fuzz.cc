// libFuzzer target: the viewer's messages (viewer/viewer_messages.h): a binary frame message
// taken apart by UnpackFrameMessage (u32 header length, JSON header, payload) and packed again,
// and a page's text message parsed as the viewer's server parses it (a JSON object with a
// string "cmd"). documented failures: penumbra::Error from UnpackFrameMessage,
// json::exception for text that is not JSON (as the server catches it); any other exception, a
// crash, a sanitizer report,
// or a frame that does not pack back to the same header and payload is a finding.
// docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/viewer/viewer_messages.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using nlohmann::json;
  const std::string message(reinterpret_cast<const char*>(data), size);
  try {
    const auto [header, payload] = penumbra::UnpackFrameMessage(message);
    const auto [header2, payload2] =
        penumbra::UnpackFrameMessage(penumbra::PackFrameMessage(header, payload));
    if (header2 != header || payload2 != payload) __builtin_trap();
  } catch (const penumbra::Error&) {
  }
  try {
    const json request = json::parse(message);
    if (request.is_object()) {
      const json cmd = request.value("cmd", json());
      if (cmd.is_string()) cmd.get<std::string>();
      request.dump();
    }
  } catch (const json::exception&) {
  }
  return 0;
}
