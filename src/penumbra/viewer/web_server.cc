#include "penumbra/viewer/web_server.h"

#include <errno.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/random.h>
#include <unistd.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

void WebServerOptions::ValidateOrThrow() const {
  if (host.empty()) throw ConfigError("", 0, "viewer.host", "empty; expected an IP address");
  if (port < 0 || port > 65535)
    throw ConfigError("", 0, "viewer.port",
                      fmt::format("{} is out of range; expected 0..65535", port));
  std::error_code ec;
  if (!std::filesystem::is_directory(web_root, ec))
    throw ConfigError("", 0, "viewer.web_root",
                      "'" + web_root + "' is not a folder; expected the viewer's web/ folder");
  if (max_message_bytes == 0)
    throw ConfigError("", 0, "viewer.max_message_bytes", "0; expected a positive size");
  if (max_pending_replies == 0)
    throw ConfigError("", 0, "viewer.max_pending_replies", "0; expected a positive count");
  if (max_clients < 1)
    throw ConfigError("", 0, "viewer.max_clients",
                      fmt::format("{}; expected at least 1", max_clients));
  for (const std::string& o : allowed_origins) NormalizeOrigin(o);
}

std::string NormalizeOrigin(std::string_view origin) {
  auto fail = [&](const std::string& why) {
    throw ConfigError("", 0, "--viewer-allow-origin",
                      "'" + std::string(origin) + "' " + why +
                          "; expected http://HOST[:PORT] or https://HOST[:PORT], e.g. "
                          "http://192.168.1.20:8080");
  };
  std::string o;
  for (const char c : origin) {
    const auto b = static_cast<unsigned char>(c);
    if (b <= 0x20 || b >= 0x7f) fail("holds a space, control or non-ASCII character");
    o += static_cast<char>(std::tolower(b));
  }
  if (!o.empty() && o.back() == '/') o.pop_back();
  size_t at = 0;
  if (o.rfind("http://", 0) == 0)
    at = 7;
  else if (o.rfind("https://", 0) == 0)
    at = 8;
  else
    fail("does not start with http:// or https://");
  const std::string authority = o.substr(at);
  if (authority.empty()) fail("has no host");
  if (authority.find_first_of("/?#@\\") != std::string::npos)
    fail("holds a path, query, fragment or user name");
  std::string host = authority, port;
  if (authority.front() == '[') {
    const size_t close = authority.find(']');
    if (close == std::string::npos || close == 1) fail("has an unclosed or empty [IPv6] host");
    host = authority.substr(0, close + 1);
    const std::string rest = authority.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') fail("has text after the [IPv6] host");
      port = rest.substr(1);
      if (port.empty()) fail("has an empty port");
    }
  } else if (const size_t colon = authority.find(':'); colon != std::string::npos) {
    host = authority.substr(0, colon);
    port = authority.substr(colon + 1);
    if (port.empty()) fail("has an empty port");
  }
  if (host.empty()) fail("has no host");
  if (!port.empty()) {
    if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
        std::stoi(port) < 1 || std::stoi(port) > 65535)
      fail("has a port that is not 1..65535");
  }
  return o;
}

std::string MakeSecretToken(size_t bytes) {
  std::string raw(bytes, '\0');
  size_t got = 0;
  while (got < bytes) {
    const ssize_t n = ::getrandom(raw.data() + got, bytes - got, 0);
    if (n > 0) {
      got += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != ENOSYS)
      throw Error(std::string("viewer: no random bytes from the OS (getrandom): ") +
                  std::strerror(errno));
    // no getrandom(2): the kernel's pool through /dev/urandom
    const int fd = ::open("/dev/urandom", O_RDONLY | O_CLOEXEC);
    if (fd < 0)
      throw Error(std::string("viewer: cannot open /dev/urandom: ") + std::strerror(errno));
    while (got < bytes) {
      const ssize_t r = ::read(fd, raw.data() + got, bytes - got);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) {
        ::close(fd);
        throw Error("viewer: cannot read /dev/urandom");
      }
      got += static_cast<size_t>(r);
    }
    ::close(fd);
  }
  static const char* kHex = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * bytes);
  for (const char c : raw) {
    const auto b = static_cast<unsigned char>(c);
    hex += kHex[b >> 4];
    hex += kHex[b & 15];
  }
  return hex;
}

