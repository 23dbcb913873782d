#pragma once
// the live viewer of a run (`penumbra run WORLD --viewer [HOST:PORT]`, `penumbra view WORLD`;
// docs/viewer.md): a RunBridge (command/run_bridge.h) that serves the page (web/) over HTTP and
// talks to it over one WebSocket per browser (viewer/web_server.h).
//
//   page -> run: the commands of the ZeroMQ protocol (docs/zmq-protocol.md) as JSON text,
//                handed unchanged to the run's CommandDispatcher (the one command layer); its
//                replies go back to the asking page. the viewer's own command is `subscribe`
//                (which camera streams the page shows).
//   run -> page: on connect a `viewer_hello` (model_info, controls) and the `scene` (geometry,
//                once); a `state` message (time, step, body and camera poses, plot signals) at
//                up to state_hz of wall-clock time, and after every step while paused; camera
//                frames of the subscribed streams as JPEG (binary messages), LiDAR scans.
//
// the simulation never waits for the viewer: the loop, render and sensor threads only hand
// shared pointers to the viewer's encoder thread (latest wins per stream), which colours,
// compresses and publishes; the server keeps one pending message per stream and client.

#include <memory>
#include <string>
#include <vector>

#include "penumbra/command/run_bridge.h"
#include "penumbra/viewer/jpeg_encoder.h"

namespace penumbra {

/// settings of the viewer bridge.
struct ViewerOptions {
  std::string host = "127.0.0.1";  ///< address to bind (loopback unless told)
  int port = 8080;                 ///< 0 = any free port (printed at start)
  std::string web_root;            ///< the page's folder; "" = FindWebRoot() (viewer/web_root.h)
  double state_hz = 30;            ///< state messages per wall-clock second while running
  size_t max_message_bytes = 64 * 1024;  ///< largest message accepted from a page
  int max_clients = 64;                  ///< pages connected at once
  /// origins allowed besides the page's own and loopback (--viewer-allow-origin, repeatable;
  /// viewer/web_server.h WebServerOptions::allowed_origins).
  std::vector<std::string> allowed_origins;
  AdaptiveJpegOptions jpeg;              ///< JPEG quality range and byte budget per stream
  /// called once the server listens, with its URL and secret token
  /// ("http://127.0.0.1:PORT/?token=..."; e.g. to print it). may be empty.
  std::function<void(const std::string& url)> on_listening;

  /// @throws ConfigError (key "--viewer" or "viewer.<field>") for a bad host/port, a state
  ///         rate outside (0, 1000] and the errors of the server and JPEG options;
  ///         (key "--viewer-allow-origin") for an origin that is not http(s)://HOST[:PORT].
  void ValidateOrThrow() const;
};

/// the host and port of a --viewer value: "HOST:PORT", "PORT", ":PORT" or "[IPv6]:PORT"; ""
/// keeps `options`' defaults (127.0.0.1:8080).
/// @throws ConfigError("", 0, "--viewer", ...) for a port that is not 0..65535 or an empty host.
void ParseViewerAddress(const std::string& spec, ViewerOptions* options);

/// a factory for RunOptions::bridges (run/runner.h).
RunBridgeFactory MakeViewerBridgeFactory(ViewerOptions options);

}  // namespace penumbra
