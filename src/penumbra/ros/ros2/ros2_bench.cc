#include "penumbra/ros/ros2/ros2_bench.h"

#include <dds/dds.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2_names.h"
#include "penumbra/ros/udp_bind_pin.h"
#include "ros2_msgs.h"

namespace penumbra {

namespace {

constexpr int kTopics = 4;
constexpr const char* kTopicNames[kTopics] = {"/bench/image_raw", "/bench/depth/image_raw",
                                              "/bench/imu/data", "/tf"};
constexpr char kRequest[] = "rq/bench/stepRequest";
constexpr char kReply[] = "rr/bench/stepReply";
constexpr char kTripFrame[] = "trip";

int64_t NowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

builtin_interfaces_msg_dds__Time_ StampOf(int64_t ns) {
  builtin_interfaces_msg_dds__Time_ t{};
  t.sec = static_cast<int32_t>(ns / 1000000000);
  t.nanosec = static_cast<uint32_t>(ns % 1000000000);
  return t;
}

int64_t NsOf(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<int64_t>(t.sec) * 1000000000 + t.nanosec;
}

// what the subscriber sends back through its pipe
struct TopicReport {
  int64_t received = 0;
  double median_ms = 0, p99_ms = 0, max_ms = 0;
};
struct StreamReport {
  std::array<TopicReport, kTopics> topics{};
  char error[256] = {};
};
struct TripReport {
  int32_t trips = 0;
  int32_t resent = 0;  // requests sent again after 1 s without frame and reply
  double median_ms = 0, p99_ms = 0;
  char error[256] = {};
};

void Percentiles(std::vector<double> v, double* median, double* p99, double* max) {
  if (v.empty()) return;
  std::sort(v.begin(), v.end());
  *median = v[v.size() / 2];
  *p99 = v[std::min(v.size() - 1, static_cast<size_t>(static_cast<double>(v.size()) * 0.99))];
  if (max) *max = v.back();
}

// the bridge's configuration for the interface (ros/ros2_names.h), with the UDP receive buffer as
// asked (Cyclone's default: the system's, net.core.rmem_default)
std::string Config(const std::string& address, int64_t receive_buffer) {
  std::string xml = CycloneConfigXml(address);
  if (receive_buffer > 0)
    xml.insert(xml.rfind("</Domain>"), "<Internal><SocketReceiveBufferSize min=\"" +
                                           std::to_string(receive_buffer) + "B\"/></Internal>");
  return xml;
}

// a DDS participant on its own domain entity; everything is deleted with it
struct Participant {
  dds_entity_t domain = 0, pp = 0;
  Participant(int id, const std::string& address, int64_t receive_buffer) {
    // as the bridge: Cyclone's receive sockets pinned to the interface (ros/udp_bind_pin.h)
    const ScopedUdpBindPin pin(address);
    domain =
        dds_create_domain(static_cast<dds_domainid_t>(id), Config(address, receive_buffer).c_str());
    if (domain < 0)
      throw Error("bench ros2: cannot start DDS on " + address + ": " + dds_strretcode(domain));
    pp = dds_create_participant(static_cast<dds_domainid_t>(id), nullptr, nullptr);
    if (pp < 0) {
      dds_delete(domain);
      throw Error(std::string("bench ros2: cannot create a DDS participant: ") +
                  dds_strretcode(pp));
    }
  }
  ~Participant() { dds_delete(domain); }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t Topic(const dds_topic_descriptor_t* desc, const std::string& name) const {
    const dds_entity_t t = dds_create_topic(pp, desc, name.c_str(), nullptr, nullptr);
    if (t < 0)
      throw Error("bench ros2: cannot create the topic " + name + ": " + dds_strretcode(t));
    return t;
  }
};

// a ROS 2 profile of the bridge (ros/ros2_names.h: sensor data, /tf, services), XCDR1 as
// rmw_cyclonedds
dds_qos_t* Qos(const Ros2QosProfile& profile) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, profile.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, profile.depth);
  dds_qset_durability(
      q, profile.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  return q;
}

struct TopicSpec {
  const dds_topic_descriptor_t* desc;
  Ros2QosProfile qos;  // the bridge's writer QoS of such a topic
};
const std::array<TopicSpec, kTopics>& Specs() {
  static const std::array<TopicSpec, kTopics> specs = {{
      {&sensor_msgs_msg_dds__Image__desc, Ros2WriterQos(RosTopicType::kImage)},
      {&sensor_msgs_msg_dds__Image__desc, Ros2WriterQos(RosTopicType::kImage)},
      {&sensor_msgs_msg_dds__Imu__desc, Ros2WriterQos(RosTopicType::kImu)},
      {&tf2_msgs_msg_dds__TFMessage__desc, Ros2WriterQos(RosTopicType::kTf)},
  }};
  return specs;
}

dds_entity_t MakeEndpoint(const Participant& p, const dds_topic_descriptor_t* desc,
                          const std::string& dds_name, const Ros2QosProfile& qos, bool writer) {
  dds_qos_t* q = Qos(qos);
  const dds_entity_t topic = p.Topic(desc, dds_name);
  const dds_entity_t e = writer ? dds_create_writer(p.pp, topic, q, nullptr)
                                : dds_create_reader(p.pp, topic, q, nullptr);
  dds_delete_qos(q);
  if (e < 0)
    throw Error("bench ros2: cannot create a " + std::string(writer ? "writer" : "reader") +
                " on " + dds_name + ": " + dds_strretcode(e));
  return e;
}

void WriteAll(int fd, const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(3);
    p += n;
    size -= static_cast<size_t>(n);
  }
}

