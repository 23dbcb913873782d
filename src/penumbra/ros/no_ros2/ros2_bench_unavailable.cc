// a build without ROS 2 (CMake PENUMBRA_WITH_ROS2=OFF, or Cyclone DDS / idlc / the venv's
// rosbags not found): `penumbra bench ros2` refuses with an error that says how to get it.
#include "penumbra/core/error.h"
#include "penumbra/ros/ros2/ros2_bench.h"

namespace penumbra {

Ros2BenchResult RunRos2Bench(const Ros2BenchOptions&) {
  throw Error(
      "penumbra bench ros2 needs ROS 2, which this penumbra was built without (Cyclone DDS): run "
      "scripts/install-deps.sh (cyclonedds-dev, cyclonedds-tools and the venv .venv with "
      "rosbags) and configure again with -DPENUMBRA_WITH_ROS2=AUTO or ON");
}

}  // namespace penumbra
