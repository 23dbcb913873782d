// ROS 2 types over Cyclone DDS (ros/ros2/ros2_types.h): the type table, stamps, CDR bytes,
// round trips through Cyclone's serializer and reader, and the bounds on received samples.
// Ros2Types.WritesSamplesForTheIndependentCheck also writes one CDR sample of every type to
// $PENUMBRA_ROS2_CDR_DIR (if set), which tests/ros/ros2_types_test.py decodes with rosbags and
// mcap_ros2.
#include "penumbra/ros/ros2/ros2_types.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <regex>

#include "penumbra/core/error.h"

#if __has_include(<dds/dds.h>)
#include <dds/dds.h>  // the descriptors' type names (Cyclone DDS's headers, no library call)
#define PENUMBRA_TEST_HAS_DDS 1
#endif

namespace penumbra {
namespace ros2_types_test {
namespace {

#define SKIP_WITHOUT_ROS2() \
  if (!Ros2Available()) GTEST_SKIP() << "skipped: this build has no ROS 2 (PENUMBRA_WITH_ROS2)"

template <typename T>
T At(const std::vector<uint8_t>& data, size_t offset) {
  T v;
  std::memcpy(&v, data.data() + offset, sizeof(T));
  return v;
}

template <class M>
std::vector<uint8_t> Cdr(Ros2Type t, const M& m) {
  std::vector<uint8_t> out;
  WithSample(m, [&](const void* s) { out = SerializeCdr(t, s); });
  return out;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Ros2Types, TableNamesHashesAndDefinitions) {
  SKIP_WITHOUT_ROS2();
  const std::regex hash("RIHS01_[0-9a-f]{64}");
  for (int i = 0; i < kRos2TypeCount; ++i) {
    const Ros2TypeInfo& t = Ros2TypeOf(static_cast<Ros2Type>(i));
    SCOPED_TRACE(t.ros_name);
    std::string ros = t.ros_name;
    auto a = ros.find('/'), b = ros.rfind('/');
    // pkg/msg/T -> pkg::msg::dds_::T_ (rmw_cyclonedds)
    EXPECT_EQ(std::string(t.dds_name), ros.substr(0, a) + "::" + ros.substr(a + 1, b - a - 1) +
                                           "::dds_::" + ros.substr(b + 1) + "_");
    EXPECT_TRUE(std::regex_match(t.type_hash, hash)) << t.type_hash;
    ASSERT_NE(t.descriptor, nullptr);
#ifdef PENUMBRA_TEST_HAS_DDS
    // the name Cyclone registers and announces in discovery
    EXPECT_STREQ(t.descriptor->m_typename, t.dds_name);
#endif
    EXPECT_NE(t.definition, nullptr);
  }
  EXPECT_STREQ(Ros2TypeOf(Ros2Type::kImage).ros_name, "sensor_msgs/msg/Image");
  EXPECT_STREQ(Ros2TypeOf(Ros2Type::kTriggerRequest).dds_name,
               "std_srvs::srv::dds_::Trigger_Request_");
  EXPECT_STREQ(Ros2TypeOf(Ros2Type::kTfMessage).ros_name, "tf2_msgs/msg/TFMessage");
  // rosbag2's layout: the type's fields, then each dependency after 80 '=' and "MSG: pkg/Type"
  const std::string image = Ros2TypeOf(Ros2Type::kImage).definition;
  EXPECT_EQ(image.rfind("std_msgs/Header header\nuint32 height\n", 0), 0u) << image;
  EXPECT_NE(image.find("\n" + std::string(80, '=') +
                       "\nMSG: std_msgs/Header\n"
                       "builtin_interfaces/Time stamp\nstring frame_id\n"),
            std::string::npos)
      << image;
  EXPECT_NE(image.find("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"),
            std::string::npos);
  EXPECT_THROW(Ros2TypeOf(static_cast<Ros2Type>(kRos2TypeCount)), Error);
}

TEST(Ros2Types, StampsAreFlooredSecondsAndNanoseconds) {
  SKIP_WITHOUT_ROS2();
  EXPECT_EQ(Ros2Stamp(0), std::make_pair(int32_t{0}, uint32_t{0}));
  EXPECT_EQ(Ros2Stamp(1500000000), std::make_pair(int32_t{1}, uint32_t{500000000}));
  EXPECT_EQ(Ros2Stamp(-1), std::make_pair(int32_t{-1}, uint32_t{999999999}));
  EXPECT_EQ(Ros2Stamp(int64_t{2147483647} * 1000000000 + 999999999),
            std::make_pair(int32_t{2147483647}, uint32_t{999999999}));
  EXPECT_NE(ErrorOf([] { Ros2Stamp(int64_t{2147483648} * 1000000000); }).find("int32"),
            std::string::npos);
  std::vector<uint8_t> clock;
  WithClockSample(3250000001, [&](const void* s) {
    clock = SerializeCdr(Ros2Type::kClock, s);
    EXPECT_EQ(ClockFromSample(s), 3250000001);
  });
  // XCDR1 little endian: {0, 1, 0, 0}, int32 sec, uint32 nanosec
  ASSERT_EQ(clock.size(), 12u);
  EXPECT_EQ(clock[0], 0x00);
  EXPECT_EQ(clock[1], 0x01);
  EXPECT_EQ(clock[3], 0x00);
  EXPECT_EQ(At<int32_t>(clock, 4), 3);
  EXPECT_EQ(At<uint32_t>(clock, 8), 250000001u);
}

TEST(Ros2Types, TwistBytesAreSixLittleEndianDoubles) {
  SKIP_WITHOUT_ROS2();
  RosTwist t;
  t.linear = {0.5, -1, 2};
  t.angular = {0, 0.25, -3.5};
  const auto cdr = Cdr(Ros2Type::kTwist, t);
  ASSERT_EQ(cdr.size(), 4u + 6 * 8);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(At<double>(cdr, 4 + 8 * i), t.linear[i]);
    EXPECT_EQ(At<double>(cdr, 28 + 8 * i), t.angular[i]);
  }
  RosTwist back;
  WithCdrSample(Ros2Type::kTwist, cdr, [&](const void* s) { back = TwistFromSample(s); });
  EXPECT_EQ(back.linear, t.linear);
  EXPECT_EQ(back.angular, t.angular);
}

TEST(Ros2Types, PoseStampedAndJointStateRoundTrip) {
  SKIP_WITHOUT_ROS2();
  RosPoseStamped p;
  p.header = {12345678901, "mocap"};
  p.position = {1, 2, 3};
  p.orientation = {0, 0, std::sqrt(0.5), std::sqrt(0.5)};
  const auto pose_cdr = Cdr(Ros2Type::kPoseStamped, p);
  EXPECT_EQ(pose_cdr.size() % 4, 0u);
  RosPoseStamped pb;
  WithCdrSample(Ros2Type::kPoseStamped, pose_cdr,
                [&](const void* s) { pb = PoseStampedFromSample(s); });
  EXPECT_EQ(pb.header.stamp_ns, p.header.stamp_ns);
  EXPECT_EQ(pb.header.frame_id, "mocap");
  EXPECT_EQ(pb.position, p.position);
  EXPECT_EQ(pb.orientation, p.orientation);

  RosJointState j;
  j.header = {-5, "base_link"};
  j.name = {"shoulder", "elbow", "wrist"};
  j.position = {0.1, -0.2, 0.3};
  j.effort = {1, 2, 3};
  RosJointState jb;
  WithCdrSample(Ros2Type::kJointState, Cdr(Ros2Type::kJointState, j),
                [&](const void* s) { jb = JointStateFromSample(s); });
  EXPECT_EQ(jb.header.stamp_ns, -5);
  EXPECT_EQ(jb.header.frame_id, "base_link");
  EXPECT_EQ(jb.name, j.name);
  EXPECT_EQ(jb.position, j.position);
  EXPECT_TRUE(jb.velocity.empty());
  EXPECT_EQ(jb.effort, j.effort);
}

TEST(Ros2Types, TriggerSamplesCarryTheRequestHeader) {
  SKIP_WITHOUT_ROS2();
  std::vector<uint8_t> req;
  WithTriggerRequestSample({0x0102030405060708ull, 42}, [&](const void* s) {
    req = SerializeCdr(Ros2Type::kTriggerRequest, s);
    EXPECT_EQ(TriggerRequestFromSample(s).sequence_number, 42);
  });
  // header, u64 guid, i64 seq, uint8 structure_needs_at_least_one_member, 3 bytes of padding
  ASSERT_EQ(req.size(), 4u + 16 + 1 + 3);
  EXPECT_EQ(req[3], 3);
  EXPECT_EQ(At<uint64_t>(req, 4), 0x0102030405060708ull);
  EXPECT_EQ(At<int64_t>(req, 12), 42);
  Ros2TriggerResponse r{{7, 42}, true, "step 3, t=0.006 s"};
  Ros2TriggerResponse rb;
  WithCdrSample(Ros2Type::kTriggerResponse, Cdr(Ros2Type::kTriggerResponse, r),
                [&](const void* s) { rb = TriggerResponseFromSample(s); });
  EXPECT_EQ(rb.header.client_guid, 7u);
  EXPECT_EQ(rb.header.sequence_number, 42);
  EXPECT_TRUE(rb.success);
  EXPECT_EQ(rb.message, r.message);
}

TEST(Ros2Types, ReceivedSamplesAreBounded) {
  SKIP_WITHOUT_ROS2();
  RosJointState many;
  many.name.assign(kRos2MaxJoints + 1, "j");
  const auto cdr = Cdr(Ros2Type::kJointState, many);
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kJointState, cdr,
                            [](const void* s) { JointStateFromSample(s); });
            }).find("JointState.name has 1025 elements"),
            std::string::npos);
  RosJointState uneven;
  uneven.name = {"a", "b"};
  uneven.position = {1};
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kJointState, Cdr(Ros2Type::kJointState, uneven),
                            [](const void* s) { JointStateFromSample(s); });
            }).find("JointState.position has 1 values for 2 names"),
            std::string::npos);
  // no names: the values are in the controller's joint order, any count up to the bound
  RosJointState ordered;
  ordered.position = {0.1, 0.2, 0.3};
  RosJointState back;
  WithCdrSample(Ros2Type::kJointState, Cdr(Ros2Type::kJointState, ordered),
                [&](const void* s) { back = JointStateFromSample(s); });
  EXPECT_TRUE(back.name.empty());
  EXPECT_EQ(back.position, ordered.position);
  RosPoseStamped p;
  p.header.frame_id = std::string(kRos2MaxNameBytes + 1, 'f');
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kPoseStamped, Cdr(Ros2Type::kPoseStamped, p),
                            [](const void* s) { PoseStampedFromSample(s); });
            }).find("PoseStamped.header.frame_id is longer"),
            std::string::npos);
  // a nanosec of 1e9 (offset 4 + 4: after the header and sec)
  p.header.frame_id = "f";
  auto bad = Cdr(Ros2Type::kPoseStamped, p);
  const uint32_t ns = 1000000000;
  std::memcpy(bad.data() + 8, &ns, 4);
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kPoseStamped, bad,
                            [](const void* s) { PoseStampedFromSample(s); });
            }).find("PoseStamped.header.stamp.nanosec is 1000000000"),
            std::string::npos);
}

