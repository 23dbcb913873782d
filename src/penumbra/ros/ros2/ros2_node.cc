#include "penumbra/ros/ros2/ros2_node.h"

#include <dds/dds.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <iterator>
#include <map>
#include <mutex>
#include <thread>
#include <tuple>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_types.h"
#include "penumbra/ros/ros2_names.h"
#include "penumbra/ros/udp_bind_pin.h"

namespace penumbra {

namespace {

// samples taken from a reader at once
constexpr uint32_t kTakeBatch = 16;
// how long a service waits for its reply writer to match the caller's reply reader
constexpr auto kReplyMatchWait = std::chrono::milliseconds(500);

std::string DdsError(dds_return_t rc) { return dds_strretcode(rc); }

// a DDS entity, or Error naming what failed and Cyclone's reason
dds_entity_t Check(dds_entity_t e, const std::string& what) {
  if (e < 0) throw Error(fmt::format("cannot create {}: {}", what, DdsError(e)));
  return e;
}

struct QosDeleter {
  void operator()(dds_qos_t* q) const { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;

// ros_discovery_info's QoS (rmw_dds_common): a late reader gets the last graph update
constexpr Ros2QosProfile kDiscoveryInfoQos{true, true, 1};

// a ROS 2 QoS profile and REP-2011's type hash user data
// (`user_data_prefix`: more "key=value;" pairs before the type hash, as rmw_cyclonedds's
// serviceid)
QosPtr MakeQos(const Ros2QosProfile& profile, const char* type_hash,
               const std::string& user_data_prefix = "") {
  QosPtr q(dds_create_qos());
  // a KEEP_LAST writer drops its oldest sample instead of waiting for a slow reader; should
  // Cyclone still throttle it, a write gives up after max_blocking_time (the DDS default)
  dds_qset_reliability(q.get(),
                       profile.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_durability(
      q.get(), profile.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, profile.depth);
  // rmw_cyclonedds: samples of a deleted writer are not disposed (ROS 2 has no instances)
  dds_qset_writer_data_lifecycle(q.get(), false);
  const std::string user_data = fmt::format("{}typehash={};", user_data_prefix, type_hash);
  dds_qset_userdata(q.get(), user_data.data(), user_data.size());
  return q;
}

}  // namespace

struct Ros2Node::Impl {
  Options options;
  dds_entity_t domain = 0, participant = 0;
  dds_entity_t stop = 0;                       // guard condition that ends every callback thread
  std::map<std::string, dds_entity_t> topics;  // DDS topic name -> topic

  struct Publisher {
    std::string name;
    RosTopicType type;
    dds_entity_t writer;
  };
  std::vector<Publisher> publishers;  // fixed before Start (Advertise is a set-up call)
  mutable std::mutex mutex;           // guards publishers and params

  struct Reader {
    std::string topic;  // ROS name, for the log
    dds_entity_t reader;
    std::function<void(const void*)> on_sample;
  };
  std::vector<Reader> readers;

  struct Service {
    std::string name;
    dds_entity_t request_reader, reply_writer;
    std::function<std::pair<bool, std::string>()> callback;
  };
  std::vector<Service> services;

  std::map<std::string, int64_t> params;
  dds_entity_t discovery_writer = 0;  // ros_discovery_info
  std::vector<std::thread> threads;   // subscriptions, then one per service
  bool started = false;

  // idlc's descriptors without their XTypes type information, one per type used
  std::map<Ros2Type, std::unique_ptr<dds_topic_descriptor_t>> descriptors;

  // the descriptor of `type` without XTypes type information: rmw_cyclonedds's topics carry
  // none either (ROS 2 matches on the type name), and with it Cyclone 0.10 asks a peer whose
  // type ids differ (e.g. a Cyclone 0.11 peer that types uint8 as TK_UINT8, not octet) for its
  // type objects and crashes on the answer: a network peer could end the run
  const dds_topic_descriptor_t* Descriptor(Ros2Type type) {
    auto& d = descriptors[type];
    if (!d) {
      const dds_topic_descriptor_t& s = *Ros2TypeOf(type).descriptor;
      d.reset(new dds_topic_descriptor_t{
          s.m_size,
          s.m_align,
          s.m_flagset & ~static_cast<uint32_t>(DDS_TOPIC_XTYPES_METADATA),
          s.m_nkeys,
          s.m_typename,
          s.m_keys,
          s.m_nops,
          s.m_ops,
          s.m_meta,
          {nullptr, 0},
          {nullptr, 0},
          s.restrict_data_representation});
    }
    return d.get();
  }

  dds_entity_t Topic(const std::string& dds_name, Ros2Type type) {
    auto it = topics.find(dds_name);
    if (it != topics.end()) return it->second;
    const Ros2TypeInfo& info = Ros2TypeOf(type);
    const dds_entity_t t =
        Check(dds_create_topic(participant, Descriptor(type), dds_name.c_str(), nullptr, nullptr),
              fmt::format("the DDS topic {} ({})", dds_name, info.dds_name));
    topics[dds_name] = t;
    return t;
  }

  dds_entity_t Writer(int id, RosTopicType type) const {
    std::lock_guard<std::mutex> lock(mutex);
    if (id < 0 || id >= static_cast<int>(publishers.size()))
      throw Error(fmt::format("no ROS 2 publisher {}", id));
    const Publisher& p = publishers[id];
    if (p.type != type && !(type == RosTopicType::kTf && p.type == RosTopicType::kTfStatic))
      throw Error("ROS 2 publisher " + p.name + " has another message type");
    return p.writer;
  }

  void Write(dds_entity_t writer, const void* sample, const std::string& what) {
    const dds_return_t rc = dds_write(writer, sample);
    if (rc < 0) spdlog::warn("ROS 2 bridge: cannot publish on {}: {}", what, DdsError(rc));
  }

  // takes every sample `reader` holds, in batches, and hands each valid one to `f`; Cyclone
  // lends the samples for the call
  static void TakeEach(dds_entity_t reader, const std::function<void(const void*)>& f) {
    void* samples[kTakeBatch];
    dds_sample_info_t infos[kTakeBatch];
    for (;;) {
      // a null first pointer asks Cyclone to lend its samples (returned below)
      std::fill(std::begin(samples), std::end(samples), nullptr);
      const dds_return_t n = dds_take(reader, samples, infos, kTakeBatch, kTakeBatch);
      if (n <= 0) return;
      for (dds_return_t i = 0; i < n; ++i)
        if (infos[i].valid_data) f(samples[i]);
      dds_return_loan(reader, samples, n);
    }
  }

  // takes every sample of `r` and hands each valid one to its callback
  void TakeAll(const Reader& r) {
    TakeEach(r.reader, [&](const void* sample) {
      try {
        r.on_sample(sample);
      } catch (const std::exception& e) {
        spdlog::warn("ROS 2 bridge: a message on {} was dropped: {}", r.topic, e.what());
      }
    });
  }

  void Serve(const Service& s) {
    TakeEach(s.request_reader, [&](const void* request) {
      Ros2TriggerResponse reply;
      try {
        reply.header = TriggerRequestFromSample(request);
      } catch (const std::exception& e) {
        spdlog::warn("ROS 2 bridge: a request to {} was dropped: {}", s.name, e.what());
        return;
      }
      try {
        std::tie(reply.success, reply.message) = s.callback();
      } catch (const std::exception& e) {
        reply.success = false;
        reply.message = e.what();
      }
      // the caller made its reply reader before it sent the request; a reply written before
      // the two have matched would be lost (volatile), so wait for a match (bounded)
      const auto deadline = std::chrono::steady_clock::now() + kReplyMatchWait;
      dds_publication_matched_status_t st{};
      while (dds_get_publication_matched_status(s.reply_writer, &st) == DDS_RETCODE_OK &&
             st.current_count == 0 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      WithSample(reply, [&](const void* sample) {
        Write(s.reply_writer, sample, Ros2ReplyTopic(s.name));
      });
    });
  }

  // waits on `waitset` until its guard condition (attached as `count`) triggers;
  // `on_trigger(index)` for each triggered reader (attached as its index)
  static void Loop(dds_entity_t waitset, const std::function<void(size_t)>& on_trigger,
                   size_t count) {
    std::vector<dds_attach_t> triggered(count + 1);
    for (;;) {
      const dds_return_t n =
          dds_waitset_wait(waitset, triggered.data(), triggered.size(), DDS_INFINITY);
      if (n < 0) {
        spdlog::error("ROS 2 bridge: waiting for DDS samples failed: {}", DdsError(n));
        return;
      }
      for (dds_return_t i = 0; i < n; ++i) {
        const auto a = static_cast<size_t>(triggered[i]);
        if (a == count) return;
        if (a < count) on_trigger(a);
      }
    }
  }
};

Ros2Node::Ros2Node(const Options& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  if (options.domain_id < 0 || options.domain_id > kRos2MaxDomainId)
    throw ConfigError("", 0, "--ros-domain",
                      fmt::format("{} is not a ROS 2 domain id; expected an integer in [0, {}]",
                                  options.domain_id, kRos2MaxDomainId));
  const std::string xml = CycloneConfigXml(options.interface_address);
  const auto domain_id = static_cast<dds_domainid_t>(options.domain_id);
  // Cyclone creates its sockets in these calls; its receive sockets would otherwise listen on
  // every interface (ros/udp_bind_pin.h)
  const ScopedUdpBindPin pin(options.interface_address);
  m.domain = dds_create_domain(domain_id, xml.c_str());
  if (m.domain < 0)
    throw Error(fmt::format("cannot create ROS 2 domain {} on {}: {}{}", options.domain_id,
                            options.interface_address, DdsError(m.domain),
                            m.domain == DDS_RETCODE_PRECONDITION_NOT_MET
                                ? " (a ROS 2 node of this process already uses the domain)"
                                : " (is the address one of this machine's network interfaces?)"));
  QosPtr pq(dds_create_qos());
  // rmw_cyclonedds: the participant's security enclave, "/" without ROS 2 security
  const std::string enclave = "enclave=/;";
  dds_qset_userdata(pq.get(), enclave.data(), enclave.size());
  m.participant = dds_create_participant(domain_id, pq.get(), nullptr);
  if (m.participant < 0) {
    const dds_return_t rc = m.participant;
    dds_delete(m.domain);
    throw Error(fmt::format("cannot create the ROS 2 participant in domain {} on {}: {}",
                            options.domain_id, options.interface_address, DdsError(rc)));
  }
}

Ros2Node::~Ros2Node() {
  Impl& m = *impl_;
  if (m.stop > 0) dds_set_guardcondition(m.stop, true);
  for (std::thread& t : m.threads) t.join();
  // deleting the domain deletes the participant and everything in it
  dds_delete(m.domain);
}

int Ros2Node::Advertise(const std::string& topic, RosTopicType type, int) {
  Impl& m = *impl_;
  const Ros2Type t = Ros2TypeOfTopic(type);
  const std::string dds_name = Ros2TopicName(topic);
  const QosPtr q = MakeQos(Ros2WriterQos(type), Ros2TypeOf(t).type_hash);
  const dds_entity_t w =
      Check(dds_create_writer(m.participant, m.Topic(dds_name, t), q.get(), nullptr),
            "the ROS 2 publisher " + topic);
  std::lock_guard<std::mutex> lock(m.mutex);
  m.publishers.push_back({topic, type, w});
  return static_cast<int>(m.publishers.size()) - 1;
}

int Ros2Node::Subscribers(int id) const {
  dds_entity_t w = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (id < 0 || id >= static_cast<int>(impl_->publishers.size())) return 0;
    w = impl_->publishers[id].writer;
  }
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(w, &st) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(st.current_count);
}

void Ros2Node::Publish(int id, RosImage&& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kImage);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "an image topic"); });
}
void Ros2Node::Publish(int id, const RosCameraInfo& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kCameraInfo);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "a camera_info topic"); });
}
void Ros2Node::Publish(int id, RosPointCloud2&& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kPointCloud2);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "a points topic"); });
}
void Ros2Node::Publish(int id, const RosImu& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kImu);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "an imu topic"); });
}
void Ros2Node::Publish(int id, const RosJointState& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kJointState);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "a joint_states topic"); });
}
void Ros2Node::Publish(int id, const RosOdometry& m) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kOdometry);
  WithSample(m, [&](const void* s) { impl_->Write(w, s, "an odom topic"); });
}
void Ros2Node::Publish(int id, const std::vector<RosTransform>& transforms) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kTf);
  WithSample(transforms, [&](const void* s) { impl_->Write(w, s, "/tf"); });
}
void Ros2Node::PublishClock(int id, int64_t stamp_ns) {
  const dds_entity_t w = impl_->Writer(id, RosTopicType::kClock);
  WithClockSample(stamp_ns, [&](const void* s) { impl_->Write(w, s, "/clock"); });
}