std::string_view MimeTypeFor(std::string_view path) {
  const size_t dot = path.rfind('.');
  const std::string_view ext = dot == std::string_view::npos ? "" : path.substr(dot + 1);
  if (ext == "html" || ext == "htm") return "text/html; charset=utf-8";
  if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "json") return "application/json";
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "ico") return "image/vnd.microsoft.icon";
  if (ext == "txt") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

std::string ResolveWebPath(const std::string& web_root, std::string_view target) {
  const size_t q = target.find_first_of("?#");
  if (q != std::string_view::npos) target = target.substr(0, q);
  if (target.empty() || target[0] != '/') return "";
  if (target.find("..") != std::string_view::npos) return "";
  if (target.find('\\') != std::string_view::npos) return "";
  if (target.find('\0') != std::string_view::npos) return "";
  if (target.find("//") != std::string_view::npos) return "";
  std::string rel(target.substr(1));
  if (rel.empty() || rel.back() == '/') rel += "index.html";
  return (std::filesystem::path(web_root) / rel).string();
}

namespace {

std::string ErrorReply(std::string_view what) {
  return nlohmann::json{{"type", "error"}, {"error", SanitizeForMessage(what)}}.dump();
}

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// the value of `key` in the target's query string ("" if absent); tokens are hex, so no
// percent-decoding is needed
std::string QueryParam(std::string_view target, std::string_view key) {
  const size_t q = target.find('?');
  if (q == std::string_view::npos) return "";
  std::string_view query = target.substr(q + 1);
  if (const size_t hash = query.find('#'); hash != std::string_view::npos)
    query = query.substr(0, hash);
  while (!query.empty()) {
    const size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const size_t eq = pair.find('=');
    if (eq != std::string_view::npos && pair.substr(0, eq) == key)
      return std::string(pair.substr(eq + 1));
    if (amp == std::string_view::npos) break;
    query = query.substr(amp + 1);
  }
  return "";
}

// the value of cookie `name` in a Cookie header ("" if absent)
std::string CookieValue(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    const size_t semi = header.find(';');
    std::string_view item = header.substr(0, semi);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    const size_t eq = item.find('=');
    if (eq != std::string_view::npos && item.substr(0, eq) == name)
      return std::string(item.substr(eq + 1));
    if (semi == std::string_view::npos) break;
    header = header.substr(semi + 1);
  }
  return "";
}

// a == b in time that depends only on their lengths (the token's length is no secret)
bool ConstantTimeEquals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

// the page that a request without the token gets instead of the viewer
constexpr std::string_view kTokenPage =
    "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    "<title>Penumbra viewer: open the printed URL</title></head>\n<body>\n"
    "<h1>Penumbra live viewer</h1>\n"
    "<p>This viewer only answers pages that carry the secret token of its run. Open the URL "
    "that <code>penumbra run --viewer</code> or <code>penumbra view</code> printed when it "
    "started, of the form <code>http://127.0.0.1:PORT/?token=...</code> (docs/viewer.md, "
    "\"Access\").</p>\n</body></html>\n";

}  // namespace

class WebSocketSession;

// shared state; every member but the atomics and the thread is used on the server thread only
class WebServerImpl : public std::enable_shared_from_this<WebServerImpl> {
 public:
  WebServerImpl(const WebServerOptions& options, WebServerHandlers handlers)
      : options_(options),
        handlers_(std::move(handlers)),
        acceptor_(ioc_),
        token_(MakeSecretToken()) {}

  void Start();
  void Stop();
  void Accept();
  void Register(int id, const std::shared_ptr<WebSocketSession>& s) { sessions_[id] = s; }
  void Unregister(int id);
  // the names this server answers to (after the port is known)
  void BuildAllowList();
  // why `req` is refused with 403 ("" = it may go on); `token_ok` tells whether it carried the
  // token in its query (a page request may carry it in the cookie instead)
  std::string Refusal(const http::request<http::string_body>& req, bool upgrade,
                      bool* query_token) const;
  std::string CookieName() const { return fmt::format("penumbra_viewer_token_{}", port_); }
  std::shared_ptr<WebSocketSession> Find(int id) {
    auto it = sessions_.find(id);
    return it == sessions_.end() ? nullptr : it->second.lock();
  }

