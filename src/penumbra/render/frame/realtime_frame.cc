#include "penumbra/render/frame/realtime_frame.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/film/film_math.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra::cuda {
namespace {

Float3 Float3Of(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }
F3 FrameToF3(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

MaterialPod PodOf(const Material& m, const std::vector<int>& texture_slot) {
  MaterialPod p;
  p.base_color = Float3Of(m.base_color);
  p.roughness = m.roughness;
  p.metallic = m.metallic;
  p.specular = m.specular;
  p.emission = Float3Of(m.emission);
  p.texture = m.texture >= 0 && m.texture < static_cast<int>(texture_slot.size())
                  ? texture_slot[m.texture]
                  : -1;
  p.texrepeat[0] = m.texrepeat.x();
  p.texrepeat[1] = m.texrepeat.y();
  p.texuniform = m.texuniform ? 1 : 0;
  p.mirror = m.reflectance > 0 ? std::min(m.reflectance, 1.0f) : 0.0f;
  return p;
}

}  // namespace

PinholeCamera PinholeCameraOf(const CameraView& view) {
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  const Camera::PinholeTerms t = camera.pinhole_terms();
  PinholeCamera c;
  c.o = FrameToF3(t.o_W);
  c.ex = FrameToF3(t.ex_W);
  c.ey = FrameToF3(t.ey_W);
  c.ez = FrameToF3(t.ez_W);
  c.cx = t.cx;
  c.cy = t.cy;
  c.inv_fx = t.inv_fx;
  c.inv_fy = t.inv_fy;
  c.near = static_cast<float>(view.near_m);
  c.width = camera.width();
  c.height = camera.height();
  return c;
}

namespace {

// the statics' ray queries RealtimeFrameData's constructor was given, else BvhRayQuery's
RayQueryFactory StaticsQueryOr(RayQueryFactory given) {
  return given ? given : BvhRayQueryFactory();
}

}  // namespace

RealtimeFrameData::RealtimeFrameData(const SceneDescription& scene, const RenderSettings& settings,
                                     RayQueryFactory statics_query)
    : scene_(scene),
      settings_(settings),
      lights_(scene),
      sky_(scene.sky, MjcfSkyboxOf(scene)),
      volume_(StaticsQueryOr(statics_query)),
      shelter_(StaticsQueryOr(statics_query)),
      film_(settings) {
  // 2d textures with one face and cube (or skybox) textures with six: every level's texels,
  // one after the other.
  // (cube textures only where a material wraps a geom in one: an MJCF skybox is the sky's.)
  std::vector<int> slot(scene.textures.size(), -1);
  std::vector<bool> on_material(scene.textures.size(), false);
  for (const Material& m : scene.materials)
    if (m.texture >= 0 && m.texture < static_cast<int>(on_material.size()))
      on_material[m.texture] = true;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (!t.image) continue;
    const bool cube = t.kind != Texture::Kind::k2D;
    if (t.image->faces() != (cube ? 6 : 1) || (cube && !on_material[i])) continue;
    const TextureImage& im = *t.image;
    if (im.num_levels() > kMaxTextureLevels)
      throw Error("texture '" + t.name + "': " + std::to_string(im.num_levels()) +
                  " mip levels, the CUDA backend takes at most " +
                  std::to_string(kMaxTextureLevels));
    TexturePod pod;
    pod.num_levels = im.num_levels();
    pod.cube = cube ? 1 : 0;
    for (int l = 0; l < im.num_levels(); ++l) {
      const TextureLevel& L = im.level(l);
      pod.width[l] = L.width;
      pod.height[l] = L.height;
      pod.level_offset[l] = static_cast<int64_t>(texels_.size());
      texels_.insert(texels_.end(), L.rgb_srgb.begin(), L.rgb_srgb.end());
    }
    slot[i] = static_cast<int>(textures_.size());
    textures_.push_back(pod);
  }
  // the PBR maps by name, as MaterialEvaluator finds them
  const MaterialEvaluator evaluator(scene, settings.max_anisotropy);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    MaterialPod pod = PodOf(scene.materials[i], slot);
    const MaterialEvaluator::PbrMaps& maps = evaluator.pbr_maps(static_cast<int>(i));
    auto slot_of = [&](int tex) {
      return tex >= 0 && tex < static_cast<int>(slot.size()) ? slot[tex] : -1;
    };
    pod.normal_map = slot_of(maps.normal);
    pod.metallic_roughness_map = slot_of(maps.metallic_roughness);
    pod.occlusion_map = slot_of(maps.occlusion);
    pod.emissive_map = slot_of(maps.emissive);
    any_mirror_ = any_mirror_ || pod.mirror > 0;
    materials_.push_back(pod);
  }
  default_material_ = PodOf(Material(), slot);
  any_mirror_ = any_mirror_ || default_material_.mirror > 0;
  geoms_.resize(scene.geoms.size());
  for (size_t g = 0; g < scene.geoms.size(); ++g) {
    const Geom& geom = scene.geoms[g];
    GeomPod& pod = geoms_[g];
    pod.half_extent = Float3Of(GeomHalfExtents(scene, geom));
    pod.plane = geom.shape == GeomShape::kPlane ? 1 : 0;
    pod.box = geom.shape == GeomShape::kBox ? 1 : 0;
  }
}

