// compose/agent_bodies.h from neutral MocapBodySpecs: one mocap body per spec at its pose,
// the built-in shapes, and specs that are refused before anything is added.

#include "penumbra/compose/agent_bodies.h"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr const char* kEmptyScene = "<mujoco><worldbody/></mujoco>";

ComposedScene Empty() {
  ComposedScene s;
  s.document->Parse(kEmptyScene);
  return s;
}

std::vector<double> Numbers(const tinyxml2::XMLElement* e, const char* attr) {
  const char* v = e->Attribute(attr);
  return v ? compose::ParseNumbers(v).value_or(std::vector<double>{}) : std::vector<double>{};
}

// the <body> named `name` under <worldbody>, or nullptr
const tinyxml2::XMLElement* Body(const tinyxml2::XMLDocument& doc, const std::string& name) {
  const auto* wb = doc.FirstChildElement("mujoco")->FirstChildElement("worldbody");
  for (const auto* b = wb->FirstChildElement("body"); b; b = b->NextSiblingElement("body"))
    if (name == b->Attribute("name")) return b;
  return nullptr;
}

const tinyxml2::XMLElement* Geom(const tinyxml2::XMLElement* body, const std::string& name) {
  for (const auto* g = body->FirstChildElement("geom"); g; g = g->NextSiblingElement("geom"))
    if (name == g->Attribute("name")) return g;
  return nullptr;
}

TEST(AgentBodies, EachSpecBecomesAMocapBodyAtItsPose) {
  MocapBodySpec person;
  person.name = "walker";
  person.height_m = 2.0;
  person.X_WB =
      Eigen::Translation3d(1, 2, 0.5) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  MocapBodySpec cart;
  cart.name = "trolley";
  cart.shape = MocapBodySpec::Shape::kCart;
  MocapBodySpec forklift;
  forklift.name = "fl";
  forklift.shape = MocapBodySpec::Shape::kForklift;
  ComposedScene scene = Empty();
  AddAgentBodies({person, cart, forklift}, "w.yaml", &scene);

  tinyxml2::XMLDocument doc;
  const std::string xml = scene.Xml();
  ASSERT_EQ(doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS) << xml;
  const auto* p = Body(doc, "agents/walker");
  ASSERT_NE(p, nullptr) << xml;
  EXPECT_STREQ(p->Attribute("mocap"), "true");
  EXPECT_EQ(Numbers(p, "pos"), (std::vector<double>{1, 2, 0.5}));
  const std::vector<double> q = Numbers(p, "quat");
  ASSERT_EQ(q.size(), 4u);
  EXPECT_NEAR(q[0], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q[3], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q[1], 0, 1e-12);
  // a person's parts scale with its height: the head sphere's top at the height
  const auto* head = Geom(p, "agents/walker/head");
  ASSERT_NE(head, nullptr);
  EXPECT_NEAR(Numbers(head, "pos").at(2) + Numbers(head, "size").at(0), 2.0, 1e-12);
  EXPECT_NEAR(Numbers(head, "size").at(0), 0.063 * 2.0, 1e-12);
  // its limbs are mocap bodies of their own, standing: the left thigh hangs from the hip
  // (0.53 H up, 0.05 H to the left; the body frame turned by the person's yaw)
  const auto* thigh = Body(doc, "agents/walker/thigh_l");
  ASSERT_NE(thigh, nullptr) << xml;
  EXPECT_STREQ(thigh->Attribute("mocap"), "true");
  const std::vector<double> hip = Numbers(thigh, "pos");
  EXPECT_NEAR(hip.at(0), 1 - 0.1, 1e-9);  // yaw 90 deg: left is -x
  EXPECT_NEAR(hip.at(1), 2, 1e-9);
  EXPECT_NEAR(hip.at(2), 0.5 + 0.53 * 2.0, 1e-9);
  EXPECT_NE(Geom(thigh, "agents/walker/thigh_l"), nullptr);
  for (const char* part :
       {"thigh_r", "shin_l", "shin_r", "upper_arm_l", "upper_arm_r", "forearm_l", "forearm_r"})
    EXPECT_NE(Body(doc, std::string("agents/walker/") + part), nullptr) << part;
  // vehicles: a wheel body per wheel, at its axle, with a tyre and a hub bar
  const auto* wheel = Body(doc, "agents/fl/wheel_rr");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(Numbers(wheel, "pos"), (std::vector<double>{-0.55, -0.49, 0.25}));
  EXPECT_NE(Geom(wheel, "agents/fl/wheel_rr"), nullptr);
  EXPECT_NE(Geom(wheel, "agents/fl/wheel_rr_hub"), nullptr);
  EXPECT_NE(Body(doc, "agents/trolley/wheel_fl"), nullptr);

  const auto* c = Body(doc, "agents/trolley");
  ASSERT_NE(c, nullptr);
  EXPECT_NE(Geom(c, "agents/trolley/deck"), nullptr);
  EXPECT_NE(Geom(c, "agents/trolley/handle"), nullptr);
  EXPECT_EQ(Numbers(c, "pos"), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(Numbers(c, "quat"), (std::vector<double>{1, 0, 0, 0}));
  const auto* f = Body(doc, "agents/fl");
  ASSERT_NE(f, nullptr);
  EXPECT_NE(Geom(f, "agents/fl/fork_l"), nullptr);
}

TEST(AgentBodies, InvalidSpecsAreRefusedNamingSpecAndField) {
  const auto error_of = [](const std::vector<MocapBodySpec>& specs) {
    ComposedScene scene = Empty();
    try {
      AddAgentBodies(specs, "w.yaml", &scene);
    } catch (const Error& e) {
      EXPECT_EQ(scene.Xml(), Empty().Xml());  // nothing added
      return std::string(e.what());
    }
    return std::string("no error");
  };
  MocapBodySpec ok;
  ok.name = "a";
  MocapBodySpec bad = ok;
  bad.name = "";
  EXPECT_EQ(error_of({ok, bad}),
            "mocap body spec 1 (''): name: expected a non-empty name of [A-Za-z0-9_-]");
  bad.name = "x/y";
  EXPECT_EQ(error_of({bad}),
            "mocap body spec 0 ('x/y'): name: expected a non-empty name of [A-Za-z0-9_-]");
  bad = ok;
  bad.height_m = 0;
  EXPECT_EQ(error_of({bad}),
            "mocap body spec 0 ('a'): height_m: got 0; expected a finite number > 0 (m)");
  bad = ok;
  bad.height_m = 3.5;
  EXPECT_EQ(error_of({bad}), "mocap body spec 0 ('a'): height_m: got 3.5; expected at most 3 (m)");
  bad = ok;
  bad.shirt_rgb[1] = 1.5;
  EXPECT_EQ(error_of({bad}),
            "mocap body spec 0 ('a'): shirt_rgb: got 1.5; expected a channel in [0, 1]");
  bad = ok;
  bad.X_WB.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of({bad}), "mocap body spec 0 ('a'): X_WB: expected a finite pose");
  EXPECT_EQ(error_of({ok, ok}),
            "mocap body spec 1 ('a'): name: used by an earlier spec; expected unique names");
}

TEST(AgentBodies, NoSpecsLeaveTheSceneAlone) {
  ComposedScene scene = Empty();
  AddAgentBodies({}, "w.yaml", &scene);
  EXPECT_EQ(scene.Xml(), Empty().Xml());
}

}  // namespace
}  // namespace penumbra
