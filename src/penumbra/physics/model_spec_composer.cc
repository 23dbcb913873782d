#include "penumbra/physics/model_spec_composer.h"

#include <fmt/format.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <regex>

#include "penumbra/core/error.h"
#include "penumbra/core/magnitude_limits.h"
#include "penumbra/physics/mujoco_runtime.h"

namespace penumbra {
namespace {

// MuJoCo's messages say "Element 'geom', line 3" (parser) or "Element name 'M/g', id 0,
// line 5" (compiler)
int LineOf(const std::string& msg) {
  static const std::regex re("line (?:= )?([0-9]+)");
  std::smatch m;
  if (std::regex_search(msg, m, re)) return std::stoi(m[1].str());
  return 0;
}

// the element name a compiler message names, or ""
std::string ElementNameOf(const std::string& msg) {
  static const std::regex re("Element name '([^']*)'");
  std::smatch m;
  if (std::regex_search(msg, m, re)) return m[1].str();
  return "";
}

// one line: MuJoCo's messages end in newlines and put the element on a line of its own
std::string Trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

struct SpecDeleter {
  void operator()(mjSpec* s) const { mj_deleteSpec(s); }
};
using SpecPtr = std::unique_ptr<mjSpec, SpecDeleter>;
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

std::string ModelKey(const SpecModel& m) {
  return m.key.empty() ? "models[" + m.name + "]" : m.key;
}

// a relative asset path made absolute: the model file's folder, then the compiler's
// meshdir or texturedir (MuJoCo's own resolution, kept when the spec is saved elsewhere).
// MuJoCo's strings are reached through mjs_getString / mjs_setString only: the library's
// C++ standard library need not be ours.
void Absolutize(mjString* file, const std::string& model_dir, const std::string& dir) {
  const std::string f = mjs_getString(file);
  if (f.empty() || std::filesystem::path(f).is_absolute()) return;
  if (f.find(':') != std::string::npos) return;  // a URI or a VFS name
  const std::filesystem::path base = std::filesystem::path(dir).is_absolute()
                                         ? std::filesystem::path(dir)
                                         : std::filesystem::path(model_dir) / dir;
  mjs_setString(file, std::filesystem::absolute(base / f).lexically_normal().string().c_str());
}

void AbsolutizeAssets(mjSpec* s) {
  // strippath: MuJoCo keeps only the file names; the attached model is compiled with the
  // world's setting, so strip them here
  if (s->strippath) {
    const auto strip = [](mjString* f) {
      const std::string name = std::filesystem::path(mjs_getString(f)).filename().string();
      mjs_setString(f, name.c_str());
    };
    for (mjsElement* e = mjs_firstElement(s, mjOBJ_MESH); e; e = mjs_nextElement(s, e))
      strip(mjs_asMesh(e)->file);
    for (mjsElement* e = mjs_firstElement(s, mjOBJ_TEXTURE); e; e = mjs_nextElement(s, e))
      strip(mjs_asTexture(e)->file);
    s->strippath = 0;
  }
  // an asset resolves against the spec it came from: a model the file itself attaches
  // (<attach model>) has its own folder and meshdir
  const auto resolve = [](mjsElement* e, mjString* file, bool texture) {
    const mjSpec* origin = mjs_getOriginSpec(e);
    const std::string dir =
        mjs_getString(texture ? origin->compiler.texturedir : origin->compiler.meshdir);
    Absolutize(file, mjs_getString(origin->modelfiledir), dir);
  };
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_MESH); e; e = mjs_nextElement(s, e))
    resolve(e, mjs_asMesh(e)->file, false);
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_HFIELD); e; e = mjs_nextElement(s, e))
    resolve(e, mjs_asHField(e)->file, false);
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_SKIN); e; e = mjs_nextElement(s, e))
    resolve(e, mjs_asSkin(e)->file, false);
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_TEXTURE); e; e = mjs_nextElement(s, e))
    resolve(e, mjs_asTexture(e)->file, true);
}