void RealtimeFrameData::Prepare(const WorldSnapshot& snapshot, const CameraView& view,
                                ThreadPool* pool, const EffectsFrame* effects,
                                const CameraRayTables* rays, const RayQuery* media_rays,
                                bool streaks) {
  PoseWorld(snapshot, pool, effects);
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  if (rays == nullptr) {
    camera_rays_.Prepare(view, pool);
    rays = &camera_rays_;
  }
  SetCamera(rays->Point(PinholeCameraOf(view), rays->xy().data(), rays->rows().data()),
            camera.pixel_spread_rad(), view.camera_index, view.frame_index,
            view.white_balance_gains);
  if (streaks)
    PrepareStreaks(snapshot, effects, camera, view, pool);
  else
    ClearStreaks();
  PrepareMedia(snapshot, effects, camera, view, pool, media_rays);
}

void RealtimeFrameData::ClearStreaks() {
  streaks_culled_ = 0;
  path_streaks_.Clear();
  splat_streaks_.Clear();
  device_list_ = DeviceStreakList();
  device_pods_copied_ = false;
}

void RealtimeFrameData::PrepareMedia(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                                     const Camera& camera, const CameraView& view, ThreadPool* pool,
                                     const RayQuery* media_rays) {
  media_ready_ = false;
  media_build_ms_ = 0;
  const EffectsFrame* fx = effects != nullptr && !effects->empty() ? effects : nullptr;
  if (fx == nullptr || (fx->homogeneous_media.empty() && fx->grid_media.empty())) return;
  // as the CPU's MediaFrame::Prepare: the media of the frame (homogeneous and grids),
  // lit by the frame's lights and sky through the occluded sky volume, for this camera
  BuildMediaScene(fx);
  if (media_.empty()) return;
  const auto t0 = std::chrono::steady_clock::now();
  if (media_rays == nullptr) {
    if (!media_query_) media_query_ = std::make_unique<BvhRayQuery>(scene_);
    media_query_->Update(snapshot);
    media_rays = media_query_.get();
  }
  realtime_media_.Build(
      media_, lights_, *media_rays, camera, FrameKey(view.camera_index, view.frame_index),
      scene_.center_W.cast<float>(), scene_.extent_m, SkyAmbientRadiance(*frame_sky_),
      volume_.empty() ? nullptr : &volume_, pool, /*device_volumes=*/true);
  media_view_ = realtime_media_.HostView(&media_arrays_);
  media_build_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  media_ready_ = true;
}

void RealtimeFrameData::BuildMediaScene(const EffectsFrame* fx) {
  if (media_scene_built_) return;
  media_.Build(fx);
  media_scene_built_ = true;
}

