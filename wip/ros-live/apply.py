# applies the live ROS bridge integration on top of a tree that has cmd's hook
import re, shutil, os
root = '/work/wt-ros'
def edit(p, old, new, count=1):
    path = os.path.join(root, p); s = open(path).read()
    assert old in s, (p, old[:60]); s = s.replace(old, new, count); open(path, 'w').write(s)
shutil.copy('/tmp/ros-pending/ros_bridge.h', root + '/src/penumbra/ros/ros_bridge.h')
shutil.copy('/tmp/ros-pending/ros_bridge.cc', root + '/src/penumbra/ros/ros_bridge.cc')
shutil.copy('/tmp/ros-pending/ros_live_test.py', root + '/tests/ros/ros_live_test.py')
shutil.copy('/tmp/ros-pending/ros_live_world.yaml', root + '/tests/ros/ros_live_world.yaml')
# DEPENDENCIES: ros uses the command layer
p = root + '/src/penumbra/DEPENDENCIES'; s = open(p).read()
s = s.replace('ros: dataset output physics world control sensors scene core\n', '')
s = s.replace('\napp: ', '\nros: command session dataset output physics world control sensors scene core\napp: ', 1)
open(p, 'w').write(s)
edit('src/penumbra/app/bridge_flags.h', '//   --lockstep ', '//   --ros [MASTER_URI]    ROS 1 bridge (docs/ros.md); default $ROS_MASTER_URI\n//   --lockstep ')
edit('src/penumbra/app/bridge_flags.h', '  bool lockstep = false;', '  bool lockstep = false;\n  std::string ros_master;  ///< --ros [MASTER_URI]')
edit('src/penumbra/app/bridge_flags.cc', '#include "penumbra/zmq/zmq_bridge.h"', '#include "penumbra/ros/ros_bridge.h"\n#include "penumbra/zmq/zmq_bridge.h"')
edit('src/penumbra/app/bridge_flags.cc', '''  run->add_flag("--lockstep", lockstep,''', '''  run->add_option("--ros", ros_master,
                  "serve the run over ROS 1 (docs/ros.md): topics, tf, /clock, cmd_vel and the "
                  "/penumbra/step service; the master at MASTER_URI (default $ROS_MASTER_URI)")
      ->expected(0, 1)
      ->type_name("[MASTER_URI]");
  run->add_flag("--lockstep", lockstep,''')
edit('src/penumbra/app/bridge_flags.cc', '''  const bool zmq = run.count("--zmq") > 0;
  for (const char* flag :
       {"--zmq-pub", "--bind", "--lockstep", "--zmq-hwm", "--zmq-max-request", "--zmq-state-hz"})
    if (run.count(flag) > 0 && !zmq)
      throw ConfigError("", 0, flag, "needs --zmq (a bridge to serve the run)");
  if (!zmq) return;''', '''  const bool zmq = run.count("--zmq") > 0;
  const bool ros = run.count("--ros") > 0;
  for (const char* flag : {"--zmq-pub", "--bind", "--zmq-hwm", "--zmq-max-request", "--zmq-state-hz"})
    if (run.count(flag) > 0 && !zmq)
      throw ConfigError("", 0, flag, "needs --zmq (a bridge to serve the run)");
  if (run.count("--lockstep") > 0 && !zmq && !ros)
    throw ConfigError("", 0, "--lockstep", "needs --zmq or --ros (a bridge to serve the run)");
  if (ros) {
    RosBridgeOptions r;
    r.master_uri = ros_master;
    options->bridges.push_back(MakeRosBridgeFactory(r));
    options->lockstep = lockstep;
  }
  if (!zmq) return;''')
# CMake: the live test
edit('CMakeLists.txt', '''    set_tests_properties(RosbagExport.RosbagInfoAndMessages PROPERTIES TIMEOUT 300)''', '''    set_tests_properties(RosbagExport.RosbagInfoAndMessages PROPERTIES TIMEOUT 300)
    # `penumbra run --ros` against a real roscore and the ROS tools (rostopic, rosbag)
    add_test(NAME RosLive.RoscoreTopicsTfBagCmdVel
             COMMAND ${PENUMBRA_SYSTEM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/ros/ros_live_test.py
                     $<TARGET_FILE:penumbra> ${CMAKE_SOURCE_DIR}
                     ${CMAKE_BINARY_DIR}/ros_live_test)
    set_tests_properties(RosLive.RoscoreTopicsTfBagCmdVel PROPERTIES TIMEOUT 300 RUN_SERIAL TRUE)''')
print("applied")
