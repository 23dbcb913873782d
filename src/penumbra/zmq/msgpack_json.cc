#include "penumbra/zmq/msgpack_json.h"

#include <msgpack.hpp>
#include <stdexcept>

namespace penumbra {
namespace {

nlohmann::json ToJson(const msgpack::object& o) {
  using json = nlohmann::json;
  switch (o.type) {
    case msgpack::type::NIL:
      return nullptr;
    case msgpack::type::BOOLEAN:
      return o.via.boolean;
    case msgpack::type::POSITIVE_INTEGER:
      return o.via.u64;
    case msgpack::type::NEGATIVE_INTEGER:
      return o.via.i64;
    case msgpack::type::FLOAT32:
    case msgpack::type::FLOAT64:
      return o.via.f64;
    case msgpack::type::STR:
      return std::string(o.via.str.ptr, o.via.str.size);
    case msgpack::type::BIN:
      return json::binary(
          std::vector<uint8_t>(reinterpret_cast<const uint8_t*>(o.via.bin.ptr),
                               reinterpret_cast<const uint8_t*>(o.via.bin.ptr) + o.via.bin.size));
    case msgpack::type::ARRAY: {
      json a = json::array();
      for (uint32_t i = 0; i < o.via.array.size; ++i) a.push_back(ToJson(o.via.array.ptr[i]));
      return a;
    }
    case msgpack::type::MAP: {
      json m = json::object();
      for (uint32_t i = 0; i < o.via.map.size; ++i) {
        const msgpack::object_kv& kv = o.via.map.ptr[i];
        if (kv.key.type != msgpack::type::STR)
          throw std::runtime_error("a map key is not a string; expected string keys");
        m[std::string(kv.key.via.str.ptr, kv.key.via.str.size)] = ToJson(kv.val);
      }
      return m;
    }
    default:
      throw std::runtime_error("an ext value; expected nil, bool, numbers, str, bin, arrays, maps");
  }
}

void Pack(msgpack::packer<msgpack::sbuffer>& pk, const nlohmann::json& v) {
  using t = nlohmann::json::value_t;
  switch (v.type()) {
    case t::null:
    case t::discarded:
      pk.pack_nil();
      break;
    case t::boolean:
      v.get<bool>() ? pk.pack_true() : pk.pack_false();
      break;
    case t::number_integer:
      pk.pack(v.get<int64_t>());
      break;
    case t::number_unsigned:
      pk.pack(v.get<uint64_t>());
      break;
    case t::number_float:
      pk.pack_double(v.get<double>());
      break;
    case t::string: {
      const std::string& s = v.get_ref<const std::string&>();
      pk.pack_str(static_cast<uint32_t>(s.size()));
      pk.pack_str_body(s.data(), static_cast<uint32_t>(s.size()));
      break;
    }
    case t::binary: {
      const auto& b = v.get_binary();
      pk.pack_bin(static_cast<uint32_t>(b.size()));
      pk.pack_bin_body(reinterpret_cast<const char*>(b.data()), static_cast<uint32_t>(b.size()));
      break;
    }
    case t::array:
      pk.pack_array(static_cast<uint32_t>(v.size()));
      for (const auto& e : v) Pack(pk, e);
      break;
    case t::object:
      pk.pack_map(static_cast<uint32_t>(v.size()));
      for (auto it = v.begin(); it != v.end(); ++it) {
        pk.pack_str(static_cast<uint32_t>(it.key().size()));
        pk.pack_str_body(it.key().data(), static_cast<uint32_t>(it.key().size()));
        Pack(pk, it.value());
      }
      break;
  }
}

}  // namespace

nlohmann::json DecodeMsgpack(const void* data, size_t size, const MsgpackLimits& limits) {
  if (size == 0) throw std::runtime_error("empty message; expected one msgpack map");
  const msgpack::unpack_limit limit(limits.max_elements, limits.max_elements, limits.max_bytes,
                                    limits.max_bytes, 0, limits.max_depth);
  size_t off = 0;
  msgpack::object_handle h;
  try {
    h = msgpack::unpack(static_cast<const char*>(data), size, off, nullptr, nullptr, limit);
  } catch (const msgpack::depth_size_overflow&) {
    throw std::runtime_error("nested deeper than " + std::to_string(limits.max_depth) + " levels");
  } catch (const msgpack::size_overflow& e) {
    throw std::runtime_error(std::string("a value exceeds the size limits (") + e.what() + ")");
  } catch (const msgpack::insufficient_bytes&) {
    throw std::runtime_error("truncated msgpack (the value needs more bytes than were sent)");
  } catch (const msgpack::unpack_error& e) {
    throw std::runtime_error(std::string("not valid msgpack (") + e.what() + ")");
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("a value declares more data than can be held");
  }
  if (off != size)
    throw std::runtime_error(std::to_string(size - off) +
                             " bytes after the msgpack value; expected exactly one value");
  return ToJson(h.get());
}

std::string EncodeMsgpack(const nlohmann::json& value) {
  msgpack::sbuffer buffer;
  msgpack::packer<msgpack::sbuffer> pk(buffer);
  Pack(pk, value);
  return std::string(buffer.data(), buffer.size());
}

}  // namespace penumbra
