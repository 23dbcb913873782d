#include "penumbra/config/json_document.h"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

// 1-based line of byte `pos` of `text`
int JsonLineOf(const std::string& text, size_t pos) {
  pos = std::min(pos, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
}

// builds the tree from nlohmann's SAX events. nlohmann gives no position with an event, so the
// line of each value is found by scanning the text alongside: every event's token is the next
// non-blank, non-separator text after the previous one.
class JsonTreeBuilder : public nlohmann::json_sax<nlohmann::json> {
 public:
  JsonTreeBuilder(const std::string& text, const std::string& file) : text_(text), file_(file) {}

  bool null() override { return Value(Make(ConfigKind::kNull, "")); }
  bool boolean(bool v) override { return Value(Make(ConfigKind::kScalar, v ? "true" : "false")); }
  bool number_integer(number_integer_t v) override {
    return Value(Make(ConfigKind::kScalar, std::to_string(v)));
  }
  bool number_unsigned(number_unsigned_t v) override {
    return Value(Make(ConfigKind::kScalar, std::to_string(v)));
  }
  bool number_float(number_float_t, const string_t& text) override {
    return Value(Make(ConfigKind::kScalar, text));
  }
  bool string(string_t& v) override {
    auto n = Make(ConfigKind::kScalar, v);
    n->quoted = true;
    return Value(std::move(n));
  }
  bool binary(binary_t&) override { return false; }
  bool start_object(std::size_t) override { return Open(ConfigKind::kMap); }
  bool key(string_t& k) override {
    const int line = SkipToken();
    ConfigEntry e;
    e.key = k;
    e.key_line = line;
    stack_.back()->entries.push_back(std::move(e));
    return true;
  }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override { return Open(ConfigKind::kList); }
  bool end_array() override { return Close(); }
  bool parse_error(std::size_t position, const std::string&,
                   const nlohmann::detail::exception& ex) override {
    std::string what = ex.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 5: ..." -> from "parse"
    const size_t at = what.find("] ");
    if (at != std::string::npos) what = what.substr(at + 2);
    throw ConfigError(file_, JsonLineOf(text_, position > 0 ? position - 1 : 0), "",
                      "JSON syntax error: " + what);
  }

  ConfigValue root() const { return ConfigValue(root_); }

 private:
  std::shared_ptr<ConfigNode> Make(ConfigKind kind, std::string scalar) {
    auto n = std::make_shared<ConfigNode>();
    n->kind = kind;
    n->scalar = std::move(scalar);
    n->line = SkipToken();
    return n;
  }

  // the line of the next token, moving past it (strings, numbers and literals as a whole)
  int SkipToken() {
    while (pos_ < text_.size() && (std::isspace(static_cast<unsigned char>(text_[pos_])) ||
                                   text_[pos_] == ',' || text_[pos_] == ':'))
      ++pos_;
    const int line = JsonLineOf(text_, pos_);
    if (pos_ >= text_.size()) return line;
    const char c = text_[pos_];
    if (c == '"') {
      for (++pos_; pos_ < text_.size() && text_[pos_] != '"'; ++pos_)
        if (text_[pos_] == '\\') ++pos_;
      ++pos_;
    } else if (c == '{' || c == '[' || c == '}' || c == ']') {
      ++pos_;
    } else {
      while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_])) &&
             text_[pos_] != ',' && text_[pos_] != ']' && text_[pos_] != '}')
        ++pos_;
    }
    return line;
  }

  bool Open(ConfigKind kind) {
    if (static_cast<int>(stack_.size()) >= kMaxJsonDepth) {
      throw ConfigError(file_, JsonLineOf(text_, pos_), "",
                        "nested deeper than " + std::to_string(kMaxJsonDepth) +
                            " lists and objects; expected a shallower document");
    }
    auto n = Make(kind, "");
    n->flow = true;
    Value(n);
    stack_.push_back(n);
    return true;
  }

  bool Close() {
    SkipToken();  // the closing bracket
    stack_.pop_back();
    return true;
  }

  bool Value(std::shared_ptr<ConfigNode> n) {
    if (stack_.empty()) {
      root_ = std::move(n);
    } else if (stack_.back()->kind == ConfigKind::kList) {
      stack_.back()->items.push_back(std::move(n));
    } else {
      stack_.back()->entries.back().value = std::move(n);
    }
    return true;
  }

  const std::string& text_;
  const std::string& file_;
  size_t pos_ = 0;
  std::vector<std::shared_ptr<ConfigNode>> stack_;
  std::shared_ptr<ConfigNode> root_;
};

}  // namespace

ConfigValue ParseJson(const std::string& text, const std::string& file) {
  JsonTreeBuilder builder(text, file);
  nlohmann::json::sax_parse(text, &builder);
  return builder.root();
}

}  // namespace penumbra
