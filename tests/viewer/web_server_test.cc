#include "penumbra/viewer/web_server.h"

#include <gtest/gtest.h>

#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

// a web root with an index page and a script in a sub-folder
std::string MakeWebRoot() {
  namespace fs = std::filesystem;
  const fs::path root =
      fs::temp_directory_path() / ("penumbra_web_test_" + std::to_string(::getpid()));
  fs::create_directories(root / "js");
  std::ofstream(root / "index.html") << "<html>viewer</html>";
  std::ofstream(root / "js" / "app.js") << "console.log(1);";
  return root.string();
}

// one HTTP request on a fresh connection; Host is 127.0.0.1:PORT unless `headers` name one
http::response<http::string_body> HttpGet(int port, const std::string& target,
                                          http::verb verb = http::verb::get,
                                          const std::map<http::field, std::string>& headers = {}) {
  net::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req{verb, target, 11};
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  for (const auto& [field, value] : headers) req.set(field, value);
  req.keep_alive(false);
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.skip(verb == http::verb::head);  // a HEAD answer has a length but no body
  http::read(socket, buffer, parser);
  return parser.release();
}

// a blocking WebSocket client that presents the server's token (and no Origin, as programs do)
struct Client {
  net::io_context ioc;
  websocket::stream<tcp::socket> ws{ioc};
  explicit Client(const WebServer& server) {
    ws.next_layer().connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), server.port()));
    ws.read_message_max(64 << 20);
    ws.handshake("127.0.0.1:" + std::to_string(server.port()), "/ws?token=" + server.token());
  }
  std::string Read() {
    beast::flat_buffer b;
    ws.read(b);
    return beast::buffers_to_string(b.data());
  }
  void Write(const std::string& s, bool binary = false) {
    ws.binary(binary);
    ws.write(net::buffer(s));
  }
};

struct Fixture {
  WebServerOptions options;
  std::unique_ptr<WebServer> server;
  std::atomic<int> opened{0}, closed{0};
  explicit Fixture(size_t max_message = 1024, std::vector<std::string> allowed_origins = {}) {
    options.port = 0;
    options.allowed_origins = std::move(allowed_origins);
    options.web_root = MakeWebRoot();
    options.max_message_bytes = max_message;
    WebServerHandlers h;
    h.on_open = [this](int client) {
      ++opened;
      return std::vector<WebMessage>{WebMessage::Text(json{{"type", "hello"}}.dump())};
    };
    h.on_message = [](int client, std::string_view text) -> std::string {
      const json j = json::parse(text);  // throws on malformed JSON -> error reply
      if (j.value("cmd", "") == "throw") throw Error("asked to fail");
      return json{{"type", "echo"}, {"client", client}, {"got", j}}.dump();
    };
    h.on_close = [this](int) { ++closed; };
    server = std::make_unique<WebServer>(options, h);
  }
};

TEST(WebServerTest, ServesStaticFilesSafely) {
  Fixture f;
  ASSERT_GT(f.server->port(), 0);
  const std::string t = "token=" + f.server->token();
  auto res = HttpGet(f.server->port(), "/?" + t);
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(res.body(), "<html>viewer</html>");
  EXPECT_EQ(res[http::field::content_type], "text/html; charset=utf-8");
  res = HttpGet(f.server->port(), "/js/app.js?v=2&" + t);
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(res.body(), "console.log(1);");
  EXPECT_EQ(res[http::field::content_type], "text/javascript; charset=utf-8");
  EXPECT_EQ(HttpGet(f.server->port(), "/missing.js?" + t).result(), http::status::not_found);
  EXPECT_EQ(HttpGet(f.server->port(), "/../../etc/passwd?" + t).result(),
            http::status::bad_request);
  EXPECT_EQ(HttpGet(f.server->port(), "/js/%2e%2e/..?" + t).result(), http::status::bad_request);
  EXPECT_EQ(HttpGet(f.server->port(), "/?" + t, http::verb::post).result(),
            http::status::method_not_allowed);
  res = HttpGet(f.server->port(), "/?" + t, http::verb::head);
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(f.server->stats().http_requests, 7);
  EXPECT_EQ(res[http::field::content_length], "19");
}