  WebServerOptions options_;
  WebServerHandlers handlers_;
  net::io_context ioc_;
  tcp::acceptor acceptor_;
  std::thread thread_;
  int port_ = 0;
  int next_id_ = 1;
  std::map<int, std::weak_ptr<WebSocketSession>> sessions_;
  std::atomic<int> clients_{0};
  std::atomic<int64_t> received_{0}, sent_{0}, replaced_{0}, bytes_sent_{0}, http_requests_{0},
      refused_{0};
  const std::string token_;
  std::set<std::string> hosts_;    // allowed Host values, lowercase
  std::set<std::string> origins_;  // allowed Origin values, lowercase
};

// one WebSocket client: a read loop and a write pump over replies and per-channel latest slots
class WebSocketSession : public std::enable_shared_from_this<WebSocketSession> {
 public:
  WebSocketSession(tcp::socket socket, std::shared_ptr<WebServerImpl> server, int id)
      : ws_(std::move(socket)), server_(std::move(server)), id_(id) {}

  void Accept(http::request<http::string_body> req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(server_->options_.max_message_bytes);
    ws_.async_accept(req,
                     [self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
  }

  void Offer(const std::string& channel, const WebMessage& m) {
    if (closed_) return;
    for (auto& [c, pending] : latest_) {
      if (c == channel) {
        pending = m;
        ++server_->replaced_;
        return;
      }
    }
    latest_.emplace_back(channel, m);
    Pump();
  }

  void Reply(WebMessage m) {
    if (closed_) return;
    if (replies_.size() >= server_->options_.max_pending_replies) {
      spdlog::warn("viewer: client {} does not read its replies; disconnecting it", id_);
      Close();
      return;
    }
    replies_.push_back(std::move(m));
    Pump();
  }

  void Close() {
    if (closed_) return;
    closed_ = true;
    replies_.clear();
    latest_.clear();
    server_->Unregister(id_);
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  void OnAccept(beast::error_code ec) {
    if (ec) return;
    server_->Register(id_, shared_from_this());
    ++server_->clients_;
    registered_ = true;
    if (server_->handlers_.on_open) {
      try {
        for (WebMessage& m : server_->handlers_.on_open(id_)) Reply(std::move(m));
      } catch (const std::exception& e) {
        Reply(WebMessage::Text(ErrorReply(e.what())));
      }
    }
    Read();
  }

  void Read() {
    ws_.async_read(buffer_,
                   [self = shared_from_this()](beast::error_code ec, size_t) { self->OnRead(ec); });
  }

  void OnRead(beast::error_code ec) {
    if (ec) {
      // message_too_big: beast has already sent the close frame with 1009
      if (ec != websocket::error::closed && ec != net::error::operation_aborted &&
          ec != net::error::eof && ec != websocket::error::message_too_big)
        spdlog::debug("viewer: client {}: {}", id_, ec.message());
      Close();
      return;
    }
    ++server_->received_;
    const bool text = ws_.got_text();
    std::string msg = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    if (!text) {
      Reply(WebMessage::Text(ErrorReply("binary messages are not accepted; expected JSON text")));
    } else if (server_->handlers_.on_message) {
      std::string reply;
      try {
        reply = server_->handlers_.on_message(id_, msg);
      } catch (const std::exception& e) {
        reply = ErrorReply(e.what());
      }
      if (!reply.empty()) Reply(WebMessage::Text(std::move(reply)));
    }
    if (!closed_) Read();
  }

  void Pump() {
    if (writing_ || closed_) return;
    WebMessage next;
    if (!replies_.empty()) {
      next = std::move(replies_.front());
      replies_.pop_front();
    } else if (!latest_.empty()) {
      next = std::move(latest_.front().second);
      latest_.pop_front();
    } else {
      return;
    }
    writing_ = true;
    ws_.binary(next.binary);
    ws_.async_write(net::buffer(*next.bytes),
                    [self = shared_from_this(), bytes = next.bytes](
                        beast::error_code ec, size_t n) { self->OnWrite(ec, n); });
  }

  void OnWrite(beast::error_code ec, size_t n) {
    writing_ = false;
    if (ec) {
      Close();
      return;
    }
    ++server_->sent_;
    server_->bytes_sent_ += static_cast<int64_t>(n);
    Pump();
  }

 public:
  ~WebSocketSession() {
    if (registered_) {
      --server_->clients_;
      if (server_->handlers_.on_close) {
        try {
          server_->handlers_.on_close(id_);
        } catch (const std::exception& e) {
          spdlog::warn("viewer: on_close: {}", e.what());
        }
      }
    }
  }

 private:
  websocket::stream<beast::tcp_stream> ws_;
  std::shared_ptr<WebServerImpl> server_;
  int id_;
  beast::flat_buffer buffer_;
  std::deque<WebMessage> replies_;
  std::deque<std::pair<std::string, WebMessage>> latest_;
  bool writing_ = false;
  bool closed_ = false;
  bool registered_ = false;
};

// one HTTP connection: static files, or the upgrade to a WebSocket
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, std::shared_ptr<WebServerImpl> server)
      : stream_(std::move(socket)), server_(std::move(server)) {}

  void Read() {
    parser_.emplace();
    parser_->header_limit(16 * 1024);
    parser_->body_limit(server_->options_.max_message_bytes);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, size_t) { self->OnRead(ec); });
  }

 private:
  void OnRead(beast::error_code ec) {
    if (ec == http::error::end_of_stream) return Shutdown();
    if (ec) {
      if (ec == http::error::body_limit || ec == http::error::header_limit)
        return Respond(
            ErrorResponse(http::status::payload_too_large, "request too large", 11, false));
      return;  // malformed or cut off: drop the connection
    }
    http::request<http::string_body> req = parser_->release();
    const bool upgrade = websocket::is_upgrade(req);
    // Host, Origin and token first: nothing else is answered to a stranger
    bool query_token = false;
    if (const std::string why = server_->Refusal(req, upgrade, &query_token); !why.empty()) {
      const int64_t n = ++server_->refused_;
      if (n <= 10 || n % 1000 == 0) {
        // the path only: a query may hold the token
        const std::string_view target(req.target().data(), req.target().size());
        spdlog::warn("viewer: refused {} {} ({} refused so far): {}",
                     upgrade ? "a WebSocket to" : "a request for",
                     SanitizeForMessage(target.substr(0, target.find('?')), 80), n, why);
      }
      if (why == "no token") {
        if (upgrade)
          return Respond(ErrorResponse(
              http::status::forbidden,
              "missing or wrong token: connect to /ws?token=TOKEN with the token of the URL "
              "penumbra printed at start (docs/viewer.md, Access)",
              req.version(), false));
        http::response<http::string_body> res{http::status::forbidden, req.version()};
        res.set(http::field::content_type, "text/html; charset=utf-8");
        res.set(http::field::cache_control, "no-store");
        res.keep_alive(false);
        if (req.method() != http::verb::head) res.body() = std::string(kTokenPage);
        res.prepare_payload();
        return Respond(std::move(res));
      }
      return Respond(ErrorResponse(http::status::forbidden, why, req.version(), false));
    }
    if (upgrade) {
      const std::string_view target(req.target().data(), req.target().size());
      if (target.substr(0, target.find('?')) != "/ws")
        return Respond(ErrorResponse(http::status::not_found, "WebSocket endpoint is /ws",
                                     req.version(), false));
      if (server_->clients_.load() >= server_->options_.max_clients)
        return Respond(ErrorResponse(http::status::service_unavailable, "too many viewers",
                                     req.version(), false));
      stream_.expires_never();
      const int id = server_->next_id_++;
      std::make_shared<WebSocketSession>(stream_.release_socket(), server_, id)
          ->Accept(std::move(req));
      return;
    }
    ++server_->http_requests_;
    http::response<http::string_body> res = Serve(req);
    // a page opened with ?token= gets it as a cookie, so that its scripts and styles load
    if (query_token && res.result() == http::status::ok)
      res.set(http::field::set_cookie, fmt::format("{}={}; Path=/; HttpOnly; SameSite=Strict",
                                                   server_->CookieName(), server_->token_));
    Respond(std::move(res));
  }

  static http::response<http::string_body> ErrorResponse(http::status status, std::string_view what,
                                                         unsigned version, bool keep_alive) {
    http::response<http::string_body> res{status, version};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.keep_alive(keep_alive);
    res.body() = std::string(what) + "\n";
    res.prepare_payload();
    return res;
  }

  http::response<http::string_body> Serve(const http::request<http::string_body>& req) {
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return ErrorResponse(http::status::method_not_allowed, "only GET and HEAD", req.version(),
                           req.keep_alive());
    const std::string path = ResolveWebPath(
        server_->options_.web_root, std::string_view(req.target().data(), req.target().size()));
    if (path.empty())
      return ErrorResponse(http::status::bad_request, "bad path", req.version(), req.keep_alive());
    std::string body;
    try {
      body = ReadInputFile(path, "web file");  // a regular file, at most 256 MiB
    } catch (const ConfigError&) {
      return ErrorResponse(http::status::not_found, "not found", req.version(), req.keep_alive());
    }
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::content_type, std::string(MimeTypeFor(path)));
    res.set(http::field::cache_control, "no-cache");
    res.keep_alive(req.keep_alive());
    if (req.method() == http::verb::get) res.body() = body;
    res.prepare_payload();
    if (req.method() == http::verb::head) res.content_length(body.size());
    return res;
  }

  void Respond(http::response<http::string_body> res) {
    auto sp = std::make_shared<http::response<http::string_body>>(std::move(res));
    const bool close = sp->need_eof();
    http::async_write(stream_, *sp,
                      [self = shared_from_this(), sp, close](beast::error_code ec, size_t) {
                        if (ec) return;
                        if (close) return self->Shutdown();
                        self->Read();
                      });
  }

  void Shutdown() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<WebServerImpl> server_;
};

