#include "penumbra/ros/ros2/ros2_types.h"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string_view>

#include "penumbra/core/error.h"
#include "ros2_msgs.h"

namespace penumbra {

namespace {

// rows PENUMBRA_ROS2_TYPE(enumerator, ros name, DDS name, hash, definition, descriptor), in
// Ros2Type's order (scripts/ros2_idl.py)
const Ros2TypeInfo kTypes[] = {
#define PENUMBRA_ROS2_TYPE(e, ros, dds, hash, def, desc) {ros, dds, hash, def, &desc},
#include "ros2_types.inc"
#undef PENUMBRA_ROS2_TYPE
};

constexpr Ros2Type kOrder[] = {
#define PENUMBRA_ROS2_TYPE(e, ros, dds, hash, def, desc) Ros2Type::e,
#include "ros2_types.inc"
#undef PENUMBRA_ROS2_TYPE
};

constexpr bool TableInEnumOrder() {
  for (int i = 0; i < kRos2TypeCount; ++i) {
    if (static_cast<int>(kOrder[i]) != i) return false;
  }
  return std::size(kOrder) == kRos2TypeCount;
}
static_assert(TableInEnumOrder(), "scripts/ros2_idl.py's ENUM_TYPES must follow Ros2Type");

// the wire's lengths are uint32
uint32_t Length(size_t n, const char* what) {
  if (n > std::numeric_limits<uint32_t>::max()) {
    throw Error(std::string("ROS 2: ") + what + " has " + std::to_string(n) +
                " elements, more than a CDR sequence holds (2^32 - 1)");
  }
  return static_cast<uint32_t>(n);
}

template <class Seq, class T>
Seq Borrow(const T* data, size_t n, const char* what) {
  Seq s{};
  s._maximum = s._length = Length(n, what);
  s._buffer = const_cast<T*>(data);
  s._release = false;
  return s;
}

char* Str(const std::string& s) { return const_cast<char*>(s.c_str()); }

builtin_interfaces_msg_dds__Time_ Time(int64_t stamp_ns) {
  auto [sec, nanosec] = Ros2Stamp(stamp_ns);
  return {sec, nanosec};
}

std_msgs_msg_dds__Header_ Header(const RosHeader& h) {
  std_msgs_msg_dds__Header_ out{};
  out.stamp = Time(h.stamp_ns);
  out.frame_id = Str(h.frame_id);
  return out;
}

geometry_msgs_msg_dds__Vector3_ Vector3(const std::array<double, 3>& v) {
  return {v[0], v[1], v[2]};
}
geometry_msgs_msg_dds__Point_ Point(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }
geometry_msgs_msg_dds__Quaternion_ Quaternion(const std::array<double, 4>& q) {
  return {q[0], q[1], q[2], q[3]};
}

template <size_t N>
void CopyArray(double (&to)[N], const std::array<double, N>& from) {
  std::memcpy(to, from.data(), sizeof(to));
}

// a string of a received sample: at most kRos2MaxNameBytes
std::string Name(const char* s, const char* field) {
  if (s == nullptr) return {};
  size_t n = strnlen(s, kRos2MaxNameBytes + 1);
  if (n > kRos2MaxNameBytes) {
    throw Error(std::string("ROS 2: ") + field + " is longer than " +
                std::to_string(kRos2MaxNameBytes) + " bytes");
  }
  return std::string(s, n);
}

int64_t StampNs(const builtin_interfaces_msg_dds__Time_& t, const char* field) {
  if (t.nanosec >= 1000000000u) {
    throw Error(std::string("ROS 2: ") + field + ".nanosec is " + std::to_string(t.nanosec) +
                ", expected below 1000000000");
  }
  return int64_t{t.sec} * 1000000000 + t.nanosec;
}

template <class Seq>
uint32_t Bounded(const Seq& s, uint32_t bound, const char* field) {
  if (s._length > bound) {
    throw Error(std::string("ROS 2: ") + field + " has " + std::to_string(s._length) +
                " elements, at most " + std::to_string(bound) + " are accepted");
  }
  if (s._length > 0 && s._buffer == nullptr) {
    throw Error(std::string("ROS 2: ") + field + " has no data");
  }
  return s._length;
}

void CopyNodeName(char (&to)[257], const std::string& from, const char* field) {
  if (from.size() > 256) {
    throw Error(std::string("ROS 2: ") + field + " '" + from.substr(0, 64) +
                "...' is longer than 256 bytes");
  }
  std::memcpy(to, from.c_str(), from.size() + 1);
}

const dds_topic_descriptor_t& Descriptor(Ros2Type type) { return *Ros2TypeOf(type).descriptor; }

}  // namespace

bool Ros2Available() { return true; }

const Ros2TypeInfo& Ros2TypeOf(Ros2Type type) {
  int i = static_cast<int>(type);
  if (i < 0 || i >= kRos2TypeCount) {
    throw Error("ROS 2: no type " + std::to_string(i) + " (Ros2Type has " +
                std::to_string(kRos2TypeCount) + ")");
  }
  return kTypes[i];
}

std::pair<int32_t, uint32_t> Ros2Stamp(int64_t stamp_ns) {
  int64_t sec = stamp_ns / 1000000000;
  int64_t nanosec = stamp_ns % 1000000000;
  if (nanosec < 0) {
    sec -= 1;
    nanosec += 1000000000;
  }
  if (sec < std::numeric_limits<int32_t>::min() || sec > std::numeric_limits<int32_t>::max()) {
    throw Error("ROS 2: the stamp " + std::to_string(stamp_ns) +
                " ns is outside builtin_interfaces/Time's int32 seconds");
  }
  return {static_cast<int32_t>(sec), static_cast<uint32_t>(nanosec)};
}

void WithSample(const RosImage& m, const std::function<void(const void*)>& f) {
  sensor_msgs_msg_dds__Image_ s{};
  s.header = Header(m.header);
  s.height = m.height;
  s.width = m.width;
  s.encoding = Str(m.encoding);
  s.is_bigendian = m.is_bigendian;
  s.step = m.step;
  s.data = Borrow<dds_sequence_uint8>(m.data.data(), m.data.size(), "Image.data");
  f(&s);
}

void WithSample(const RosCameraInfo& m, const std::function<void(const void*)>& f) {
  sensor_msgs_msg_dds__CameraInfo_ s{};
  s.header = Header(m.header);
  s.height = m.height;
  s.width = m.width;
  s.distortion_model = Str(m.distortion_model);
  s.d = Borrow<dds_sequence_double>(m.D.data(), m.D.size(), "CameraInfo.d");
  CopyArray(s.k, m.K);
  CopyArray(s.r, m.R);
  CopyArray(s.p, m.P);
  f(&s);
}

void WithSample(const RosPointCloud2& m, const std::function<void(const void*)>& f) {
  std::vector<sensor_msgs_msg_dds__PointField_> fields(m.fields.size());
  for (size_t i = 0; i < m.fields.size(); ++i) {
    fields[i].name = Str(m.fields[i].name);
    fields[i].offset = m.fields[i].offset;
    fields[i].datatype = m.fields[i].datatype;
    fields[i].count = m.fields[i].count;
  }
  sensor_msgs_msg_dds__PointCloud2_ s{};
  s.header = Header(m.header);
  s.height = m.height;
  s.width = m.width;
  s.fields = Borrow<dds_sequence_sensor_msgs_msg_dds__PointField_>(fields.data(), fields.size(),
                                                                   "PointCloud2.fields");
  s.is_bigendian = m.is_bigendian != 0;
  s.point_step = m.point_step;
  s.row_step = m.row_step;
  s.data = Borrow<dds_sequence_uint8>(m.data.data(), m.data.size(), "PointCloud2.data");
  s.is_dense = m.is_dense != 0;
  f(&s);
}

void WithSample(const RosImu& m, const std::function<void(const void*)>& f) {
  sensor_msgs_msg_dds__Imu_ s{};
  s.header = Header(m.header);
  s.orientation = Quaternion(m.orientation);
  CopyArray(s.orientation_covariance, m.orientation_covariance);
  s.angular_velocity = Vector3(m.angular_velocity);
  CopyArray(s.angular_velocity_covariance, m.angular_velocity_covariance);
  s.linear_acceleration = Vector3(m.linear_acceleration);
  CopyArray(s.linear_acceleration_covariance, m.linear_acceleration_covariance);
  f(&s);
}

void WithSample(const RosJointState& m, const std::function<void(const void*)>& f) {
  std::vector<char*> names(m.name.size());
  for (size_t i = 0; i < m.name.size(); ++i) names[i] = Str(m.name[i]);
  sensor_msgs_msg_dds__JointState_ s{};
  s.header = Header(m.header);
  s.name = Borrow<dds_sequence_string>(names.data(), names.size(), "JointState.name");
  s.position =
      Borrow<dds_sequence_double>(m.position.data(), m.position.size(), "JointState.position");
  s.velocity =
      Borrow<dds_sequence_double>(m.velocity.data(), m.velocity.size(), "JointState.velocity");
  s.effort = Borrow<dds_sequence_double>(m.effort.data(), m.effort.size(), "JointState.effort");
  f(&s);
}

void WithSample(const RosOdometry& m, const std::function<void(const void*)>& f) {
  nav_msgs_msg_dds__Odometry_ s{};
  s.header = Header(m.header);
  s.child_frame_id = Str(m.child_frame_id);
  s.pose.pose.position = Point(m.position);
  s.pose.pose.orientation = Quaternion(m.orientation);
  CopyArray(s.pose.covariance, m.pose_covariance);
  s.twist.twist.linear = Vector3(m.linear);
  s.twist.twist.angular = Vector3(m.angular);
  CopyArray(s.twist.covariance, m.twist_covariance);
  f(&s);
}

void WithSample(const std::vector<RosTransform>& m, const std::function<void(const void*)>& f) {
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms(m.size());
  for (size_t i = 0; i < m.size(); ++i) {
    auto& t = transforms[i];
    t.header = Header(m[i].header);
    t.child_frame_id = Str(m[i].child_frame_id);
    t.transform.translation = Vector3(m[i].translation);
    t.transform.rotation = Quaternion(m[i].rotation);
  }
  tf2_msgs_msg_dds__TFMessage_ s{};
  s.transforms = Borrow<dds_sequence_geometry_msgs_msg_dds__TransformStamped_>(
      transforms.data(), transforms.size(), "TFMessage.transforms");
  f(&s);
}

void WithSample(const RosTwist& m, const std::function<void(const void*)>& f) {
  geometry_msgs_msg_dds__Twist_ s{};
  s.linear = Vector3(m.linear);
  s.angular = Vector3(m.angular);
  f(&s);
}

void WithSample(const RosPoseStamped& m, const std::function<void(const void*)>& f) {
  geometry_msgs_msg_dds__PoseStamped_ s{};
  s.header = Header(m.header);
  s.pose.position = Point(m.position);
  s.pose.orientation = Quaternion(m.orientation);
  f(&s);
}

void WithSample(const Ros2ParticipantEntities& m, const std::function<void(const void*)>& f) {
  static_assert(sizeof(rmw_dds_common_msg_dds__Gid_) == 16);
  std::vector<rmw_dds_common_msg_dds__NodeEntitiesInfo_> nodes(m.nodes.size());
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const auto& n = m.nodes[i];
    CopyNodeName(nodes[i].node_namespace, n.node_namespace, "NodeEntitiesInfo.node_namespace");
    CopyNodeName(nodes[i].node_name, n.node_name, "NodeEntitiesInfo.node_name");
    // Gid is a struct of uint8_t[16], laid out as std::array<uint8_t, 16>
    nodes[i].reader_gid_seq = Borrow<dds_sequence_rmw_dds_common_msg_dds__Gid_>(
        reinterpret_cast<const rmw_dds_common_msg_dds__Gid_*>(n.readers.data()), n.readers.size(),
        "NodeEntitiesInfo.reader_gid_seq");
    nodes[i].writer_gid_seq = Borrow<dds_sequence_rmw_dds_common_msg_dds__Gid_>(
        reinterpret_cast<const rmw_dds_common_msg_dds__Gid_*>(n.writers.data()), n.writers.size(),
        "NodeEntitiesInfo.writer_gid_seq");
  }
  rmw_dds_common_msg_dds__ParticipantEntitiesInfo_ s{};
  std::memcpy(s.gid.data, m.gid.data(), sizeof(s.gid.data));
  s.node_entities_info_seq = Borrow<dds_sequence_rmw_dds_common_msg_dds__NodeEntitiesInfo_>(
      nodes.data(), nodes.size(), "ParticipantEntitiesInfo.node_entities_info_seq");
  f(&s);
}

