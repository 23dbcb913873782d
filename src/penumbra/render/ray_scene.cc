#include "penumbra/render/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/analytic_shapes.h"
#include "penumbra/render/triangle_shapes.h"

namespace penumbra {
namespace {

// rays per Embree stream call in IntersectMany / OccludedMany.
constexpr int kStreamChunk = 64;

// a geom traced as Embree user geometry; lives at a stable address (geometry user pointer).
struct AnalyticGeom {
  AnalyticShape shape;
  Eigen::Matrix3d R_GB;  // p_G = R_GB p_B + p_GB
  Eigen::Vector3d p_GB;
  Eigen::Matrix3f R_BG_f;  // for the body-frame Ng reported to Embree
};

// a geom traced as triangles, in the body frame. vertices carry one padding element at
// the end: Embree reads vertex buffers with 16-byte loads.
struct TriangleGeom {
  std::vector<Eigen::Vector3f> vertices_B;
  std::vector<Eigen::Vector3f> normals_B;
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<Eigen::Vector3i> faces;
  Eigen::Matrix3f R_GB;  // p_G = R_GB p_B + p_GB
  Eigen::Vector3f p_GB;
};

// what an Embree (body scene, geomID) pair stands for.
struct GeomRecord {
  int geom = -1;
  int material = -1;
  int analytic = -1;   // index into Impl::analytic, or -1
  int triangles = -1;  // index into Impl::triangles, or -1
};

struct BodyScene {
  int body = -1;
  RTCScene scene = nullptr;
  RTCGeometry instance = nullptr;
  std::vector<GeomRecord> geoms;  // by geomID in `scene`
};

void AnalyticBounds(const RTCBoundsFunctionArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  const Eigen::Vector3d h = AnalyticHalfExtents(g->shape);
  // body-frame box of the rotated geom box: centre p_BG, half extents |R_BG| h.
  const Eigen::Matrix3d R_BG = g->R_GB.transpose();
  const Eigen::Vector3d c = -(R_BG * g->p_GB);
  const Eigen::Vector3d e = R_BG.cwiseAbs() * h;
  // pad by a relative epsilon so that flat shapes (planes) have volume and float rounding
  // of the box never clips the surface.
  const Eigen::Vector3d pad =
      Eigen::Vector3d::Constant(1e-5 * (1.0 + e.maxCoeff() + c.cwiseAbs().maxCoeff()));
  const Eigen::Vector3d lo = c - e - pad, hi = c + e + pad;
  args->bounds_o->lower_x = static_cast<float>(lo.x());
  args->bounds_o->lower_y = static_cast<float>(lo.y());
  args->bounds_o->lower_z = static_cast<float>(lo.z());
  args->bounds_o->upper_x = static_cast<float>(hi.x());
  args->bounds_o->upper_y = static_cast<float>(hi.y());
  args->bounds_o->upper_z = static_cast<float>(hi.z());
}

// intersects ray i of an N-wide Embree ray (already in the body frame) with an analytic geom.
inline bool IntersectLane(const AnalyticGeom& g, RTCRayN* ray, unsigned N, unsigned i, double* t,
                          ShapePart* part) {
  const Eigen::Vector3d o_B(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i),
                            RTCRayN_org_z(ray, N, i));
  const Eigen::Vector3d d_B(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i),
                            RTCRayN_dir_z(ray, N, i));
  const Eigen::Vector3d o_G = g.R_GB * o_B + g.p_GB;
  const Eigen::Vector3d d_G = g.R_GB * d_B;
  return IntersectAnalytic(g.shape, o_G, d_G, RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i), t,
                           part);
}

