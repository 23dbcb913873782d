#include "penumbra/ros/rosbag_writer.h"

#include <rosbag/bag.h>
#include <spdlog/spdlog.h>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros1/ros1_msgs.h"

namespace penumbra {

bool RosAvailable() { return true; }

struct RosbagWriter::Impl {
  std::string path;
  rosbag::Bag bag;
  bool open = false;

  template <typename M>
  void Write(const std::string& topic, int64_t time_ns, const M& msg) {
    // rosbag refuses times below ros::TIME_MIN (1 ns); sim time starts at 0
    const ros::Time t = ros1::ToRosTime(std::max<int64_t>(time_ns, 1));
    try {
      bag.write(topic, t, msg);
    } catch (const std::exception& e) {
      throw Error("cannot write topic " + topic + " to the bag " + path + ": " + e.what());
    }
  }
};

RosbagWriter::RosbagWriter(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  try {
    impl_->bag.open(path, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    throw Error("cannot create the bag " + path + ": " + e.what());
  }
  impl_->open = true;
}

RosbagWriter::~RosbagWriter() {
  try {
    Close();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosImage& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosCameraInfo& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosPointCloud2& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosImu& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosJointState& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosOdometry& m) {
  impl_->Write(topic, time_ns, ros1::ToMsg(m));
  ++messages_;
}
void RosbagWriter::Write(const std::string& topic, int64_t time_ns, const RosTransform& m) {
  impl_->Write(topic, time_ns, ros1::ToTfMsg({m}));
  ++messages_;
}

void RosbagWriter::Close() {
  if (!impl_ || !impl_->open) return;
  impl_->open = false;
  try {
    impl_->bag.close();
  } catch (const std::exception& e) {
    throw Error("cannot finish the bag " + impl_->path + ": " + e.what());
  }
}

}  // namespace penumbra