// reads exactly size bytes, false at end of file or after timeout_ms without data
bool ReadAll(int fd, void* data, size_t size, int timeout_ms) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    pollfd pfd{fd, POLLIN, 0};
    const int r = poll(&pfd, 1, timeout_ms);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    const ssize_t n = read(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

bool Readable(int fd) {
  pollfd pfd{fd, POLLIN, 0};
  return poll(&pfd, 1, 0) > 0;
}

// waits until every writer has a matched reader and every reader a matched writer
bool WaitMatched(const std::vector<dds_entity_t>& writers, const std::vector<dds_entity_t>& readers,
                 double seconds) {
  const int64_t end = NowNs() + static_cast<int64_t>(seconds * 1e9);
  while (NowNs() < end) {
    bool all = true;
    for (dds_entity_t w : writers) {
      dds_publication_matched_status_t s{};
      if (dds_get_publication_matched_status(w, &s) < 0 || s.current_count < 1) all = false;
    }
    for (dds_entity_t r : readers) {
      dds_subscription_matched_status_t s{};
      if (dds_get_subscription_matched_status(r, &s) < 0 || s.current_count < 1) all = false;
    }
    if (all) return true;
    usleep(10000);
  }
  return false;
}

// --- the subscriber (child process) ----------------------------------------------------------

[[noreturn]] void RunSubscriber(const Ros2BenchOptions& o, int domain, int to_parent,
                                int from_parent) {
  StreamReport stream;
  TripReport trip;
  bool stream_sent = false;
  try {
    Participant p(domain, o.interface, o.receive_buffer);
    std::array<dds_entity_t, kTopics> readers{};
    std::array<std::vector<double>, kTopics> latencies;
    const dds_entity_t ws = dds_create_waitset(p.pp);
    for (int i = 0; i < kTopics; ++i) {
      // subscribers ask for what ROS 2 subscribers ask for: the same profiles
      readers[i] = MakeEndpoint(p, Specs()[i].desc, std::string("rt") + kTopicNames[i],
                                Specs()[i].qos, false);
      dds_waitset_attach(ws, dds_create_readcondition(readers[i], DDS_ANY_STATE), i);
    }
    const dds_entity_t request =
        MakeEndpoint(p, &std_srvs_srv_dds__Trigger_Request__desc, kRequest, kRos2DefaultQos, true);
    const dds_entity_t reply =
        MakeEndpoint(p, &std_srvs_srv_dds__Trigger_Response__desc, kReply, kRos2DefaultQos, false);
    const dds_entity_t reply_cond = dds_create_readcondition(reply, DDS_ANY_STATE);
    dds_waitset_attach(ws, reply_cond, kTopics);

    constexpr int kBatch = 64;
    void* samples[kBatch];
    dds_sample_info_t infos[kBatch];
    bool trip_frame = false;
    int64_t trip_seq = 0;
    bool trip_replied = false;
    // takes what is there; stream samples are timed, trip frames and replies noted
    auto drain = [&](bool timing) {
      for (int i = 0; i < kTopics; ++i) {
        for (;;) {
          std::fill(std::begin(samples), std::end(samples), nullptr);
          const int n = dds_take(readers[i], samples, infos, kBatch, kBatch);
          if (n <= 0) break;
          const int64_t now = NowNs();
          for (int k = 0; k < n; ++k) {
            if (!infos[k].valid_data) continue;
            int64_t stamp = 0;
            const char* frame = "";
            if (i < 2) {
              const auto* m = static_cast<const sensor_msgs_msg_dds__Image_*>(samples[k]);
              stamp = NsOf(m->header.stamp);
              frame = m->header.frame_id ? m->header.frame_id : "";
            } else if (i == 2) {
              stamp = NsOf(static_cast<const sensor_msgs_msg_dds__Imu_*>(samples[k])->header.stamp);
            } else {
              const auto* m = static_cast<const tf2_msgs_msg_dds__TFMessage_*>(samples[k]);
              if (m->transforms._length > 0) stamp = NsOf(m->transforms._buffer[0].header.stamp);
            }
            if (std::strcmp(frame, kTripFrame) == 0) {
              if (stamp == trip_seq) trip_frame = true;
            } else if (timing) {
              latencies[i].push_back(static_cast<double>(now - stamp) * 1e-6);
            }
          }
          dds_return_loan(readers[i], samples, n);
        }
      }
      for (;;) {
        std::fill(std::begin(samples), std::end(samples), nullptr);
        const int n = dds_take(reply, samples, infos, kBatch, kBatch);
        if (n <= 0) break;
        for (int k = 0; k < n; ++k) {
          const auto* r = static_cast<const std_srvs_srv_dds__Trigger_Response_*>(samples[k]);
          if (infos[k].valid_data && r->sequence_number == trip_seq && r->success)
            trip_replied = true;
        }
        dds_return_loan(reply, samples, n);
      }
    };

    // 1. streams until the parent says they ended (one byte), then a last drain
    dds_attach_t triggered[kTopics + 1];
    for (;;) {
      dds_waitset_wait(ws, triggered, kTopics + 1, DDS_MSECS(20));
      drain(true);
      if (Readable(from_parent)) {
        char c = 0;
        if (read(from_parent, &c, 1) != 1) _exit(2);
        break;
      }
    }
    usleep(200000);
    drain(true);
    for (int i = 0; i < kTopics; ++i) {
      stream.topics[i].received = static_cast<int64_t>(latencies[i].size());
      Percentiles(latencies[i], &stream.topics[i].median_ms, &stream.topics[i].p99_ms,
                  &stream.topics[i].max_ms);
    }
    WriteAll(to_parent, &stream, sizeof stream);
    stream_sent = true;

    // 2. lockstep round trips, as a ROS 2 client calls a Trigger service
    std::vector<double> trips;
    const uint64_t guid = 0x5045'4E55'4D42'5241ull;  // any client id
    for (int i = 1; i <= o.trips; ++i) {
      trip_seq = i;
      trip_frame = trip_replied = false;
      std_srvs_srv_dds__Trigger_Request_ rq{};
      rq.client_guid = guid;
      rq.sequence_number = i;
      const int64_t t0 = NowNs();
      // the frame travels best effort: a lost one is asked for again after 1 s (counted)
      for (int attempt = 0; attempt < 5 && !(trip_frame && trip_replied); ++attempt) {
        if (attempt > 0) ++trip.resent;
        if (dds_write(request, &rq) < 0) throw Error("bench ros2: cannot write a request");
        const int64_t deadline = NowNs() + 1000000000;
        while (!(trip_frame && trip_replied) && NowNs() < deadline) {
          dds_waitset_wait(ws, triggered, kTopics + 1, DDS_MSECS(5));
          drain(false);
        }
      }
      if (!(trip_frame && trip_replied))
        throw Error("bench ros2: no frame and reply to request " + std::to_string(i) +
                    " within 5 s");
      trips.push_back(static_cast<double>(NowNs() - t0) * 1e-6);
    }
    trip.trips = static_cast<int32_t>(trips.size());
    Percentiles(trips, &trip.median_ms, &trip.p99_ms, nullptr);
  } catch (const std::exception& e) {
    std::snprintf(trip.error, sizeof trip.error, "%s", e.what());
    std::snprintf(stream.error, sizeof stream.error, "%s", e.what());
  }
  if (!stream_sent) WriteAll(to_parent, &stream, sizeof stream);
  WriteAll(to_parent, &trip, sizeof trip);
  _exit(0);
}

// --- the publisher (this process) --------------------------------------------------------------

void Check(const Ros2BenchOptions& o) {
  if (o.domain < -1 || o.domain > 232)
    throw Error("bench ros2: --ros-domain " + std::to_string(o.domain) +
                ": expected 0..232 (ROS 2's domain ids)");
  CheckInterfaceAddress(o.interface);
  if (o.width < 1 || o.width > 8192 || o.height < 1 || o.height > 8192)
    throw Error("bench ros2: image size: expected 1..8192 x 1..8192 pixels");
  auto rate = [](double hz, const char* what) {
    if (!(hz > 0 && hz <= 10000))
      throw Error(std::string("bench ros2: ") + what + ": expected (0, 10000] per second");
  };
  rate(o.camera_hz, "camera rate");
  rate(o.imu_hz, "IMU rate");
  rate(o.tf_hz, "/tf rate");
  if (!(o.seconds > 0 && o.seconds <= 600)) throw Error("bench ros2: --seconds: expected (0, 600]");
  if (o.trips < 1 || o.trips > 1000000) throw Error("bench ros2: --trips: expected 1..1000000");
  if (o.receive_buffer < 0 || o.receive_buffer > (int64_t{1} << 31))
    throw Error("bench ros2: --receive-buffer: expected 0 (the system's default) .. 2 GiB");
}

}  // namespace