void AnalyticIntersect(const RTCIntersectFunctionNArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    double t;
    ShapePart part;
    if (!IntersectLane(*g, ray, args->N, i, &t, &part)) continue;
    const float tf = static_cast<float>(t);
    if (!(tf < RTCRayN_tfar(ray, args->N, i))) continue;
    RTCRayN_tfar(ray, args->N, i) = tf;
    // Ng: rough body-frame normal (RayScene recomputes the exact one in double).
    const Eigen::Vector3d o_B(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i),
                              RTCRayN_org_z(ray, args->N, i));
    const Eigen::Vector3d d_B(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i),
                              RTCRayN_dir_z(ray, args->N, i));
    const Eigen::Vector3d p_G = g->R_GB * (o_B + t * d_B) + g->p_GB;
    const Eigen::Vector3f n_B = g->R_BG_f * AnalyticNormal(g->shape, p_G, part).cast<float>();
    RTCHitN_Ng_x(hit, args->N, i) = n_B.x();
    RTCHitN_Ng_y(hit, args->N, i) = n_B.y();
    RTCHitN_Ng_z(hit, args->N, i) = n_B.z();
    RTCHitN_u(hit, args->N, i) = static_cast<float>(static_cast<int>(part));
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void AnalyticOccluded(const RTCOccludedFunctionNArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    double t;
    ShapePart part;
    if (IntersectLane(*g, args->ray, args->N, i, &t, &part) &&
        static_cast<float>(t) < RTCRayN_tfar(args->ray, args->N, i))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

void ErrorCallback(void* user, RTCError code, const char* message) {
  auto* first = static_cast<std::string*>(user);
  if (first->empty())
    *first = std::string("Embree error ") + std::to_string(code) + ": " + (message ? message : "");
}

inline void ToEmbree(const Ray& r, RTCRay* e) {
  e->org_x = r.o.x();
  e->org_y = r.o.y();
  e->org_z = r.o.z();
  e->tnear = r.tmin;
  e->dir_x = r.d.x();
  e->dir_y = r.d.y();
  e->dir_z = r.d.z();
  e->time = 0;
  e->tfar = r.tmax;
  e->mask = 0xffffffffu;
  e->id = 0;
  e->flags = 0;
}

}  // namespace

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  std::string error;                        // first Embree error message
  std::vector<BodyScene> bodies;            // bodies with visible geoms
  std::vector<int> body_scene_of;           // body index -> index into bodies, or -1
  std::vector<int> instance_to_body_scene;  // top-level geomID -> index into bodies
  std::vector<std::unique_ptr<AnalyticGeom>> analytic;
  std::vector<std::unique_ptr<TriangleGeom>> triangles;
  // per body: R_WB, p_WB in float and double for hit reconstruction.
  std::vector<Eigen::Matrix3f> R_WB_f;
  std::vector<Eigen::Vector3f> p_WB_f;

  void Check(const char* what) const {
    if (!error.empty()) throw Error(std::string("RayScene: ") + what + ": " + error);
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE)
      throw Error(std::string("RayScene: ") + what + ": Embree error " + std::to_string(code));
  }

  // fills `hit` from Embree's hit of world ray `ray`: geom, exact surface point and
  // normals (analytic shapes in double from the world ray; triangles from barycentrics).
  void FinishHit(const Ray& ray, const RTCRayHit& rh, const std::vector<Pose>& X_WB,
                 SurfaceHit* hit) const {
    const BodyScene& bs = bodies[instance_to_body_scene[rh.hit.instID[0]]];
    const GeomRecord& rec = bs.geoms[rh.hit.geomID];
    const int b = bs.body;
    const float t = rh.ray.tfar;
    hit->t = t;
    hit->p_W = ray.o + t * ray.d;
    hit->geom = rec.geom;
    hit->material = rec.material;
    hit->has_uv = false;
    hit->uv.setZero();
    const Eigen::Matrix3f& R_WB = R_WB_f[b];
    Eigen::Vector3f ng_W, ns_W;
    if (rec.analytic >= 0) {
      const AnalyticGeom& g = *analytic[rec.analytic];
      const Pose& X = X_WB[b];
      const Eigen::Vector3d p_W =
          ray.o.cast<double>() + static_cast<double>(t) * ray.d.cast<double>();
      const Eigen::Vector3d p_B = X.linear().transpose() * (p_W - X.translation());
      const Eigen::Vector3d p_G = g.R_GB * p_B + g.p_GB;
      const Eigen::Vector3d n_G =
          AnalyticNormal(g.shape, p_G, static_cast<ShapePart>(static_cast<int>(rh.hit.u)));
      hit->p_G = p_G.cast<float>();
      hit->n_G = n_G.cast<float>();
      ng_W = (X.linear() * (g.R_GB.transpose() * n_G)).cast<float>();
      ns_W = ng_W;
    } else {
      const TriangleGeom& g = *triangles[rec.triangles];
      const Eigen::Vector3i& f = g.faces[rh.hit.primID];
      const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
      const Eigen::Vector3f& v0 = g.vertices_B[f[0]];
      const Eigen::Vector3f& v1 = g.vertices_B[f[1]];
      const Eigen::Vector3f& v2 = g.vertices_B[f[2]];
      Eigen::Vector3f n_B = (v1 - v0).cross(v2 - v0);
      const float len = n_B.norm();
      n_B = len > 0 ? Eigen::Vector3f(n_B / len) : Eigen::Vector3f::UnitZ();
      const Eigen::Vector3f p_B = w * v0 + u * v1 + v * v2;
      hit->p_G = g.R_GB * p_B + g.p_GB;
      hit->n_G = g.R_GB * n_B;
      ng_W = R_WB * n_B;
      ns_W = ng_W;
      if (!g.normals_B.empty()) {
        const Eigen::Vector3f ns_B =
            w * g.normals_B[f[0]] + u * g.normals_B[f[1]] + v * g.normals_B[f[2]];
        const float ls = ns_B.norm();
        if (ls > 0) ns_W = R_WB * (ns_B / ls);
      }
      if (!g.texcoords.empty()) {
        hit->uv = w * g.texcoords[f[0]] + u * g.texcoords[f[1]] + v * g.texcoords[f[2]];
        hit->has_uv = true;
      }
    }
    hit->front_face = ng_W.dot(ray.d) <= 0;
    if (!hit->front_face) {
      ng_W = -ng_W;
      ns_W = -ns_W;
    }
    hit->ng_W = ng_W;
    hit->ns_W = ns_W;
  }

  void Release() {
    for (BodyScene& b : bodies) {
      if (b.instance) rtcReleaseGeometry(b.instance);
      if (b.scene) rtcReleaseScene(b.scene);
    }
    bodies.clear();
    if (top) rtcReleaseScene(top);
    top = nullptr;
    if (device) rtcReleaseDevice(device);
    device = nullptr;
  }
};