void WithClockSample(int64_t stamp_ns, const std::function<void(const void*)>& f) {
  rosgraph_msgs_msg_dds__Clock_ s{};
  s.clock = Time(stamp_ns);
  f(&s);
}

void WithTriggerRequestSample(const Ros2RequestHeader& h,
                              const std::function<void(const void*)>& f) {
  std_srvs_srv_dds__Trigger_Request_ s{};
  s.client_guid = h.client_guid;
  s.sequence_number = h.sequence_number;
  f(&s);
}

void WithSample(const Ros2TriggerResponse& m, const std::function<void(const void*)>& f) {
  std_srvs_srv_dds__Trigger_Response_ s{};
  s.client_guid = m.header.client_guid;
  s.sequence_number = m.header.sequence_number;
  s.success = m.success;
  s.message = Str(m.message);
  f(&s);
}

std::vector<uint8_t> SerializeCdr(Ros2Type type, const void* sample) {
  const dds_topic_descriptor_t& desc = Descriptor(type);
  dds_ostreamLE_t os;
  dds_ostreamLE_init(&os, 0, CDR_ENC_VERSION_1);
  std::unique_ptr<dds_ostreamLE_t, void (*)(dds_ostreamLE_t*)> guard(&os, dds_ostreamLE_fini);
  if (dds_stream_writeLE(&os, static_cast<const char*>(sample), desc.m_ops) == nullptr) {
    throw Error(std::string("ROS 2: Cyclone DDS could not serialize the ") +
                Ros2TypeOf(type).ros_name + " (a bounded sequence or string over its bound?)");
  }
  const uint32_t n = os.x.m_index;
  const uint8_t pad = static_cast<uint8_t>((4 - n % 4) % 4);
  std::vector<uint8_t> out(4 + n + pad, 0);
  out[1] = 0x01;  // CDR_LE
  out[3] = pad;
  if (n > 0) std::memcpy(out.data() + 4, os.x.m_buffer, n);
  return out;
}

