// libFuzzer target: a ROS 2 sample as the ROS 2 bridge receives it from the network
// (ros/ros2/ros2_types.h): CDR bytes with their 4-byte encapsulation header through
// WithCdrSample (Cyclone DDS's checked deserialization, as the bridge's readers run it), then the
// sample through the *FromSample conversion of its type. the first byte picks the type (modulo
// kRos2TypeCount, in Ros2Type's order: the received cmd_vel Twist, joint command JointState, mocap
// PoseStamped and Trigger request, and the published types too); the rest is the CDR. the
// documented failure is penumbra::Error. a finding is any other exception, a crash, a sanitizer
// report, or an accepted sample that breaks a check:
//   - a JointState with more names or values than kRos2MaxJoints, a string over
//     kRos2MaxNameBytes, or non-empty values whose count differs from non-empty names';
//   - the sample serialized again (SerializeCdr) is refused, or does not decode to a sample that
//     serializes to the same bytes;
//   - for the converted types, the plain message made into a sample again (WithSample) does not
//     serialize to the bytes of the received sample, or does not decode to the same plain message
//     (doubles compared bit for bit). docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace {

using namespace penumbra;

// a broken check: libFuzzer writes the input as a crash
[[noreturn]] void Finding() { __builtin_trap(); }

template <class T>
bool SameBits(const T& a, const T& b) {
  if (a.size() != b.size()) return false;
  return a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

bool Same(const RosHeader& a, const RosHeader& b) {
  return a.stamp_ns == b.stamp_ns && a.frame_id == b.frame_id;
}
bool Same(const RosTwist& a, const RosTwist& b) {
  return SameBits(a.linear, b.linear) && SameBits(a.angular, b.angular);
}
bool Same(const RosPoseStamped& a, const RosPoseStamped& b) {
  return Same(a.header, b.header) && SameBits(a.position, b.position) &&
         SameBits(a.orientation, b.orientation);
}
bool Same(const RosJointState& a, const RosJointState& b) {
  return Same(a.header, b.header) && a.name == b.name && SameBits(a.position, b.position) &&
         SameBits(a.velocity, b.velocity) && SameBits(a.effort, b.effort);
}
bool Same(const Ros2RequestHeader& a, const Ros2RequestHeader& b) {
  return a.client_guid == b.client_guid && a.sequence_number == b.sequence_number;
}
bool Same(const Ros2TriggerResponse& a, const Ros2TriggerResponse& b) {
  return Same(a.header, b.header) && a.success == b.success && a.message == b.message;
}

// what a received JointState may hold
void CheckBounds(const RosJointState& j) {
  if (j.header.frame_id.size() > kRos2MaxNameBytes) Finding();
  if (j.name.size() > kRos2MaxJoints) Finding();
  for (const std::string& n : j.name) {
    if (n.size() > kRos2MaxNameBytes) Finding();
  }
  for (const auto* v : {&j.position, &j.velocity, &j.effort}) {
    if (v->size() > kRos2MaxJoints) Finding();
    if (!j.name.empty() && !v->empty() && v->size() != j.name.size()) Finding();
  }
}

// the CDR of an accepted sample: Cyclone writes it back, and reads it back to the same bytes
std::vector<uint8_t> Reserialize(Ros2Type type, const void* sample) {
  std::vector<uint8_t> bytes, again;
  try {
    bytes = SerializeCdr(type, sample);
    WithCdrSample(type, bytes, [&](const void* s) { again = SerializeCdr(type, s); });
  } catch (const Error&) {
    Finding();
  }
  if (again != bytes) Finding();
  return bytes;
}

// plain message m of a received sample whose CDR (serialized again) is `bytes`: m made into a
// sample serializes to the same bytes, which decode to the same m. with_sample(m, f) calls f with
// the sample of m, from(p) converts a sample.
template <class M, class WithFn, class FromFn>
void RoundTrip(Ros2Type type, const M& m, const std::vector<uint8_t>& bytes, WithFn with_sample,
               FromFn from, bool same_bytes) {
  std::vector<uint8_t> out;
  M back;
  try {
    with_sample(m, [&](const void* s) { out = SerializeCdr(type, s); });
    WithCdrSample(type, out, [&](const void* s) { back = from(s); });
  } catch (const Error&) {
    Finding();
  }
  if (same_bytes && out != bytes) Finding();
  if (!Same(m, back)) Finding();
}

void Check(Ros2Type type, const void* sample) {
  const std::vector<uint8_t> bytes = Reserialize(type, sample);
  auto with = [](const auto& m, const std::function<void(const void*)>& f) { WithSample(m, f); };
  switch (type) {
    case Ros2Type::kTwist:
      RoundTrip(type, TwistFromSample(sample), bytes, with, TwistFromSample, true);
      break;
    case Ros2Type::kPoseStamped:
      RoundTrip(type, PoseStampedFromSample(sample), bytes, with, PoseStampedFromSample, true);
      break;
    case Ros2Type::kJointState: {
      const RosJointState j = JointStateFromSample(sample);
      CheckBounds(j);
      RoundTrip(type, j, bytes, with, JointStateFromSample, true);
      break;
    }
    case Ros2Type::kTriggerRequest:
      // the request's one data byte (structure_needs_at_least_one_member) is not kept
      RoundTrip(
          type, TriggerRequestFromSample(sample), bytes,
          [](const Ros2RequestHeader& h, const std::function<void(const void*)>& f) {
            WithTriggerRequestSample(h, f);
          },
          TriggerRequestFromSample, false);
      break;
    case Ros2Type::kTriggerResponse:
      RoundTrip(type, TriggerResponseFromSample(sample), bytes, with, TriggerResponseFromSample,
                true);
      break;
    case Ros2Type::kClock: {
      const int64_t ns = ClockFromSample(sample);
      int64_t back = 0;
      std::vector<uint8_t> out;
      try {
        WithClockSample(ns, [&](const void* s) { out = SerializeCdr(type, s); });
        WithCdrSample(type, out, [&](const void* s) { back = ClockFromSample(s); });
      } catch (const Error&) {
        Finding();
      }
      if (out != bytes || back != ns) Finding();
      break;
    }
    default:
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const auto type = static_cast<Ros2Type>(data[0] % kRos2TypeCount);
  try {
    WithCdrSample(type, std::span<const uint8_t>(data + 1, size - 1),
                  [&](const void* sample) { Check(type, sample); });
  } catch (const Error&) {
    // refused: a malformed CDR, or a sample over the bounds (*FromSample)
  }
  return 0;
}
