#include "penumbra/runlog/run_log_codec.h"

#include <fmt/format.h>
#include <zlib.h>
#include <zstd.h>

#include <nlohmann/json.hpp>

#include "penumbra/scene/scene_limits.h"

namespace penumbra::runlog_codec {
namespace {

uint32_t LoadU32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
uint64_t LoadU64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

bool KnownKind(uint32_t k) {
  return k >= static_cast<uint32_t>(RunLogChunkKind::kHeader) &&
         k <= static_cast<uint32_t>(RunLogChunkKind::kEnd);
}

// one vector field of a step record as 64-bit words (doubles by their bits, int64 as is)
template <typename T>
void EncodeField(const std::vector<T>& v, const std::vector<T>* prev, std::string* body) {
  static_assert(sizeof(T) == 8);
  const size_t n = v.size();
  bool zero = true;
  for (const T& x : v) zero = zero && std::bit_cast<uint64_t>(x) == 0;
  if (zero) {
    PutU8(body, kFieldZero);
    PutU32(body, static_cast<uint32_t>(n));
    return;
  }
  const bool xor_prev = prev && prev->size() == n;
  PutU8(body, xor_prev ? kFieldXor : kFieldPlain);
  PutU32(body, static_cast<uint32_t>(n));
  const size_t at = body->size();
  body->resize(at + 8 * n);
  char* out = body->data() + at;
  for (size_t i = 0; i < n; ++i) {
    uint64_t w = std::bit_cast<uint64_t>(v[i]);
    if (xor_prev) w ^= std::bit_cast<uint64_t>((*prev)[i]);
    std::memcpy(out + 8 * i, &w, 8);
  }
}

// `expected` < 0: any count up to kMaxLayoutEntries (no layout to check against)
template <typename T>
void DecodeField(BodyReader* in, const std::vector<T>* prev, std::string_view name,
                 int64_t expected, std::vector<T>* out) {
  const uint8_t enc = in->U8();
  const uint32_t n = in->U32();
  if (expected >= 0 && n != static_cast<uint64_t>(expected))
    in->Fail(
        fmt::format("field {} has {} entries; the header's layout says {}", name, n, expected));
  if (expected < 0 && n > static_cast<uint64_t>(kMaxLayoutEntries))
    in->Fail(
        fmt::format("field {} has {} entries; expected at most {}", name, n, kMaxLayoutEntries));
  if (enc == kFieldZero) {
    out->assign(n, std::bit_cast<T>(uint64_t{0}));
    return;
  }
  if (enc != kFieldXor && enc != kFieldPlain)
    in->Fail(fmt::format("field {}: unknown encoding {}", name, enc));
  if (enc == kFieldXor && (!prev || prev->size() != n))
    in->Fail(
        fmt::format("field {}: XOR encoding without a previous record of {} entries", name, n));
  const std::string_view data = in->Bytes(uint64_t{8} * n);
  out->resize(n);
  for (size_t i = 0; i < n; ++i) {
    uint64_t w;
    std::memcpy(&w, data.data() + 8 * i, 8);
    if (enc == kFieldXor) w ^= std::bit_cast<uint64_t>((*prev)[i]);
    (*out)[i] = std::bit_cast<T>(w);
  }
}

}  // namespace

std::string EncodePreamble(uint32_t version) {
  std::string b(reinterpret_cast<const char*>(kRunLogMagic.data()), kRunLogMagic.size());
  PutU32(&b, version);
  PutU32(&b, 0);
  return b;
}

std::string EncodeChunkHeader(const ChunkHeader& h) {
  std::string b(kChunkMagic, 4);
  PutU32(&b, static_cast<uint32_t>(h.kind));
  PutU64(&b, h.index);
  PutU32(&b, h.record_count);
  PutU32(&b, h.codec);
  PutI64(&b, h.first_step);
  PutI64(&b, h.last_step);
  PutU64(&b, h.raw_size);
  PutU64(&b, h.stored_size);
  PutU32(&b, 0);
  PutU32(&b, Crc32(b.data(), b.size()));
  return b;
}

std::string DecodeChunkHeader(const uint8_t* p, ChunkHeader* out) {
  if (std::memcmp(p, kChunkMagic, 4) != 0) return "no chunk header here (bad chunk magic)";
  const uint32_t stored_crc = LoadU32(p + 60);
  const uint32_t crc = Crc32(p, 60);
  if (crc != stored_crc)
    return fmt::format("chunk header CRC mismatch (stored {:08x}, computed {:08x})", stored_crc,
                       crc);
  const uint32_t kind = LoadU32(p + 4);
  if (!KnownKind(kind)) return fmt::format("unknown chunk kind {}", kind);
  out->kind = static_cast<RunLogChunkKind>(kind);
  out->index = LoadU64(p + 8);
  out->record_count = LoadU32(p + 16);
  out->codec = LoadU32(p + 20);
  if (out->codec != kCodecNone && out->codec != kCodecZstd)
    return fmt::format("unknown body codec {}", out->codec);
  out->first_step = static_cast<int64_t>(LoadU64(p + 24));
  out->last_step = static_cast<int64_t>(LoadU64(p + 32));
  out->raw_size = LoadU64(p + 40);
  out->stored_size = LoadU64(p + 48);
  // sizes against the format's caps before anything adds to them or allocates them
  const bool header = out->kind == RunLogChunkKind::kHeader;
  const uint64_t cap = header ? kMaxHeaderChunkBytes : kMaxChunkBodyBytes;
  const char* cap_name = header ? "header chunk" : "chunk body";
  if (out->stored_size > cap)
    return fmt::format(
        "stored size {} bytes is above the format's maximum {} of {} bytes "
        "(docs/run-log.md \"Limits\")",
        out->stored_size, cap_name, cap);
  if (out->raw_size > cap)
    return fmt::format(
        "uncompressed size {} bytes is above the format's maximum {} of {} bytes "
        "(docs/run-log.md \"Limits\")",
        out->raw_size, cap_name, cap);
  if (out->codec == kCodecNone && out->raw_size != out->stored_size)
    return "an uncompressed body whose raw and stored sizes differ";
  if (out->record_count > 0 && out->first_step > out->last_step)
    return fmt::format("first step {} is after last step {}", out->first_step, out->last_step);
  return "";
}

uint32_t Crc32(const void* data, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  const Bytef* p = static_cast<const Bytef*>(data);
  while (n > 0) {
    const uInt part = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = crc32(crc, p, part);
    p += part;
    n -= part;
  }
  return static_cast<uint32_t>(crc);
}

std::string ZstdCompress(std::string_view raw, int level) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  if (ZSTD_isError(n)) throw RunLogError(std::string("zstd compression: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::string ZstdDecompress(std::string_view stored, uint64_t raw_size) {
  if (raw_size > kMaxChunkBodyBytes)
    throw RunLogError(
        fmt::format("declared uncompressed size {} bytes is above the format's maximum of {} bytes",
                    raw_size, kMaxChunkBodyBytes));
  const unsigned long long content = ZSTD_getFrameContentSize(stored.data(), stored.size());
  if (content == ZSTD_CONTENTSIZE_ERROR) throw RunLogError("body is not a zstd frame");
  if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != raw_size)
    throw RunLogError(
        fmt::format("zstd frame holds {} bytes, the chunk header says {}", content, raw_size));
  std::string out(raw_size, '\0');
  const size_t n = ZSTD_decompress(out.data(), out.size(), stored.data(), stored.size());
  if (ZSTD_isError(n))
    throw RunLogError(std::string("zstd decompression: ") + ZSTD_getErrorName(n));
  if (n != raw_size)
    throw RunLogError(
        fmt::format("body decompresses to {} bytes, the chunk header says {}", n, raw_size));
  return out;
}

std::string_view BodyReader::Bytes(uint64_t n) {
  if (n > data_.size() - pos_)
    Fail(fmt::format("record runs past the end of the body ({} bytes wanted, {} left)", n,
                     data_.size() - pos_));
  std::string_view s = data_.substr(pos_, n);
  pos_ += n;
  return s;
}

void BodyReader::Fail(const std::string& problem) const {
  throw RunLogError(fmt::format("{}: {} at byte {} of the body", what_, problem, pos_));
}

void EncodeStep(const StepRecord& r, const StepRecord* prev, std::string* body) {
  PutI64(body, r.step);
  PutF64(body, r.time_sec);
  // fields in table order (the file order); each against the same field of the previous record
  if (prev) {
    ForEachStateField(
        [&](const StateFieldInfo&, const auto& v, const auto& pv) { EncodeField(v, &pv, body); }, r,
        *prev);
  } else {
    ForEachStateField(
        [&](const StateFieldInfo&, const auto& v) {
          EncodeField(v, static_cast<const std::decay_t<decltype(v)>*>(nullptr), body);
        },
        r);
  }
}

void DecodeStep(BodyReader* in, const StepRecord* prev, StepRecord* out, const RunLogLayout* layout,
                uint32_t format_version) {
  out->step = in->I64();
  out->time_sec = in->F64();
  // entries each field must have (-1: no layout given)
  const StateDims dims = layout ? layout->dims() : StateDims{};
  const auto want = [&](const StateFieldInfo& f) -> int64_t {
    return layout ? StateFieldSize(f, dims) : -1;
  };
  // the fields of the log's version are in the record; later ones are not
  const int fields = RunLogStateShapeOf(format_version).fields;
  const auto recorded = [fields](const StateFieldInfo& f) {
    return static_cast<int>(f.field) < fields;
  };
  if (prev) {
    ForEachStateField(
        [&](const StateFieldInfo& f, auto& v, const auto& pv) {
          if (recorded(f))
            DecodeField(in, &pv, f.name, want(f), &v);
          else
            v.clear();
        },
        *out, *prev);
  } else {
    ForEachStateField(
        [&](const StateFieldInfo& f, auto& v) {
          if (recorded(f))
            DecodeField(in, static_cast<const std::decay_t<decltype(v)>*>(nullptr), f.name, want(f),
                        &v);
          else
            v.clear();
        },
        *out);
  }
}

uint64_t StepRecordMemoryBytes(const RunLogLayout& l) {
  const StateDims dims = l.dims();
  uint64_t entries = 0;
  for (const StateFieldInfo& f : kStateFields) entries += uint64_t(StateFieldSize(f, dims));
  return sizeof(StepRecord) + 8 * entries;
}

std::string CheckLayout(const RunLogLayout& l) {
  const StateDims dims = l.dims();
  for (int i = 0; i < kNumStateDims; ++i)
    if (dims.n[i] < 0 || dims.n[i] > kMaxLayoutEntries)
      return fmt::format("layout.{} is {}; expected 0 to {}", kStateDimNames[i], dims.n[i],
                         kMaxLayoutEntries);
  for (size_t i = 0; i < l.joints.size(); ++i) {
    const RunLogJoint& j = l.joints[i];
    if (j.qpos_adr < 0 || j.qpos_width < 0 || int64_t{j.qpos_adr} + j.qpos_width > l.nq)
      return fmt::format(
          "layout.joints[{}] ('{}'): qpos_adr {} and qpos_width {} are not inside nq {}", i,
          j.name.substr(0, 64), j.qpos_adr, j.qpos_width, l.nq);
    if (j.qvel_adr < 0 || j.qvel_width < 0 || int64_t{j.qvel_adr} + j.qvel_width > l.nv)
      return fmt::format(
          "layout.joints[{}] ('{}'): qvel_adr {} and qvel_width {} are not inside nv {}", i,
          j.name.substr(0, 64), j.qvel_adr, j.qvel_width, l.nv);
  }
  return "";
}

std::string CheckHeader(const RunLogHeader& h) {
  // also false for NaN
  if (!(h.timestep_sec >= kMinTimestepSec && h.timestep_sec <= kMaxTimestepSec))
    return fmt::format("timestep_sec is {} s; expected a physics timestep in [{}, {}] s",
                       h.timestep_sec, kMinTimestepSec, kMaxTimestepSec);
  return CheckLayout(h.layout);
}

void EncodeEvent(const EventRecord& e, std::string* body) {
  PutI64(body, e.step);
  PutF64(body, e.time_sec);
  PutString(body, e.kind);
  PutBlob(body, e.payload);
}

void EncodeSensor(const SensorRecord& s, std::string* body) {
  PutI64(body, s.step);
  PutF64(body, s.time_sec);
  PutString(body, s.sensor);
  PutString(body, s.kind);
  PutBlob(body, s.payload);
}

EventRecord DecodeEvent(BodyReader* in) {
  EventRecord e;
  e.step = in->I64();
  e.time_sec = in->F64();
  e.kind = in->String();
  e.payload = in->Blob();
  return e;
}

SensorRecord DecodeSensor(BodyReader* in) {
  SensorRecord s;
  s.step = in->I64();
  s.time_sec = in->F64();
  s.sensor = in->String();
  s.kind = in->String();
  s.payload = in->Blob();
  return s;
}

std::string HeaderToJson(const RunLogHeader& h) {
  using nlohmann::json;
  json assets = json::array();
  for (const RunLogAsset& a : h.assets)
    assets.push_back(
        {{"role", a.role}, {"path", a.path}, {"sha256", a.sha256}, {"size_bytes", a.size_bytes}});
  json joints = json::array();
  for (const RunLogJoint& j : h.layout.joints)
    joints.push_back({{"name", j.name},
                      {"type", j.type},
                      {"qpos_adr", j.qpos_adr},
                      {"qpos_width", j.qpos_width},
                      {"qvel_adr", j.qvel_adr},
                      {"qvel_width", j.qvel_width}});
  const RunLogLayout& l = h.layout;
  json layout = {{"joints", joints},
                 {"actuator_names", l.actuator_names},
                 {"mocap_body_names", l.mocap_body_names},
                 {"body_names", l.body_names},
                 {"controller_names", l.controller_names}};
  const StateDims dims = l.dims();
  for (int i = 0; i < RunLogStateShapeOf(h.format_version).dims; ++i)
    layout[std::string(kStateDimNames[i])] = dims.n[i];
  json j = {{"format_version", h.format_version},
            {"penumbra_version", h.penumbra_version},
            {"mujoco_version", h.mujoco_version},
            {"world_file", h.world_file},
            {"world_text", h.world_text},
            {"model_file", h.model_file},
            {"model_text", h.model_text},
            {"composed_mjcf", h.composed_mjcf},
            {"assets", assets},
            {"seed", h.seed},
            {"command_line", h.command_line},
            {"timestep_sec", h.timestep_sec},
            {"layout", layout},
            {"has_sensor_records", h.has_sensor_records},
            {"adversity", h.adversity}};
  // invalid UTF-8 in a text (a world file in Latin-1) is replaced, not refused
  return j.dump(1, ' ', false, json::error_handler_t::replace);
}

RunLogHeader HeaderFromJson(std::string_view text) {
  using nlohmann::json;
  if (text.size() > kMaxHeaderChunkBytes)
    throw RunLogError(fmt::format("header chunk: {} bytes of JSON; expected at most {}",
                                  text.size(), kMaxHeaderChunkBytes));
  // values and nesting counted while parsing, so that a small text cannot build a huge or
  // deeply nested document
  uint64_t values = 0;
  const json::parser_callback_t limit = [&values](int depth, json::parse_event_t event, json&) {
    if (depth > kMaxHeaderJsonDepth)
      throw RunLogError(
          fmt::format("header chunk: JSON nested deeper than {} levels", kMaxHeaderJsonDepth));
    if ((event == json::parse_event_t::value || event == json::parse_event_t::object_start ||
         event == json::parse_event_t::array_start) &&
        ++values > kMaxHeaderJsonValues)
      throw RunLogError(
          fmt::format("header chunk: more than {} JSON values", kMaxHeaderJsonValues));
    return true;
  };
  json j;
  try {
    j = json::parse(text, limit);
  } catch (const json::exception& e) {
    throw RunLogError(std::string("header chunk is not valid JSON: ") + e.what());
  }
  auto get = [](const json& obj, const char* key, auto* out, const char* where) {
    if (!obj.is_object() || !obj.contains(key))
      throw RunLogError(fmt::format("header chunk: {}'{}' is missing", where, key));
    try {
      obj.at(key).get_to(*out);
    } catch (const json::exception&) {
      throw RunLogError(fmt::format("header chunk: {}'{}' has the wrong type ({})", where, key,
                                    obj.at(key).type_name()));
    }
  };
  RunLogHeader h;
  get(j, "format_version", &h.format_version, "");
  get(j, "penumbra_version", &h.penumbra_version, "");
  get(j, "mujoco_version", &h.mujoco_version, "");
  get(j, "world_file", &h.world_file, "");
  get(j, "world_text", &h.world_text, "");
  get(j, "model_file", &h.model_file, "");
  get(j, "model_text", &h.model_text, "");
  get(j, "composed_mjcf", &h.composed_mjcf, "");
  get(j, "seed", &h.seed, "");
  get(j, "command_line", &h.command_line, "");
  get(j, "timestep_sec", &h.timestep_sec, "");
  get(j, "has_sensor_records", &h.has_sensor_records, "");
  get(j, "adversity", &h.adversity, "");
  json assets, layout;
  get(j, "assets", &assets, "");
  get(j, "layout", &layout, "");
  if (!assets.is_array()) throw RunLogError("header chunk: 'assets' is not an array");
  for (const json& a : assets) {
    RunLogAsset x;
    get(a, "role", &x.role, "assets[]: ");
    get(a, "path", &x.path, "assets[]: ");
    get(a, "sha256", &x.sha256, "assets[]: ");
    get(a, "size_bytes", &x.size_bytes, "assets[]: ");
    h.assets.push_back(std::move(x));
  }
  RunLogLayout& l = h.layout;
  const char* w = "layout: ";
  // the dimensions of the log's format version (a format 1 layout has no nhistory, neq,
  // npluginstate or nplastic: they count 0)
  StateDims dims;
  for (int i = 0; i < RunLogStateShapeOf(h.format_version).dims; ++i) {
    int n = 0;
    get(layout, std::string(kStateDimNames[i]).c_str(), &n, w);
    dims.n[i] = n;
  }
  l.set_dims(dims);
  get(layout, "actuator_names", &l.actuator_names, w);
  get(layout, "mocap_body_names", &l.mocap_body_names, w);
  get(layout, "body_names", &l.body_names, w);
  get(layout, "controller_names", &l.controller_names, w);
  json joints;
  get(layout, "joints", &joints, w);
  if (!joints.is_array()) throw RunLogError("header chunk: 'layout.joints' is not an array");
  for (const json& jj : joints) {
    RunLogJoint x;
    const char* wj = "layout.joints[]: ";
    get(jj, "name", &x.name, wj);
    get(jj, "type", &x.type, wj);
    get(jj, "qpos_adr", &x.qpos_adr, wj);
    get(jj, "qpos_width", &x.qpos_width, wj);
    get(jj, "qvel_adr", &x.qvel_adr, wj);
    get(jj, "qvel_width", &x.qvel_width, wj);
    l.joints.push_back(std::move(x));
  }
  if (const std::string bad = CheckHeader(h); !bad.empty())
    throw RunLogError("header chunk: " + bad);
  return h;
}

}  // namespace penumbra::runlog_codec
