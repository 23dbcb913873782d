#include "penumbra/control/joint_type_name.h"

namespace penumbra {

const char* JointTypeName(JointInfo::Type type) {
  switch (type) {
    case JointInfo::Type::kFree:
      return "free";
    case JointInfo::Type::kBall:
      return "ball";
    case JointInfo::Type::kSlide:
      return "slide";
    case JointInfo::Type::kHinge:
      return "hinge";
  }
  return "hinge";
}

}  // namespace penumbra
