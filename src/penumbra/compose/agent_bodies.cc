#include "penumbra/compose/agent_bodies.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdio>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"
#include "penumbra/effects/agent_animation.h"

namespace penumbra {
namespace {

using tinyxml2::XMLElement;

std::string Nums(std::initializer_list<double> v) {
  return compose::FormatNumbers(std::vector<double>(v));
}

// sRGB colours (MJCF rgba is display-referred, see physics/scene_extractor.h)
struct Rgb {
  double r, g, b;
};
Rgb FromArray(const std::array<double, 3>& c) { return {c[0], c[1], c[2]}; }
constexpr Rgb kShoe{0.08, 0.07, 0.07};
constexpr Rgb kSafetyYellow{0.95, 0.72, 0.05};
constexpr Rgb kTyre{0.06, 0.06, 0.06};
constexpr Rgb kSteel{0.35, 0.36, 0.38};
constexpr Rgb kCartBlue{0.10, 0.30, 0.65};

// adds one collision geom; mass is set explicitly so density defaults never matter
class BodyWriter {
 public:
  BodyWriter(XMLElement* body, std::string prefix) : body_(body), prefix_(std::move(prefix)) {}

  XMLElement* Geom(const std::string& part, const char* type, const Rgb& c, double mass) {
    XMLElement* g = body_->InsertNewChildElement("geom");
    g->SetAttribute("name", (prefix_ + "/" + part).c_str());
    g->SetAttribute("type", type);
    g->SetAttribute("contype", 1);
    g->SetAttribute("conaffinity", 1);
    g->SetAttribute("condim", 3);
    g->SetAttribute("friction", "0.8 0.005 0.0001");
    g->SetAttribute("group", 1);
    g->SetAttribute("mass", compose::FormatNumbers({mass}).c_str());
    g->SetAttribute("rgba", Nums({c.r, c.g, c.b, 1.0}).c_str());
    return g;
  }
  void Box(const std::string& part, Eigen::Vector3d center, Eigen::Vector3d half, const Rgb& c,
           double mass) {
    XMLElement* g = Geom(part, "box", c, mass);
    g->SetAttribute("pos", Nums({center.x(), center.y(), center.z()}).c_str());
    g->SetAttribute("size", Nums({half.x(), half.y(), half.z()}).c_str());
  }
  void FromTo(const std::string& part, const char* type, Eigen::Vector3d a, Eigen::Vector3d b,
              double radius, const Rgb& c, double mass) {
    XMLElement* g = Geom(part, type, c, mass);
    g->SetAttribute("fromto", Nums({a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}).c_str());
    g->SetAttribute("size", compose::FormatNumbers({radius}).c_str());
  }
  void Sphere(const std::string& part, Eigen::Vector3d center, double radius, const Rgb& c,
              double mass) {
    XMLElement* g = Geom(part, "sphere", c, mass);
    g->SetAttribute("pos", Nums({center.x(), center.y(), center.z()}).c_str());
    g->SetAttribute("size", compose::FormatNumbers({radius}).c_str());
  }

