#pragma once
// msgpack <-> JSON values for the ZeroMQ bridge (docs/zmq-protocol.md, "Encoding"): requests
// arrive as msgpack (https://github.com/msgpack/msgpack/blob/master/spec.md), the command layer
// works on nlohmann::json objects, replies and headers go back as msgpack. decoding uses
// msgpack-cxx with limits, so hostile input (deep nesting, huge declared sizes, trailing
// bytes) is an error, never a crash.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace penumbra {

/// limits of DecodeMsgpack.
struct MsgpackLimits {
  size_t max_depth = 32;          ///< nesting of arrays and maps
  size_t max_elements = 1 << 20;  ///< entries of one array or map
  size_t max_bytes = 64u << 20;   ///< one string or bin
};

/// the value in `size` bytes at `data`: nil, bool, integers, floats, str (as UTF-8 text, not
/// checked), bin (json binary), arrays and maps with string keys.
/// @throws std::runtime_error naming the problem: not msgpack / truncated, bytes after the
///         value, a limit exceeded, a map key that is not a string, an ext value.
nlohmann::json DecodeMsgpack(const void* data, size_t size, const MsgpackLimits& limits = {});

/// `value` as msgpack: integers as the smallest msgpack int, floats as float64, binary as bin,
/// objects as maps in key order.
std::string EncodeMsgpack(const nlohmann::json& value);

}  // namespace penumbra
