#include "penumbra/ros/rosbag2_writer.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/ros/mcap_writer.h"
#include "penumbra/ros/ros2/ros2_types.h"

namespace penumbra {

namespace {

namespace fs = std::filesystem;

// rosbag2's metadata version as ROS 2 Jazzy writes it (QoS policies by name)
constexpr int kMetadataVersion = 9;

// a YAML double-quoted scalar
std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

bool Rosbag2Available() { return Ros2Available(); }

void RequireRosbag2() {
  // a build without the ROS 2 types: Ros2TypeOf throws the error that says how to get them
  if (!Ros2Available()) Ros2TypeOf(Ros2Type::kImage);
}

std::string Rosbag2Writer::QosYaml(const Ros2QosProfile& q, const std::string& indent) {
  // rmw's infinite duration (RMW_DURATION_INFINITE) as rosbag2 writes it
  const std::string infinite = indent + "    sec: 9223372036\n" + indent + "    nsec: 854775807\n";
  return indent + "- history: keep_last\n" + indent + "  depth: " + std::to_string(q.depth) + "\n" +
         indent + "  reliability: " + (q.reliable ? "reliable" : "best_effort") + "\n" + indent +
         "  durability: " + (q.transient_local ? "transient_local" : "volatile") + "\n" + indent +
         "  deadline:\n" + infinite + indent + "  lifespan:\n" + infinite + indent +
         "  liveliness: automatic\n" + indent + "  liveliness_lease_duration:\n" + infinite +
         indent + "  avoid_ros_namespace_conventions: false\n";
}

struct Rosbag2Writer::Impl {
  fs::path dir;
  std::string shown;      // the bag folder in messages
  std::string file_name;  // "<name>_0.mcap"
  std::unique_ptr<McapWriter> mcap;
  struct Topic {
    RosTopicType topic_type;  // its writer QoS in the live bridge (ros/ros2_names.h)
    Ros2Type type;
    uint16_t channel = 0;
  };
  std::map<std::string, Topic> topics;
  std::vector<std::string> topic_order;  // in the order first written
  std::map<Ros2Type, uint16_t> schemas;
  bool open = false;
  bool abandoned = false;

  uint16_t ChannelOf(const std::string& topic, RosTopicType topic_type) {
    const Ros2Type type = Ros2TypeOfTopic(topic_type);
    const auto it = topics.find(topic);
    if (it != topics.end()) return it->second.channel;
    const Ros2TypeInfo& info = Ros2TypeOf(type);
    auto schema = schemas.find(type);
    if (schema == schemas.end())
      schema =
          schemas.emplace(type, mcap->AddSchema(info.ros_name, "ros2msg", info.definition)).first;
    const uint16_t channel =
        mcap->AddChannel(schema->second, topic, "cdr",
                         {{"offered_qos_profiles", QosYaml(Ros2WriterQos(topic_type))},
                          {"topic_type_hash", info.type_hash}});
    topics.emplace(topic, Topic{topic_type, type, channel});
    topic_order.push_back(topic);
    return channel;
  }

  template <typename M>
  void Write(const std::string& topic, int64_t time_ns, RosTopicType topic_type, const M& m) {
    const Ros2Type type = Ros2TypeOfTopic(topic_type);
    if (!open)
      throw Error("cannot write topic " + topic + " to the ROS 2 bag " + shown +
                  (abandoned ? ": an earlier write failed" : ": it is closed"));
    const auto it = topics.find(topic);
    if (it != topics.end() && it->second.type != type)
      throw Error("cannot write topic " + topic + " to the ROS 2 bag " + shown + " as " +
                  Ros2TypeOf(type).ros_name + ": it holds " + Ros2TypeOf(it->second.type).ros_name);
    std::vector<uint8_t> cdr;
    WithSample(m, [&](const void* sample) { cdr = SerializeCdr(type, sample); });
    try {
      const uint16_t channel = ChannelOf(topic, topic_type);
      const auto t = static_cast<uint64_t>(std::max<int64_t>(time_ns, 0));
      mcap->WriteMessage(channel, t, t, cdr);
    } catch (const Error& e) {
      Abandon();
      throw Error("cannot write topic " + topic + " to the ROS 2 bag " + shown + ": " + e.what());
    }
  }

  void Abandon() {
    open = false;
    abandoned = true;
  }