TEST(WebServerTest, ResolvesOnlyRelativePaths) {
  EXPECT_EQ(ResolveWebPath("/w", "/"), "/w/index.html");
  EXPECT_EQ(ResolveWebPath("/w", "/a/b.js?x=1#y"), "/w/a/b.js");
  EXPECT_EQ(ResolveWebPath("/w", "/a/"), "/w/a/index.html");
  for (const char* bad : {"", "a.js", "/../x", "/a/../../x", "/a\\b", "//etc/passwd"})
    EXPECT_EQ(ResolveWebPath("/w", bad), "") << bad;
  EXPECT_EQ(ResolveWebPath("/w", std::string_view("/a\0b", 4)), "");
  EXPECT_EQ(MimeTypeFor("x/three.module.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(MimeTypeFor("a.png"), "image/png");
  EXPECT_EQ(MimeTypeFor("noext"), "application/octet-stream");
}

TEST(WebServerTest, RejectsBadOptions) {
  WebServerOptions o;
  o.web_root = MakeWebRoot();
  o.port = 70000;
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
  o.port = 0;
  o.web_root = "/nonexistent/web";
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
  o.web_root = MakeWebRoot();
  o.host = "not-an-ip";
  EXPECT_THROW(WebServer(o, {}), ConfigError);
  // a port already taken names host and port
  Fixture f;
  o.host = "127.0.0.1";
  o.port = f.server->port();
  try {
    WebServer second(o, {});
    ADD_FAILURE() << "bound a port in use";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(o.port)), std::string::npos)
        << e.what();
  }
}

TEST(WebServerTest, RepliesAndSurvivesMalformedMessages) {
  Fixture f;
  Client c(*f.server);
  EXPECT_EQ(json::parse(c.Read())["type"], "hello");
  c.Write(R"({"cmd":"ping","x":1})");
  json r = json::parse(c.Read());
  EXPECT_EQ(r["type"], "echo");
  EXPECT_EQ(r["got"]["x"], 1);
  // malformed JSON, a handler error, a binary message: error replies, connection kept
  c.Write("{not json");
  r = json::parse(c.Read());
  EXPECT_EQ(r["type"], "error");
  EXPECT_NE(r["error"].get<std::string>().find("parse"), std::string::npos) << r;
  c.Write(R"({"cmd":"throw"})");
  EXPECT_EQ(json::parse(c.Read())["error"], "asked to fail");
  c.Write(std::string("\x00\xff\x10", 3), true);
  r = json::parse(c.Read());
  EXPECT_EQ(r["type"], "error");
  EXPECT_NE(r["error"].get<std::string>().find("binary"), std::string::npos);
  c.Write(R"({"cmd":"still here"})");
  EXPECT_EQ(json::parse(c.Read())["type"], "echo");

  // a message over the cap closes that connection with 1009; the server keeps serving
  c.Write(std::string(4096, 'x'));
  beast::flat_buffer b;
  beast::error_code ec;
  c.ws.read(b, ec);
  // the close frame with 1009, or, when the server's close overtook the client's answer to
  // it, a broken pipe / reset / not connected (the socket already shut down: seen once on CI's
  // loaded 2 cores): either way the connection is gone
  if (ec == websocket::error::closed)
    EXPECT_EQ(c.ws.reason().code, websocket::close_code::too_big);
  else
    EXPECT_TRUE(ec == net::error::broken_pipe || ec == net::error::connection_reset ||
                ec == net::error::eof || ec == net::error::not_connected)
        << ec.message();
  Client d(*f.server);
  EXPECT_EQ(json::parse(d.Read())["type"], "hello");
  d.Write(R"({"cmd":"ping"})");
  EXPECT_EQ(json::parse(d.Read())["type"], "echo");
  EXPECT_EQ(HttpGet(f.server->port(), "/?token=" + f.server->token()).result(), http::status::ok);
}

TEST(WebServerTest, FiveClientsEachGetEveryMessageTheyAreSent) {
  Fixture f;
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < 5; ++i) {
    clients.push_back(std::make_unique<Client>(*f.server));
    EXPECT_EQ(json::parse(clients.back()->Read())["type"], "hello");
  }
  EXPECT_EQ(f.server->stats().clients, 5);
  // one channel, a message at a time read by all: nothing is replaced
  for (int k = 0; k < 10; ++k) {
    f.server->Publish("status", WebMessage::Text(json{{"k", k}}.dump()));
    for (auto& c : clients) EXPECT_EQ(json::parse(c->Read())["k"], k);
  }
  // replies go to the asking client only
  clients[2]->Write(R"({"cmd":"who"})");
  const json r = json::parse(clients[2]->Read());
  EXPECT_EQ(r["type"], "echo");
  // clients come and go
  clients.erase(clients.begin());
  for (int i = 0; i < 100 && f.server->stats().clients != 4; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(f.server->stats().clients, 4);
  EXPECT_EQ(f.closed.load(), 1);
  f.server->Publish("status", WebMessage::Text(json{{"k", 99}}.dump()));
  for (auto& c : clients) EXPECT_EQ(json::parse(c->Read())["k"], 99);
  // a message for some clients only: client ids are 1..5 in connection order, 1 left
  f.server->PublishTo({3, 42}, "camera/x/rgb", WebMessage::Text(json{{"only", 3}}.dump()));
  f.server->Publish("status", WebMessage::Text(json{{"k", 100}}.dump()));
  for (size_t i = 0; i < clients.size(); ++i) {
    json first = json::parse(clients[i]->Read());
    if (i == 1) {  // the third client to connect
      EXPECT_EQ(first["only"], 3);
      first = json::parse(clients[i]->Read());
    }
    EXPECT_EQ(first["k"], 100) << i;
  }
}

