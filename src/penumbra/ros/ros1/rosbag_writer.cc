#include "penumbra/ros/rosbag_writer.h"

#include <dirent.h>
#include <fcntl.h>
#include <rosbag/bag.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include "penumbra/core/error.h"
#include "penumbra/ros/ros1/ros1_msgs.h"

namespace penumbra {

bool RosAvailable() { return true; }

struct RosbagWriter::Impl {
  std::string path;   // the file written
  std::string shown;  // the name in messages
  std::unique_ptr<rosbag::Bag> bag = std::make_unique<rosbag::Bag>();
  dev_t dev = 0;  // the file's identity, to find the descriptor of rosbag's FILE
  ino_t ino = 0;
  bool open = false;
  bool abandoned = false;

  // the reason of the last failed system call, for messages ("" when none is known)
  static std::string Reason(int err) {
    return err != 0 ? std::string(": ") + std::strerror(err) : "";
  }

  template <typename M>
  void Write(const std::string& topic, int64_t time_ns, const M& msg) {
    if (!open)
      throw Error("cannot write topic " + topic + " to the bag " + shown +
                  (abandoned ? ": an earlier write failed" : ": it is closed"));
    // rosbag refuses times below ros::TIME_MIN (1 ns); sim time starts at 0
    const ros::Time t = ros1::ToRosTime(std::max<int64_t>(time_ns, 1));
    errno = 0;
    try {
      bag->write(topic, t, msg);
    } catch (const std::exception& e) {
      const int err = errno;
      const std::string what = e.what();
      Abandon();
      throw Error("cannot write topic " + topic + " to the bag " + shown + ": " + what +
                  Reason(err));
    }
  }

  // the bag cannot be finished: the descriptor of rosbag's FILE is pointed at /dev/null (found
  // by the file's device and inode among this process's descriptors), so that rosbag's close,
  // here and in ~Bag, writes its index there and succeeds. if that fails the Bag is left
  // unreleased: its destructor would throw and abort the process.
  void Abandon() noexcept {
    open = false;
    abandoned = true;
    if (!bag || !bag->isOpen()) return;
    bool redirected = false;
    const int null_fd = ::open("/dev/null", O_RDWR | O_CLOEXEC);
    if (null_fd >= 0) {
      if (DIR* d = ::opendir("/proc/self/fd")) {
        while (const dirent* e = ::readdir(d)) {
          int fd = -1;
          const char* end = e->d_name + std::strlen(e->d_name);
          if (std::from_chars(e->d_name, end, fd).ptr != end || fd == null_fd || fd == ::dirfd(d))
            continue;
          struct stat st {};
          if (::fstat(fd, &st) == 0 && st.st_dev == dev && st.st_ino == ino &&
              ::dup2(null_fd, fd) >= 0)
            redirected = true;
        }
        ::closedir(d);
      }
      ::close(null_fd);
    }
    if (redirected) {
      try {
        bag->close();
        bag.reset();
        return;
      } catch (const std::exception& e) {
        spdlog::debug("abandoned bag {}: {}", shown, e.what());
      }
    }
    static_cast<void>(bag.release());
  }
};

RosbagWriter::RosbagWriter(const std::string& path, const std::string& shown_path)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->shown = shown_path.empty() ? path : shown_path;
  auto identify = [this] {
    struct stat st {};
    if (::stat(impl_->path.c_str(), &st) == 0) {
      impl_->dev = st.st_dev;
      impl_->ino = st.st_ino;
    }
  };
  errno = 0;
  try {
    impl_->bag->open(path, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    const int err = errno;
    const std::string what = e.what();
    // the file may be open with its header half written: its close must not reach ~Bag
    identify();
    impl_->Abandon();
    throw Error("cannot create the bag " + impl_->shown + ": " + what + Impl::Reason(err));
  }
  identify();
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
  errno = 0;
  try {
    impl_->bag->close();
  } catch (const std::exception& e) {
    const int err = errno;
    const std::string what = e.what();
    impl_->Abandon();
    throw Error("cannot finish the bag " + impl_->shown + ": " + what + Impl::Reason(err));
  }
}

}  // namespace penumbra
