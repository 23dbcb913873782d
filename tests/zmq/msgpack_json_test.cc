// msgpack <-> JSON (zmq/msgpack_json.h): values round-trip; hostile input is an error.
#include "penumbra/zmq/msgpack_json.h"

#include <gtest/gtest.h>

#include <string>

namespace penumbra {
namespace {

using json = nlohmann::json;

TEST(MsgpackJson, RoundTrips) {
  const json v = {{"cmd", "step"},
                  {"n", 5},
                  {"neg", -7},
                  {"big", 18446744073709551615ull},
                  {"x", 0.25},
                  {"flag", true},
                  {"nil", nullptr},
                  {"list", {1, 2.5, "s", {{"k", {}}}}},
                  {"bin", json::binary({0, 1, 255})}};
  const std::string b = EncodeMsgpack(v);
  EXPECT_EQ(DecodeMsgpack(b.data(), b.size()), v);
  // a float stays a float, an int an int
  const json d = DecodeMsgpack(b.data(), b.size());
  EXPECT_TRUE(d["x"].is_number_float());
  EXPECT_TRUE(d["n"].is_number_integer());
}

void ExpectRejected(const std::string& bytes, const std::string& words) {
  try {
    DecodeMsgpack(bytes.data(), bytes.size());
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(MsgpackJson, RejectsHostileInput) {
  ExpectRejected("", "empty");
  ExpectRejected("\xc1", "not valid msgpack");
  const std::string map = EncodeMsgpack({{"cmd", "step"}});
  ExpectRejected(map.substr(0, map.size() - 1), "truncated");
  ExpectRejected(map + "\x01", "after the msgpack value");
  ExpectRejected(std::string(40, '\x91') + "\x00", "nested deeper");
  ExpectRejected(std::string("\x81\x01\x02", 3), "not a string");  // {1: 2}
  ExpectRejected(std::string("\xd4\x01\x00", 3), "ext");           // fixext 1
  ExpectRejected(std::string("\xdd\xff\xff\xff\xff", 5), "");      // 4e9-entry array
  ExpectRejected(std::string("\xdb\xff\xff\xff\xff", 5), "");      // 4 GB string
}

}  // namespace
}  // namespace penumbra
