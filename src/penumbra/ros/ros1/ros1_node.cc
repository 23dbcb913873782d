#include "penumbra/ros/ros1_node.h"

#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <spdlog/spdlog.h>
#include <std_srvs/Trigger.h>

#include <mutex>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros1/ros1_msgs.h"

namespace penumbra {

struct Ros1Node::Impl {
  std::unique_ptr<ros::NodeHandle> nh;
  std::unique_ptr<ros::AsyncSpinner> spinner;
  int spinner_threads = 2;
  mutable std::mutex mutex;  // guards the vectors (publishing itself is thread-safe)
  std::vector<ros::Publisher> publishers;
  std::vector<RosTopicType> types;
  std::vector<ros::Subscriber> subscribers;
  std::vector<ros::ServiceServer> services;

  ros::Publisher Get(int id, RosTopicType type) const {
    std::lock_guard<std::mutex> lock(mutex);
    if (id < 0 || id >= static_cast<int>(publishers.size()))
      throw Error("no ROS publisher " + std::to_string(id));
    if (types[id] != type && !(type == RosTopicType::kTf && types[id] == RosTopicType::kTfStatic))
      throw Error("ROS publisher " + publishers[id].getTopic() + " has another message type");
    return publishers[id];
  }
};

Ros1Node::Ros1Node(const Options& options) : impl_(std::make_unique<Impl>()) {
  if (ros::isInitialized())
    throw Error("a ROS node already runs in this process; expected one ROS bridge per run");
  ros::M_string remappings;
  if (!options.master_uri.empty()) remappings["__master"] = options.master_uri;
  // penumbra handles SIGINT itself (a clean stop writes the outputs)
  ros::init(remappings, options.name, ros::init_options::NoSigintHandler);
  if (!ros::master::check())
    throw Error("no ROS master answers at " + ros::master::getURI() +
                "; start one (roscore) or point ROS_MASTER_URI (or --ros URI) at it");
  impl_->nh = std::make_unique<ros::NodeHandle>();
  impl_->spinner_threads = options.spinner_threads;
  if (options.set_use_sim_time) ros::param::set("/use_sim_time", true);
}

Ros1Node::~Ros1Node() {
  if (impl_->spinner) impl_->spinner->stop();
  impl_->services.clear();
  impl_->subscribers.clear();
  impl_->publishers.clear();
  impl_->nh.reset();
  ros::shutdown();
}

int Ros1Node::Advertise(const std::string& topic, RosTopicType type, int queue_size) {
  ros::NodeHandle& nh = *impl_->nh;
  ros::Publisher p;
  switch (type) {
    case RosTopicType::kImage:
      p = nh.advertise<sensor_msgs::Image>(topic, queue_size);
      break;
    case RosTopicType::kCameraInfo:
      p = nh.advertise<sensor_msgs::CameraInfo>(topic, queue_size);
      break;
    case RosTopicType::kPointCloud2:
      p = nh.advertise<sensor_msgs::PointCloud2>(topic, queue_size);
      break;
    case RosTopicType::kImu:
      p = nh.advertise<sensor_msgs::Imu>(topic, queue_size);
      break;
    case RosTopicType::kJointState:
      p = nh.advertise<sensor_msgs::JointState>(topic, queue_size);
      break;
    case RosTopicType::kOdometry:
      p = nh.advertise<nav_msgs::Odometry>(topic, queue_size);
      break;
    case RosTopicType::kTf:
      p = nh.advertise<tf2_msgs::TFMessage>(topic, queue_size);
      break;
    case RosTopicType::kTfStatic:
      p = nh.advertise<tf2_msgs::TFMessage>(topic, queue_size, /*latch=*/true);
      break;
    case RosTopicType::kClock:
      p = nh.advertise<rosgraph_msgs::Clock>(topic, queue_size);
      break;
  }
  if (!p) throw Error("cannot advertise the ROS topic " + topic);
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->publishers.push_back(p);
  impl_->types.push_back(type);
  return static_cast<int>(impl_->publishers.size()) - 1;
}

int Ros1Node::Subscribers(int id) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (id < 0 || id >= static_cast<int>(impl_->publishers.size())) return 0;
  return static_cast<int>(impl_->publishers[id].getNumSubscribers());
}

