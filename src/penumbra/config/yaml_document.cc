#include "penumbra/config/yaml_document.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <sstream>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

int YamlMarkLine(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

// the 1-based number of the last line of `text` (a final line without '\n' counts; an empty
// text has line 1)
int LastLine(const std::string& text) {
  int lines = 1;
  for (size_t i = 0; i + 1 < text.size(); ++i)
    if (text[i] == '\n') ++lines;
  return lines;
}

// a mark's line within the document: yaml-cpp marks the end of the input (an unclosed '[' or
// quote, a null value before trailing blank or comment lines) one line after the last line
// ends, so such errors cited line 129 of a 127-line file; they name the last line instead
int YamlLineIn(const YAML::Mark& mark, int last_line) {
  const int line = YamlMarkLine(mark);
  return line > last_line ? last_line : line;
}

// the parser's events of a document, refusing the first node with a tag of its own. yaml-cpp
// gives untagged nodes the non-specific tags "?" (plain scalars, mappings, lists) and "!"
// (quoted scalars); anything else was written in the file.
class YamlTagRefuser : public YAML::EventHandler {
 public:
  YamlTagRefuser(const std::string& file, int last_line) : file_(file), last_line_(last_line) {}
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                const std::string&) override {
    Check(mark, tag);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Check(mark, tag);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Check(mark, tag);
  }
  void OnMapEnd() override {}

 private:
  void Check(const YAML::Mark& mark, const std::string& tag) const {
    if (tag.empty() || tag == "?" || tag == "!") return;
    // yaml-cpp expands the standard "!!" handle
    const std::string kStandard = "tag:yaml.org,2002:";
    const std::string shown =
        tag.rfind(kStandard, 0) == 0 ? "!!" + tag.substr(kStandard.size()) : tag;
    throw ConfigError(file_, YamlLineIn(mark, last_line_), "",
                      "YAML tag '" + shown +
                          "' is not supported; expected a plain value, list or mapping without a "
                          "tag (Penumbra reads no YAML tags: remove it)");
  }
  const std::string& file_;
  int last_line_ = 1;
};

// counts the documents of a YAML stream without building nodes; a document that holds only a
// null (a trailing '---') does not count
class YamlDocumentCounter : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override { content_ = false; }
  void OnDocumentEnd() override {
    if (content_) marks.push_back(mark_);
  }
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Content(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Content(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnMapEnd() override {}

  /// where the root node of each document with content starts
  std::vector<YAML::Mark> marks;

 private:
  void Content(const YAML::Mark& mark) {
    if (!content_) mark_ = mark;
    content_ = true;
  }
  YAML::Mark mark_;
  bool content_ = false;
};

// yaml-cpp's node tree -> ConfigNode tree, counting nodes against kMaxYamlNodes
class YamlTreeBuilder {
 public:
  YamlTreeBuilder(const std::string& file, int last_line) : file_(file), last_line_(last_line) {}

  std::shared_ptr<const ConfigNode> Build(const YAML::Node& n) {
    if (++count_ > kMaxYamlNodes) {
      throw ConfigError(file_, YamlLineIn(n.Mark(), last_line_), "",
                        "the document expands to more than " + std::to_string(kMaxYamlNodes) +
                            " values (aliases of aliases?); expected a smaller document");
    }
    auto out = std::make_shared<ConfigNode>();
    out->line = YamlLineIn(n.Mark(), last_line_);
    switch (n.Type()) {
      case YAML::NodeType::Undefined:
      case YAML::NodeType::Null:
        // a null's mark is that of the next token (the next key, or the end of the input):
        // no line of its own; readers use its key's or its list's line
        out->line = 0;
        out->kind = ConfigKind::kNull;
        break;
      case YAML::NodeType::Scalar:
        out->kind = ConfigKind::kScalar;
        out->scalar = n.Scalar();
        out->quoted = n.Tag() == "!";
        break;
      case YAML::NodeType::Sequence:
        out->kind = ConfigKind::kList;
        out->flow = n.Style() == YAML::EmitterStyle::Flow;
        out->items.reserve(n.size());
        for (const YAML::Node& e : n) out->items.push_back(Build(e));
        break;
      case YAML::NodeType::Map:
        out->kind = ConfigKind::kMap;
        out->flow = n.Style() == YAML::EmitterStyle::Flow;
        for (auto it = n.begin(); it != n.end(); ++it) {
          ConfigEntry e;
          e.key_is_scalar = it->first.IsScalar();
          if (e.key_is_scalar) e.key = it->first.Scalar();
          e.key_line = YamlLineIn(it->first.Mark(), last_line_);
          e.value = Build(it->second);
          out->entries.push_back(std::move(e));
        }
        break;
    }
    return out;
  }

 private:
  const std::string& file_;
  int last_line_ = 1;
  size_t count_ = 0;
};

// a ConfigValue as a yaml-cpp node, for the emitter
YAML::Node ToYamlNode(const ConfigValue& v) {
  switch (v.kind()) {
    case ConfigKind::kUndefined:
    case ConfigKind::kNull:
      return YAML::Node(YAML::NodeType::Null);
    case ConfigKind::kScalar:
      return YAML::Node(v.Scalar());
    case ConfigKind::kList: {
      YAML::Node n(YAML::NodeType::Sequence);
      for (size_t i = 0; i < v.size(); ++i) n.push_back(ToYamlNode(v[i]));
      return n;
    }
    case ConfigKind::kMap: {
      YAML::Node n(YAML::NodeType::Map);
      for (const ConfigEntry& e : v.entries())
        n.force_insert(YAML::Node(e.key), ToYamlNode(ConfigValue(e.value)));
      return n;
    }
  }
  return YAML::Node();
}

}  // namespace