void WebServerImpl::Start() {
  beast::error_code ec;
  const net::ip::address address = net::ip::make_address(options_.host, ec);
  if (ec)
    throw ConfigError("", 0, "viewer.host",
                      "'" + options_.host + "' is not a numeric IP address (e.g. 127.0.0.1)");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(options_.port));
  auto fail = [&](const char* what) {
    throw Error(fmt::format("viewer: cannot {} {}:{}: {}", what, options_.host, options_.port,
                            ec.message()));
  };
  acceptor_.open(endpoint.protocol(), ec);
  if (ec) fail("open");
  acceptor_.set_option(net::socket_base::reuse_address(true), ec);
  acceptor_.bind(endpoint, ec);
  if (ec) fail("bind");
  acceptor_.listen(net::socket_base::max_listen_connections, ec);
  if (ec) fail("listen on");
  port_ = acceptor_.local_endpoint().port();
  BuildAllowList();
  Accept();
  thread_ = std::thread([self = shared_from_this()] { self->ioc_.run(); });
}

void WebServerImpl::Accept() {
  acceptor_.async_accept(net::make_strand(ioc_),
                         [self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
                           if (ec) {
                             if (ec == net::error::operation_aborted) return;
                           } else {
                             socket.set_option(tcp::no_delay(true), ec);
                             std::make_shared<HttpSession>(std::move(socket), self)->Read();
                           }
                           self->Accept();
                         });
}