void Ros1Node::Publish(int id, RosImage&& m) {
  impl_->Get(id, RosTopicType::kImage).publish(ros1::ToMsg(std::move(m)));
}
void Ros1Node::Publish(int id, const RosCameraInfo& m) {
  impl_->Get(id, RosTopicType::kCameraInfo).publish(ros1::ToMsg(m));
}
void Ros1Node::Publish(int id, RosPointCloud2&& m) {
  impl_->Get(id, RosTopicType::kPointCloud2).publish(ros1::ToMsg(std::move(m)));
}
void Ros1Node::Publish(int id, const RosImu& m) {
  impl_->Get(id, RosTopicType::kImu).publish(ros1::ToMsg(m));
}
void Ros1Node::Publish(int id, const RosJointState& m) {
  impl_->Get(id, RosTopicType::kJointState).publish(ros1::ToMsg(m));
}
void Ros1Node::Publish(int id, const RosOdometry& m) {
  impl_->Get(id, RosTopicType::kOdometry).publish(ros1::ToMsg(m));
}
void Ros1Node::Publish(int id, const std::vector<RosTransform>& transforms) {
  impl_->Get(id, RosTopicType::kTf).publish(ros1::ToTfMsg(transforms));
}
void Ros1Node::PublishClock(int id, int64_t stamp_ns) {
  rosgraph_msgs::Clock c;
  c.clock = ros1::ToRosTime(stamp_ns);
  impl_->Get(id, RosTopicType::kClock).publish(c);
}

void Ros1Node::SubscribeTwist(const std::string& topic,
                              std::function<void(const RosTwist&)> callback) {
  ros::Subscriber s = impl_->nh->subscribe<geometry_msgs::Twist>(
      topic, 10,
      [callback](const geometry_msgs::Twist::ConstPtr& m) { callback(ros1::FromMsg(*m)); });
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->subscribers.push_back(s);
}

void Ros1Node::SubscribeJointState(const std::string& topic,
                                   std::function<void(const RosJointState&)> callback) {
  ros::Subscriber s = impl_->nh->subscribe<sensor_msgs::JointState>(
      topic, 10,
      [callback](const sensor_msgs::JointState::ConstPtr& m) { callback(ros1::FromMsg(*m)); });
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->subscribers.push_back(s);
}

void Ros1Node::SubscribePose(const std::string& topic,
                             std::function<void(const RosPoseStamped&)> callback) {
  ros::Subscriber s = impl_->nh->subscribe<geometry_msgs::PoseStamped>(
      topic, 10,
      [callback](const geometry_msgs::PoseStamped::ConstPtr& m) { callback(ros1::FromMsg(*m)); });
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->subscribers.push_back(s);
}

void Ros1Node::AdvertiseTrigger(const std::string& service,
                                std::function<std::pair<bool, std::string>()> callback) {
  boost::function<bool(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&)> f =
      [callback](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
        const std::pair<bool, std::string> r = callback();
        res.success = r.first;
        res.message = r.second;
        return true;
      };
  ros::ServiceServer s = impl_->nh->advertiseService(service, f);
  if (!s) throw Error("cannot advertise the ROS service " + service);
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->services.push_back(s);
}

int64_t Ros1Node::IntParam(const std::string& name, int64_t fallback) const {
  int v = 0;
  if (ros::param::get(name, v)) return v;
  return fallback;
}

void Ros1Node::SetParam(const std::string& name, int64_t value) {
  ros::param::set(name, static_cast<int>(value));
}

void Ros1Node::Start() {
  impl_->spinner = std::make_unique<ros::AsyncSpinner>(impl_->spinner_threads);
  impl_->spinner->start();
}

std::string Ros1Node::master_uri() const { return ros::master::getURI(); }

std::string Ros1Node::where() const { return "at " + master_uri(); }

}  // namespace penumbra
