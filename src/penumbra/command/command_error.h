#pragma once
// the error of a command (docs/zmq-protocol.md, "Requests and replies"): a code, the request
// field it concerns and a message; turned into an error reply by the command layer.

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace penumbra {

/// error codes of command replies (docs/zmq-protocol.md lists when each is used).
namespace command_code {
inline constexpr const char* kMalformed = "malformed";
inline constexpr const char* kTooLarge = "too_large";
inline constexpr const char* kUnknownCommand = "unknown_command";
inline constexpr const char* kMissingField = "missing_field";
inline constexpr const char* kBadField = "bad_field";
inline constexpr const char* kUnknownField = "unknown_field";
inline constexpr const char* kVersionMismatch = "version_mismatch";
inline constexpr const char* kConflict = "conflict";
inline constexpr const char* kNotAvailable = "not_available";
inline constexpr const char* kRunEnded = "run_ended";
inline constexpr const char* kStopping = "stopping";
inline constexpr const char* kFailed = "failed";
}  // namespace command_code

/// a command that cannot be carried out; what() is the message.
class CommandError : public std::runtime_error {
 public:
  /// `code`: one of command_code; `field`: the request field ("" = none), e.g. "ctrl[3]".
  CommandError(std::string code, std::string field, const std::string& message)
      : std::runtime_error(message), code_(std::move(code)), field_(std::move(field)) {}

  const std::string& code() const { return code_; }
  const std::string& field() const { return field_; }

  /// {"code", "field" (null when none), "message"}: the reply's `error` value.
  nlohmann::json ToJson() const {
    return {{"code", code_},
            {"field", field_.empty() ? nlohmann::json(nullptr) : nlohmann::json(field_)},
            {"message", what()}};
  }

 private:
  std::string code_;
  std::string field_;
};

/// an error reply: {"ok": false, "cmd", "id" (if the request had one), "error"}. `cmd` may be
/// null (a request without a usable `cmd`).
inline nlohmann::json ErrorReply(const nlohmann::json& cmd, const nlohmann::json* id,
                                 const CommandError& e) {
  nlohmann::json r = {{"ok", false}, {"cmd", cmd}, {"error", e.ToJson()}};
  if (id) r["id"] = *id;
  return r;
}

}  // namespace penumbra