void WebServerImpl::Unregister(int id) { sessions_.erase(id); }

void WebServerImpl::BuildAllowList() {
  const bool v6 = options_.host.find(':') != std::string::npos;
  const std::string bound = v6 ? "[" + options_.host + "]" : options_.host;
  for (const std::string& name :
       {std::string("127.0.0.1"), std::string("localhost"), std::string("[::1]"), bound}) {
    const std::string n = Lower(name);
    hosts_.insert(fmt::format("{}:{}", n, port_));
    origins_.insert(fmt::format("http://{}:{}", n, port_));
    if (port_ == 80) {  // browsers leave the default port out
      hosts_.insert(n);
      origins_.insert("http://" + n);
    }
  }
  for (const std::string& o : options_.allowed_origins) {
    const std::string origin = NormalizeOrigin(o);
    origins_.insert(origin);
    hosts_.insert(origin.substr(origin.find("://") + 3));
  }
}

std::string WebServerImpl::Refusal(const http::request<http::string_body>& req, bool upgrade,
                                   bool* query_token) const {
  const auto host_it = req.find(http::field::host);
  if (host_it == req.end()) return "no Host header";
  const std::string host =
      Lower(std::string_view(host_it->value().data(), host_it->value().size()));
  if (!hosts_.count(host))
    return fmt::format(
        "Host '{}' is not a name of this viewer (127.0.0.1:{}, localhost:{}, [::1]:{} or the "
        "host of an --viewer-allow-origin); a page of another site reached it by DNS rebinding",
        SanitizeForMessage(host, 200), port_, port_, port_);
  // browsers always send Origin with a WebSocket handshake and with cross-origin requests;
  // a request without one comes from a program, which still needs the token
  if (const auto it = req.find(http::field::origin); it != req.end()) {
    const std::string origin = Lower(std::string_view(it->value().data(), it->value().size()));
    if (!origins_.count(origin))
      return fmt::format(
          "Origin '{}' is not allowed: only the viewer's own page (http://127.0.0.1:{}) or an "
          "origin given with --viewer-allow-origin may connect",
          SanitizeForMessage(origin, 200), port_);
  }
  const std::string_view target(req.target().data(), req.target().size());
  *query_token = ConstantTimeEquals(QueryParam(target, "token"), token_);
  if (*query_token) return "";
  if (!upgrade) {
    if (const auto it = req.find(http::field::cookie); it != req.end()) {
      const std::string cookie =
          CookieValue(std::string_view(it->value().data(), it->value().size()), CookieName());
      if (ConstantTimeEquals(cookie, token_)) return "";
    }
  }
  return "no token";
}