// a model whose compiler infers body inertias otherwise than the world (inertiafromgeom,
// boundmass, boundinertia, settotalmass, balanceinertia) gets the inertials its own compile
// made, explicitly, and the world's settings: the saved file has one <compiler> (MuJoCo
// refuses to save differing inference settings), and the physics is the model's own
void AdoptCompiledInertials(mjSpec* s, const mjModel* m) {
  mjsCompiler& c = s->compiler;
  const bool same = c.inertiafromgeom == mjINERTIAFROMGEOM_AUTO && c.boundmass == 0 &&
                    c.boundinertia == 0 && c.settotalmass <= 0 && !c.balanceinertia;
  if (same) return;
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_BODY); e; e = mjs_nextElement(s, e)) {
    const int b = mjs_getId(e);
    if (b < 1 || b >= m->nbody) continue;
    mjsBody* body = mjs_asBody(e);
    body->mass = m->body_mass[b];
    for (int i = 0; i < 3; ++i) body->ipos[i] = m->body_ipos[3 * b + i];
    for (int i = 0; i < 4; ++i) body->iquat[i] = m->body_iquat[4 * b + i];
    for (int i = 0; i < 3; ++i) body->inertia[i] = m->body_inertia[3 * b + i];
    body->ialt.type = mjORIENTATION_QUAT;
    for (double& f : body->fullinertia) f = std::nan("");
    body->explicitinertial = 1;
  }
  c.inertiafromgeom = mjINERTIAFROMGEOM_AUTO;
  c.boundmass = 0;
  c.boundinertia = 0;
  c.settotalmass = -1;
  c.balanceinertia = 0;
}

// a copy of one of MuJoCo's number vectors
std::vector<double> Doubles(const mjDoubleVec* v) {
  int n = 0;
  const double* p = mjs_getDouble(v, &n);
  return p ? std::vector<double>(p, p + n) : std::vector<double>();
}

Eigen::Vector3d Vec3(const double* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }
Eigen::Quaterniond Quat(const double* q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }
void Store(const Eigen::Vector3d& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}
void Store(const Eigen::Quaterniond& q, double* out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

// the model's keyframes with its top-level free joints and mocap bodies placed by the model
// pose X_WM (key vectors are in the model's world frame; the attach frame moves the bodies,
// not the keys' numbers). free-joint qvel: linear velocity in the world frame, angular in
// the body frame.
void PlaceKeys(mjSpec* s, const mjModel* m, const Eigen::Vector3d& p_WM,
               const Eigen::Quaterniond& q_WM) {
  int index = 0;
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_KEY); e; e = mjs_nextElement(s, e), ++index) {
    // an unnamed key (e.g. from <size nkey="5">) would become "M/" for each: name it by its
    // index, "M/key<i>"
    if (mjs_getName(e)->empty()) mjs_setName(e, ("key" + std::to_string(index)).c_str());
    mjsKey* k = mjs_asKey(e);
    std::vector<double> qpos = Doubles(k->qpos), qvel = Doubles(k->qvel);
    std::vector<double> mpos = Doubles(k->mpos), mquat = Doubles(k->mquat);
    for (int j = 0; j < m->njnt; ++j) {
      if (m->jnt_type[j] != mjJNT_FREE) continue;
      const int qadr = m->jnt_qposadr[j];
      const int vadr = m->jnt_dofadr[j];
      if (static_cast<int>(qpos.size()) >= qadr + 7) {
        double* q = qpos.data() + qadr;
        Store(Eigen::Vector3d(p_WM + q_WM * Vec3(q)), q);
        Store((q_WM * Quat(q + 3)).normalized(), q + 3);
      }
      if (static_cast<int>(qvel.size()) >= vadr + 6) {
        double* v = qvel.data() + vadr;
        Store(Eigen::Vector3d(q_WM * Vec3(v)), v);
      }
    }
    for (size_t i = 0; i + 3 <= mpos.size(); i += 3) {
      Store(Eigen::Vector3d(p_WM + q_WM * Vec3(mpos.data() + i)), mpos.data() + i);
    }
    for (size_t i = 0; i + 4 <= mquat.size(); i += 4) {
      Store((q_WM * Quat(mquat.data() + i)).normalized(), mquat.data() + i);
    }
    const auto set = [](mjDoubleVec* dest, const std::vector<double>& v) {
      if (!v.empty()) mjs_setDouble(dest, v.data(), static_cast<int>(v.size()));
    };
    set(k->qpos, qpos);
    set(k->qvel, qvel);
    set(k->mpos, mpos);
    set(k->mquat, mquat);
  }
}

}  // namespace