Ray SpawnRay(const SurfaceHit& hit, const Eigen::Vector3f& d) {
  const float eps = kRayOffsetScale * (1.0f + hit.p_W.cwiseAbs().maxCoeff());
  Ray r;
  r.o = hit.p_W + (d.dot(hit.ng_W) >= 0 ? eps : -eps) * hit.ng_W;
  r.d = d;
  return r;
}

Ray SpawnRayTo(const SurfaceHit& hit, const Eigen::Vector3f& p_W) {
  Ray r = SpawnRay(hit, p_W - hit.p_W);
  r.d = p_W - r.o;
  r.tmax = 1.0f - 1e-4f;
  return r;
}

RayScene::RayScene(const SceneDescription& scene) : impl_(std::make_unique<Impl>()), scene_(scene) {
  Impl& m = *impl_;
  m.device = rtcNewDevice(nullptr);
  if (!m.device) throw Error("RayScene: cannot create the Embree device (rtcNewDevice failed)");
  rtcSetDeviceErrorFunction(m.device, ErrorCallback, &m.error);

  const int num_bodies = static_cast<int>(scene.bodies.size());
  m.body_scene_of.assign(num_bodies, -1);
  X_WB_.assign(num_bodies, Pose::Identity());
  m.R_WB_f.assign(num_bodies, Eigen::Matrix3f::Identity());
  m.p_WB_f.assign(num_bodies, Eigen::Vector3f::Zero());

  try {
    for (int gi = 0; gi < static_cast<int>(scene.geoms.size()); ++gi) {
      const Geom& geom = scene.geoms[gi];
      if (geom.group > 2) continue;
      if (geom.material >= static_cast<int>(scene.materials.size()))
        throw Error("RayScene: geom '" + geom.name + "' refers to missing material " +
                    std::to_string(geom.material));
      if (geom.material >= 0 && scene.materials[geom.material].alpha < 0.5f) continue;
      if (geom.body < 0 || geom.body >= num_bodies)
        throw Error("RayScene: geom '" + geom.name + "' refers to missing body " +
                    std::to_string(geom.body));

      int& bs = m.body_scene_of[geom.body];
      if (bs < 0) {
        bs = static_cast<int>(m.bodies.size());
        BodyScene b;
        b.body = geom.body;
        b.scene = rtcNewScene(m.device);
        rtcSetSceneFlags(b.scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(b.scene, RTC_BUILD_QUALITY_HIGH);
        m.bodies.push_back(b);
      }
      BodyScene& body = m.bodies[bs];
      GeomRecord rec;
      rec.geom = gi;
      rec.material = geom.material;
      const Pose& X_BG = geom.X_BG;
      const Pose X_GB = X_BG.inverse();

      RTCGeometry eg = nullptr;
      if (geom.shape == GeomShape::kBox || geom.shape == GeomShape::kMesh ||
          geom.shape == GeomShape::kHeightField) {
        TriangleShape shape;
        if (geom.shape == GeomShape::kBox) {
          shape = BoxTriangles(geom.size);
        } else if (geom.shape == GeomShape::kMesh) {
          if (geom.mesh < 0 || geom.mesh >= static_cast<int>(scene.meshes.size()))
            throw Error("RayScene: mesh geom '" + geom.name + "' refers to missing mesh " +
                        std::to_string(geom.mesh));
          shape = MeshTriangles(scene.meshes[geom.mesh]);
        } else {
          if (geom.hfield < 0 || geom.hfield >= static_cast<int>(scene.hfields.size()))
            throw Error("RayScene: hfield geom '" + geom.name +
                        "' refers to missing height field " + std::to_string(geom.hfield));
          shape = HeightFieldTriangles(scene.hfields[geom.hfield]);
        }
        if (shape.faces.empty()) continue;
        auto tg = std::make_unique<TriangleGeom>();
        const Eigen::Matrix3f R_BG = X_BG.linear().cast<float>();
        const Eigen::Vector3f p_BG = X_BG.translation().cast<float>();
        tg->vertices_B.reserve(shape.vertices.size() + 1);
        for (const Eigen::Vector3f& v : shape.vertices) tg->vertices_B.push_back(R_BG * v + p_BG);
        tg->vertices_B.push_back(Eigen::Vector3f::Zero());  // padding for Embree's 16-byte loads
        for (const Eigen::Vector3f& n : shape.normals)
          tg->normals_B.push_back((R_BG * n).normalized());
        tg->texcoords = std::move(shape.texcoords);
        tg->faces = std::move(shape.faces);
        tg->R_GB = X_GB.linear().cast<float>();
        tg->p_GB = X_GB.translation().cast<float>();

        eg = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(eg, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   tg->vertices_B.data(), 0, sizeof(Eigen::Vector3f),
                                   tg->vertices_B.size() - 1);
        rtcSetSharedGeometryBuffer(eg, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, tg->faces.data(),
                                   0, sizeof(Eigen::Vector3i), tg->faces.size());
        num_triangles_ += static_cast<int64_t>(tg->faces.size());
        rec.triangles = static_cast<int>(m.triangles.size());
        m.triangles.push_back(std::move(tg));
      } else {
        auto ag = std::make_unique<AnalyticGeom>();
        switch (geom.shape) {
          case GeomShape::kPlane: {
            ag->shape.kind = AnalyticKind::kPlane;
            const double hx = geom.size.x() > 0 ? geom.size.x() : kInfinitePlaneHalfSize;
            const double hy = geom.size.y() > 0 ? geom.size.y() : kInfinitePlaneHalfSize;
            ag->shape.size = {hx, hy, 0};
            break;
          }
          case GeomShape::kSphere:
            ag->shape.kind = AnalyticKind::kSphere;
            break;
          case GeomShape::kCapsule:
            ag->shape.kind = AnalyticKind::kCapsule;
            break;
          case GeomShape::kEllipsoid:
            ag->shape.kind = AnalyticKind::kEllipsoid;
            break;
          default:
            ag->shape.kind = AnalyticKind::kCylinder;
            break;
        }
        if (geom.shape != GeomShape::kPlane) ag->shape.size = geom.size;
        const Eigen::Vector3d h = AnalyticHalfExtents(ag->shape);
        const bool bad_size = (ag->shape.kind == AnalyticKind::kPlane)
                                  ? !(h.x() > 0 && h.y() > 0)
                                  : !(h.minCoeff() > 0) || !h.allFinite();
        if (bad_size)
          throw Error("RayScene: geom '" + geom.name + "' has a non-positive size for its shape");
        ag->R_GB = X_GB.linear();
        ag->p_GB = X_GB.translation();
        ag->R_BG_f = X_BG.linear().cast<float>();
        eg = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(eg, 1);
        rtcSetGeometryUserData(eg, ag.get());
        rtcSetGeometryBoundsFunction(eg, AnalyticBounds, nullptr);
        rtcSetGeometryIntersectFunction(eg, AnalyticIntersect);
        rtcSetGeometryOccludedFunction(eg, AnalyticOccluded);
        rec.analytic = static_cast<int>(m.analytic.size());
        m.analytic.push_back(std::move(ag));
      }
      rtcCommitGeometry(eg);
      const unsigned id = rtcAttachGeometry(body.scene, eg);
      rtcReleaseGeometry(eg);
      if (body.geoms.size() <= id) body.geoms.resize(id + 1);
      body.geoms[id] = rec;
      ++num_visible_geoms_;
    }
    m.Check("building geometry");

    m.top = rtcNewScene(m.device);
    rtcSetSceneFlags(m.top,
                     static_cast<RTCSceneFlags>(RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST));
    rtcSetSceneBuildQuality(m.top, RTC_BUILD_QUALITY_LOW);
    for (int i = 0; i < static_cast<int>(m.bodies.size()); ++i) {
      BodyScene& b = m.bodies[i];
      rtcCommitScene(b.scene);
      b.instance = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(b.instance, b.scene);
      rtcSetGeometryTimeStepCount(b.instance, 1);
      const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
      rtcSetGeometryTransform(b.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
      rtcCommitGeometry(b.instance);
      const unsigned id = rtcAttachGeometry(m.top, b.instance);
      if (m.instance_to_body_scene.size() <= id) m.instance_to_body_scene.resize(id + 1, -1);
      m.instance_to_body_scene[id] = i;
    }
    rtcCommitScene(m.top);
    m.Check("committing scenes");
  } catch (...) {
    m.Release();
    throw;
  }
}

RayScene::~RayScene() { impl_->Release(); }

void RayScene::Update(const WorldSnapshot& snapshot) {
  Impl& m = *impl_;
  if (snapshot.X_WB.size() != X_WB_.size())
    throw Error("RayScene::Update: snapshot has " + std::to_string(snapshot.X_WB.size()) +
                " body poses, scene has " + std::to_string(X_WB_.size()) + " bodies");
  bool changed = false;
  for (const BodyScene& b : m.bodies) {
    const Pose& X = snapshot.X_WB[b.body];
    if (X.matrix() == X_WB_[b.body].matrix()) continue;
    changed = true;
    X_WB_[b.body] = X;
    m.R_WB_f[b.body] = X.linear().cast<float>();
    m.p_WB_f[b.body] = X.translation().cast<float>();
    float xfm[12];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = static_cast<float>(X.linear()(r, c));
    for (int r = 0; r < 3; ++r) xfm[9 + r] = static_cast<float>(X.translation()(r));
    rtcSetGeometryTransform(b.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(b.instance);
  }
  // bodies without visible geoms still report their pose.
  for (size_t i = 0; i < X_WB_.size(); ++i) {
    if (m.body_scene_of[i] < 0) X_WB_[i] = snapshot.X_WB[i];
  }
  if (changed) {
    rtcCommitScene(m.top);
    ++num_top_level_commits_;
    m.Check("updating body poses");
  }
}

bool RayScene::Intersect(const Ray& ray, SurfaceHit* hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  ToEmbree(ray, &rh.ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  impl_->FinishHit(ray, rh, X_WB_, hit);
  return true;
}

bool RayScene::Occluded(const Ray& ray) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  ToEmbree(ray, &r);
  rtcOccluded1(impl_->top, &ctx, &r);
  return r.tfar < 0;
}

void RayScene::IntersectMany(const Ray* rays, int n, bool coherent, SurfaceHit* hits,
                             bool* did_hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags =
      coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  alignas(64) RTCRayHit rh[kStreamChunk];
  for (int start = 0; start < n; start += kStreamChunk) {
    const int m = std::min(kStreamChunk, n - start);
    for (int i = 0; i < m; ++i) {
      ToEmbree(rays[start + i], &rh[i].ray);
      rh[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect1M(impl_->top, &ctx, rh, static_cast<unsigned>(m), sizeof(RTCRayHit));
    for (int i = 0; i < m; ++i) {
      did_hit[start + i] = rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      if (did_hit[start + i]) impl_->FinishHit(rays[start + i], rh[i], X_WB_, &hits[start + i]);
    }
  }
}

void RayScene::OccludedMany(const Ray* rays, int n, const bool* active, bool* occluded) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  alignas(64) RTCRay r[kStreamChunk];
  int index[kStreamChunk];
  int start = 0;
  while (start < n) {
    // gather up to kStreamChunk active rays.
    int m = 0;
    while (start < n && m < kStreamChunk) {
      occluded[start] = false;
      if (!active || active[start]) {
        ToEmbree(rays[start], &r[m]);
        index[m++] = start;
      }
      ++start;
    }
    if (m == 0) continue;
    rtcOccluded1M(impl_->top, &ctx, r, static_cast<unsigned>(m), sizeof(RTCRay));
    for (int i = 0; i < m; ++i) occluded[index[i]] = r[i].tfar < 0;
  }
}

}  // namespace penumbra