void WithCdrSample(Ros2Type type, std::span<const uint8_t> cdr,
                   const std::function<void(const void*)>& f) {
  const Ros2TypeInfo& info = Ros2TypeOf(type);
  const dds_topic_descriptor_t& desc = *info.descriptor;
  auto bad = [&](const std::string& why) {
    return Error(std::string("ROS 2: the CDR of a ") + info.ros_name + " " + why);
  };
  if (cdr.size() <= 4) {
    throw bad("has " + std::to_string(cdr.size()) + " bytes, no data after its 4-byte header");
  }
  if (cdr[0] != 0x00 || (cdr[1] != 0x00 && cdr[1] != 0x01)) {
    throw bad("starts with " + std::to_string(cdr[0]) + ", " + std::to_string(cdr[1]) +
              ", expected the encapsulation of plain CDR (0, 0 big or 0, 1 little endian)");
  }
  if (cdr.size() - 4 > std::numeric_limits<uint32_t>::max()) throw bad("is over 4 GiB");
  const bool little = cdr[1] == 0x01;
  const bool bswap = little != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  std::vector<uint8_t> data(cdr.begin() + 4, cdr.end());
  const uint32_t size = static_cast<uint32_t>(data.size());
  uint32_t off = 0;
  if (dds_stream_normalize_data(reinterpret_cast<char*>(data.data()), &off, size, bswap,
                                CDR_ENC_VERSION_1, desc.m_ops) == nullptr) {
    throw bad("is malformed (a length or value runs past its " + std::to_string(size) +
              " bytes, or a bound or enum is broken)");
  }
  dds_istream_t is;
  dds_istream_init(&is, size, data.data(), CDR_ENC_VERSION_1);
  void* sample = std::calloc(1, desc.m_size);
  if (sample == nullptr) throw bad("could not be allocated");
  struct Free {
    const uint32_t* ops;
    void operator()(void* p) const {
      dds_stream_free_sample(p, ops);
      std::free(p);
    }
  };
  std::unique_ptr<void, Free> owned(sample, Free{desc.m_ops});
  dds_stream_read(&is, static_cast<char*>(sample), desc.m_ops);
  dds_istream_fini(&is);
  f(sample);
}

