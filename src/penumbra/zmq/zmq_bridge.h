#pragma once
// the ZeroMQ bridge of `penumbra run --zmq` (docs/zmq-protocol.md is the wire schema):
//
//   ROUTER (commands)  <- msgpack requests -> CommandDispatcher (command/) -> msgpack replies
//   XPUB   (sensors)   -> [topic, msgpack header, raw payload] for every camera image, LiDAR
//                         scan, IMU / MuJoCo-sensor sample, and the state topics (clock,
//                         joint_states, ground_truth/poses, contacts)
//
// two I/O threads: the command thread owns the ROUTER socket, the publish thread the XPUB socket
// (so ZeroMQ's work on subscriptions, e.g. thousands removed when their subscriber leaves, never
// delays a reply). outgoing publications (from the loop, render and sensor threads) go through
// one queue in call order; replies through another; a lockstep `step` reply is sent only once
// every publication queued before it has been sent, so it always follows the messages of its
// steps. eventfds wake the threads; zmq_poll waits on them and the sockets.
//
// robustness: requests above ZmqBridgeOptions::max_request_bytes get a too_large reply,
// undecodable ones (not msgpack, truncated, too deep) a malformed reply, and the server keeps
// serving; ZeroMQ drops peers that send more than 64 MiB in one message. only topics some
// subscriber wants are formatted and sent (XPUB subscription messages). subscriptions are
// capped: 1024 distinct prefixes, each at most 256 bytes (or the run's longest topic); the
// excess is dropped and logged, subscription messages above twice that make ZeroMQ drop the
// subscriber, and at most 256 are handled per turn of the publish thread. a full subscriber
// queue (SNDHWM) drops that subscriber's messages; a full outgoing queue drops publications
// while the run is running free, and makes the producer wait while it is paused (lockstep).
// shutdown: once the run ended every request gets a `stopping` error reply until the peers
// have been quiet for 0.3 s (3 s at most after the bridge is destroyed); commands queued but
// not carried out get `stopping` from the RunControl (docs/zmq-protocol.md).

#include <cstdint>
#include <memory>
#include <string>

#include "penumbra/command/run_bridge.h"

namespace penumbra {

/// settings of the ZeroMQ bridge (the --zmq flags).
struct ZmqBridgeOptions {
  /// command socket endpoint (ROUTER), e.g. "tcp://127.0.0.1:5555" or "ipc:///tmp/p.sock".
  std::string endpoint = "tcp://127.0.0.1:5555";
  /// publish socket endpoint (XPUB); "" = the command endpoint's port + 1 (tcp only).
  std::string pub_endpoint;
  /// host for both tcp endpoints instead of theirs ("" = as given; default loopback), e.g.
  /// "0.0.0.0" to accept other machines (--bind).
  std::string bind;
  /// send high-water mark per subscriber, messages (ZMQ_SNDHWM), >= 1.
  int hwm = 1000;
  /// requests above this many bytes get a too_large reply, 64 .. 64 MiB.
  int64_t max_request_bytes = 1 << 20;
  /// rate of the state topics (clock, joint_states, ground_truth/poses, contacts), Hz on sim
  /// time; 0 = every physics step.
  double state_hz = 0;
  /// publications waiting in the outgoing queue before the drop policy applies, >= 1.
  int queue_capacity = 256;

  /// @throws ConfigError (key "--zmq", "--zmq-pub", "--bind", "--zmq-hwm",
  ///         "--zmq-max-request", "--zmq-state-hz") for a bad value.
  void ValidateOrThrow() const;
  /// the two endpoints after --bind and the port + 1 rule: {command, publish}.
  /// @throws ConfigError for an endpoint that is not tcp://HOST:PORT or ipc://PATH, an ipc
  ///         command endpoint without pub_endpoint, or a port of 65535 without pub_endpoint.
  std::pair<std::string, std::string> ResolveEndpoints() const;
};

/// a factory for RunOptions::bridges that makes the ZeroMQ bridge; binding happens when the
/// run calls it (@throws Error naming the endpoint when it cannot be bound, e.g. in use).
RunBridgeFactory MakeZmqBridgeFactory(ZmqBridgeOptions options);

}  // namespace penumbra