ModelSpecComposer::ModelSpecComposer(const std::string& base_xml, bool world_sets_timestep)
    : world_sets_timestep_(world_sets_timestep) {
  InstallMujocoHandlers();
  char error[1024] = "";
  {
    std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
    world_ = mj_parseXMLString(base_xml.c_str(), nullptr, error, sizeof(error));
  }
  if (world_ == nullptr) {
    throw Error("ModelSpecComposer: MuJoCo cannot parse the world's own MJCF: " + Trimmed(error));
  }
  world_->compiler.savecompiled = 0;
  world_->compiler.conflict = mjCONFLICT_MERGE;
  mjs_setDeepCopy(world_, 1);
}

ModelSpecComposer::~ModelSpecComposer() { mj_deleteSpec(world_); }

void ModelSpecComposer::AgreeGlobals(const SpecModel& model, mjSpec* child) {
  const mjsAuthored& a = child->authored;
  if (a.option || a.disableflags || a.enableflags || a.disableactuator) {
    const mjOption& o = child->option;
    if (option_owner_ == nullptr) {
      const double timestep = o.timestep;
      if (!world_sets_timestep_ && !(timestep >= kMinTimestepSec && timestep <= kMaxTimestepSec)) {
        throw ConfigError(model.file, 0, "option.timestep",
                          fmt::format("'{}' is not a usable physics timestep; expected seconds in "
                                      "[{}, {}] (or set physics.timestep_sec in a world file, "
                                      "which overrides it)",
                                      timestep, kMinTimestepSec, kMaxTimestepSec));
      }
      world_->option = o;
      option_owner_ = &models_.back();
    } else {
      const mjOption& w = world_->option;
      mjOption d;
      mj_defaultOption(&d);
      // a field the model sets (not MuJoCo's default) to another value than the world's
      std::vector<std::string> differ;
      const auto check = [&](bool same, bool set, const char* name) {
        if (set && !same) differ.emplace_back(name);
      };
      const auto eq3 = [](const double* a, const double* b) { return std::equal(a, a + 3, b); };
      check(o.timestep == w.timestep, o.timestep != d.timestep, "timestep");
      check(o.integrator == w.integrator, o.integrator != d.integrator, "integrator");
      check(o.cone == w.cone, o.cone != d.cone, "cone");
      check(o.solver == w.solver, o.solver != d.solver, "solver");
      check(o.iterations == w.iterations, o.iterations != d.iterations, "iterations");
      check(o.ls_iterations == w.ls_iterations, o.ls_iterations != d.ls_iterations,
            "ls_iterations");
      check(o.noslip_iterations == w.noslip_iterations, o.noslip_iterations != d.noslip_iterations,
            "noslip_iterations");
      check(o.impratio == w.impratio, o.impratio != d.impratio, "impratio");
      check(o.tolerance == w.tolerance, o.tolerance != d.tolerance, "tolerance");
      check(eq3(o.gravity, w.gravity), !eq3(o.gravity, d.gravity), "gravity");
      check(eq3(o.wind, w.wind), !eq3(o.wind, d.wind), "wind");
      check(o.density == w.density && o.viscosity == w.viscosity,
            o.density != d.density || o.viscosity != d.viscosity, "density/viscosity");
      check(o.disableflags == w.disableflags && o.enableflags == w.enableflags,
            o.disableflags != d.disableflags || o.enableflags != d.enableflags, "flag");
      if (!differ.empty()) {
        std::string list;
        for (const std::string& d : differ) list += (list.empty() ? "" : ", ") + d;
        warnings_.push_back("model '" + model.name + "' (" + model.file +
                            "): its <option> differs from model '" + option_owner_->name + "' (" +
                            option_owner_->file + ")'s (" + list +
                            "); the composed world uses the latter. the world file's physics "
                            "section decides timestep_sec, integrator, gravity_mps2, "
                            "solver_iterations and cone (docs/world-file.md)");
      }
      // the world's values: MuJoCo's attach then sees no conflict
      child->option = w;
    }
  }
  const bool visual = a.visual_global || a.visual_quality || a.visual_headlight || a.visual_map ||
                      a.visual_scale || a.visual_rgba;
  if (visual) {
    if (!visual_owner_) {
      world_->visual = child->visual;
      visual_owner_ = true;
    } else {
      child->visual = world_->visual;
    }
  }
}