Ros2BenchResult RunRos2Bench(const Ros2BenchOptions& o) {
  Check(o);
  Ros2BenchResult r;
  r.domain = o.domain;
  if (r.domain < 0) {
    std::random_device seed;
    r.domain = std::uniform_int_distribution<int>(100, 232)(seed);
  }
  int up[2], down[2];
  if (pipe(up) != 0) throw Error("bench ros2: cannot create a pipe");
  if (pipe(down) != 0) {
    close(up[0]);
    close(up[1]);
    throw Error("bench ros2: cannot create a pipe");
  }
  const pid_t child = fork();
  if (child < 0) throw Error("bench ros2: cannot fork the subscriber");
  if (child == 0) {
    close(up[0]);
    close(down[1]);
    RunSubscriber(o, r.domain, up[1], down[0]);
  }
  close(up[1]);
  close(down[0]);
  struct Reap {
    pid_t pid;
    int from_child, to_child;
    ~Reap() {
      close(to_child);
      close(from_child);
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  } reap{child, up[0], down[1]};

  Participant p(r.domain, o.interface, o.receive_buffer);
  std::array<dds_entity_t, kTopics> writers{};
  for (int i = 0; i < kTopics; ++i)
    writers[i] =
        MakeEndpoint(p, Specs()[i].desc, std::string("rt") + kTopicNames[i], Specs()[i].qos, true);
  const dds_entity_t request =
      MakeEndpoint(p, &std_srvs_srv_dds__Trigger_Request__desc, kRequest, kRos2DefaultQos, false);
  const dds_entity_t reply =
      MakeEndpoint(p, &std_srvs_srv_dds__Trigger_Response__desc, kReply, kRos2DefaultQos, true);
  if (!WaitMatched({writers[0], writers[1], writers[2], writers[3], reply}, {request}, 20))
    throw Error("bench ros2: the subscriber process did not match within 20 s (domain " +
                std::to_string(r.domain) + " on " + o.interface + ")");
  usleep(300000);

  // pre-rendered messages: an rgb gradient, a depth ramp in metres, an IMU at rest, one pose
  std::vector<uint8_t> rgb(static_cast<size_t>(o.width) * o.height * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 7);
  std::vector<float> depth(static_cast<size_t>(o.width) * o.height);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = 0.5f + static_cast<float>(i % 997) * 0.01f;
  char frame_rgb[] = "bench/optical", enc_rgb[] = "rgb8", enc_depth[] = "32FC1";
  char trip_frame[] = "trip", imu_frame[] = "bench_imu", odom[] = "odom", base[] = "base_link";
  sensor_msgs_msg_dds__Image_ image{};
  image.height = static_cast<uint32_t>(o.height);
  image.width = static_cast<uint32_t>(o.width);
  image.encoding = enc_rgb;
  image.step = image.width * 3;
  image.data._buffer = rgb.data();
  image.data._length = image.data._maximum = static_cast<uint32_t>(rgb.size());
  image.header.frame_id = frame_rgb;
  sensor_msgs_msg_dds__Image_ depth_image = image;
  depth_image.encoding = enc_depth;
  depth_image.step = image.width * 4;
  depth_image.data._buffer = reinterpret_cast<uint8_t*>(depth.data());
  depth_image.data._length = depth_image.data._maximum =
      static_cast<uint32_t>(depth.size() * sizeof(float));
  sensor_msgs_msg_dds__Imu_ imu{};
  imu.header.frame_id = imu_frame;
  imu.orientation.w = 1;
  imu.orientation_covariance[0] = -1;
  imu.linear_acceleration.z = 9.81;
  geometry_msgs_msg_dds__TransformStamped_ pose{};
  pose.header.frame_id = odom;
  pose.child_frame_id = base;
  pose.transform.rotation.w = 1;
  tf2_msgs_msg_dds__TFMessage_ tf{};
  tf.transforms._buffer = &pose;
  tf.transforms._length = tf.transforms._maximum = 1;

  // 1. streams: each topic at its own rate, samples stamped with the monotonic clock
  const std::array<double, kTopics> hz = {o.camera_hz, o.camera_hz, o.imu_hz, o.tf_hz};
  std::array<int64_t, kTopics> next{};
  const int64_t start = NowNs(), end = start + static_cast<int64_t>(o.seconds * 1e9);
  for (int i = 0; i < kTopics; ++i) next[i] = start;
  if (!o.depth) next[1] = end;  // never sent
  std::array<int64_t, kTopics> sent{};
  for (;;) {
    const int i = static_cast<int>(std::min_element(next.begin(), next.end()) - next.begin());
    if (next[i] >= end) break;
    const int64_t wait = next[i] - NowNs();
    if (wait > 0) {
      const timespec ts{static_cast<time_t>(wait / 1000000000),
                        static_cast<long>(wait % 1000000000)};
      nanosleep(&ts, nullptr);
    }
    const builtin_interfaces_msg_dds__Time_ stamp = StampOf(NowNs());
    dds_return_t rc = 0;
    if (i == 0) {
      image.header.stamp = stamp;
      rc = dds_write(writers[0], &image);
    } else if (i == 1) {
      depth_image.header.stamp = stamp;
      rc = dds_write(writers[1], &depth_image);
    } else if (i == 2) {
      imu.header.stamp = stamp;
      rc = dds_write(writers[2], &imu);
    } else {
      pose.header.stamp = stamp;
      rc = dds_write(writers[3], &tf);
    }
    if (rc >= 0) ++sent[i];
    next[i] = start + static_cast<int64_t>(static_cast<double>(sent[i] + 1) * 1e9 / hz[i]);
    if (rc < 0) next[i] = NowNs() + static_cast<int64_t>(1e9 / hz[i]);
  }
  usleep(300000);
  const char go = 'e';
  if (write(reap.to_child, &go, 1) != 1) throw Error("bench ros2: the subscriber went away");
  StreamReport stream;
  if (!ReadAll(reap.from_child, &stream, sizeof stream, 60000))
    throw Error("bench ros2: the subscriber process ended without a report");
  if (stream.error[0]) throw Error(std::string("bench ros2: subscriber: ") + stream.error);
  const int64_t sizes[kTopics] = {
      static_cast<int64_t>(rgb.size()), static_cast<int64_t>(depth.size() * sizeof(float)),
      static_cast<int64_t>(sizeof imu), static_cast<int64_t>(sizeof pose)};
  for (int i = 0; i < kTopics; ++i) {
    Ros2TopicStats s;
    s.topic = kTopicNames[i];
    const Ros2QosProfile& q = Specs()[i].qos;
    s.qos = std::string(q.reliable ? "RELIABLE" : "BEST_EFFORT") + " KEEP_LAST " +
            std::to_string(q.depth);
    s.sent = sent[i];
    s.received = stream.topics[i].received;
    s.median_ms = stream.topics[i].median_ms;
    s.p99_ms = stream.topics[i].p99_ms;
    s.max_ms = stream.topics[i].max_ms;
    s.bytes = sizes[i];
    r.topics.push_back(s);
  }

  // 2. serve the round trips: each request answered with one rgb frame, then the reply
  const dds_entity_t ws = dds_create_waitset(p.pp);
  dds_waitset_attach(ws, dds_create_readcondition(request, DDS_ANY_STATE), 0);
  char ok[] = "step";
  TripReport trip;
  for (;;) {
    dds_attach_t triggered[1];
    dds_waitset_wait(ws, triggered, 1, DDS_MSECS(20));
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    const int n = dds_take(request, samples, infos, 16, 16);
    for (int k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      const auto* rq = static_cast<const std_srvs_srv_dds__Trigger_Request_*>(samples[k]);
      image.header.frame_id = trip_frame;
      image.header.stamp = StampOf(rq->sequence_number);
      dds_write(writers[0], &image);
      std_srvs_srv_dds__Trigger_Response_ rs{};
      rs.client_guid = rq->client_guid;
      rs.sequence_number = rq->sequence_number;
      rs.success = true;
      rs.message = ok;
      dds_write(reply, &rs);
    }
    if (n > 0) dds_return_loan(request, samples, n);
    if (Readable(reap.from_child)) {
      if (!ReadAll(reap.from_child, &trip, sizeof trip, 10000))
        throw Error("bench ros2: the subscriber process ended without a report");
      break;
    }
  }
  if (trip.error[0]) throw Error(std::string("bench ros2: subscriber: ") + trip.error);
  r.trips = trip.trips;
  r.trips_resent = trip.resent;
  r.trip_median_ms = trip.median_ms;
  r.trip_p99_ms = trip.p99_ms;
  return r;
}

}  // namespace penumbra