namespace {
// a reader with the subscription QoS (RELIABLE KEEP_LAST 10 VOLATILE)
dds_entity_t MakeReader(dds_entity_t participant, dds_entity_t topic, Ros2Type type,
                        const std::string& what) {
  const QosPtr q = MakeQos(kRos2DefaultQos, Ros2TypeOf(type).type_hash);
  return Check(dds_create_reader(participant, topic, q.get(), nullptr), what);
}
}  // namespace

void Ros2Node::SubscribeTwist(const std::string& topic,
                              std::function<void(const RosTwist&)> callback) {
  Impl& m = *impl_;
  const dds_entity_t r = MakeReader(m.participant, m.Topic(Ros2TopicName(topic), Ros2Type::kTwist),
                                    Ros2Type::kTwist, "the ROS 2 subscription " + topic);
  m.readers.push_back({topic, r, [callback](const void* s) { callback(TwistFromSample(s)); }});
}

void Ros2Node::SubscribeJointState(const std::string& topic,
                                   std::function<void(const RosJointState&)> callback) {
  Impl& m = *impl_;
  const dds_entity_t r =
      MakeReader(m.participant, m.Topic(Ros2TopicName(topic), Ros2Type::kJointState),
                 Ros2Type::kJointState, "the ROS 2 subscription " + topic);
  m.readers.push_back({topic, r, [callback](const void* s) { callback(JointStateFromSample(s)); }});
}

