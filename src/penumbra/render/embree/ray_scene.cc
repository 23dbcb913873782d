#include "penumbra/render/embree/ray_scene.h"

#include <embree3/rtcore.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/embree/analytic_lanes.h"
#include "penumbra/render/geometry/analytic_shapes.h"
#include "penumbra/render/geometry/mesh_shading_math.h"
#include "penumbra/render/geometry/moving_bounds.h"
#include "penumbra/render/geometry/ray_cone.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/render/geometry/triangle_shapes.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

// rays per Embree packet in IntersectMany / OccludedLanes (rtcIntersect16 / rtcOccluded16).
constexpr int kPacket = 16;

// frames: G = geom, I = the frame of the instanced scene that holds the geom (the body frame
// for a moving body, the world frame for the merged static bodies).

// a geom traced as Embree user geometry; lives at a stable address (geometry user pointer).
struct AnalyticGeom {
  AnalyticShape shape;
  Eigen::Matrix3d R_GI;  // p_G = R_GI p_I + p_GI
  Eigen::Vector3d p_GI;
  // the same with the instance pose folded in (set with the pose, for FinishHit):
  // p_G = R_GW p_W + p_GW, n_W = R_WG n_G.
  Eigen::Matrix3d R_GW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_GW = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_WG = Eigen::Matrix3d::Identity();
};

// a geom traced as triangles, in the instance frame. vertices carry one padding element at
// the end: Embree reads vertex buffers with 16-byte loads.
struct TriangleGeom {
  std::vector<Eigen::Vector3f> vertices_I;
  std::vector<Eigen::Vector3f> normals_I;
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<Eigen::Vector3i> faces;
  // per face: unit geometric normal in the instance frame (counter-clockwise) and in the geom
  // frame, precomputed for FinishHit.
  struct FaceNormal {
    Eigen::Vector3f n_I, n_G;
  };
  std::vector<FaceNormal> face_normals;
  std::vector<Eigen::Vector3f> vertices_G;  // the same vertices in the geom frame (FinishHit)
  // per face when there are texcoords: sqrt(texcoord area / surface area), texcoord units per
  // metre (the ray-cone texture level of detail's triangle term, SurfaceHit::uv_per_m).
  std::vector<float> uv_per_m;
  // per face when there are texcoords: the texcoord gradient in the geom frame
  // (SurfaceHit::duv_dp_G).
  std::vector<Eigen::Matrix<float, 2, 3>> duv_dp_G;
  // rotation from the instance frame to the geom frame (SurfaceHit::d_G).
  Eigen::Matrix3f R_GI = Eigen::Matrix3f::Identity();
};

// what an Embree (instanced scene, geomID) pair stands for.
struct GeomRecord {
  int geom = -1;
  int material = -1;
  const AnalyticGeom* analytic = nullptr;  // exactly one of analytic / triangles is set
  const TriangleGeom* triangles = nullptr;
};

// one instanced scene: the geoms of one moving body, or of every static body merged.
struct InstanceGroup {
  bool is_static = false;
  int body = -1;           // moving body; -1 for the static group
  std::vector<int> geoms;  // indices into SceneDescription::geoms
  RTCScene scene = nullptr;
  RTCGeometry instance = nullptr;
  std::vector<GeomRecord> records;  // by geomID in `scene`
  std::vector<std::unique_ptr<AnalyticGeom>> analytic;
  std::vector<std::unique_ptr<TriangleGeom>> triangles;
  // per geom, a box in the instance frame that holds it (MovingBounds): analytic shapes their
  // half extents in the geom frame, triangle geoms the box of their geom-frame vertices.
  std::vector<MovingBounds::Box> boxes_I;
  Pose X_WI = Pose::Identity();  // current instance pose (identity for the static group)
  Eigen::Matrix3f R_WI_f = Eigen::Matrix3f::Identity();
  bool rotated = false;  // R_WI_f is not the identity (FinishHit skips it for the static group)
  int64_t num_triangles = 0;
};

void AnalyticBounds(const RTCBoundsFunctionArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  const Eigen::Vector3d h = AnalyticHalfExtents(g->shape);
  // instance-frame box of the rotated geom box: centre p_IG, half extents |R_IG| h.
  const Eigen::Matrix3d R_IG = g->R_GI.transpose();
  const Eigen::Vector3d c = -(R_IG * g->p_GI);
  const Eigen::Vector3d e = R_IG.cwiseAbs() * h;
  // pad each axis by a relative epsilon, so that float rounding of the box never clips the
  // surface and flat shapes have volume, while rays leaving a flat shape (shadow rays from a
  // floor) stay out of its box.
  const Eigen::Vector3d pad = 1e-6 * (Eigen::Vector3d::Ones() + c.cwiseAbs() + e);
  const Eigen::Vector3d lo = c - e - pad, hi = c + e + pad;
  args->bounds_o->lower_x = static_cast<float>(lo.x());
  args->bounds_o->lower_y = static_cast<float>(lo.y());
  args->bounds_o->lower_z = static_cast<float>(lo.z());
  args->bounds_o->upper_x = static_cast<float>(hi.x());
  args->bounds_o->upper_y = static_cast<float>(hi.y());
  args->bounds_o->upper_z = static_cast<float>(hi.z());
}