void WebServerImpl::Stop() {
  net::post(ioc_, [self = shared_from_this()] {
    beast::error_code ec;
    self->acceptor_.close(ec);
    // copies: Close() unregisters
    std::vector<std::shared_ptr<WebSocketSession>> open;
    for (auto& [id, w] : self->sessions_)
      if (auto s = w.lock()) open.push_back(s);
    for (auto& s : open) s->Close();
    self->ioc_.stop();
  });
  if (thread_.joinable()) thread_.join();
}

WebServer::WebServer(const WebServerOptions& options, WebServerHandlers handlers) {
  options.ValidateOrThrow();
  impl_ = std::make_shared<WebServerImpl>(options, std::move(handlers));
  impl_->Start();
}

WebServer::~WebServer() {
  impl_->Stop();
  // pending handlers hold the Impl; drop them while the io_context is still alive
  impl_->ioc_.restart();
  impl_->ioc_.poll();
}

int WebServer::port() const { return impl_->port_; }

std::string WebServer::url() const {
  std::string host = impl_->options_.host;
  // bound to every address: the loopback one is the URL to open on this machine
  if (host == "0.0.0.0") host = "127.0.0.1";
  if (host == "::") host = "::1";
  const bool v6 = host.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/?token={}", v6 ? "[" : "", host, v6 ? "]" : "", impl_->port_,
                     impl_->token_);
}

const std::string& WebServer::token() const { return impl_->token_; }

void WebServer::Publish(const std::string& channel, WebMessage message) {
  net::post(impl_->ioc_, [impl = impl_, channel, message = std::move(message)] {
    for (auto& [id, w] : impl->sessions_)
      if (auto s = w.lock()) s->Offer(channel, message);
  });
}

void WebServer::PublishTo(const std::vector<int>& clients, const std::string& channel,
                          WebMessage message) {
  net::post(impl_->ioc_, [impl = impl_, clients, channel, message = std::move(message)] {
    for (int id : clients)
      if (auto s = impl->Find(id)) s->Offer(channel, message);
  });
}

void WebServer::Send(int client, WebMessage message) {
  net::post(impl_->ioc_, [impl = impl_, client, message = std::move(message)]() mutable {
    if (auto s = impl->Find(client)) s->Reply(std::move(message));
  });
}

WebServerStats WebServer::stats() const {
  WebServerStats s;
  s.clients = impl_->clients_.load();
  s.messages_received = impl_->received_.load();
  s.messages_sent = impl_->sent_.load();
  s.messages_replaced = impl_->replaced_.load();
  s.bytes_sent = impl_->bytes_sent_.load();
  s.http_requests = impl_->http_requests_.load();
  s.refused = impl_->refused_.load();
  return s;
}

}  // namespace penumbra