void Ros2Node::SubscribePose(const std::string& topic,
                             std::function<void(const RosPoseStamped&)> callback) {
  Impl& m = *impl_;
  const dds_entity_t r =
      MakeReader(m.participant, m.Topic(Ros2TopicName(topic), Ros2Type::kPoseStamped),
                 Ros2Type::kPoseStamped, "the ROS 2 subscription " + topic);
  m.readers.push_back(
      {topic, r, [callback](const void* s) { callback(PoseStampedFromSample(s)); }});
}

void Ros2Node::AdvertiseTrigger(const std::string& service,
                                std::function<std::pair<bool, std::string>()> callback) {
  Impl& m = *impl_;
  const std::string what = "the ROS 2 service " + service;
  // rmw_cyclonedds pairs a service's request reader and reply writer by the "serviceid=" of
  // their USER_DATA (a client waits for both halves of one service): 16 bytes, the
  // participant's GUID prefix and a counter, as hex bytes joined by '.'
  dds_guid_t guid;
  std::array<uint8_t, 16> id{};
  if (dds_get_guid(m.participant, &guid) == DDS_RETCODE_OK)
    std::copy(guid.v, guid.v + 12, id.begin());
  const auto n = static_cast<uint32_t>(m.services.size() + 1);
  for (int i = 0; i < 4; ++i) id[12 + i] = static_cast<uint8_t>(n >> (24 - 8 * i));
  std::string service_id = "serviceid=";
  for (size_t i = 0; i < id.size(); ++i) service_id += fmt::format("{}{:x}", i ? "." : "", id[i]);
  service_id += ";";
  const QosPtr rq =
      MakeQos(kRos2DefaultQos, Ros2TypeOf(Ros2Type::kTriggerRequest).type_hash, service_id);
  const dds_entity_t r =
      Check(dds_create_reader(m.participant,
                              m.Topic(Ros2RequestTopic(service), Ros2Type::kTriggerRequest),
                              rq.get(), nullptr),
            what);
  const QosPtr wq =
      MakeQos(kRos2DefaultQos, Ros2TypeOf(Ros2Type::kTriggerResponse).type_hash, service_id);
  const dds_entity_t w = Check(
      dds_create_writer(m.participant, m.Topic(Ros2ReplyTopic(service), Ros2Type::kTriggerResponse),
                        wq.get(), nullptr),
      what);
  m.services.push_back({service, r, w, std::move(callback)});
}