// lanes [base, base + n) of an N-wide Embree ray (already in the instance frame), n =
// min(N - base, kAnalyticLanes), taken to an analytic geom's frame in double. all n lanes are
// computed, active or not (inactive lanes hold harmless values; their results are ignored):
// a packet's lanes are read in place when n is a lane width (Embree's 4, 8 and 16-wide
// packets), else copied and padded with the last lane (single rays).
inline int LoadLanes(const AnalyticGeom& g, RTCRayN* ray, unsigned N, unsigned base,
                     AnalyticRayLanes* out) {
  const int n = static_cast<int>(std::min<unsigned>(N - base, kAnalyticLanes));
  const int w = AnalyticLaneWidth(n);
  const float* ox = &RTCRayN_org_x(ray, N, base);
  const float* oy = &RTCRayN_org_y(ray, N, base);
  const float* oz = &RTCRayN_org_z(ray, N, base);
  const float* dx = &RTCRayN_dir_x(ray, N, base);
  const float* dy = &RTCRayN_dir_y(ray, N, base);
  const float* dz = &RTCRayN_dir_z(ray, N, base);
  const float* tnear = &RTCRayN_tnear(ray, N, base);
  const float* tfar = &RTCRayN_tfar(ray, N, base);
  alignas(64) float pad[8][kAnalyticLanes];
  if (w != n) {
    const float* src[8] = {ox, oy, oz, dx, dy, dz, tnear, tfar};
    for (int a = 0; a < 8; ++a)
      for (int k = 0; k < w; ++k) pad[a][k] = src[a][std::min(k, n - 1)];
    ox = pad[0], oy = pad[1], oz = pad[2], dx = pad[3], dy = pad[4], dz = pad[5];
    tnear = pad[6], tfar = pad[7];
  }
  for (int k = 0; k < w; ++k) {
    out->tmin[k] = tnear[k];
    out->tmax[k] = tfar[k];
  }
  TransformRayLanes(g.R_GI, g.p_GI, ox, oy, oz, dx, dy, dz, n, out);
  return n;
}

// Embree's intersect callback of an analytic geom: the packet's lanes at once
// (IntersectAnalyticLanes, in double), each hit of an active lane stored with its float t.
void AnalyticIntersect(const RTCIntersectFunctionNArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  const unsigned N = args->N;
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, N);
  AnalyticRayLanes lanes;
  AnalyticHitLanes hits;
  for (unsigned base = 0; base < N; base += kAnalyticLanes) {
    const int n = LoadLanes(*g, ray, N, base, &lanes);
    IntersectAnalyticLanes(g->shape, lanes, n, &hits);
    for (int k = 0; k < n; ++k) {
      const unsigned i = base + k;
      if (args->valid[i] != -1 || !(hits.t[k] < std::numeric_limits<double>::infinity())) continue;
      const float tf = static_cast<float>(hits.t[k]);
      if (!(tf < RTCRayN_tfar(ray, N, i))) continue;
      RTCRayN_tfar(ray, N, i) = tf;
      // Ng is left unset: FinishHit computes the exact normal from the part hit (in u).
      RTCHitN_u(hit, N, i) = static_cast<float>(hits.part[k]);
      RTCHitN_v(hit, N, i) = 0.0f;
      RTCHitN_primID(hit, N, i) = args->primID;
      RTCHitN_geomID(hit, N, i) = args->geomID;
      RTCHitN_instID(hit, N, i, 0) = args->context->instID[0];
    }
  }
}

