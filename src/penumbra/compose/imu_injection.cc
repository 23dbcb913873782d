#include "penumbra/compose/imu_injection.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/sensors/mujoco_sensors.h"

namespace penumbra {
namespace {

using tinyxml2::XMLElement;

// depth-first search for <tag name="name">
XMLElement* FindNamed(XMLElement* e, const char* tag, const std::string& name) {
  for (XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const char* n = c->Attribute("name");
    if (std::string(c->Name()) == tag && n && name == n) return c;
    if (XMLElement* f = FindNamed(c, tag, name)) return f;
  }
  return nullptr;
}

std::string Num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

bool ParseVec(const char* text, int n, double* out) {
  if (!text) return false;
  std::istringstream ss(text);
  for (int i = 0; i < n; ++i)
    if (!(ss >> out[i])) return false;
  return true;
}

// adds site "penumbra_imu/<imu_name>" to `body` at X_BS (pose in the body frame), in the
// invisible group 5; returns its name.
std::string AddImuSite(XMLElement* body, const std::string& imu_name, const Pose& X_BS) {
  const std::string name = "penumbra_imu/" + imu_name;
  XMLElement* site = body->InsertNewChildElement("site");
  site->SetAttribute("name", name.c_str());
  const Eigen::Quaterniond q(X_BS.linear());
  const Eigen::Vector3d p = X_BS.translation();
  site->SetAttribute("pos", (Num(p.x()) + " " + Num(p.y()) + " " + Num(p.z())).c_str());
  site->SetAttribute("quat",
                     (Num(q.w()) + " " + Num(q.x()) + " " + Num(q.y()) + " " + Num(q.z())).c_str());
  site->SetAttribute("size", "0.005");
  site->SetAttribute("group", "5");
  return name;
}

}  // namespace

void AddImuSensors(const std::vector<SensorConfig>& sensors, ComposedScene* scene) {
  bool any = false;
  for (const SensorConfig& s : sensors) any = any || s.kind() == SensorKind::kImu;
  if (!any) return;
  XMLElement* root = scene->document->RootElement();
  if (!root) throw Error("AddImuSensors: the composed MJCF has no <mujoco> root");
  XMLElement* worldbody = root->FirstChildElement("worldbody");
  if (!worldbody) worldbody = root->InsertNewChildElement("worldbody");
  XMLElement* sensor_section = root->FirstChildElement("sensor");
  if (!sensor_section) sensor_section = root->InsertNewChildElement("sensor");
  for (const SensorConfig& s : sensors) {
    if (s.kind() != SensorKind::kImu) continue;
    const Pose X_AS = s.X_AS();
    const bool identity = X_AS.isApprox(Pose::Identity(), 1e-12);
    std::string site_name;
    if (!s.site.empty()) {
      XMLElement* site = FindNamed(worldbody, "site", s.site);
      if (!site)
        throw ConfigError(s.file, s.line, s.key + ".site",
                          "sensor '" + s.name + "': no site named '" + s.site +
                              "' in the composed model; expected a site name (\"<model>/<site>\")");
      if (identity) {
        site_name = s.site;
      } else {
        for (const char* a : {"axisangle", "xyaxes", "zaxis", "euler", "fromto"})
          if (site->Attribute(a))
            throw ConfigError(s.file, s.line, s.key + ".pose",
                              "sensor '" + s.name + "': site '" + s.site + "' is oriented by '" +
                                  a +
                                  "'; a pose relative to it is not supported: attach the "
                                  "imu to the site's body instead");
        double pos[3] = {0, 0, 0}, q[4] = {1, 0, 0, 0};
        ParseVec(site->Attribute("pos"), 3, pos);
        ParseVec(site->Attribute("quat"), 4, q);
        Pose X_BA = PoseFromPosQuat(pos, q);
        XMLElement* body = site->Parent()->ToElement();
        const Pose X_BS = X_BA * X_AS;
        site_name = AddImuSite(body, s.name, X_BS);
      }
    } else {
      XMLElement* body = s.body == "world" ? worldbody : FindNamed(worldbody, "body", s.body);
      if (!body)
        throw ConfigError(s.file, s.line, s.key + ".body",
                          "sensor '" + s.name + "': no body named '" + s.body +
                              "' in the composed model; expected a body name (\"<model>/<body>\")"
                              " or world");
      site_name = AddImuSite(body, s.name, X_AS);
    }
    const auto [acc, gyr] = ImuSensorNames(s.name);
    XMLElement* a = sensor_section->InsertNewChildElement("accelerometer");
    a->SetAttribute("name", acc.c_str());
    a->SetAttribute("site", site_name.c_str());
    XMLElement* g = sensor_section->InsertNewChildElement("gyro");
    g->SetAttribute("name", gyr.c_str());
    g->SetAttribute("site", site_name.c_str());
  }
}

}  // namespace penumbra
