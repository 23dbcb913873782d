#pragma once
// the live viewer's HTTP + WebSocket server (Boost.Beast, RFC 6455): serves the page's static
// files from one folder and keeps any number of WebSocket clients at "/ws".
//
// threading: one server thread runs every network operation and calls the handlers. Publish
// and Send may be called from any thread and never block on a client: they hand the bytes to
// the server thread and return. each client has, per channel, a queue of ONE pending message:
// a newer message on the same channel replaces one not yet sent (latest frame wins), so a slow
// browser sees fewer frames but never slows the caller. replies (Send, handler results) are
// never replaced; a client whose reply queue passes WebServerOptions::max_pending_replies is
// disconnected.
//
// access (docs/viewer.md "Access"): every request, page or WebSocket, must name this server in
// `Host` (127.0.0.1, localhost or [::1] with its port, the bound address, or the host of an
// allowed origin: a DNS-rebinding page sends its own name and is refused), a browser's `Origin`
// must be the page's own (those names as http://NAME:PORT) or one in allowed_origins, and the
// request must carry the server's secret token (WebServer::token(), random from the OS, 256
// bits): the WebSocket as /ws?token=TOKEN, a page as ?token=TOKEN or the cookie the server sets
// when the page is opened with it. anything else is answered 403 before any upgrade (tokens
// compared in constant time); a page without the token gets a short page that says to open the
// URL the server printed (WebServer::url()).
//
// input: HTTP requests are GET/HEAD of files under the web root (no "..", no absolute paths),
// with header and body limits; WebSocket messages larger than max_message_bytes close that
// connection with status 1009 (message too big, RFC 6455 7.4.1); binary messages and anything a
// handler throws get an error reply ({"type":"error","error":"..."}) and the connection stays.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// where and how the server listens.
struct WebServerOptions {
  std::string host = "127.0.0.1";        ///< numeric IPv4/IPv6 address to bind; loopback by default
  int port = 8080;                       ///< TCP port; 0 = any free port (see WebServer::port)
  std::string web_root;                  ///< folder of the static files ("/" serves index.html)
  size_t max_message_bytes = 64 * 1024;  ///< largest WebSocket message accepted from a client
  size_t max_pending_replies = 256;      ///< replies queued for one client before it is dropped
  int max_clients = 64;                  ///< WebSocket clients at once; more are refused (503)
  /// origins allowed besides the page's own and the loopback ones (--viewer-allow-origin), as
  /// browsers send them in `Origin`: "http://HOST[:PORT]" or "https://HOST[:PORT]"; their
  /// HOST[:PORT] is then accepted in `Host` too (a reverse proxy, a LAN address).
  std::vector<std::string> allowed_origins;

  /// @throws ConfigError (key "viewer.<field>") for an empty host, a port outside 0..65535, a
  ///         web root that is not a folder, a zero message cap or max_clients < 1;
  ///         ConfigError (key "--viewer-allow-origin") for an origin NormalizeOrigin refuses.
  void ValidateOrThrow() const;
};

/// one message to a client: text (UTF-8 JSON) or binary, shared between clients.
struct WebMessage {
  std::shared_ptr<const std::string> bytes;
  bool binary = false;
  static WebMessage Text(std::string s) {
    return {std::make_shared<const std::string>(std::move(s)), false};
  }
  static WebMessage Binary(std::string s) {
    return {std::make_shared<const std::string>(std::move(s)), true};
  }
};

/// what the server calls on its own thread. each may be empty.
struct WebServerHandlers {
  /// a client connected (its WebSocket handshake ended); returns the messages it gets first,
  /// in order, before any published message.
  std::function<std::vector<WebMessage>(int client)> on_open;
  /// a text message of a client; returns the reply ("" = none). an exception becomes an error
  /// reply with its what().
  std::function<std::string(int client, std::string_view text)> on_message;
  /// a client disconnected.
  std::function<void(int client)> on_close;
};

/// counters since the server started (read from any thread).
struct WebServerStats {
  int clients = 0;                ///< WebSocket clients connected now
  int64_t messages_received = 0;  ///< WebSocket messages read from clients
  int64_t messages_sent = 0;      ///< WebSocket messages written to clients
  int64_t messages_replaced = 0;  ///< published messages replaced before being sent
  int64_t bytes_sent = 0;         ///< WebSocket payload bytes written
  int64_t http_requests = 0;      ///< plain HTTP requests answered
  int64_t refused = 0;            ///< requests answered 403 (Host, Origin or token)
};

/// the server; listening from construction to destruction.
class WebServer {
 public:
  /// binds and starts the server thread.
  /// @throws ConfigError (options invalid) or Error naming host:port when it cannot bind.
  WebServer(const WebServerOptions& options, WebServerHandlers handlers);
  /// stops the thread and closes every connection.
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// the port listened on (the one picked when options.port was 0).
  int port() const;
  /// "http://HOST:PORT/?token=TOKEN": the page's URL with the secret token (HOST: the bound
  /// address; 127.0.0.1 or [::1] when bound to every address).
  std::string url() const;
  /// the secret token of this server (64 hex digits), made at construction.
  const std::string& token() const;

  /// offers `message` to every client on `channel`; replaces a message of that channel a
  /// client has not been sent yet. returns at once.
  void Publish(const std::string& channel, WebMessage message);
  /// Publish to the listed clients only (those gone are skipped).
  void PublishTo(const std::vector<int>& clients, const std::string& channel, WebMessage message);
  /// queues a reply for one client (never replaced); no-op if it is gone. returns at once.
  void Send(int client, WebMessage message);
  /// the counters now.
  WebServerStats stats() const;

 private:
  std::shared_ptr<class WebServerImpl> impl_;
};

/// `origin` in the form browsers send it (lowercase, no trailing '/'): "http://" or
/// "https://" followed by a host name, IPv4 address or [IPv6] address and an optional
/// ":PORT" (1..65535), nothing else.
/// @throws ConfigError("", 0, "--viewer-allow-origin", ...) naming the origin otherwise.
std::string NormalizeOrigin(std::string_view origin);

/// `bytes` random bytes from the OS (getrandom(2), /dev/urandom where it is missing) as
/// lowercase hex.
/// @throws Error naming the reason when the OS gives none.
std::string MakeSecretToken(size_t bytes = 32);

/// the Content-Type the server sends for a file name (by extension; unknown ones are
/// application/octet-stream).
std::string_view MimeTypeFor(std::string_view path);

/// the file under `web_root` an HTTP target names ("/" and "/dir/" -> index.html; a query
/// string is ignored), or "" when the target is not a safe relative path (empty, not starting
/// with '/', holding "..", a backslash or a NUL byte).
std::string ResolveWebPath(const std::string& web_root, std::string_view target);

}  // namespace penumbra