TEST(WebServerTest, SlowClientGetsTheLatestFrameAndNeverBlocksThePublisher) {
  Fixture f;
  Client slow(*f.server);
  EXPECT_EQ(json::parse(slow.Read())["type"], "hello");
  Client fast(*f.server);
  EXPECT_EQ(json::parse(fast.Read())["type"], "hello");
  // 300 frames of 1 MiB, far more than the socket buffers hold; the slow client reads none
  // while they are published. a frame: 8-byte sequence number + payload
  constexpr int kFrames = 300;
  auto frame = [](int k) {
    std::string s(1 << 20, static_cast<char>(k));
    std::memcpy(s.data(), &k, sizeof k);
    return s;
  };
  for (int k = 0; k < kFrames; ++k) f.server->Publish("camera/front", WebMessage::Binary(frame(k)));
  // the last one arrives at both; the slow one skipped most of them
  auto drain = [](Client& c, int* count) {
    int last = -1;
    while (last != kFrames - 1) {
      const std::string m = c.Read();
      EXPECT_EQ(m.size(), size_t{1} << 20);
      std::memcpy(&last, m.data(), sizeof last);
      EXPECT_EQ(static_cast<char>(m.back()), static_cast<char>(last));
      ++*count;
    }
  };
  int fast_count = 0, slow_count = 0;
  drain(fast, &fast_count);
  drain(slow, &slow_count);
  EXPECT_LE(slow_count, kFrames);
  EXPECT_LT(slow_count, kFrames / 2) << "the slow client got most frames: nothing was dropped";
  EXPECT_GT(f.server->stats().messages_replaced, 0);
  // a frame on another channel is not replaced by camera frames
  f.server->Publish("status", WebMessage::Text("{\"t\":1}"));
  f.server->Publish("camera/front", WebMessage::Binary(frame(kFrames - 1)));
  std::string a = slow.Read(), b = slow.Read();
  EXPECT_TRUE(a == "{\"t\":1}" || b == "{\"t\":1}");
}

// ---- access: Host, Origin and the token (docs/viewer.md "Access") ----

// the HTTP status of a WebSocket handshake request (RFC 6455 4.1) on a real socket: 101 =
// upgraded; `origin` "" sends none. (beast's client does not hand back a declined response.)
unsigned HandshakeStatus(const WebServer& server, const std::string& host,
                         const std::string& target, const std::string& origin) {
  std::map<http::field, std::string> h = {
      {http::field::host, host},
      {http::field::connection, "Upgrade"},
      {http::field::upgrade, "websocket"},
      {http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ=="},
      {http::field::sec_websocket_version, "13"}};
  if (!origin.empty()) h[http::field::origin] = origin;
  return HttpGet(server.port(), target, http::verb::get, h).result_int();
}

TEST(WebServerAccessTest, RefusesForeignOriginsRebindingHostsAndWrongTokensBeforeTheUpgrade) {
  Fixture f;
  const std::string port = std::to_string(f.server->port());
  const std::string token = f.server->token();
  const std::string host = "127.0.0.1:" + port, own = "http://127.0.0.1:" + port;
  const std::string good = "/ws?token=" + token;
  std::string wrong = token;
  wrong.back() = wrong.back() == '0' ? '1' : '0';
  // cross-site WebSocket hijacking: a page of another site, with the right token even
  EXPECT_EQ(HandshakeStatus(*f.server, host, good, "http://evil.example"), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, host, good, "https://evil.example:" + port), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, host, good, "null"), 403u);
  // DNS rebinding: the browser names the attacker's host in Host (and Origin)
  EXPECT_EQ(HandshakeStatus(*f.server, "evil.example:" + port, good, ""), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, "evil.example:8080", good, "http://evil.example:8080"),
            403u);
  // no token, an empty one, a wrong one
  EXPECT_EQ(HandshakeStatus(*f.server, host, "/ws", own), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, host, "/ws?token=", own), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, host, "/ws?token=" + wrong, own), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, host, "/ws?token=" + token.substr(1), own), 403u);
  EXPECT_EQ(f.opened.load(), 0);
  EXPECT_EQ(f.server->stats().refused, 9);
  // the refusal says why, in plain words, and never echoes the token
  const auto res = HttpGet(f.server->port(), "/ws", http::verb::get,
                           {{http::field::connection, "Upgrade"},
                            {http::field::upgrade, "websocket"},
                            {http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ=="},
                            {http::field::sec_websocket_version, "13"},
                            {http::field::origin, "http://evil.example"}});
  EXPECT_EQ(res.result(), http::status::forbidden);
  EXPECT_NE(res.body().find("Origin 'http://evil.example' is not allowed"), std::string::npos)
      << res.body();
  EXPECT_EQ(res.body().find(token), std::string::npos);
  // the page's own origin on any loopback name, and programs that send no Origin, with the
  // token: upgraded
  EXPECT_EQ(HandshakeStatus(*f.server, host, good, own), 101u);
  EXPECT_EQ(HandshakeStatus(*f.server, "localhost:" + port, good, "http://localhost:" + port),
            101u);
  EXPECT_EQ(HandshakeStatus(*f.server, "[::1]:" + port, good, "http://[::1]:" + port), 101u);
  EXPECT_EQ(HandshakeStatus(*f.server, "LocalHost:" + port, good, ""), 101u);
  Client c(*f.server);
  EXPECT_EQ(json::parse(c.Read())["type"], "hello");
}