void AnalyticOccluded(const RTCOccludedFunctionNArguments* args) {
  const auto* g = static_cast<const AnalyticGeom*>(args->geometryUserPtr);
  const unsigned N = args->N;
  AnalyticRayLanes lanes;
  AnalyticHitLanes hits;
  for (unsigned base = 0; base < N; base += kAnalyticLanes) {
    const int n = LoadLanes(*g, args->ray, N, base, &lanes);
    IntersectAnalyticLanes(g->shape, lanes, n, &hits);
    for (int k = 0; k < n; ++k) {
      const unsigned i = base + k;
      if (args->valid[i] == -1 && hits.t[k] < std::numeric_limits<double>::infinity() &&
          static_cast<float>(hits.t[k]) < RTCRayN_tfar(args->ray, N, i))
        RTCRayN_tfar(args->ray, N, i) = -std::numeric_limits<float>::infinity();
    }
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
  std::string error;  // first Embree error message
  const SceneDescription* scene = nullptr;
  // groups[0] is the static group (may hold no geoms); then one per moving body with geoms.
  std::vector<InstanceGroup> groups;
  std::vector<int> group_of_instance;  // top-level geomID -> index into groups
  std::vector<Pose> static_poses;      // X_WB of every body as the static group was built
  unsigned static_instance_id = 0;     // top-level geomID of the static group's instance
  // bounds of the moving groups (group i >= 1 is body i - 1 here), for the static-only path.
  MovingBounds moving;
  // the group of the tendons' capsules (world frame, rebuilt when the paths change; the last
  // group), or -1 if the scene has no tendons. with tendons the static-only path is not taken.
  int tendon_group = -1;
  std::vector<WorldSnapshot::TendonPath> tendon_paths;  // as the tendon group was built
  // rays refused by IsTraceableRay (never passed to Embree)
  mutable std::atomic<int64_t> untraceable{0};

  // counts a refused ray; the first one is logged.
  void NoteUntraceable(float ox, float oy, float oz, float dx, float dy, float dz) const {
    if (untraceable.fetch_add(1, std::memory_order_relaxed) == 0)
      spdlog::warn(
          "renderer: a ray with origin ({:g}, {:g}, {:g}) and direction ({:g}, {:g}, {:g}) is "
          "NaN, infinite or beyond {:g} m and was treated as a miss; expected the scene within "
          "the limits of docs/world-file.md (\"Input limits\")",
          ox, oy, oz, dx, dy, dz, kMaxRayComponent);
  }
  // IsTraceableRay(r); a refused ray is noted (NoteUntraceable).
  bool Traceable(const Ray& r) const {
    if (IsTraceableRay(r)) return true;
    NoteUntraceable(r.o.x(), r.o.y(), r.o.z(), r.d.x(), r.d.y(), r.d.z());
    return false;
  }

  // the closest hit of one ray over the whole scene (rtcIntersect1) in *rh; false for a miss or
  // a ray Traceable refuses.
  bool Closest(const Ray& ray, RTCRayHit* rh) const {
    if (!Traceable(ray)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ToEmbree(ray, &rh->ray);
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(top, &ctx, rh);
    return rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }

  void Check(const char* what) const {
    if (!error.empty()) throw Error(std::string("RayScene: ") + what + ": " + error);
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE)
      throw Error(std::string("RayScene: ") + what + ": Embree error " + std::to_string(code));
  }

  // the instance-frame box of a geom-frame box (centre c_G, half extents h_G) of a geom at X_IG.
  static MovingBounds::Box BoxInInstance(const Pose& X_IG, const Eigen::Vector3f& c_G,
                                         const Eigen::Vector3f& h_G) {
    MovingBounds::Box b;
    b.c = (X_IG * c_G.cast<double>()).cast<float>();
    b.axes = (X_IG.linear() * h_G.cast<double>().asDiagonal()).cast<float>();
    return b;
  }

  // adds geom `gi` to `group`'s scene with pose X_IG in the instance frame.
  void AddGeom(InstanceGroup* group, int gi, const Pose& X_IG) {
    const SceneDescription& sd = *scene;
    const Geom& geom = sd.geoms[gi];
    GeomRecord rec;
    rec.geom = gi;
    rec.material = geom.material;
    const Pose X_GI = X_IG.inverse();
    RTCGeometry eg = nullptr;
    if (geom.shape == GeomShape::kBox || geom.shape == GeomShape::kMesh ||
        geom.shape == GeomShape::kHeightField) {
      TriangleShape shape;
      if (geom.shape == GeomShape::kBox) {
        shape = BoxTriangles(geom.size);
      } else if (geom.shape == GeomShape::kMesh) {
        shape = MeshTriangles(sd.meshes[geom.mesh]);
      } else {
        shape = HeightFieldTriangles(sd.hfields[geom.hfield]);
      }
      if (shape.faces.empty()) return;
      Eigen::Vector3f lo = shape.vertices.front(), hi = lo;
      for (const Eigen::Vector3f& v : shape.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      group->boxes_I.push_back(BoxInInstance(X_IG, 0.5f * (lo + hi), 0.5f * (hi - lo)));
      auto tg = std::make_unique<TriangleGeom>();
      const Eigen::Matrix3f R_IG = X_IG.linear().cast<float>();
      const Eigen::Vector3f p_IG = X_IG.translation().cast<float>();
      tg->vertices_I.reserve(shape.vertices.size() + 1);
      for (const Eigen::Vector3f& v : shape.vertices) tg->vertices_I.push_back(R_IG * v + p_IG);
      tg->vertices_I.push_back(Eigen::Vector3f::Zero());  // padding for Embree's 16-byte loads
      TriangleShadingTerms terms = ShadingTermsOf(shape, R_IG);
      tg->normals_I = std::move(terms.normals_I);
      tg->uv_per_m = std::move(terms.uv_per_m);
      tg->duv_dp_G = std::move(terms.duv_dp_G);
      tg->texcoords = std::move(shape.texcoords);
      tg->faces = std::move(shape.faces);
      tg->vertices_G = std::move(shape.vertices);
      const Eigen::Matrix3f R_GI = X_GI.linear().cast<float>();
      tg->face_normals.reserve(tg->faces.size());
      for (const Eigen::Vector3i& f : tg->faces) {
        const Eigen::Vector3f& v0 = tg->vertices_I[f[0]];
        Eigen::Vector3f n_I = (tg->vertices_I[f[1]] - v0).cross(tg->vertices_I[f[2]] - v0);
        const float len = n_I.norm();
        n_I = len > 0 ? Eigen::Vector3f(n_I / len) : Eigen::Vector3f::UnitZ();
        tg->face_normals.push_back({n_I, R_GI * n_I});
      }
      tg->R_GI = R_GI;
      eg = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetSharedGeometryBuffer(eg, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                 tg->vertices_I.data(), 0, sizeof(Eigen::Vector3f),
                                 tg->vertices_I.size() - 1);
      rtcSetSharedGeometryBuffer(eg, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, tg->faces.data(),
                                 0, sizeof(Eigen::Vector3i), tg->faces.size());
      group->num_triangles += static_cast<int64_t>(tg->faces.size());
      rec.triangles = tg.get();
      group->triangles.push_back(std::move(tg));
    } else {
      auto ag = std::make_unique<AnalyticGeom>();
      ag->shape = AnalyticShapeOf(geom);
      ag->R_GI = X_GI.linear();
      ag->p_GI = X_GI.translation();
      group->boxes_I.push_back(BoxInInstance(X_IG, Eigen::Vector3f::Zero(),
                                             AnalyticHalfExtents(ag->shape).cast<float>()));
      eg = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(eg, 1);
      rtcSetGeometryUserData(eg, ag.get());
      rtcSetGeometryBoundsFunction(eg, AnalyticBounds, nullptr);
      rtcSetGeometryIntersectFunction(eg, AnalyticIntersect);
      rtcSetGeometryOccludedFunction(eg, AnalyticOccluded);
      rec.analytic = ag.get();
      group->analytic.push_back(std::move(ag));
    }
    rtcCommitGeometry(eg);
    const unsigned id = rtcAttachGeometry(group->scene, eg);
    rtcReleaseGeometry(eg);
    if (group->records.size() <= id) group->records.resize(id + 1);
    group->records[id] = rec;
  }

  // (re)builds the scene of `group`: a moving body's geoms in its body frame, or the static
  // bodies' geoms in the world frame posed with X_WB.
  void BuildGroup(InstanceGroup* group, const std::vector<Pose>& X_WB) {
    if (group->scene) rtcReleaseScene(group->scene);
    group->records.clear();
    group->analytic.clear();
    group->triangles.clear();
    group->boxes_I.clear();
    group->num_triangles = 0;
    group->scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(group->scene, RTC_BUILD_QUALITY_HIGH);
    for (int gi : group->geoms) {
      const Geom& g = scene->geoms[gi];
      AddGeom(group, gi, group->is_static ? Pose(X_WB[g.body] * g.X_BG) : g.X_BG);
    }
    SetAnalyticWorldTransforms(group);
    rtcCommitScene(group->scene);
  }

  // rebuilds the tendon group's scene: a capsule around every segment of `paths` (world frame;
  // a segment shorter than 1e-9 m is a sphere).
  void BuildTendonGroup(const std::vector<WorldSnapshot::TendonPath>& paths) {
    InstanceGroup* group = &groups[tendon_group];
    if (group->scene) rtcReleaseScene(group->scene);
    group->records.clear();
    group->analytic.clear();
    group->scene = rtcNewScene(device);
    for (const WorldSnapshot::TendonPath& path : paths) {
      if (path.tendon < 0 || path.tendon >= static_cast<int>(scene->tendons.size()))
        throw Error("RayScene::Update: a tendon path refers to missing tendon " +
                    std::to_string(path.tendon));
      const Tendon& tendon = scene->tendons[path.tendon];
      for (size_t k = 0; k + 1 < path.p_W.size(); ++k) {
        const Eigen::Vector3d& a = path.p_W[k];
        const Eigen::Vector3d& b = path.p_W[k + 1];
        if (!a.allFinite() || !b.allFinite()) continue;
        const double length = (b - a).norm();
        auto ag = std::make_unique<AnalyticGeom>();
        ag->shape.kind = length > 1e-9 ? AnalyticKind::kCapsule : AnalyticKind::kSphere;
        ag->shape.size = {tendon.width_m, 0.5 * length, 0};
        // geom frame: origin at the segment's midpoint, z along it
        Eigen::Matrix3d R_WG = Eigen::Matrix3d::Identity();
        if (length > 1e-9) {
          const Eigen::Vector3d z = (b - a) / length;
          const Eigen::Vector3d x = z.unitOrthogonal();
          R_WG.col(0) = x;
          R_WG.col(1) = z.cross(x);
          R_WG.col(2) = z;
        }
        ag->R_GI = R_WG.transpose();
        ag->p_GI = -(ag->R_GI * (0.5 * (a + b)));
        RTCGeometry eg = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(eg, 1);
        rtcSetGeometryUserData(eg, ag.get());
        rtcSetGeometryBoundsFunction(eg, AnalyticBounds, nullptr);
        rtcSetGeometryIntersectFunction(eg, AnalyticIntersect);
        rtcSetGeometryOccludedFunction(eg, AnalyticOccluded);
        rtcCommitGeometry(eg);
        const unsigned id = rtcAttachGeometry(group->scene, eg);
        rtcReleaseGeometry(eg);
        GeomRecord rec;
        rec.geom = -1;
        rec.material = tendon.material;
        rec.analytic = ag.get();
        if (group->records.size() <= id) group->records.resize(id + 1);
        group->records[id] = rec;
        group->analytic.push_back(std::move(ag));
      }
    }
    SetAnalyticWorldTransforms(group);
    rtcCommitScene(group->scene);
    rtcSetGeometryInstancedScene(group->instance, group->scene);
    rtcCommitGeometry(group->instance);
    tendon_paths = paths;
  }

  // folds the instance pose of `group` into its analytic geoms' transforms.
  static void SetAnalyticWorldTransforms(InstanceGroup* group) {
    const Eigen::Matrix3d R_IW = group->X_WI.linear().transpose();
    for (const std::unique_ptr<AnalyticGeom>& g : group->analytic) {
      g->R_GW = g->R_GI * R_IW;
      g->p_GW = g->p_GI - g->R_GW * group->X_WI.translation();
      g->R_WG = g->R_GW.transpose();
    }
  }

  // sets the instance transform of `group` to X_WI.
  void SetInstancePose(InstanceGroup* group, const Pose& X_WI) {
    group->X_WI = X_WI;
    group->R_WI_f = X_WI.linear().cast<float>();
    group->rotated = group->R_WI_f != Eigen::Matrix3f::Identity();
    SetAnalyticWorldTransforms(group);
    float xfm[12];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = static_cast<float>(X_WI.linear()(r, c));
    for (int r = 0; r < 3; ++r) xfm[9 + r] = static_cast<float>(X_WI.translation()(r));
    rtcSetGeometryTransform(group->instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(group->instance);
  }

  static AnalyticShape AnalyticShapeOf(const Geom& geom) {
    AnalyticShape shape;
    switch (geom.shape) {
      case GeomShape::kPlane:
        shape.kind = AnalyticKind::kPlane;
        shape.size = {geom.size.x() > 0 ? geom.size.x() : kInfinitePlaneHalfSize,
                      geom.size.y() > 0 ? geom.size.y() : kInfinitePlaneHalfSize, 0};
        return shape;
      case GeomShape::kSphere:
        shape.kind = AnalyticKind::kSphere;
        break;
      case GeomShape::kCapsule:
        shape.kind = AnalyticKind::kCapsule;
        break;
      case GeomShape::kEllipsoid:
        shape.kind = AnalyticKind::kEllipsoid;
        break;
      default:
        shape.kind = AnalyticKind::kCylinder;
        break;
    }
    shape.size = geom.size;
    return shape;
  }

  // fills `hit` from Embree's hit of world ray `ray`: geom, exact surface point and
  // normals (analytic shapes in double from the world ray; triangles from barycentrics).
  void FinishHit(const Ray& ray, const RTCRayHit& rh, SurfaceHit* hit) const {
    const InstanceGroup& group = groups[group_of_instance[rh.hit.instID[0]]];
    const GeomRecord& rec = group.records[rh.hit.geomID];
    const float t = rh.ray.tfar;
    const ShapePart part = static_cast<ShapePart>(static_cast<int>(rh.hit.u));
    BeginSurfaceHit(ray, t, rec.geom, rec.material, hit);
    Eigen::Vector3f ng_W, ns_W;
    if (rec.analytic) {
      const AnalyticGeom& g = *rec.analytic;
      const Eigen::Vector3d p_W =
          ray.o.cast<double>() + static_cast<double>(t) * ray.d.cast<double>();
      const Eigen::Vector3d p_G = g.R_GW * p_W + g.p_GW;
      const Eigen::Vector3d n_G = AnalyticNormal(g.shape, p_G, part);
      hit->p_G = p_G.cast<float>();
      hit->n_G = n_G.cast<float>();
      hit->d_G = (g.R_GW * ray.d.cast<double>()).normalized().cast<float>();
      ng_W = (g.R_WG * n_G).cast<float>();
      ns_W = ng_W;
    } else {
      const TriangleGeom& g = *rec.triangles;
      const Eigen::Vector3i& f = g.faces[rh.hit.primID];
      const TriangleGeom::FaceNormal& fn = g.face_normals[rh.hit.primID];
      const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
      // p_G straight from the geom-frame vertices (no transform of p_I).
      hit->p_G = w * g.vertices_G[f[0]] + u * g.vertices_G[f[1]] + v * g.vertices_G[f[2]];
      hit->n_G = fn.n_G;
      // the static group's frame is the world frame: no rotation to apply.
      ng_W = group.rotated ? Eigen::Vector3f(group.R_WI_f * fn.n_I) : fn.n_I;
      const Eigen::Vector3f d_I =
          group.rotated ? Eigen::Vector3f(group.R_WI_f.transpose() * ray.d) : ray.d;
      hit->d_G = (g.R_GI * d_I).normalized();
      ns_W = ng_W;
      if (!g.normals_I.empty()) {
        const Eigen::Vector3f ns_I =
            BarycentricMix(g.normals_I[f[0]], g.normals_I[f[1]], g.normals_I[f[2]], u, v);
        const float ls = ns_I.norm();
        if (ls > 0) ns_W = group.rotated ? Eigen::Vector3f(group.R_WI_f * (ns_I / ls)) : ns_I / ls;
      }
      if (!g.texcoords.empty()) {
        hit->uv = BarycentricMix(g.texcoords[f[0]], g.texcoords[f[1]], g.texcoords[f[2]], u, v);
        hit->has_uv = true;
        hit->uv_per_m = g.uv_per_m[rh.hit.primID];
        hit->duv_dp_G = g.duv_dp_G[rh.hit.primID];
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

  // traces rays[index[k]] for the lanes k with index[k] >= 0 as one Embree packet and
  // writes hits[index[k]], did_hit[index[k]]. static_only: against the static group's scene
  // alone, not the top level (the caller has made sure that no ray can hit a moving geom; the
  // hits are then those of the top level, whose static instance has the identity pose).
  // the packets are traced with an incoherent context: with RTC_INTERSECT_CONTEXT_FLAG_COHERENT,
  // Embree 3.13.5 was seen to loop forever inside rtcIntersect16 / rtcOccluded16 (and
  // rtcOccluded1M) on some packets of this renderer's scenes (instanced user geometry;
  // reproduced by the realtime lighting tests), so that flag is not used.
  void IntersectPacket(const Ray* rays, const int* index, bool static_only, SurfaceHit* hits,
                       bool* did_hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(64) RTCRayHit16 p;
    alignas(64) int valid[kPacket];
    // idle lanes repeat an active ray (harmless values). the common case, every active ray
    // traceable, is checked in one branch-free pass; the rest only when one is not
    int fill = -1;
    bool all_traceable = true;
    for (int k = 0; k < kPacket; ++k) {
      if (index[k] < 0) continue;
      fill = index[k];
      all_traceable &= IsTraceableRay(rays[index[k]]);
    }
    if (fill < 0) return;
    int local_index[kPacket];
    for (int k = 0; k < kPacket; ++k) local_index[k] = index[k];
    if (!all_traceable) {
      // untraceable rays are misses: their lanes stay inactive (filled with a traceable ray)
      fill = -1;
      for (int k = 0; k < kPacket; ++k) {
        if (index[k] < 0) continue;
        if (Traceable(rays[index[k]])) {
          fill = index[k];
          continue;
        }
        did_hit[index[k]] = false;
        local_index[k] = -1;
      }
      if (fill < 0) return;
    }
    for (int k = 0; k < kPacket; ++k) {
      valid[k] = local_index[k] >= 0 ? -1 : 0;
      const Ray& r = rays[local_index[k] >= 0 ? local_index[k] : fill];
      p.ray.org_x[k] = r.o.x();
      p.ray.org_y[k] = r.o.y();
      p.ray.org_z[k] = r.o.z();
      p.ray.dir_x[k] = r.d.x();
      p.ray.dir_y[k] = r.d.y();
      p.ray.dir_z[k] = r.d.z();
      p.ray.tnear[k] = r.tmin;
      p.ray.tfar[k] = r.tmax;
      p.ray.time[k] = 0;
      p.ray.mask[k] = 0xffffffffu;
      p.ray.id[k] = 0;
      p.ray.flags[k] = 0;
      p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, static_only ? groups[0].scene : top, &ctx, &p);
    if (static_only)
      for (int k = 0; k < kPacket; ++k) p.hit.instID[0][k] = static_instance_id;
    for (int k = 0; k < kPacket; ++k) {
      const int i = local_index[k];
      if (i < 0) continue;
      did_hit[i] = p.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
      if (!did_hit[i]) continue;
      RTCRayHit rh;
      rh.ray.tfar = p.ray.tfar[k];
      rh.hit.u = p.hit.u[k];
      rh.hit.v = p.hit.v[k];
      rh.hit.primID = p.hit.primID[k];
      rh.hit.geomID = p.hit.geomID[k];
      rh.hit.instID[0] = p.hit.instID[0][k];
      FinishHit(rays[i], rh, &hits[i]);
    }
  }

  void Release() {
    for (InstanceGroup& g : groups) {
      if (g.instance) rtcReleaseGeometry(g.instance);
      if (g.scene) rtcReleaseScene(g.scene);
    }
    groups.clear();
    if (top) rtcReleaseScene(top);
    top = nullptr;
    if (device) rtcReleaseDevice(device);
    device = nullptr;
  }
};

RayScene::RayScene(const SceneDescription& scene) : impl_(std::make_unique<Impl>()), scene_(scene) {
  Impl& m = *impl_;
  m.scene = &scene;
  const int num_bodies = static_cast<int>(scene.bodies.size());
  X_WB_.assign(num_bodies, Pose::Identity());
  m.static_poses = X_WB_;

  // visible geoms, grouped: static bodies (the world body and Body::is_static) together,
  // every other body on its own (static_geometry.h)
  const std::vector<RayGeomGroup> groups = GroupRayGeoms(scene, "RayScene");
  m.groups.resize(groups.size());
  m.groups[0].is_static = true;
  for (size_t k = 0; k < groups.size(); ++k) {
    m.groups[k].body = groups[k].body;
    m.groups[k].geoms = groups[k].geoms;
    num_visible_geoms_ += static_cast<int>(groups[k].geoms.size());
  }

  // the tendons' capsules: one group of their own, rebuilt by Update
  for (const Tendon& tendon : scene.tendons) ValidateRayTendon(scene, tendon, "RayScene");
  if (!scene.tendons.empty()) {
    m.tendon_group = static_cast<int>(m.groups.size());
    m.groups.emplace_back();
  }

  m.device = rtcNewDevice(nullptr);
  if (!m.device) throw Error("RayScene: cannot create the Embree device (rtcNewDevice failed)");
  rtcSetDeviceErrorFunction(m.device, ErrorCallback, &m.error);
  try {
    m.top = rtcNewScene(m.device);
    rtcSetSceneFlags(m.top, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(m.top, RTC_BUILD_QUALITY_LOW);
    for (int i = 0; i < static_cast<int>(m.groups.size()); ++i) {
      InstanceGroup& g = m.groups[i];
      m.BuildGroup(&g, X_WB_);
      g.instance = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g.instance, g.scene);
      rtcSetGeometryTimeStepCount(g.instance, 1);
      m.SetInstancePose(&g, Pose::Identity());
      const unsigned id = rtcAttachGeometry(m.top, g.instance);
      if (m.group_of_instance.size() <= id) m.group_of_instance.resize(id + 1, -1);
      m.group_of_instance[id] = i;
      if (i == 0) m.static_instance_id = id;
      if (i > 0 && i != m.tendon_group) {
        // cluster: the root of the body's kinematic tree (the child of the world body).
        int root = g.body;
        while (scene.bodies[root].parent > 0) root = scene.bodies[root].parent;
        m.moving.AddBody(g.boxes_I, root);
      }
      num_triangles_ += g.num_triangles;
    }
    rtcCommitScene(m.top);
    m.Check("building the scene");
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
  // static bodies do not move; their merged scene is rebuilt only if one did (normally only
  // at the first Update, which brings their actual poses).
  InstanceGroup& statics = m.groups[0];
  bool static_moved = false;
  for (int gi : statics.geoms) {
    const int b = scene_.geoms[gi].body;
    if (snapshot.X_WB[b].matrix() != m.static_poses[b].matrix()) static_moved = true;
  }
  if (static_moved) {
    num_triangles_ -= statics.num_triangles;
    m.static_poses = snapshot.X_WB;
    m.BuildGroup(&statics, m.static_poses);
    num_triangles_ += statics.num_triangles;
    rtcSetGeometryInstancedScene(statics.instance, statics.scene);
    rtcCommitGeometry(statics.instance);
    changed = true;
  }
  for (size_t i = 1; i < m.groups.size(); ++i) {
    if (static_cast<int>(i) == m.tendon_group) continue;
    InstanceGroup& g = m.groups[i];
    const Pose& X = snapshot.X_WB[g.body];
    if (X.matrix() == g.X_WI.matrix()) continue;
    m.SetInstancePose(&g, X);
    m.moving.SetPose(static_cast<int>(i) - 1, X);
    changed = true;
  }
  if (m.tendon_group >= 0) {
    bool same = snapshot.tendon_paths.size() == m.tendon_paths.size();
    for (size_t k = 0; same && k < m.tendon_paths.size(); ++k)
      same = snapshot.tendon_paths[k].tendon == m.tendon_paths[k].tendon &&
             snapshot.tendon_paths[k].p_W == m.tendon_paths[k].p_W;
    if (!same) {
      m.BuildTendonGroup(snapshot.tendon_paths);
      changed = true;
    }
  }
  X_WB_ = snapshot.X_WB;
  if (changed) {
    m.moving.CommitPoses();
    rtcCommitScene(m.top);
    ++num_top_level_commits_;
    m.Check("updating body poses");
  }
}

int64_t RayScene::num_untraceable_rays() const {
  return impl_->untraceable.load(std::memory_order_relaxed);
}

bool RayScene::Intersect(const Ray& ray, SurfaceHit* hit) const {
  RTCRayHit rh;
  if (!impl_->Closest(ray, &rh)) return false;
  impl_->FinishHit(ray, rh, hit);
  return true;
}

bool RayScene::IntersectIds(const Ray& ray, RayHitIds* ids) const {
  RTCRayHit rh;
  if (!impl_->Closest(ray, &rh)) return false;
  const int group = impl_->group_of_instance[rh.hit.instID[0]];
  const GeomRecord& rec = impl_->groups[group].records[rh.hit.geomID];
  ids->t = rh.ray.tfar;
  ids->geom = rec.geom;
  ids->segment = group == impl_->tendon_group ? static_cast<int>(rh.hit.geomID) : -1;
  ids->analytic = rec.analytic != nullptr;
  ids->face = ids->analytic ? 0 : static_cast<int>(rh.hit.primID);
  ids->u = ids->analytic ? 0.0f : rh.hit.u;
  ids->v = ids->analytic ? 0.0f : rh.hit.v;
  ids->part = ids->analytic ? static_cast<int>(rh.hit.u) : 0;
  return true;
}

bool RayScene::Occluded(const Ray& ray) const {
  if (!impl_->Traceable(ray)) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  ToEmbree(ray, &r);
  rtcOccluded1(impl_->top, &ctx, &r);
  return r.tfar < 0;
}

// one ray at a time (rtcOccluded1): the verdicts of Occluded(ray), which the CPU's images are
// made with, whatever the batch.
void RayScene::OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const {
  for (size_t i = 0; i < rays.size(); ++i) occluded[i] = Occluded(rays[i]);
}

// packets of kPacket rays (rtcIntersect16, Impl::IntersectPacket) for coherent rays;
// incoherent rays go one by one (rtcIntersect1), as Embree recommends.
void RayScene::IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                              std::span<bool> did_hit) const {
  // IntersectMany counts rays in int: batches of 2^30 rays (a multiple of the packet size, so
  // the packets are those of one call)
  constexpr size_t kMaxBatch = size_t{1} << 30;
  for (size_t i = 0; i < rays.size(); i += kMaxBatch) {
    const int n = static_cast<int>(std::min(kMaxBatch, rays.size() - i));
    IntersectMany(rays.data() + i, n, /*coherent=*/true, hits.data() + i, did_hit.data() + i);
  }
}

void RayScene::IntersectMany(const Ray* rays, int n, bool coherent, SurfaceHit* hits,
                             bool* did_hit) const {
  if (!coherent) {
    for (int i = 0; i < n; ++i) did_hit[i] = Intersect(rays[i], &hits[i]);
    return;
  }
  int index[kPacket];
  for (int start = 0; start < n; start += kPacket) {
    const int m = std::min(kPacket, n - start);
    for (int k = 0; k < kPacket; ++k) index[k] = k < m ? start + k : -1;
    impl_->IntersectPacket(rays, index, /*static_only=*/false, hits, did_hit);
  }
}

bool RayScene::IntersectGrid(const Ray* rays, int width, int height, SurfaceHit* hits,
                             bool* did_hit, const RayCone* cone) const {
  constexpr int kSide = 4;  // kSide x kSide cells per packet
  static_assert(kSide * kSide == kPacket, "one Embree packet per square of cells");
  const bool static_only =
      impl_->tendon_group < 0 &&
      !impl_->moving.MayHit(cone != nullptr ? *cone : RayCone::FromRays(rays, width * height));
  int index[kPacket];
  for (int y0 = 0; y0 < height; y0 += kSide) {
    for (int x0 = 0; x0 < width; x0 += kSide) {
      for (int k = 0; k < kPacket; ++k) {
        const int x = x0 + k % kSide, y = y0 + k / kSide;
        index[k] = x < width && y < height ? y * width + x : -1;
      }
      impl_->IntersectPacket(rays, index, static_only, hits, did_hit);
    }
  }
  return static_only;
}

bool RayScene::OccludedLanes(const Vec3Lanes& o, const Vec3Lanes& d, const Lanes& tmax,
                             const LaneMask& active, LaneMask* occluded) const {
  static_assert(kLanes == kPacket, "one Embree packet per lane batch");
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  alignas(64) RTCRay16 p;
  alignas(64) int valid[kPacket];
  // untraceable rays (NaN, infinite, out of range) are not traced: a miss, not occluded. the
  // common case, every active lane traceable, is one branch-free pass
  LaneMask traced = active;
  bool all_traceable = true;
  for (int k = 0; k < kPacket; ++k) {
    all_traceable &=
        !active[k] | IsTraceableRay(o.x[k], o.y[k], o.z[k], d.x[k], d.y[k], d.z[k], 0.0f, tmax[k]);
  }
  if (!all_traceable) {
    for (int k = 0; k < kPacket; ++k) {
      if (active[k] &&
          !IsTraceableRay(o.x[k], o.y[k], o.z[k], d.x[k], d.y[k], d.z[k], 0.0f, tmax[k])) {
        impl_->NoteUntraceable(o.x[k], o.y[k], o.z[k], d.x[k], d.y[k], d.z[k]);
        traced[k] = false;
      }
    }
  }
  // lanes that are not traced repeat a traced lane's ray (harmless values, as IntersectPacket's
  // idle lanes): Embree's 8-wide (AVX2) packet path asserts that the rays of the lanes it
  // traces are valid, and it was seen to take lanes marked invalid for such (a NaN origin in
  // an untraced lane aborted UntraceableRay.PacketsTraceTheGoodLanesAndMissTheBadOnes)
  int fill = -1;
  for (int k = 0; k < kPacket && fill < 0; ++k)
    if (traced[k]) fill = k;
  const bool static_only =
      impl_->tendon_group < 0 && !impl_->moving.SegmentsMayHit(o, d, tmax, traced).any();
  if (fill < 0) {
    *occluded = LaneMask::Constant(false);
    return static_only;
  }
  for (int k = 0; k < kPacket; ++k) {
    const int f = traced[k] ? k : fill;
    valid[k] = traced[k] ? -1 : 0;
    p.org_x[k] = o.x[f];
    p.org_y[k] = o.y[f];
    p.org_z[k] = o.z[f];
    p.dir_x[k] = d.x[f];
    p.dir_y[k] = d.y[f];
    p.dir_z[k] = d.z[f];
    p.tnear[k] = 0;
    p.tfar[k] = tmax[f];
    p.time[k] = 0;
    p.mask[k] = 0xffffffffu;
    p.id[k] = 0;
    p.flags[k] = 0;
  }
  rtcOccluded16(valid, static_only ? impl_->groups[0].scene : impl_->top, &ctx, &p);
  for (int k = 0; k < kPacket; ++k) (*occluded)[k] = traced[k] && p.tfar[k] < 0;
  return static_only;
}

RayQueryFactory RaySceneFactory() {
  return [](const SceneDescription& scene) -> std::unique_ptr<RayQuery> {
    return std::make_unique<RayScene>(scene);
  };
}

}  // namespace penumbra