void RealtimeFrameData::PrepareStreaks(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                                       const Camera& camera, const CameraView& view,
                                       ThreadPool* pool) {
  ClearStreaks();
  const EffectsFrame* fx = effects != nullptr && !effects->empty() ? effects : nullptr;
  if (fx == nullptr || fx->particles.empty()) {
    particles_.Build(nullptr, camera, 0, StreakRays::kAny);
    return;
  }
  const bool realtime = settings_.tier == RenderSettings::Tier::kRealtime;
  // as the CPU's MediaFrame::Prepare: the sheltered drops left out, the rain streaks the
  // frame's homogeneous media hide culled; under the realtime tier the frame itself splats the
  // streaks and shades them per pixel, under the pathtraced tier every rain streak is shaded
  // once
  bool sheltered = false;
  for (const ParticleSet& ps : fx->particles) sheltered = sheltered || ShelterApplies(ps);
  shelter_update_ms_ = 0;
  if (sheltered) {
    const auto t0 = std::chrono::steady_clock::now();
    shelter_.Update(scene_, snapshot, pool);
    shelter_update_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  if (!fx->homogeneous_media.empty() || !fx->grid_media.empty()) BuildMediaScene(fx);
  const MediaScene* media = media_scene_built_ && !media_.empty() ? &media_ : nullptr;
  // the device's drop culling (device_drop_culler_): the host prepares its inputs only
  const bool device_cull = realtime && has_drop_culler();
  particles_.set_host_splat(!realtime);
  particles_.set_host_culling(!device_cull);
  particles_.Build(fx, camera, view.exposure_time_sec,
                   realtime ? StreakRays::kPixelCentres : StreakRays::kCamera, pool, media,
                   sheltered ? &shelter_ : nullptr);
  streaks_culled_ = particles_.culled();
  if (device_cull) {
    // the streaks stay on the device: the splat reads them in place, with their count there;
    // the sets do not depend on them (BuildSets)
    device_list_ = device_drop_culler_(*fx, particles_.cull_setup());
    if (device_list_.bound <= 0) return;
    splat_streaks_.BuildSets(particles_, SkyAmbientRadiance(*frame_sky_));
    SetSplatCamera(camera);
    return;
  }
  if (particles_.empty()) return;
  const Eigen::Vector3f sky_ambient = SkyAmbientRadiance(*frame_sky_);
  if (realtime) {
    // the streaks in index order and the camera's projection for the frame's splat
    // (StreakSplatView)
    splat_streaks_.BuildList(particles_, sky_ambient);
    SetSplatCamera(camera);
    return;
  }
  // the pathtraced tier: the paths trace the streaks themselves (path_streaks.h)
  particles_.PrecomputeRain(lights_, sky_ambient, volume_.empty() ? nullptr : &volume_, pool);
  path_streaks_.Build(particles_, sky_ambient, pool);
}

void RealtimeFrameData::SetSplatCamera(const Camera& camera) {
  const Pose X_OW = camera.X_WO().inverse();
  const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> R_OW = X_OW.linear().cast<float>();
  std::copy(R_OW.data(), R_OW.data() + 9, splat_camera_.R_OW);
  splat_camera_.p_OW = Float3Of(X_OW.translation().cast<float>());
  const CameraIntrinsics& k = camera.intrinsics();
  splat_camera_.fx = k.fx;
  splat_camera_.fy = k.fy;
  splat_camera_.cx = k.cx;
  splat_camera_.cy = k.cy;
  // a moving camera: every row's pose in double, in which the splat takes the row's columns
  // (StreakSplatView::poses) and, without lens distortion, as the CPU's rays take it
  // (SplatRay), and the rows' motion, which widens the streaks' boxes (as BuildPixelHits)
  splat_camera_.rows = nullptr;
  splat_camera_.poses = nullptr;
  splat_camera_.motion = StreakMotionOf(camera);
  if (camera.motion().moving()) {
    StreakRowPoses(camera, &splat_rows_);
    splat_camera_.poses = splat_rows_.data();
    if (!k.has_distortion()) splat_camera_.rows = splat_rows_.data();
  }
}

void RealtimeFrameData::PoseWorld(const WorldSnapshot& snapshot, ThreadPool* pool,
                                  const EffectsFrame* effects) {
  // the lighting effects as the CPU backend applies them (EmbreeRenderer::Render, MediaFrame):
  // an empty frame is none.
  const EffectsFrame* fx = effects != nullptr && !effects->empty() ? effects : nullptr;
  media_ready_ = false;  // PrepareMedia builds the frame's media for its camera
  media_scene_built_ = false;
  lights_.Update(snapshot, fx);
  frame_sky_ = &effects_sky_.Update(scene_.sky, sky_, fx);
  wetness_ = SurfaceWetnessOf(fx);
  // only the geoms of bodies that moved since the last call (the others keep their bits)
  const size_t bodies = snapshot.X_WB.size();
  const bool all = posed_X_WB_.size() != bodies;
  body_moved_.assign(bodies, 1);
  for (size_t b = 0; !all && b < bodies; ++b)
    body_moved_[b] = snapshot.X_WB[b].matrix() != posed_X_WB_[b].matrix() ? 1 : 0;
  posed_X_WB_ = snapshot.X_WB;
  for (size_t g = 0; g < scene_.geoms.size(); ++g) {
    const Geom& geom = scene_.geoms[g];
    if (body_moved_[geom.body] == 0) continue;
    const Pose X_GW = (snapshot.X_WB[geom.body] * geom.X_BG).inverse();
    float* m = geoms_[g].X_GW;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[4 * r + c] = static_cast<float>(X_GW.linear()(r, c));
      m[4 * r + 3] = static_cast<float>(X_GW.translation()(r));
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  volume_.Update(scene_, snapshot, *frame_sky_, pool);
  volume_update_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void RealtimeFrameData::SetCamera(const PinholeCamera& camera, float spread_rad, int camera_index,
                                  int64_t frame_index, const Eigen::Vector3f& white_balance_gains) {
  camera_ = camera;
  white_balance_gains_ = white_balance_gains;
  spread_rad_ = spread_rad;
  frame_key_ = FrameKey(camera_index, frame_index);
}

uint64_t RealtimeFrameData::FrameKey(int camera_index, int64_t frame_index) const {
  // FrameContext::FrameKey() (render/cpu/integrator.h).
  return HashKeys(HashKeys(settings_.seed, static_cast<uint64_t>(camera_index)),
                  static_cast<uint64_t>(frame_index));
}

int RealtimeFrameData::CheckRows(const char* what, int64_t n, int row0, int row1) const {
  const int W = camera_.width, H = camera_.height;
  if (n != static_cast<int64_t>(W) * H)
    throw Error(std::string("RealtimeFrameData::") + what + ": " + std::to_string(n) +
                " pixels, the camera has " + std::to_string(static_cast<int64_t>(W) * H));
  if (row1 < 0 || row1 > H) row1 = H;
  if (row0 < 0 || row0 % 2 != 0 || (row1 % 2 != 0 && row1 != H))
    throw Error(std::string("RealtimeFrameData::") + what + ": rows [" + std::to_string(row0) +
                ", " + std::to_string(row1) +
                "): the bounds must be even (2x2 quads) or the last row + 1");
  return row1;
}

void RealtimeFrameData::SkyQuadRow(const PixelGeometry* geometry, Float3* out, int q,
                                   int row1) const {
  const SkyModelPod& sky = frame_sky_->pod();
  const SkyVolumePod volume = volume_.pod();
  for (int u0 = 0; u0 < camera_.width; u0 += 2)
    QuadSkyTerms(sky, volume, geometry, camera_.width, row1, u0, 2 * q, out);
}

void RealtimeFrameData::MirrorSkyRow(const PixelGeometry* mirror, Float3* out, int v) const {
  const SkyModelPod& sky = frame_sky_->pod();
  const SkyVolumePod volume = volume_.pod();
  const int W = camera_.width;
  for (int64_t i = static_cast<int64_t>(v) * W; i < static_cast<int64_t>(v + 1) * W; ++i)
    MirrorSkyTerm(sky, volume, mirror[i], &out[i]);
}

void RealtimeFrameData::SkyTerms(const PixelGeometry* geometry, int64_t n, Float3* out,
                                 ThreadPool* pool, int row0, int row1) const {
  FrameSkyTerms(geometry, nullptr, n, out, nullptr, pool, row0, row1);
}

void RealtimeFrameData::MirrorSkyTerms(const PixelGeometry* mirror, int64_t n, Float3* out,
                                       ThreadPool* pool, int row0, int row1) const {
  row1 = CheckRows("MirrorSkyTerms", n, row0, row1);
  if (row1 <= row0) return;
  ParallelForOrSerial(pool, row1 - row0,
                      [&](int64_t r) { MirrorSkyRow(mirror, out, row0 + static_cast<int>(r)); });
}

void RealtimeFrameData::FrameSkyTerms(const PixelGeometry* geometry, const PixelGeometry* mirror,
                                      int64_t n, Float3* sky, Float3* mirror_sky, ThreadPool* pool,
                                      int row0, int row1) const {
  row1 = CheckRows("SkyTerms", n, row0, row1);
  const int quad_row0 = row0 / 2, quad_rows = (row1 + 1) / 2 - quad_row0;
  if (quad_rows <= 0) return;
  ParallelForOrSerial(pool, quad_rows, [&](int64_t r) {
    const int q = quad_row0 + static_cast<int>(r);
    SkyQuadRow(geometry, sky, q, row1);
    if (mirror == nullptr) return;
    for (int v = 2 * q; v < 2 * q + 2 && v < row1; ++v) MirrorSkyRow(mirror, mirror_sky, v);
  });
}

RealtimeFrameView RealtimeFrameData::View(const SceneView& scene, const Float3* sky) const {
  RealtimeFrameView f;
  f.scene = scene;
  f.camera = camera_;
  f.spread_rad = spread_rad_;
  f.materials = materials_.data();
  f.default_material = default_material_;
  f.geoms = geoms_.data();
  f.textures = textures_.data();
  f.texels = texels_.data();
  f.srgb_decode = SrgbDecodeTable();
  f.lights = lights_.pods().data();
  f.num_lights = lights_.size();
  f.max_anisotropy = settings_.max_anisotropy < 1 ? 1 : settings_.max_anisotropy;
  f.frame_key = frame_key_;
  f.sky_term = sky;
  f.sky = frame_sky_->pod();
  f.wetness = wetness_;
  f.volume = volume_.pod();
  f.any_mirror = any_mirror_ ? 1 : 0;
  StreakFields(&f);
  if (media_ready_) {
    f.has_media = 1;
    f.media = media_view_;
    f.media_build = realtime_media_.device_build();
  }
  return f;
}

const PathStreakBuild& RealtimeFrameData::splat_streaks() const {
  if (device_list_.bound > 0 && !device_pods_copied_ && device_list_.download) {
    std::vector<StreakPod> pods;
    device_list_.download(&pods);
    splat_streaks_.SwapPods(&pods);
    device_pods_copied_ = true;
  }
  return splat_streaks_;
}

void RealtimeFrameData::StreakFields(RealtimeFrameView* f) const {
  f->splat = StreakSplatView();
  if (device_list_.bound > 0) {
    // the device culling's streaks in place: a bound here, their count on the device
    f->splat = splat_camera_;
    f->splat.streaks = splat_streaks_.ViewOver(device_list_.streaks, device_list_.bound);
    f->splat.count = device_list_.count;
    return;
  }
  if (!splat_streaks_.empty()) {
    f->splat = splat_camera_;
    f->splat.streaks = splat_streaks_.View();
  }
}

double RealtimeFrameData::Ev100(const std::vector<double>& row_sums, int64_t pixels,
                                float exposure[3]) const {
  // the rows in row order: independent of the launch (film_math.h, shared with the device)
  const float gains[3] = {white_balance_gains_[0], white_balance_gains_[1],
                          white_balance_gains_[2]};
  return FrameExposure(film_.exposure_pod(), row_sums.data(), static_cast<int>(row_sums.size()),
                       pixels, kMinLuminance, gains, exposure);
}

}  // namespace penumbra::cuda
