#pragma once
// the YAML backend of config/: text -> a ConfigValue tree (config/config_value.h). yaml-cpp is
// included only by yaml_document.cc; no header of Penumbra includes it.

#include <string>

#include "penumbra/config/config_value.h"

namespace penumbra {

/// the most YAML documents a reader of Penumbra's files walks: yaml-cpp 0.7 yields empty
/// documents for ever on some short inputs (",sn\xd4 !:"), so every loop over documents stops here
inline constexpr int kMaxYamlDocuments = 1024;

/// the most nodes one document may expand to (aliases are expanded into the tree): a file of
/// anchors referring to anchors ("billion laughs") is refused, not expanded.
inline constexpr size_t kMaxYamlNodes = 1'000'000;

/// what ParseYaml accepts besides one document.
struct YamlParseOptions {
  /// a second document with content (after '---') is an error ("expected ... in one
  /// document"); false reads the first and ignores the rest, as yaml-cpp's YAML::Load does.
  bool single_document = true;
  /// what the document holds, for that error ("expected the world in one document")
  std::string what = "the whole file";
};

/// parses `text` (one YAML document) into a tree. scalars keep their text; quoted scalars
/// are marked (ConfigValue::IsQuoted); every node carries the 1-based line it starts on and
/// every mapping key its own line. an empty text gives a null value.
/// YAML tags are refused (RefuseYamlTags).
/// @throws ConfigError(file, line, "", "YAML syntax error: ...") for a syntax error,
///         ("a second YAML document (after '---'); expected <options.what> in one
///         document") when
///         options.single_document, ("YAML tag '!foo' is not supported; ..."), or ("the
///         document expands to more than N values ...") when aliases blow it up.
ConfigValue ParseYaml(const std::string& text, const std::string& file = "",
                      const YamlParseOptions& options = {});

/// refuses YAML tags: every node of every document of `text` must carry no tag (a plain or a
/// quoted value, a mapping or a list as written). Penumbra's files read no tags, so a tag such
/// as `!foo 3`, `!!binary ...` or `!!str 5` would otherwise be dropped without a word.
/// works on the parser's events, so aliases are not expanded.
/// @throws ConfigError(file, line of the tagged node, "", "YAML tag '!foo' ...; expected ...");
///         ConfigError(file, line, "", "YAML syntax error: ...") for a syntax error.
void RefuseYamlTags(const std::string& text, const std::string& file);

/// `v` as one line of YAML in flow style ("{name: cam, outputs: [rgb, depth]}"), as yaml-cpp's
/// emitter writes it (scalars quoted only where YAML needs it): for a block handed on as text.
std::string EmitYamlFlow(const ConfigValue& v);

}  // namespace penumbra