void ModelSpecComposer::Attach(const SpecModel& model) {
  const std::string key = ModelKey(model);
  models_.push_back(model);
  std::vector<std::string> mj_warnings;
  std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
  const ScopedMujocoWarningSink sink(&mj_warnings);

  char error[1024] = "";
  SpecPtr child(model.text.empty()
                    ? mj_parseXML(model.file.c_str(), nullptr, error, sizeof(error))
                    : mj_parseXMLString(model.text.c_str(), nullptr, error, sizeof(error)));
  if (!child) {
    const std::string msg = Trimmed(error);
    throw ConfigError(model.file, LineOf(msg), "", msg);
  }
  if (!model.text.empty()) {
    const std::string dir = std::filesystem::absolute(model.file).parent_path().string() + "/";
    mjs_setString(child->modelfiledir, dir.c_str());
  }
  AbsolutizeAssets(child.get());
  if (model.convert_mesh) {
    for (mjsElement* e = mjs_firstElement(child.get(), mjOBJ_MESH); e;
         e = mjs_nextElement(child.get(), e)) {
      mjsMesh* mesh = mjs_asMesh(e);
      const std::string file = mjs_getString(mesh->file);
      if (file.empty()) continue;
      const std::string converted = model.convert_mesh(file);
      if (!converted.empty())
        mjs_setString(mesh->file, std::filesystem::absolute(converted).string().c_str());
    }
  }
  if (model.floating_base) {
    if (!model.from_urdf) {
      throw ConfigError("", 0, key + ".floating_base",
                        "model '" + model.name +
                            "' is MJCF; expected floating_base only for URDF models (give an "
                            "MJCF body a <freejoint/> in its file)");
    }
    mjsBody* world = mjs_findBody(child.get(), "world");
    mjsElement* root = mjs_firstChild(world, mjOBJ_BODY, 0);
    if (root == nullptr) {
      throw ConfigError(model.file, 0, key + ".floating_base",
                        "the URDF has no root link body; expected a link that is no joint's "
                        "child");
    }
    mjsJoint* j = mjs_addFreeJoint(mjs_asBody(root));
    mjs_setName(j->element, "floating_base");
  }

  // the model alone: MuJoCo's checks with the model's own lines, and the compiled values
  // that sites and keys need
  ModelPtr compiled(mj_compile(child.get(), nullptr));
  if (!compiled) {
    const std::string msg = Trimmed(mjs_getError(child.get()));
    throw ConfigError(model.file, LineOf(msg), "", msg);
  }

  for (size_t i = 0; i < model.sites.size(); ++i) {
    const SpecSite& site = model.sites[i];
    const std::string skey =
        site.key.empty() ? key + ".sites[" + std::to_string(i) + "]" : site.key;
    if (mjs_findElement(child.get(), mjOBJ_SITE, site.name.c_str())) {
      throw ConfigError("", 0, skey + ".name",
                        "model '" + model.name + "' already has a site '" + site.name +
                            "'; expected a new site name");
    }
    Eigen::Vector3d pos = Vec3(site.pos.data());
    const Eigen::Quaterniond quat = Quat(site.quat.data());
    mjsBody* body = nullptr;
    if (!site.geom.empty()) {
      const int g = mj_name2id(compiled.get(), mjOBJ_GEOM, site.geom.c_str());
      if (g < 0) {
        throw ConfigError("", 0, skey + ".geom",
                          "model '" + model.name + "' has no geom '" + site.geom +
                              "'; expected the name of one of its geoms");
      }
      // the geom's frame in its body as compiled; a mesh geom's compiled frame is its
      // mesh's centred frame, so step back to the frame the geom was written with
      Eigen::Vector3d centre = Vec3(compiled->geom_pos + 3 * g);
      const int mesh = compiled->geom_dataid[g];
      if (compiled->geom_type[g] == mjGEOM_MESH && mesh >= 0) {
        const Eigen::Quaterniond q_C = Quat(compiled->geom_quat + 4 * g);
        const Eigen::Quaterniond q_M = Quat(compiled->mesh_quat + 4 * mesh);
        centre -= (q_C * q_M.conjugate()) * Vec3(compiled->mesh_pos + 3 * mesh);
      }
      pos += centre;
      const char* body_name = mj_id2name(compiled.get(), mjOBJ_BODY, compiled->geom_bodyid[g]);
      body = mjs_findBody(child.get(), body_name ? body_name : "world");
    } else {
      body = mjs_findBody(child.get(), site.body.c_str());
      if (body == nullptr) {
        throw ConfigError("", 0, skey + ".body",
                          "model '" + model.name + "' has no body '" + site.body +
                              "'; expected the name of one of its bodies or \"world\"");
      }
    }
    if (body == nullptr) {
      throw ConfigError("", 0, skey + ".geom",
                        "the body of geom '" + site.geom + "' has no name; expected a named body");
    }
    mjsSite* s = mjs_addSite(body, nullptr);
    mjs_setName(s->element, site.name.c_str());
    Store(pos, s->pos);
    Store(quat.normalized(), s->quat);
    s->group = 4;
  }

  AdoptCompiledInertials(child.get(), compiled.get());
  AgreeGlobals(model, child.get());
  const Eigen::Vector3d p_WM = Vec3(model.pos.data());
  const Eigen::Quaterniond q_WM = Quat(model.quat.data()).normalized();
  PlaceKeys(child.get(), compiled.get(), p_WM, q_WM);

  mjsFrame* frame = mjs_addFrame(mjs_findBody(world_, "world"), nullptr);
  Store(p_WM, frame->pos);
  Store(q_WM, frame->quat);
  const std::string prefix = model.name + "/";
  if (mjs_attach(frame->element, child->element, prefix.c_str(), "") == nullptr) {
    const std::string msg = Trimmed(mjs_getError(world_));
    throw ConfigError(model.file, LineOf(msg), "",
                      "MuJoCo cannot attach the model as '" + prefix + "': " + msg);
  }
  for (const std::string& w : mj_warnings) warnings_.push_back(Trimmed(w));
}