int64_t Ros2Node::IntParam(const std::string& name, int64_t fallback) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const auto it = impl_->params.find(name);
  return it == impl_->params.end() ? fallback : it->second;
}

void Ros2Node::SetParam(const std::string& name, int64_t value) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->params[name] = value;
}

namespace {
// the GID of a DDS entity as rmw_cyclonedds makes it: the 16-byte GUID
Ros2ParticipantEntities::Gid GidOf(dds_entity_t e) {
  dds_guid_t guid;
  Ros2ParticipantEntities::Gid gid{};
  if (dds_get_guid(e, &guid) == DDS_RETCODE_OK)
    std::copy(std::begin(guid.v), std::end(guid.v), gid.begin());
  return gid;
}
}  // namespace

void Ros2Node::Start() {
  Impl& m = *impl_;
  if (m.started) return;
  m.started = true;
  // ros_discovery_info: ROS 2's graph (`ros2 node list`, rmw_dds_common) learns which node owns
  // which readers and writers from it; RELIABLE TRANSIENT_LOCAL KEEP_LAST 1, no "rt/" prefix
  {
    Ros2ParticipantEntities info;
    info.gid = GidOf(m.participant);
    Ros2ParticipantEntities::Node node;
    node.node_namespace = "/";
    node.node_name = m.options.name;
    for (const Impl::Publisher& p : m.publishers) node.writers.push_back(GidOf(p.writer));
    for (const Impl::Reader& r : m.readers) node.readers.push_back(GidOf(r.reader));
    for (const Impl::Service& sv : m.services) {
      node.readers.push_back(GidOf(sv.request_reader));
      node.writers.push_back(GidOf(sv.reply_writer));
    }
    info.nodes.push_back(std::move(node));
    const QosPtr q =
        MakeQos(kDiscoveryInfoQos, Ros2TypeOf(Ros2Type::kParticipantEntitiesInfo).type_hash);
    m.discovery_writer =
        Check(dds_create_writer(m.participant,
                                m.Topic("ros_discovery_info", Ros2Type::kParticipantEntitiesInfo),
                                q.get(), nullptr),
              "the ros_discovery_info writer");
    WithSample(info, [&](const void* s) { m.Write(m.discovery_writer, s, "ros_discovery_info"); });
  }
  // one thread for every subscription; one per service, so that a long call (a step of many
  // physics steps) does not hold back another (pause)
  m.stop = Check(dds_create_guardcondition(m.participant), "a DDS guard condition");
  const dds_entity_t topics = Check(dds_create_waitset(m.participant), "a DDS waitset");
  dds_waitset_attach(topics, m.stop, static_cast<dds_attach_t>(m.readers.size()));
  for (size_t i = 0; i < m.readers.size(); ++i) {
    const dds_entity_t c =
        Check(dds_create_readcondition(m.readers[i].reader, DDS_ANY_STATE), "a DDS read condition");
    dds_waitset_attach(topics, c, static_cast<dds_attach_t>(i));
  }
  std::vector<dds_entity_t> service_waitsets;
  for (const Impl::Service& sv : m.services) {
    const dds_entity_t ws = Check(dds_create_waitset(m.participant), "a DDS waitset");
    dds_waitset_attach(ws, m.stop, 1);
    const dds_entity_t c =
        Check(dds_create_readcondition(sv.request_reader, DDS_ANY_STATE), "a DDS read condition");
    dds_waitset_attach(ws, c, 0);
    service_waitsets.push_back(ws);
  }
  m.threads.emplace_back([&m, topics] {
    Impl::Loop(
        topics, [&m](size_t i) { m.TakeAll(m.readers[i]); }, m.readers.size());
  });
  for (size_t i = 0; i < m.services.size(); ++i)
    m.threads.emplace_back([&m, i, ws = service_waitsets[i]] {
      Impl::Loop(
          ws, [&m, i](size_t) { m.Serve(m.services[i]); }, 1);
    });
}

std::string Ros2Node::where() const {
  return fmt::format("in ROS 2 domain {} on {}", impl_->options.domain_id,
                     impl_->options.interface_address);
}

}  // namespace penumbra
