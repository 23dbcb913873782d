#include "penumbra/ros/ros_bench.h"

#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Image.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

using Clock = std::chrono::steady_clock;
constexpr char kFrames[] = "/penumbra_bench/image";
constexpr char kAck[] = "/penumbra_bench/ack";
constexpr char kDone[] = "/penumbra_bench/done";

// what the child reports through its pipe
struct ChildReport {
  int64_t received = 0;
  double span_sec = 0;
  int64_t bytes = 0;
};

// the subscriber process: answers frames with frame_id "trip", counts frames "flood", reports
// when a message arrives on kDone
[[noreturn]] void RunChild(const RosBenchOptions& o, int fd) {
  ros::M_string remap;
  if (!o.master_uri.empty()) remap["__master"] = o.master_uri;
  ros::init(remap, "penumbra_bench_subscriber", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::Publisher ack = nh.advertise<rosgraph_msgs::Clock>(kAck, 100);
  ChildReport report;
  Clock::time_point first, last;
  bool done = false;
  ros::Subscriber sub = nh.subscribe<sensor_msgs::Image>(
      kFrames, o.queue_size,
      [&](const sensor_msgs::Image::ConstPtr& m) {
        if (m->header.frame_id == "trip") {
          rosgraph_msgs::Clock c;
          c.clock = m->header.stamp;
          ack.publish(c);
          return;
        }
        // flood frames are acknowledged too: the publisher keeps a window of frames in flight
        rosgraph_msgs::Clock c;
        c.clock = m->header.stamp;
        ack.publish(c);
        const Clock::time_point now = Clock::now();
        if (report.received == 0) first = now;
        last = now;
        ++report.received;
        report.bytes += static_cast<int64_t>(m->data.size());
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::Subscriber stop = nh.subscribe<rosgraph_msgs::Clock>(
      kDone, 1, [&](const rosgraph_msgs::Clock::ConstPtr&) { done = true; });
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(60 + o.seconds + o.trips * 0.05));
  while (ros::ok() && !done && Clock::now() < deadline) {
    ros::spinOnce();
    usleep(200);
  }
  report.span_sec = std::chrono::duration<double>(last - first).count();
  if (write(fd, &report, sizeof report) != static_cast<ssize_t>(sizeof report)) _exit(2);
  ros::shutdown();
  _exit(0);
}

}  // namespace

RosBenchResult RunRosBench(const RosBenchOptions& o) {
  if (ros::isInitialized()) throw Error("bench ros: ROS already started in this process");
  int fds[2];
  if (pipe(fds) != 0) throw Error("bench ros: cannot create a pipe");
  const pid_t child = fork();
  if (child < 0) throw Error("bench ros: cannot fork the subscriber");
  if (child == 0) {
    close(fds[0]);
    RunChild(o, fds[1]);
  }
  close(fds[1]);
  struct Reap {
    pid_t pid;
    int fd;
    bool waited = false;
    ~Reap() {
      if (!waited) {
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
      }
      close(fd);
    }
  } reap{child, fds[0]};

  ros::M_string remap;
  if (!o.master_uri.empty()) remap["__master"] = o.master_uri;
  ros::init(remap, "penumbra_bench_publisher", ros::init_options::NoSigintHandler);
  if (!ros::master::check())
    throw Error("bench ros: no ROS master answers at " + ros::master::getURI() +
                "; start roscore (or set ROS_MASTER_URI)");
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::Image>(kFrames, o.queue_size);
  ros::Publisher done = nh.advertise<rosgraph_msgs::Clock>(kDone, 1, true);
  std::mutex mutex;
  std::condition_variable cv;
  uint64_t acked = 0;
  ros::Subscriber ack = nh.subscribe<rosgraph_msgs::Clock>(
      kAck, 100,
      [&](const rosgraph_msgs::Clock::ConstPtr& c) {
        std::lock_guard<std::mutex> lock(mutex);
        acked = c->clock.toNSec();
        cv.notify_all();
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const Clock::time_point connect_deadline = Clock::now() + std::chrono::seconds(10);
  while ((pub.getNumSubscribers() == 0 || ack.getNumPublishers() == 0) &&
         Clock::now() < connect_deadline)
    usleep(10000);
  if (pub.getNumSubscribers() == 0 || ack.getNumPublishers() == 0)
    throw Error("bench ros: the subscriber process did not connect within 10 s");
  usleep(200000);

  // a pre-rendered frame: a gradient
  sensor_msgs::Image frame;
  frame.width = static_cast<uint32_t>(o.width);
  frame.height = static_cast<uint32_t>(o.height);
  frame.encoding = "rgb8";
  frame.step = frame.width * 3;
  frame.data.resize(static_cast<size_t>(frame.step) * frame.height);
  for (size_t i = 0; i < frame.data.size(); ++i) frame.data[i] = static_cast<uint8_t>(i * 7);

  RosBenchResult r;
  // 1. round trips
  std::vector<double> trips;
  frame.header.frame_id = "trip";
  for (int i = 1; i <= o.trips; ++i) {
    frame.header.stamp.fromNSec(static_cast<uint64_t>(i));
    const Clock::time_point t0 = Clock::now();
    pub.publish(frame);
    std::unique_lock<std::mutex> lock(mutex);
    if (!cv.wait_for(lock, std::chrono::seconds(5),
                     [&] { return acked == static_cast<uint64_t>(i); }))
      throw Error("bench ros: no answer to frame " + std::to_string(i) + " within 5 s");
    trips.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::sort(trips.begin(), trips.end());
  r.trip_median_ms = trips[trips.size() / 2];
  r.trip_p99_ms = trips[std::min(trips.size() - 1, static_cast<size_t>(trips.size() * 0.99))];

  // 2. throughput
  frame.header.frame_id = "flood";
  const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(o.seconds));
  // at most kWindow frames unacknowledged: the rate a subscriber that keeps up receives
  // (a publisher flooding faster only serialises frames roscpp then drops, starving the
  // subscriber of CPU on a small machine)
  constexpr uint64_t kWindow = 4;
  while (Clock::now() < end) {
    const uint64_t stamp = 1000000 + static_cast<uint64_t>(r.frames_sent);
    {
      std::unique_lock<std::mutex> lock(mutex);
      cv.wait_for(lock, std::chrono::milliseconds(200),
                  [&] { return acked + kWindow >= stamp || r.frames_sent < 1; });
    }
    frame.header.stamp.fromNSec(stamp);
    pub.publish(frame);
    ++r.frames_sent;
  }
  usleep(500000);  // let the queued frames arrive
  done.publish(rosgraph_msgs::Clock());
  ChildReport report;
  ssize_t got = 0;
  while (got < static_cast<ssize_t>(sizeof report)) {
    const ssize_t n = read(fds[0], reinterpret_cast<char*>(&report) + got, sizeof report - got);
    if (n <= 0) throw Error("bench ros: the subscriber process ended without a report");
    got += n;
  }
  int status = 0;
  waitpid(child, &status, 0);
  reap.waited = true;
  spinner.stop();
  ros::shutdown();
  r.frames_received = report.received;
  if (report.span_sec > 0 && report.received > 1) {
    r.received_per_sec = static_cast<double>(report.received - 1) / report.span_sec;
    r.megabytes_per_sec = static_cast<double>(report.bytes) / report.span_sec / 1e6;
  }
  return r;
}

}  // namespace penumbra