mjModel* ModelSpecComposer::Compile(const SpecOptionOverrides& overrides) {
  mjOption& opt = world_->option;
  if (overrides.timestep_sec) opt.timestep = *overrides.timestep_sec;
  if (overrides.integrator) {
    const std::string& i = *overrides.integrator;
    opt.integrator = i == "RK4"            ? mjINT_RK4
                     : i == "implicit"     ? mjINT_IMPLICIT
                     : i == "implicitfast" ? mjINT_IMPLICITFAST
                                           : mjINT_EULER;
  }
  if (overrides.gravity_mps2) {
    for (int i = 0; i < 3; ++i) opt.gravity[i] = (*overrides.gravity_mps2)[i];
  }
  if (overrides.solver_iterations) opt.iterations = *overrides.solver_iterations;
  if (overrides.cone) opt.cone = *overrides.cone == "elliptic" ? mjCONE_ELLIPTIC : mjCONE_PYRAMIDAL;
  ApplyContactOptions(overrides.contact, &opt);

  std::vector<std::string> mj_warnings;
  std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
  const ScopedMujocoWarningSink sink(&mj_warnings);
  ModelPtr compiled(mj_compile(world_, nullptr));
  if (!compiled) {
    const std::string msg = Trimmed(mjs_getError(world_));
    // the element MuJoCo names carries its model's prefix
    const std::string element = ElementNameOf(msg);
    for (const SpecModel& m : models_) {
      if (element.rfind(m.name + "/", 0) == 0) throw ConfigError(m.file, LineOf(msg), "", msg);
    }
    throw ConfigError("", 0, "", msg);
  }
  for (const std::string& w : mj_warnings) warnings_.push_back(Trimmed(w));
  return compiled.release();
}

std::string ModelSpecComposer::SaveXml(const SpecOptionOverrides& overrides) {
  mj_deleteModel(Compile(overrides));
  std::lock_guard<std::mutex> lock(MujocoLoaderMutex());
  std::string xml(1 << 16, '\0');
  char error[1024] = "";
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int n =
        mj_saveXMLString(world_, xml.data(), static_cast<int>(xml.size()), error, sizeof(error));
    if (n == 0) {
      xml.resize(std::strlen(xml.c_str()));
      return xml;
    }
    if (n < 0) break;
    xml.assign(static_cast<size_t>(n) + 1, '\0');
  }
  throw Error("ModelSpecComposer: MuJoCo cannot save the composed model: " + Trimmed(error));
}

}  // namespace penumbra
