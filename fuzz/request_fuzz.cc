// libFuzzer target: a ZeroMQ request (zmq/msgpack_json.h DecodeMsgpack, as the bridge decodes a
// request frame) or a viewer / JSON request text (nlohmann::json::parse), then every field read
// through command/request_reader.h as the command layer reads fields. the first byte picks the
// encoding (even: msgpack, odd: JSON). documented failures: std::runtime_error from
// DecodeMsgpack, json::exception from the JSON parser (parse_error, out_of_range 406 for a
// number beyond a double; the servers catch json::exception), CommandError from RequestReader; a
// value that DecodeMsgpack accepts must also survive EncodeMsgpack and decode to itself. any
// other exception, a crash or a sanitizer report is a finding. docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "penumbra/command/command_error.h"
#include "penumbra/command/request_reader.h"
#include "penumbra/zmq/msgpack_json.h"

namespace {

using nlohmann::json;

// every getter on every field, as the command handlers call them
void ReadFields(const json& request) {
  using penumbra::CommandError;
  using penumbra::RequestReader;
  if (!request.is_object()) return;
  RequestReader rd(request);
  for (const auto& [key, value] : request.items()) {
    try {
      rd.Has(key);
      rd.Int(key, -1000, 1000, 0);
    } catch (const CommandError&) {
    }
    try {
      rd.Real(key, -1e9, 1e9, 0.0);
    } catch (const CommandError&) {
    }
    try {
      rd.Bool(key, false);
    } catch (const CommandError&) {
    }
    try {
      rd.String(key, "");
    } catch (const CommandError&) {
    }
    try {
      rd.Reals(key, -1, 0);
    } catch (const CommandError&) {
    }
    try {
      rd.Reals(key, 3);
    } catch (const CommandError&) {
    }
    try {
      rd.Raw(key);
      rd.Present(key);
    } catch (const CommandError&) {
    }
    penumbra::JsonTypeName(value);
  }
  try {
    rd.Int("missing_field", 0, 1);
  } catch (const CommandError& e) {
    e.ToJson();
  }
  try {
    rd.CheckNoUnknown();
  } catch (const CommandError& e) {
    e.ToJson();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const bool msgpack = (data[0] & 1) == 0;
  ++data;
  --size;
  json request;
  if (msgpack) {
    try {
      request = penumbra::DecodeMsgpack(data, size);
    } catch (const std::runtime_error&) {
      return 0;
    }
    // what the bridge sends back decodes to the same value: compared as bytes encoded again
    // (a NaN, which msgpack carries, is unequal to itself as a json value)
    const std::string back = penumbra::EncodeMsgpack(request);
    if (penumbra::EncodeMsgpack(penumbra::DecodeMsgpack(back.data(), back.size())) != back)
      __builtin_trap();
  } else {
    try {
      request = json::parse(reinterpret_cast<const char*>(data),
                            reinterpret_cast<const char*>(data) + size);
    } catch (const json::exception&) {
      // parse_error, or out_of_range 406 for a number beyond a double ("1e99999")
      return 0;
    }
  }
  ReadFields(request);
  return 0;
}