std::string EmitYamlFlow(const ConfigValue& v) {
  YAML::Emitter out;
  out << YAML::Flow << ToYamlNode(v);
  return out.c_str();
}

void RefuseYamlTags(const std::string& text, const std::string& file) {
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    YamlTagRefuser refuser(file, LastLine(text));
    // at most kMaxYamlDocuments documents: yaml-cpp 0.7 yields empty documents for ever on some
    // short inputs (",sn\xd4 !:", found by fuzz/world_fuzz.cc)
    for (int d = 0; d < kMaxYamlDocuments; ++d)
      if (!parser.HandleNextDocument(refuser)) break;
  } catch (const YAML::ParserException& e) {
    throw ConfigError(file, YamlLineIn(e.mark, LastLine(text)), "", "YAML syntax error: " + e.msg);
  }
}

ConfigValue ParseYaml(const std::string& text, const std::string& file,
                      const YamlParseOptions& options) {
  try {
    // documents are counted with a bounded loop, not YAML::LoadAll: yaml-cpp 0.7's LoadAll
    // never ends on some 7-byte inputs (",sn\xd4 !:" yields empty documents for ever, found by
    // fuzz/world_fuzz.cc), taking all memory
    if (options.single_document) {
      std::istringstream in(text);
      YAML::Parser parser(in);
      YamlDocumentCounter counter;
      for (int d = 0; d < kMaxYamlDocuments && counter.marks.size() < 2; ++d)
        if (!parser.HandleNextDocument(counter)) break;
      if (counter.marks.size() >= 2)
        throw ConfigError(
            file, YamlLineIn(counter.marks[1], LastLine(text)), "",
            "a second YAML document (after '---'); expected " + options.what + " in one document");
    }
    RefuseYamlTags(text, file);
    const YAML::Node root = YAML::Load(text);
    return ConfigValue(YamlTreeBuilder(file, LastLine(text)).Build(root));
  } catch (const YAML::ParserException& e) {
    throw ConfigError(file, YamlLineIn(e.mark, LastLine(text)), "", "YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    // any other yaml-cpp failure still names the file (and line when yaml-cpp knows it)
    throw ConfigError(file, YamlLineIn(e.mark, LastLine(text)), "",
                      "cannot read the YAML document: " + e.msg);
  }
}

}  // namespace penumbra