 private:
  XMLElement* body_;
  std::string prefix_;
};

using V = Eigen::Vector3d;

// the root of a person (frame R, effects/walker_gait.h): pelvis, torso, neck and head
void AddPersonRoot(BodyWriter* w, const WalkerSkeleton& k, const MocapBodySpec& spec) {
  const double h = k.height_m;
  const Rgb shirt = FromArray(spec.shirt_rgb), trousers = FromArray(spec.trousers_rgb),
            skin = FromArray(spec.skin_rgb);
  w->Box("pelvis", V(0, 0, 0.55 * h), V(0.063 * h, 0.097 * h, 0.045 * h), trousers, 10);
  w->Box("torso", V(0, 0, 0.71 * h), V(0.063 * h, 0.109 * h, 0.12 * h), shirt, 25);
  w->FromTo("neck", "capsule", V(0, 0, 0.83 * h), V(0, 0, 0.87 * h), 0.03 * h, skin, 1);
  w->Sphere("head", V(0.006 * h, 0, 0.937 * h), 0.063 * h, skin, 5);
}

// one limb segment of a person in its own frame S: from its joint along -z
void AddPersonSegment(BodyWriter* w, WalkerSegment segment, const WalkerSkeleton& k,
                      const MocapBodySpec& spec) {
  const double h = k.height_m;
  const Rgb shirt = FromArray(spec.shirt_rgb), trousers = FromArray(spec.trousers_rgb),
            skin = FromArray(spec.skin_rgb);
  const std::string lr = (static_cast<int>(segment) % 2 == 0) ? "_l" : "_r";
  switch (segment) {
    case WalkerSegment::kThighL:
    case WalkerSegment::kThighR:
      w->FromTo("thigh" + lr, "capsule", V(0, 0, 0), V(0, 0, -k.thigh_m), 0.04 * h, trousers, 8);
      break;
    case WalkerSegment::kShinL:
    case WalkerSegment::kShinR:
      w->FromTo("shin" + lr, "capsule", V(0, 0, 0), V(0, 0, -k.shank_m), 0.03 * h, trousers, 4);
      w->Box("foot" + lr, V(0.035 * h, 0, -k.shank_m - 0.0195 * h),
             V(0.075 * h, 0.03 * h, 0.0195 * h), kShoe, 1);
      break;
    case WalkerSegment::kUpperArmL:
    case WalkerSegment::kUpperArmR:
      w->FromTo("upper_arm" + lr, "capsule", V(0, 0, 0), V(0, 0, -k.upper_arm_m), 0.026 * h, shirt,
                2);
      break;
    case WalkerSegment::kForearmL:
    case WalkerSegment::kForearmR:
      w->FromTo("forearm" + lr, "capsule", V(0, 0, 0), V(0, 0, -k.forearm_m), 0.022 * h, skin, 1.5);
      w->Sphere("hand" + lr, V(0, 0, -k.forearm_m - 0.04 * h), 0.03 * h, skin, 0.5);
      break;
  }
}

// a wheel in its own frame (centre, axle along y): a tyre and a hub bar that shows the spin
void AddWheel(BodyWriter* w, const AgentWheel& wheel, double mass) {
  const double r = wheel.radius_m, half = wheel.width_m / 2;
  w->FromTo(wheel.name, "cylinder", V(0, -half, 0), V(0, half, 0), r, kTyre, mass);
  w->Box(wheel.name + "_hub", V(0, 0, 0), V(0.8 * r, half + 0.004, 0.12 * r), kSteel, 0.1 * mass);
}

// a counterbalance forklift, forks towards +x
void AddForklift(BodyWriter* w) {
  w->Box("chassis", V(0, 0, 0.6), V(0.8, 0.55, 0.35), kSafetyYellow, 1800);
  w->Box("counterweight", V(-0.7, 0, 0.75), V(0.15, 0.5, 0.3), kSteel, 1200);
  w->Box("seat", V(-0.2, 0, 1.05), V(0.2, 0.25, 0.1), kTyre, 20);
  for (int side : {-1, 1}) {
    const char* lr = side > 0 ? "l" : "r";
    w->Box(std::string("mast_") + lr, V(0.85, 0.35 * side, 1.05), V(0.05, 0.05, 1.0), kSteel, 80);
    w->Box(std::string("fork_") + lr, V(1.35, 0.25 * side, 0.12), V(0.55, 0.05, 0.025), kSteel, 40);
    for (int fx : {-1, 1})
      w->Box(std::string("post_") + (fx > 0 ? "f" : "r") + lr, V(0.05 + 0.55 * fx, 0.5 * side, 1.6),
             V(0.03, 0.03, 0.5), kSafetyYellow, 10);
  }
  w->Box("carriage", V(0.95, 0, 0.4), V(0.05, 0.4, 0.3), kSteel, 60);
  w->Box("guard", V(0.05, 0, 2.1), V(0.6, 0.55, 0.03), kSafetyYellow, 40);
}

// a hand cart pushed from the back (-x side)
void AddCart(BodyWriter* w) {
  w->Box("deck", V(0, 0, 0.3), V(0.5, 0.3, 0.04), kCartBlue, 20);
  for (int side : {-1, 1})
    w->FromTo(std::string("upright_") + (side > 0 ? "l" : "r"), "capsule",
              V(-0.48, 0.27 * side, 0.34), V(-0.5, 0.27 * side, 1.0), 0.015, kSteel, 1);
  w->FromTo("handle", "capsule", V(-0.5, -0.27, 1.0), V(-0.5, 0.27, 1.0), 0.02, kSteel, 1);
}

}  // namespace

std::string AgentBodyName(const std::string& agent_name) { return "agents/" + agent_name; }

std::string AgentPartBodyName(const std::string& agent_name, const std::string& part) {
  return AgentBodyName(agent_name) + "/" + part;
}

bool IsAgentBodyOf(const std::string& body_name, const std::string& agent_name) {
  const std::string root = AgentBodyName(agent_name);
  return body_name == root ||
         (body_name.size() > root.size() + 1 && body_name.compare(0, root.size(), root) == 0 &&
          body_name[root.size()] == '/');
}

AgentKind AgentKindOfShape(MocapBodySpec::Shape shape) {
  switch (shape) {
    case MocapBodySpec::Shape::kPerson:
      return AgentKind::kPerson;
    case MocapBodySpec::Shape::kForklift:
      return AgentKind::kForklift;
    case MocapBodySpec::Shape::kCart:
      return AgentKind::kCart;
  }
  return AgentKind::kPerson;
}

void AddAgentBodies(const std::vector<MocapBodySpec>& bodies, const std::string& world_file,
                    ComposedScene* scene) {
  if (bodies.empty()) return;
  ValidateMocapBodySpecsOrThrow(bodies);
  for (const std::string& m : scene->model_names)
    if (m == "agents")
      throw ConfigError(world_file, 0, "models",
                        "a model is named 'agents', which is reserved for the bodies of the "
                        "world's agents; expected another model name");
  XMLElement* root = scene->document->FirstChildElement("mujoco");
  if (!root) throw ConfigError(world_file, 0, "agents", "composed MJCF has no <mujoco> root");
  XMLElement* worldbody = root->FirstChildElement("worldbody");
  if (!worldbody) worldbody = root->InsertNewChildElement("worldbody");

  std::vector<double> mpos, mquat;
  const auto add_body = [&](const std::string& name, const Pose& X_WB) {
    const Eigen::Quaterniond q(X_WB.linear());
    const Eigen::Vector3d p = X_WB.translation();
    XMLElement* body = worldbody->InsertNewChildElement("body");
    body->SetAttribute("name", name.c_str());
    body->SetAttribute("mocap", "true");
    body->SetAttribute("pos", Nums({p.x(), p.y(), p.z()}).c_str());
    body->SetAttribute("quat", Nums({q.w(), q.x(), q.y(), q.z()}).c_str());
    mpos.insert(mpos.end(), {p.x(), p.y(), p.z()});
    mquat.insert(mquat.end(), {q.w(), q.x(), q.y(), q.z()});
    return body;
  };
  for (const MocapBodySpec& spec : bodies) {
    const std::string name = AgentBodyName(spec.name);
    const AgentKind kind = AgentKindOfShape(spec.shape);
    // the parts' poses at t = 0: standing still at the spec's pose
    const Pose X_WA0 = spec.X_WB;
    AgentAnimator animator(kind, spec.height_m, [X_WA0](double) { return X_WA0; });
    const std::vector<Pose>& X_W = animator.Poses(0.0);
    const std::vector<std::string> parts = AgentPartNames(kind);
    XMLElement* root = add_body(name, X_W[0]);
    BodyWriter w(root, name);
    switch (spec.shape) {
      case MocapBodySpec::Shape::kPerson:
        AddPersonRoot(&w, animator.skeleton(), spec);
        break;
      case MocapBodySpec::Shape::kForklift:
        AddForklift(&w);
        break;
      case MocapBodySpec::Shape::kCart:
        AddCart(&w);
        break;
    }
    const std::vector<AgentWheel> wheels = AgentWheels(kind);
    for (size_t j = 0; j < parts.size(); ++j) {
      XMLElement* part = add_body(AgentPartBodyName(spec.name, parts[j]), X_W[j + 1]);
      BodyWriter pw(part, name);
      if (kind == AgentKind::kPerson)
        AddPersonSegment(&pw, static_cast<WalkerSegment>(j), animator.skeleton(), spec);
      else
        AddWheel(&pw, wheels[j], kind == AgentKind::kForklift ? 40 : 2);
    }
  }
  // keyframes that list mocap poses need the new bodies' poses appended (MuJoCo requires
  // full-length vectors); keys without mpos / mquat take the bodies' own pose anyway
  if (XMLElement* keys = root->FirstChildElement("keyframe")) {
    for (XMLElement* k = keys->FirstChildElement("key"); k; k = k->NextSiblingElement("key")) {
      for (auto [attr, extra] :
           {std::pair<const char*, const std::vector<double>*>{"mpos", &mpos}, {"mquat", &mquat}}) {
        const char* v = k->Attribute(attr);
        if (!v) continue;
        std::vector<double> values = compose::ParseNumbers(v).value_or(std::vector<double>{});
        values.insert(values.end(), extra->begin(), extra->end());
        k->SetAttribute(attr, compose::FormatNumbers(values).c_str());
      }
    }
  }
}

}  // namespace penumbra
