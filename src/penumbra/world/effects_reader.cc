#include "penumbra/world/effects_reader.h"

#include <filesystem>
#include <memory>

#include "penumbra/core/error.h"

namespace fs = std::filesystem;

namespace penumbra {

namespace {

const std::vector<std::string_view> kCommonKeys = {
    "name", "type", "start_sec", "stop_sec", "fade_in_sec", "fade_out_sec", "region"};

// the effect types' view of an entry (effects/effect_type.h): typed reads that also
// remember each key's line for the validation errors.
class EntryReader : public EffectParamReader {
 public:
  EntryReader(const ParamReader& r, LineTable* lines, const fs::path* base_dir)
      : r_(r), lines_(lines), base_dir_(base_dir) {}

  bool Has(std::string_view k) const override { return r_.Has(k); }
  double Double(std::string_view k) const override { return Child(k).Double(); }
  int Integer(std::string_view k) const override { return Child(k).Int(); }
  Eigen::Vector3d Vector3(std::string_view k) const override { return Child(k).Vector3(); }
  std::string String(std::string_view k) const override { return Child(k).String(); }
  bool Boolean(std::string_view k) const override { return Child(k).Bool(); }
  std::string Enum(std::string_view k, const std::vector<std::string_view>& valid) const override {
    return Child(k).Enum(valid);
  }
  std::vector<std::unique_ptr<EffectParamReader>> List(std::string_view k) const override {
    std::vector<std::unique_ptr<EffectParamReader>> out;
    for (const ParamReader& er : Child(k).List()) {
      lines_->Record(er.path(), er.line());
      out.push_back(std::make_unique<EntryReader>(er, lines_, base_dir_));
    }
    return out;
  }
  void ExpectKeys(const std::vector<std::string_view>& keys) const override { r_.ExpectMap(keys); }
  std::string ResolvePath(const std::string& path) const override {
    fs::path p(path);
    if (p.is_relative()) p = *base_dir_ / p;
    return p.lexically_normal().string();
  }

  ParamReader Child(std::string_view k) const {
    ParamReader c = r_.Child(k);
    lines_->Record(c.path(), c.line());
    return c;
  }

 private:
  ParamReader r_;
  LineTable* lines_;
  const fs::path* base_dir_;
};

EffectConfig ReadEffect(const ParamReader& r, const fs::path& base_dir, LineTable* lines) {
  r.ExpectMapAnyKeys();
  lines->Record(r.path(), r.line());
  EntryReader e(r, lines, &base_dir);
  EffectConfig c;
  c.name = e.Child("name").String();
  std::vector<std::string_view> type_names;
  for (const std::string& n : EffectTypeNames()) type_names.push_back(n);
  const EffectTypeInfo& type = *FindEffectType(e.Child("type").Enum(type_names));
  std::vector<std::string_view> keys = kCommonKeys;
  keys.insert(keys.end(), type.keys.begin(), type.keys.end());
  r.ExpectMap(keys);

  e.Num("start_sec", &c.start_sec);
  e.Num("stop_sec", &c.stop_sec);
  e.Num("fade_in_sec", &c.fade_in_sec);
  e.Num("fade_out_sec", &c.fade_out_sec);
  if (e.Has("region")) {
    const ParamReader rr = e.Child("region");
    rr.ExpectMap({"min", "max"});
    EntryReader re(rr, lines, &base_dir);
    BoxRegion b;
    b.min_W = re.Child("min").Vector3();
    b.max_W = re.Child("max").Vector3();
    c.region = b;
  }
  // the type's own keys
  type.read(e, &c);
  return c;
}

}  // namespace

std::vector<EffectConfig> ReadEffects(const ParamReader& list, const std::string& file) {
  std::error_code ec;
  const fs::path abs =
      file.empty() ? fs::current_path(ec) / "world.yaml" : fs::absolute(fs::path(file), ec);
  const fs::path base_dir = abs.parent_path();
  LineTable lines;
  lines.Record(list.path(), list.line());
  std::vector<EffectConfig> out;
  for (const ParamReader& r : list.List()) out.push_back(ReadEffect(r, base_dir, &lines));
  // ranges and cross-effect rules, with the line of the offending key
  ValidateEffectsOrThrow(out, file, [&](const std::string& key) { return lines.Find(key); });
  return out;
}

}  // namespace penumbra