RosTwist TwistFromSample(const void* sample) {
  const auto& s = *static_cast<const geometry_msgs_msg_dds__Twist_*>(sample);
  RosTwist t;
  t.linear = {s.linear.x, s.linear.y, s.linear.z};
  t.angular = {s.angular.x, s.angular.y, s.angular.z};
  return t;
}

RosPoseStamped PoseStampedFromSample(const void* sample) {
  const auto& s = *static_cast<const geometry_msgs_msg_dds__PoseStamped_*>(sample);
  RosPoseStamped p;
  p.header.stamp_ns = StampNs(s.header.stamp, "PoseStamped.header.stamp");
  p.header.frame_id = Name(s.header.frame_id, "PoseStamped.header.frame_id");
  p.position = {s.pose.position.x, s.pose.position.y, s.pose.position.z};
  p.orientation = {s.pose.orientation.x, s.pose.orientation.y, s.pose.orientation.z,
                   s.pose.orientation.w};
  return p;
}

RosJointState JointStateFromSample(const void* sample) {
  const auto& s = *static_cast<const sensor_msgs_msg_dds__JointState_*>(sample);
  RosJointState j;
  j.header.stamp_ns = StampNs(s.header.stamp, "JointState.header.stamp");
  j.header.frame_id = Name(s.header.frame_id, "JointState.header.frame_id");
  const uint32_t n = Bounded(s.name, kRos2MaxJoints, "JointState.name");
  j.name.reserve(n);
  for (uint32_t i = 0; i < n; ++i) j.name.push_back(Name(s.name._buffer[i], "JointState.name[]"));
  auto values = [&](const dds_sequence_double& v, const char* field, std::vector<double>& out) {
    const uint32_t m = Bounded(v, kRos2MaxJoints, field);
    // without names the values are in the controller's joint order (the bridge checks the count)
    if (n != 0 && m != 0 && m != n) {
      throw Error(std::string("ROS 2: ") + field + " has " + std::to_string(m) + " values for " +
                  std::to_string(n) + " names (expected as many, or none)");
    }
    out.assign(v._buffer, v._buffer + m);
  };
  values(s.position, "JointState.position", j.position);
  values(s.velocity, "JointState.velocity", j.velocity);
  values(s.effort, "JointState.effort", j.effort);
  return j;
}

Ros2RequestHeader TriggerRequestFromSample(const void* sample) {
  const auto& s = *static_cast<const std_srvs_srv_dds__Trigger_Request_*>(sample);
  return {s.client_guid, s.sequence_number};
}

Ros2TriggerResponse TriggerResponseFromSample(const void* sample) {
  const auto& s = *static_cast<const std_srvs_srv_dds__Trigger_Response_*>(sample);
  Ros2TriggerResponse r;
  r.header = {s.client_guid, s.sequence_number};
  r.success = s.success;
  r.message = Name(s.message, "Trigger_Response.message");
  return r;
}

int64_t ClockFromSample(const void* sample) {
  const auto& s = *static_cast<const rosgraph_msgs_msg_dds__Clock_*>(sample);
  return StampNs(s.clock, "Clock.clock");
}

}  // namespace penumbra