TEST(Ros2Types, MalformedCdrIsRefusedBeforeAllocating) {
  SKIP_WITHOUT_ROS2();
  RosJointState j;
  j.name = {"a"};
  j.position = {1};
  const auto good = Cdr(Ros2Type::kJointState, j);
  auto none = [](const void*) { FAIL() << "a malformed sample was read"; };
  // too short for the header, a foreign encapsulation, truncated data
  EXPECT_THROW(WithCdrSample(Ros2Type::kJointState, std::vector<uint8_t>{0, 1}, none), Error);
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kClock, std::vector<uint8_t>{0, 1, 0, 0}, none);
            }).find("no data after its 4-byte header"),
            std::string::npos);
  auto pl = good;
  pl[1] = 0x03;  // PL_CDR_LE
  EXPECT_NE(ErrorOf([&] {
              WithCdrSample(Ros2Type::kJointState, pl, none);
            }).find("sensor_msgs/msg/JointState"),
            std::string::npos);
  for (size_t n = 4; n + 8 < good.size(); n += 3) {
    std::vector<uint8_t> cut(good.begin(), good.begin() + n);
    EXPECT_THROW(WithCdrSample(Ros2Type::kJointState, cut, none), Error) << n << " bytes";
  }
  // a name sequence that claims 2^32 - 1 elements (offset: header 4, stamp 8, frame_id "" 5 -> 20)
  auto huge = good;
  const uint32_t count = 0xffffffffu;
  std::memcpy(huge.data() + 20, &count, 4);
  EXPECT_THROW(WithCdrSample(Ros2Type::kJointState, huge, none), Error);
  // big endian is read too
  RosTwist t;
  t.linear = {1, 2, 3};
  auto be = Cdr(Ros2Type::kTwist, t);
  be[1] = 0x00;
  for (size_t i = 4; i + 8 <= be.size(); i += 8) std::reverse(be.begin() + i, be.begin() + i + 8);
  RosTwist tb;
  WithCdrSample(Ros2Type::kTwist, be, [&](const void* s) { tb = TwistFromSample(s); });
  EXPECT_EQ(tb.linear, t.linear);
}

