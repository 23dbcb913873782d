#include "penumbra/compose/agent_bodies.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdio>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

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
constexpr std::array<Rgb, 6> kShirts = {{{0.80, 0.15, 0.12},
                                         {0.15, 0.35, 0.75},
                                         {0.20, 0.55, 0.25},
                                         {0.95, 0.60, 0.10},
                                         {0.55, 0.25, 0.60},
                                         {0.90, 0.90, 0.88}}};
constexpr Rgb kTrousers{0.12, 0.14, 0.22};
constexpr Rgb kSkin{0.80, 0.62, 0.50};
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

// a standing person, feet at z = 0, facing +x; heights scale with height_m / 1.75
void AddPerson(BodyWriter* w, double height_m, const Rgb& shirt) {
  const double s = height_m / 1.75;
  for (int side : {-1, 1}) {
    const char* lr = side > 0 ? "l" : "r";
    w->FromTo(std::string("leg_") + lr, "capsule", V(0, 0.1 * side, 0.07 * s),
              V(0, 0.1 * side, 0.86 * s), 0.07, kTrousers, 10);
    w->FromTo(std::string("arm_") + lr, "capsule", V(0.0, 0.23 * side, 1.38 * s),
              V(0.04, 0.26 * side, 0.86 * s), 0.05, shirt, 4);
  }
  w->Box("pelvis", V(0, 0, 0.92 * s), V(0.11, 0.17, 0.08 * s), kTrousers, 10);
  w->Box("torso", V(0, 0, 1.2 * s), V(0.11, 0.19, 0.25 * s), shirt, 25);
  w->FromTo("neck", "capsule", V(0, 0, 1.45 * s), V(0, 0, 1.52 * s), 0.05, kSkin, 1);
  w->Sphere("head", V(0.01, 0, 1.75 * s - 0.11), 0.11, kSkin, 5);
}

// a counterbalance forklift, forks towards +x
void AddForklift(BodyWriter* w) {
  w->Box("chassis", V(0, 0, 0.6), V(0.8, 0.55, 0.35), kSafetyYellow, 1800);
  w->Box("counterweight", V(-0.7, 0, 0.75), V(0.15, 0.5, 0.3), kSteel, 1200);
  w->Box("seat", V(-0.2, 0, 1.05), V(0.2, 0.25, 0.1), kTyre, 20);
  for (int fx : {-1, 1})
    for (int side : {-1, 1}) {
      const std::string name =
          std::string("wheel_") + (fx > 0 ? "f" : "r") + (side > 0 ? "l" : "r");
      w->FromTo(name, "cylinder", V(0.55 * fx, 0.42 * side, 0.25), V(0.55 * fx, 0.56 * side, 0.25),
                0.25, kTyre, 40);
    }
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
  for (int fx : {-1, 1})
    for (int side : {-1, 1}) {
      const std::string name =
          std::string("wheel_") + (fx > 0 ? "f" : "r") + (side > 0 ? "l" : "r");
      w->FromTo(name, "cylinder", V(0.4 * fx, 0.27 * side, 0.1), V(0.4 * fx, 0.31 * side, 0.1), 0.1,
                kTyre, 2);
    }
  for (int side : {-1, 1})
    w->FromTo(std::string("upright_") + (side > 0 ? "l" : "r"), "capsule",
              V(-0.48, 0.27 * side, 0.34), V(-0.5, 0.27 * side, 1.0), 0.015, kSteel, 1);
  w->FromTo("handle", "capsule", V(-0.5, -0.27, 1.0), V(-0.5, 0.27, 1.0), 0.02, kSteel, 1);
}

}  // namespace

std::string AgentBodyName(const std::string& agent_name) { return "agents/" + agent_name; }

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
  for (size_t i = 0; i < bodies.size(); ++i) {
    const MocapBodySpec& spec = bodies[i];
    const Eigen::Quaterniond q(spec.X_WB.linear());
    const Eigen::Vector3d p = spec.X_WB.translation();
    XMLElement* body = worldbody->InsertNewChildElement("body");
    const std::string name = AgentBodyName(spec.name);
    body->SetAttribute("name", name.c_str());
    body->SetAttribute("mocap", "true");
    body->SetAttribute("pos", Nums({p.x(), p.y(), p.z()}).c_str());
    body->SetAttribute("quat", Nums({q.w(), q.x(), q.y(), q.z()}).c_str());
    BodyWriter w(body, name);
    switch (spec.shape) {
      case MocapBodySpec::Shape::kPerson:
        AddPerson(&w, spec.height_m, kShirts[HashKeys(0xA6E7, i) % kShirts.size()]);
        break;
      case MocapBodySpec::Shape::kForklift:
        AddForklift(&w);
        break;
      case MocapBodySpec::Shape::kCart:
        AddCart(&w);
        break;
    }
    mpos.insert(mpos.end(), {p.x(), p.y(), p.z()});
    mquat.insert(mquat.end(), {q.w(), q.x(), q.y(), q.z()});
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