TEST(WebServerAccessTest, AllowedOriginsExtendTheListAndAreChecked) {
  Fixture f(1024, {"http://Lab.Example:9000/"});
  const std::string good = "/ws?token=" + f.server->token();
  EXPECT_EQ(HandshakeStatus(*f.server, "lab.example:9000", good, "http://lab.example:9000"), 101u);
  EXPECT_EQ(HandshakeStatus(*f.server, "lab.example:9001", good, "http://lab.example:9001"), 403u);
  EXPECT_EQ(HandshakeStatus(*f.server, "lab.example:9000", good, "https://lab.example:9000"), 403u);
  EXPECT_EQ(NormalizeOrigin("HTTPS://[::1]:8443/"), "https://[::1]:8443");
  for (const char* bad : {"lab.example", "ftp://lab.example", "http://lab.example/viewer",
                          "http://", "http://user@lab.example", "http://lab.example:0",
                          "http://lab.example:99999", "http://lab example"}) {
    WebServerOptions o;
    o.port = 0;
    o.web_root = MakeWebRoot();
    o.allowed_origins = {bad};
    try {
      o.ValidateOrThrow();
      ADD_FAILURE() << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "--viewer-allow-origin") << bad;
      EXPECT_NE(std::string(e.what()).find("expected http://HOST[:PORT]"), std::string::npos);
    }
  }
}

TEST(WebServerAccessTest, PagesNeedTheTokenOrTheCookieItSets) {
  Fixture f;
  const int port = f.server->port();
  const std::string token = f.server->token();
  EXPECT_EQ(token.size(), 64u);
  EXPECT_EQ(token.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(f.server->url(), "http://127.0.0.1:" + std::to_string(port) + "/?token=" + token);
  Fixture other;
  EXPECT_NE(other.server->token(), token);
  // without the token: a page that says to open the printed URL
  auto res = HttpGet(port, "/");
  EXPECT_EQ(res.result(), http::status::forbidden);
  EXPECT_EQ(res[http::field::content_type], "text/html; charset=utf-8");
  EXPECT_NE(res.body().find("http://127.0.0.1:PORT/?token=..."), std::string::npos);
  EXPECT_EQ(res.body().find(token), std::string::npos);
  EXPECT_EQ(HttpGet(port, "/js/app.js").result(), http::status::forbidden);
  EXPECT_EQ(HttpGet(port, "/?token=" + token.substr(2)).result(), http::status::forbidden);
  // with it: the page, and a cookie for its scripts
  res = HttpGet(port, "/?token=" + token);
  EXPECT_EQ(res.result(), http::status::ok);
  const std::string cookie = "penumbra_viewer_token_" + std::to_string(port) + "=" + token;
  EXPECT_EQ(res[http::field::set_cookie], cookie + "; Path=/; HttpOnly; SameSite=Strict");
  res = HttpGet(port, "/js/app.js", http::verb::get, {{http::field::cookie, "a=b; " + cookie}});
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_EQ(res.body(), "console.log(1);");
  // the cookie does not open the WebSocket: it needs the token itself
  EXPECT_EQ(HttpGet(port, "/ws", http::verb::get,
                    {{http::field::connection, "Upgrade"},
                     {http::field::upgrade, "websocket"},
                     {http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ=="},
                     {http::field::sec_websocket_version, "13"},
                     {http::field::cookie, cookie}})
                .result(),
            http::status::forbidden);
  // a rebinding Host or a foreign Origin is refused even with the token
  EXPECT_EQ(HttpGet(port, "/?token=" + token, http::verb::get,
                    {{http::field::host, "evil.example:" + std::to_string(port)}})
                .result(),
            http::status::forbidden);
  EXPECT_EQ(HttpGet(port, "/js/app.js?token=" + token, http::verb::get,
                    {{http::field::origin, "http://evil.example"}})
                .result(),
            http::status::forbidden);
}

}  // namespace
}  // namespace penumbra