TEST(Ros2Types, SizesOverTheWireLengthsAreRefused) {
  SKIP_WITHOUT_ROS2();
  Ros2ParticipantEntities e;
  e.nodes.push_back({std::string(257, 'n'), "penumbra", {}, {}});
  EXPECT_NE(ErrorOf([&] { WithSample(e, [](const void*) {}); }).find("node_namespace"),
            std::string::npos);
}

// one sample of every type, with the values it was made from, for tests/ros/ros2_types_test.py
TEST(Ros2Types, WritesSamplesForTheIndependentCheck) {
  SKIP_WITHOUT_ROS2();
  const char* env = std::getenv("PENUMBRA_ROS2_CDR_DIR");
  const std::filesystem::path dir =
      env != nullptr ? std::filesystem::path(env)
                     : std::filesystem::temp_directory_path() / "penumbra_ros2_types_test";
  std::filesystem::create_directories(dir);
  nlohmann::json index = nlohmann::json::object();
  auto header = [](const RosHeader& h) {
    auto [sec, ns] = Ros2Stamp(h.stamp_ns);
    return nlohmann::json{{"stamp", {{"sec", sec}, {"nanosec", ns}}}, {"frame_id", h.frame_id}};
  };
  auto vec3 = [](const std::array<double, 3>& v) {
    return nlohmann::json{{"x", v[0]}, {"y", v[1]}, {"z", v[2]}};
  };
  auto quat = [](const std::array<double, 4>& q) {
    return nlohmann::json{{"x", q[0]}, {"y", q[1]}, {"z", q[2]}, {"w", q[3]}};
  };
  auto put = [&](Ros2Type t, const std::vector<uint8_t>& cdr, nlohmann::json expected) {
    const Ros2TypeInfo& info = Ros2TypeOf(t);
    std::string file = info.ros_name;
    std::replace(file.begin(), file.end(), '/', '.');
    file += ".cdr";
    std::ofstream(dir / file, std::ios::binary)
        .write(reinterpret_cast<const char*>(cdr.data()), static_cast<std::streamsize>(cdr.size()));
    index[info.ros_name] = {{"dds_name", info.dds_name},
                            {"type_hash", info.type_hash},
                            {"definition", info.definition},
                            {"file", file},
                            {"expected", std::move(expected)}};
  };

  RosImage img;
  img.header = {1700000000123456789, "camera_optical"};
  img.height = 2;
  img.width = 3;
  img.encoding = "rgb8";
  img.step = 9;
  for (int i = 0; i < 18; ++i) img.data.push_back(static_cast<uint8_t>(i * 13));
  put(Ros2Type::kImage, Cdr(Ros2Type::kImage, img),
      {{"header", header(img.header)},
       {"height", 2},
       {"width", 3},
       {"encoding", "rgb8"},
       {"is_bigendian", 0},
       {"step", 9},
       {"data", img.data}});

  RosCameraInfo ci;
  ci.header = {-1, "camera_optical"};
  ci.height = 480;
  ci.width = 640;
  ci.D = {0.1, -0.2, 0.001, 0.002, 0.05};
  for (int i = 0; i < 9; ++i) ci.K[i] = i + 0.5, ci.R[i] = i == 0 || i == 4 || i == 8;
  for (int i = 0; i < 12; ++i) ci.P[i] = -i;
  put(Ros2Type::kCameraInfo, Cdr(Ros2Type::kCameraInfo, ci),
      {{"header", header(ci.header)},
       {"height", 480},
       {"width", 640},
       {"distortion_model", "plumb_bob"},
       {"d", ci.D},
       {"k", ci.K},
       {"r", ci.R},
       {"p", ci.P},
       {"binning_x", 0},
       {"binning_y", 0},
       {"roi",
        {{"x_offset", 0}, {"y_offset", 0}, {"height", 0}, {"width", 0}, {"do_rectify", false}}}});

  RosPointCloud2 pc;
  pc.header = {42, "lidar"};
  pc.width = 2;
  pc.fields = {{"x", 0, kRosFloat32, 1}, {"y", 4, kRosFloat32, 1}, {"intensity", 8, kRosUint8, 1}};
  pc.point_step = 9;
  pc.row_step = 18;
  for (int i = 0; i < 18; ++i) pc.data.push_back(static_cast<uint8_t>(255 - i));
  nlohmann::json fields = nlohmann::json::array();
  for (const auto& f : pc.fields) {
    fields.push_back(
        {{"name", f.name}, {"offset", f.offset}, {"datatype", f.datatype}, {"count", f.count}});
  }
  put(Ros2Type::kPointCloud2, Cdr(Ros2Type::kPointCloud2, pc),
      {{"header", header(pc.header)},
       {"height", 1},
       {"width", 2},
       {"fields", fields},
       {"is_bigendian", false},
       {"point_step", 9},
       {"row_step", 18},
       {"data", pc.data},
       {"is_dense", true}});

  RosImu imu;
  imu.header = {2500000000, "imu_link"};
  imu.orientation = {0.1, 0.2, 0.3, 0.9};
  imu.orientation_covariance[0] = -1;
  imu.angular_velocity = {0.01, -0.02, 0.03};
  imu.angular_velocity_covariance[4] = 1e-4;
  imu.linear_acceleration = {0, 0, 9.81};
  imu.linear_acceleration_covariance[8] = 2e-3;
  put(Ros2Type::kImu, Cdr(Ros2Type::kImu, imu),
      {{"header", header(imu.header)},
       {"orientation", quat(imu.orientation)},
       {"orientation_covariance", imu.orientation_covariance},
       {"angular_velocity", vec3(imu.angular_velocity)},
       {"angular_velocity_covariance", imu.angular_velocity_covariance},
       {"linear_acceleration", vec3(imu.linear_acceleration)},
       {"linear_acceleration_covariance", imu.linear_acceleration_covariance}});

  RosJointState js;
  js.header = {999999999, ""};
  js.name = {"hip", "knee"};
  js.position = {0.5, -1.25};
  js.velocity = {0, 2};
  put(Ros2Type::kJointState, Cdr(Ros2Type::kJointState, js),
      {{"header", header(js.header)},
       {"name", js.name},
       {"position", js.position},
       {"velocity", js.velocity},
       {"effort", nlohmann::json::array()}});

  RosOdometry od;
  od.header = {3000000001, "odom"};
  od.child_frame_id = "base_link";
  od.position = {1, 2, 0};
  od.orientation = {0, 0, 0.6, 0.8};
  od.pose_covariance[0] = 0.01;
  od.pose_covariance[35] = 0.02;
  od.linear = {0.4, 0, 0};
  od.angular = {0, 0, -0.3};
  od.twist_covariance[7] = 0.5;
  put(Ros2Type::kOdometry, Cdr(Ros2Type::kOdometry, od),
      {{"header", header(od.header)},
       {"child_frame_id", "base_link"},
       {"pose",
        {{"pose", {{"position", vec3(od.position)}, {"orientation", quat(od.orientation)}}},
         {"covariance", od.pose_covariance}}},
       {"twist",
        {{"twist", {{"linear", vec3(od.linear)}, {"angular", vec3(od.angular)}}},
         {"covariance", od.twist_covariance}}}});

  std::vector<RosTransform> tf(2);
  tf[0] = {{10, "odom"}, "base_link", {1, 0, 0}, {0, 0, 0, 1}};
  tf[1] = {{11, "base_link"}, "camera", {0.1, 0.2, 0.3}, {0.5, -0.5, 0.5, -0.5}};
  nlohmann::json transforms = nlohmann::json::array();
  for (const auto& t : tf) {
    transforms.push_back(
        {{"header", header(t.header)},
         {"child_frame_id", t.child_frame_id},
         {"transform", {{"translation", vec3(t.translation)}, {"rotation", quat(t.rotation)}}}});
  }
  put(Ros2Type::kTfMessage, Cdr(Ros2Type::kTfMessage, tf), {{"transforms", transforms}});

  std::vector<uint8_t> clock;
  WithClockSample(7000000007, [&](const void* s) { clock = SerializeCdr(Ros2Type::kClock, s); });
  put(Ros2Type::kClock, clock, {{"clock", {{"sec", 7}, {"nanosec", 7}}}});

  RosTwist tw;
  tw.linear = {0.3, 0, 0};
  tw.angular = {0, 0, 1.5};
  put(Ros2Type::kTwist, Cdr(Ros2Type::kTwist, tw),
      {{"linear", vec3(tw.linear)}, {"angular", vec3(tw.angular)}});

  RosPoseStamped ps;
  ps.header = {123, "map"};
  ps.position = {-1, -2, -3};
  ps.orientation = {1, 0, 0, 0};
  put(Ros2Type::kPoseStamped, Cdr(Ros2Type::kPoseStamped, ps),
      {{"header", header(ps.header)},
       {"pose", {{"position", vec3(ps.position)}, {"orientation", quat(ps.orientation)}}}});

  std::vector<uint8_t> req;
  WithTriggerRequestSample({0xfedcba9876543210ull, 5}, [&](const void* s) {
    req = SerializeCdr(Ros2Type::kTriggerRequest, s);
  });
  put(Ros2Type::kTriggerRequest, req,
      {{"client_guid", 0xfedcba9876543210ull},
       {"sequence_number", 5},
       {"structure_needs_at_least_one_member", 0}});
  Ros2TriggerResponse resp{{0xfedcba9876543210ull, 5}, true, "paused"};
  put(Ros2Type::kTriggerResponse, Cdr(Ros2Type::kTriggerResponse, resp),
      {{"client_guid", 0xfedcba9876543210ull},
       {"sequence_number", 5},
       {"success", true},
       {"message", "paused"}});

  Ros2ParticipantEntities pe;
  for (int i = 0; i < 16; ++i) pe.gid[i] = static_cast<uint8_t>(i + 1);
  Ros2ParticipantEntities::Gid w{};
  w[0] = 0xaa;
  w[15] = 0x55;
  pe.nodes.push_back({"/", "penumbra", {}, {w, pe.gid}});
  nlohmann::json writers = nlohmann::json::array();
  for (const auto& g : pe.nodes[0].writers) writers.push_back({{"data", g}});
  put(Ros2Type::kParticipantEntitiesInfo, Cdr(Ros2Type::kParticipantEntitiesInfo, pe),
      {{"gid", {{"data", pe.gid}}},
       {"node_entities_info_seq",
        {{{"node_namespace", "/"},
          {"node_name", "penumbra"},
          {"reader_gid_seq", nlohmann::json::array()},
          {"writer_gid_seq", writers}}}}});

  ASSERT_EQ(index.size(), static_cast<size_t>(kRos2TypeCount));
  std::ofstream(dir / "types.json") << index.dump(1);
}

}  // namespace
}  // namespace ros2_types_test
}  // namespace penumbra
