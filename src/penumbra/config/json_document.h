#pragma once
// the JSON backend of config/: text -> a ConfigValue tree (config/config_value.h), read with
// the same ParamReader as YAML files. nlohmann/json.hpp is included only by json_document.cc.
//
// JSON nodes carry the line they start on (from a SAX pass over the text); numbers keep their
// text as written by nlohmann's dump (shortest round-trip form), booleans read "true"/"false",
// strings are quoted scalars (ConfigValue::IsQuoted: never read as numbers), null is null.
// mapping entries keep file order; a key given twice is kept twice, so ParamReader reports it.

#include <string>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// the deepest nesting of lists and objects a JSON document may have.
inline constexpr int kMaxJsonDepth = 256;

/// parses `text` (one JSON value) into a tree.
/// @throws ConfigError(file, line, "", "JSON syntax error: ...") for a syntax error, naming the
///         1-based line of the byte where parsing stopped; ("nested deeper than 256 lists and
///         objects; ...") for a deeper document.
ConfigValue ParseJson(const std::string& text, const std::string& file);

}  // namespace penumbra
