#include "penumbra/viewer/web_server.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "penumbra/core/error.h"

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

}  // namespace

class WebSocketSession;

// shared state; every member but the atomics and the thread is used on the server thread only
class WebServerImpl : public std::enable_shared_from_this<WebServerImpl> {
 public:
  WebServerImpl(const WebServerOptions& options, WebServerHandlers handlers)
      : options_(options), handlers_(std::move(handlers)), acceptor_(ioc_) {}

  void Start();
  void Stop();
  void Accept();
  void Register(int id, const std::shared_ptr<WebSocketSession>& s) { sessions_[id] = s; }
  void Unregister(int id);
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
  std::atomic<int64_t> received_{0}, sent_{0}, replaced_{0}, bytes_sent_{0}, http_requests_{0};
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
    if (websocket::is_upgrade(req)) {
      if (req.target() != "/ws")
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
    Respond(Serve(req));
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
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in || !std::filesystem::is_regular_file(path, ec))
      return ErrorResponse(http::status::not_found, "not found", req.version(), req.keep_alive());
    std::ostringstream body;
    body << in.rdbuf();
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::content_type, std::string(MimeTypeFor(path)));
    res.set(http::field::cache_control, "no-cache");
    res.keep_alive(req.keep_alive());
    if (req.method() == http::verb::get) res.body() = body.str();
    res.prepare_payload();
    if (req.method() == http::verb::head) res.content_length(body.str().size());
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
  const bool v6 = impl_->options_.host.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/", v6 ? "[" : "", impl_->options_.host, v6 ? "]" : "",
                     impl_->port_);
}

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
  return s;
}

}  // namespace penumbra
