// the precompiled header shared by every <module>_tests (CMakeLists.txt, PENUMBRA_TEST_PCH):
// GoogleTest, Eigen and the standard headers most test files include, parsed once per build
// instead of once per unity batch. test files still include what they use; this header only
// makes those includes cheap. only headers that do not change with the tree belong here.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