  // BagMetadata as rosbag2 encodes it, each line prefixed with `indent`
  std::string MetadataYaml(const std::string& indent) const {
    const uint64_t start = mcap->message_start_time();
    const uint64_t duration = mcap->messages() > 0 ? mcap->message_end_time() - start : 0;
    const std::string count = std::to_string(mcap->messages());
    std::string y;
    auto line = [&](const std::string& s) { y += indent + s + "\n"; };
    line("version: " + std::to_string(kMetadataVersion));
    line("storage_identifier: mcap");
    line("duration:");
    line("  nanoseconds: " + std::to_string(duration));
    line("starting_time:");
    line("  nanoseconds_since_epoch: " + std::to_string(start));
    line("message_count: " + count);
    if (topic_order.empty())
      line("topics_with_message_count: []");
    else
      line("topics_with_message_count:");
    for (const std::string& name : topic_order) {
      const Topic& t = topics.at(name);
      const Ros2TypeInfo& info = Ros2TypeOf(t.type);
      line("  - topic_metadata:");
      line("      name: " + Quote(name));
      line("      type: " + Quote(info.ros_name));
      line("      serialization_format: cdr");
      line("      offered_qos_profiles:");
      y += QosYaml(Ros2WriterQos(t.topic_type), indent + "        ");
      line("      type_description_hash: " + Quote(info.type_hash));
      line("    message_count: " + std::to_string(mcap->messages(t.channel)));
    }
    line("compression_format: \"\"");
    line("compression_mode: \"\"");
    line("relative_file_paths:");
    line("  - " + Quote(file_name));
    line("files:");
    line("  - path: " + Quote(file_name));
    line("    starting_time:");
    line("      nanoseconds_since_epoch: " + std::to_string(start));
    line("    duration:");
    line("      nanoseconds: " + std::to_string(duration));
    line("    message_count: " + count);
    line("custom_data: ~");
    line("ros_distro: jazzy");
    return y;
  }
};

Rosbag2Writer::Rosbag2Writer(const fs::path& dir, const std::string& name,
                             const std::string& shown_dir)
    : impl_(std::make_unique<Impl>()) {
  RequireRosbag2();
  Impl& b = *impl_;
  b.dir = dir;
  b.shown = shown_dir.empty() ? dir.string() : shown_dir;
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    throw Error("ROS 2 bag name '" + SanitizeForMessage(name, 200) +
                "'; expected a folder name without '/'");
  b.file_name = name + "_0.mcap";
  McapWriterOptions options;
  options.profile = "ros2";
  options.compression = McapCompression::kZstd;
  b.mcap = std::make_unique<McapWriter>((dir / b.file_name).string(), options,
                                        (fs::path(b.shown) / b.file_name).string());
  b.open = true;
}

Rosbag2Writer::~Rosbag2Writer() {
  try {
    Close();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosImage& m) {
  impl_->Write(topic, time_ns, RosTopicType::kImage, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosCameraInfo& m) {
  impl_->Write(topic, time_ns, RosTopicType::kCameraInfo, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosPointCloud2& m) {
  impl_->Write(topic, time_ns, RosTopicType::kPointCloud2, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosImu& m) {
  impl_->Write(topic, time_ns, RosTopicType::kImu, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosJointState& m) {
  impl_->Write(topic, time_ns, RosTopicType::kJointState, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosOdometry& m) {
  impl_->Write(topic, time_ns, RosTopicType::kOdometry, m);
  ++messages_;
}
void Rosbag2Writer::Write(const std::string& topic, int64_t time_ns, const RosTransform& m) {
  impl_->Write(topic, time_ns, topic == "/tf_static" ? RosTopicType::kTfStatic : RosTopicType::kTf,
               std::vector<RosTransform>{m});
  ++messages_;
}

void Rosbag2Writer::Close() {
  if (!impl_ || !impl_->open) return;
  Impl& b = *impl_;
  b.open = false;
  try {
    // the metadata rosbag2's MCAP storage embeds (readers that get the .mcap file alone)
    b.mcap->AddMetadata("rosbag2", {{"serialized_metadata", b.MetadataYaml("")}});
    b.mcap->Close();
    WriteFileAtomic(b.dir / "metadata.yaml",
                    "rosbag2_bagfile_information:\n" + b.MetadataYaml("  "));
  } catch (const Error& e) {
    b.abandoned = true;
    throw Error("cannot finish the ROS 2 bag " + b.shown + ": " + e.what());
  }
}

}  // namespace penumbra
