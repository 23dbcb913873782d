#include "penumbra/render/cuda/realtime_frame.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/bvh_ray_query.h"
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

RealtimeSky RealtimeFrameData::SkyData() const {
  RealtimeSky d;
  d.sky = frame_sky_->pod();
  d.volume = volume_.pod();
  d.num_probes = volume_.num_probes();
  return d;
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
  f->streaks = nullptr;
  f->num_streaks = 0;
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

void BuildMediaVolumesOnHost(RealtimeFrameView* f, ThreadPool* pool, MediaVolumeArrays* out) {
  if (f->has_media == 0) return;
  const MediaVolumesToBuild& b = f->media_build;
  RealtimeMediaView& m = f->media;
  if (b.grids != 0 && m.num_grids > 0) {
    const GridLightPod& last = m.grids[m.num_grids - 1];
    out->grids.T.assign(last.offset + static_cast<size_t>(m.num_grid_lights) * GridLightCells(last),
                        0.0f);
    const int64_t cells = GridSourceOffset(m.grids, m.num_grids);
    out->grids.source.assign(cells, Float3{});
    ParallelForOrSerial(pool, cells, [&](int64_t c) {
      MediaGridLightCell(*f, c, out->grids.T.data(), out->grids.source.data());
    });
    m.grid_light_T = out->grids.T.data();
    const int columns = m.grid_nx * m.grid_ny;
    out->grids.t0.assign(columns, 0.0f);
    out->grids.t1.assign(columns, 0.0f);
    out->grids.slices_per_m.assign(columns, 0.0f);
    out->grids.records.assign(static_cast<size_t>(columns) * (kFroxelSlices + 1),
                              GridFroxelRecord<Rgb4>{});
    ParallelForOrSerial(pool, columns, [&](int64_t c) {
      MediaGridFroxelColumn(*f, static_cast<int>(c), out->grids.source.data(), out->grids.t0.data(),
                            out->grids.t1.data(), out->grids.slices_per_m.data(),
                            out->grids.records.data());
    });
    if (columns > 0) {
      m.grid_t0 = out->grids.t0.data();
      m.grid_t1 = out->grids.t1.data();
      m.grid_slices_per_m = out->grids.slices_per_m.data();
      m.grid_records = out->grids.records.data();
    }
  }
  float* vis = nullptr;
  if (b.light_volume != 0) {
    const int64_t cells = LightVolumeCells(m.light_volume);
    const size_t values = static_cast<size_t>(cells) * m.light_volume.stride;
    out->trans.assign(values, 0.0f);
    out->vis.assign(b.with_visibility != 0 ? values : 0, 0.0f);
    if (b.with_visibility != 0) vis = out->vis.data();
    ParallelForOrSerial(pool, cells,
                        [&](int64_t c) { MediaLightVolumeCell(*f, c, out->trans.data(), vis); });
    m.light_trans = out->trans.data();
  }
  if (b.fog != 0) {
    const int columns = m.fog_nx * m.fog_ny;
    out->fog.assign(static_cast<size_t>(columns) * (kFogFroxelSlices + 1), Rgb4{});
    out->inv_log_far.assign(columns, 0.0f);
    ParallelForOrSerial(pool, columns, [&](int64_t c) {
      MediaFogColumn(*f, static_cast<int>(c), vis, out->fog.data(), out->inv_log_far.data());
    });
    m.fog_S = out->fog.data();
    m.fog_inv_log_far = out->inv_log_far.data();
  }
}

namespace {

// ShadeQueuedLights' queue on the host (RenderRealtimeOnHost's queued_shadows): light j's ray
// of pixel `pixel` at rays[j n + pixel].
struct HostShadowPush {
  QueuedShadowRay* rays;
  int64_t pixel, n;
  void Push(int j, const TraceRay& r) const {
    rays[j * n + pixel] = QueueEntryOf(r, static_cast<uint32_t>(pixel), j);
  }
};

}  // namespace

namespace {

// the shared visibility of frame f by shadow tiles, as the kernels' blocks
// (VisibilityRaysWarpKernel, VisibilityTileKernel) do it in shared memory: per tile, its
// surfaces and every light's verdicts as bit rows copied for the penumbra rays
// (TileWindowSurfaces, RowLightVerdicts, SharedVisibilityRaysOf), then light after light its
// verdicts, ray counts (packed once, ShadowWindowCounts) and fractions (SharedWindowFraction)
// for the resolve (SharedLampFraction, AddSharedVisibility).
void TiledSharedVisibility(const RealtimeFrameView& f, ThreadPool* pool, Float3* radiance) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int tiles_x = (W + kShadowTileSize - 1) / kShadowTileSize;
  const int tiles_y = (H + kShadowTileSize - 1) / kShadowTileSize;
  constexpr int kTile = kShadowTileSize * kShadowTileSize;
  // a tile's pixels (tile-local index t = y kShadowTileSize + x) in the image, -1 outside it
  const auto tile_pixel = [&](int64_t tile, int t) -> int64_t {
    const int u = static_cast<int>(tile % tiles_x) * kShadowTileSize + t % kShadowTileSize;
    const int v = static_cast<int>(tile / tiles_x) * kShadowTileSize + t / kShadowTileSize;
    return u < W && v < H ? static_cast<int64_t>(v) * W + u : -1;
  };
  ParallelForOrSerial(pool, int64_t{tiles_x} * tiles_y, [&](int64_t tile) {
    // the tile's surfaces (TileWindowSurfaces) and every light's verdicts as bit rows
    // (ShadowVerdictBits), as the kernels' shared memory keeps them
    std::vector<uint32_t> rows(static_cast<size_t>(kShadowVerdictRows) * std::max(f.num_lights, 1));
    int32_t key[kTile];
    float ng[3][kTile], p[3][kTile];
    for (int t = 0; t < kTile; ++t) {
      const int64_t i = tile_pixel(tile, t);
      key[t] = TileWindowSurfaces::kNoWindowSurface;
      ng[0][t] = ng[1][t] = ng[2][t] = p[0][t] = p[1][t] = p[2][t] = 0;
      if (i < 0) continue;
      const PixelGeometry& g = f.geometry[i];
      key[t] = TileWindowSurfaces::KeyOf(g);
      ng[0][t] = g.ng.x, ng[1][t] = g.ng.y, ng[2][t] = g.ng.z;
      p[0][t] = g.p_or_d.x, p[1][t] = g.p_or_d.y, p[2][t] = g.p_or_d.z;
      for (int j = 0; j < f.num_lights; ++j)
        rows[j * kShadowVerdictRows + kShadowWindowRadius + t / kShadowTileSize] |=
            ShadowVerdictBits(t % kShadowTileSize, f.area_vis[j * n + i]);
    }
    const TileWindowSurfaces surfaces{key, ng[0], ng[1], ng[2], p[0], p[1], p[2]};
    for (int t = 0; t < kTile; ++t) {
      const int64_t i = tile_pixel(tile, t);
      if (i >= 0)
        SharedVisibilityRaysOf(
            f, static_cast<int>(i % W), static_cast<int>(i / W), surfaces, t, kShadowTileSize,
            RowLightVerdicts{rows.data(), t % kShadowTileSize, t / kShadowTileSize});
    }
  });
  ParallelForOrSerial(pool, int64_t{tiles_x} * tiles_y, [&](int64_t tile) {
    int8_t vis[kTile];
    uint32_t counts[kTile];
    float fraction[kTile];
    const VisibilityTaps taps{vis, nullptr, nullptr, fraction, kShadowTileSize, counts};
    for (int j = 0; j < f.num_lights; ++j) {
      if (!IsExtendedLightPod(f.lights[j])) continue;
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        vis[t] = i < 0 ? int8_t{-1} : f.area_vis[j * n + i];
        counts[t] = vis[t] < 0 ? 0u
                               : ShadowWindowCounts(vis[t], f.area_visible[j * n + i],
                                                    f.area_rays[j * n + i]);
      }
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        if (vis[t] >= 0)
          fraction[t] = SharedWindowFraction(taps, t, f.window[i], f.area_own[j * n + i] != 0);
      }
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        if (vis[t] < 0) continue;
        const int u = static_cast<int>(i % W), v = static_cast<int>(i / W);
        const ShadowTile st = ShadowTileOf(u, v, W, H);
        const bool lamp = f.lights[j].kind != LightKind::kDirectional && f.area_own[j * n + i] == 0;
        const float V = SharedLampFraction(taps, t, f.window[i], lamp, u - st.x0, v - st.y0, st);
        radiance[i] = AddSharedVisibility(radiance[i], V, f.area_c[j * n + i]);
      }
    }
  });
}

}  // namespace

void RenderRealtimeOnHost(const RealtimeFrameData& data, const BvhScene& bvh, ThreadPool* pool,
                          RenderedFrame* out, bool stored_surface, bool strided_terms,
                          bool queued_shadows, bool tiled_visibility) {
  const PinholeCamera& c = data.camera();
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const SceneView scene = bvh.view();
  const RealtimeFrameView geo_view = data.View(scene, nullptr);
  std::vector<PixelGeometry> geometry(n);
  std::vector<SurfaceTerms> surfaces(stored_surface ? n : 0);
  if (out->depth_m.width != W || out->depth_m.height != H || out->depth_m.channels != 1)
    out->depth_m = ImageF(W, H, 1);
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    for (int u = 0; u < W; ++u) {
      const int64_t i = v * W + u;
      geometry[i] = PrimaryGeometry(geo_view, u, static_cast<int>(v), &out->depth_m.data[i],
                                    nullptr, stored_surface ? &surfaces[i] : nullptr);
    }
  });
  // the mirror layer's rays, traced from the primary geometry (on the GPU their geometry
  // makes the round trip to the host with the primary geometry's)
  std::vector<PixelGeometry> mirror_geometry;
  std::vector<TraceHit> mirror_hits;
  std::vector<Float3> mirror_sky, mirror_radiance;
  if (data.any_mirror()) {
    mirror_geometry.resize(n);
    mirror_hits.resize(n);
    mirror_sky.resize(n);
    mirror_radiance.resize(n);
    RealtimeFrameView mirror_view = geo_view;
    mirror_view.geometry = geometry.data();
    mirror_view.mirror_geometry = mirror_geometry.data();
    mirror_view.mirror_hits = mirror_hits.data();
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) TraceMirrorRay(mirror_view, u, static_cast<int>(v));
    });
    data.MirrorSkyTerms(mirror_geometry.data(), n, mirror_sky.data(), pool);
  }
  std::vector<Float3> sky(n);
  data.SkyTerms(geometry.data(), n, sky.data(), pool);
  RealtimeFrameView f = data.View(scene, sky.data());
  // the frame's own splat of the particle streaks, as the device's kernels: every streak's
  // rows (one streak at a time: a plain minimum per pixel), then the shading of every pixel
  // that has a streak
  std::vector<unsigned long long> splat_nearest;
  std::vector<StreakPixel> splat_pixels;
  if (f.splat.streaks.num > 0) {
    splat_nearest.assign(n, kNoStreakKey);
    splat_pixels.resize(n);
    f.splat.nearest = splat_nearest.data();
    f.splat.pixels = splat_pixels.data();
    const int32_t num = SplatStreakCount(f.splat);
    for (int k = 0; k < num; ++k) {
      const StreakProjection p = SplatProjection(f, f.splat.streaks.streaks[k]);
      for (int v = p.v0; v <= p.v1 && !p.empty(); ++v) SplatStreakRow(f, k, p, v);
    }
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) ShadeSplatPixel(f, u, static_cast<int>(v));
    });
  }
  // the media volumes the frame builds itself, as the device's kernels (before the shading)
  MediaVolumeArrays media_volumes;
  BuildMediaVolumesOnHost(&f, pool, &media_volumes);
  f.mirror_geometry = mirror_geometry.data();
  f.mirror_hits = mirror_hits.data();
  f.mirror_sky = mirror_sky.data();
  f.mirror_radiance = mirror_radiance.data();
  // the shared visibility's buffers (RealtimeFrameView), per pixel and per light and pixel.
  const size_t nl = static_cast<size_t>(n) * static_cast<size_t>(f.num_lights);
  std::vector<uint32_t> window(n);
  std::vector<float> total(n);
  std::vector<Float3> area_c(nl);
  std::vector<int8_t> area_vis(nl);
  std::vector<float> area_visible(nl), area_rays(nl), area_fraction(nl);
  std::vector<uint8_t> area_own(nl);
  f.geometry = geometry.data();
  f.window = window.data();
  f.total = total.data();
  f.area_c = area_c.data();
  f.area_vis = area_vis.data();
  f.area_visible = area_visible.data();
  f.area_rays = area_rays.data();
  f.area_own = area_own.data();
  f.area_fraction = area_fraction.data();
  std::vector<Float3> radiance(n);
  const int term_lights = std::min(std::max(f.num_lights, 0), kShadeCachedLights);
  // queued_shadows: the kernels' three passes (ShadeQueuedKernel, TraceQueuedKernel,
  // SumQueuedKernel), the rays at [light][pixel] in place of the device's queue
  std::vector<QueuedShadowRay> queued_rays;
  std::vector<QueuedLightMasks> queued_masks;
  std::vector<uint32_t> queued_occluded;
  if (stored_surface && queued_shadows && f.num_lights <= kMaxQueuedShadowLights) {
    queued_rays.resize(nl);
    queued_masks.resize(n);
    queued_occluded.assign(n, 0);
  }
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    // strided_terms: the row's pixels share one array, interleaved as a block's threads
    std::vector<float> row_terms;
    if (strided_terms) row_terms.resize(StridedLightTerms::kLightTermFloats * term_lights * W);
    for (int u = 0; u < W; ++u) {
      const int64_t i = v * W + u;
      if (!queued_masks.empty()) {
        const HostShadowPush push{queued_rays.data(), i, n};
        LocalLightTerms terms;
        radiance[i] = ShadeQueuedStored<true>(f, u, static_cast<int>(v), geometry[i], surfaces[i],
                                              terms, push, &queued_masks[i]);
      } else if (stored_surface && strided_terms) {
        StridedLightTerms terms;
        terms.at = row_terms.data() + u;
        terms.stride = W;
        terms.lights = term_lights;
        radiance[i] =
            ShadeRealtimeStored(f, u, static_cast<int>(v), geometry[i], surfaces[i], terms);
      } else {
        radiance[i] = stored_surface
                          ? ShadeRealtimeStored(f, u, static_cast<int>(v), geometry[i], surfaces[i])
                          : ShadeRealtimePixel(f, u, static_cast<int>(v));
      }
    }
  });
  if (!queued_masks.empty()) {
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int64_t i = v * W; i < (v + 1) * W; ++i)
        for (uint32_t b = queued_masks[i].traced; b != 0; b &= b - 1) {
          const QueuedShadowRay& e = queued_rays[LowestSetBit(b) * n + i];
          if (TraceOccluded(f.scene, QueuedRay(e)))
            queued_occluded[i] |= 1u << (e.key % kMaxQueuedShadowLights);
        }
    });
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int64_t i = v * W; i < (v + 1) * W; ++i)
        radiance[i] = SumQueuedLights(f, i, n, radiance[i], queued_masks[i], queued_occluded[i]);
    });
  }
  if (tiled_visibility) {
    TiledSharedVisibility(f, pool, radiance.data());
  } else {
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) SharedVisibilityRays(f, u, static_cast<int>(v));
    });
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) SharedVisibilityFraction(f, u, static_cast<int>(v));
    });
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) {
        Float3& L = radiance[v * W + u];
        L = SharedVisibilityResolve(f, u, static_cast<int>(v), L);
      }
    });
  }
  if (f.any_mirror != 0) {
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) ShadeMirrorHit(f, u, static_cast<int>(v));
    });
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int u = 0; u < W; ++u) {
        Float3& L = radiance[v * W + u];
        L = ApplyMirrorLayer(f, u, static_cast<int>(v), L);
      }
    });
  }
  // the media (and the streaks seen through them) over the final radiance, per 2x2 quad, as
  // MediaViewKernel
  if (f.has_media != 0) {
    ParallelForOrSerial(pool, (H + 1) / 2, [&](int64_t q) {
      for (int u0 = 0; u0 < W; u0 += 2)
        MediaViewQuad(f, u0, 2 * static_cast<int>(q), out->depth_m.data.data(), radiance.data());
    });
  }
  // the particle streaks over the final radiance, as StreakSplatApplyKernel (with media:
  // MediaViewQuad)
  for (int64_t i = 0; f.has_media == 0 && f.splat.streaks.num > 0 && i < n; ++i) {
    StreakPixel s;
    if (PixelStreakOf(f, i, &s)) radiance[i] = ApplyStreak(s, out->depth_m.data[i], radiance[i]);
  }
  std::vector<double> rows(H);
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    rows[v] = RowLogLuminance(radiance.data(), W, static_cast<int>(v), kMinLuminance);
  });
  float exposure[3];
  out->ev100 = data.Ev100(rows, n, exposure);
  if (out->radiance.width != W || out->radiance.height != H || out->radiance.channels != 3)
    out->radiance = ImageF(W, H, 3);
  if (out->rgb.width != W || out->rgb.height != H || out->rgb.channels != 3)
    out->rgb = ImageU8(W, H, 3);
  const bool filmic = data.film().filmic();
  const uint8_t* lut = data.film().oetf_lut().data();
  for (int64_t i = 0; i < n; ++i) {
    out->radiance.data[3 * i] = radiance[i].x;
    out->radiance.data[3 * i + 1] = radiance[i].y;
    out->radiance.data[3 * i + 2] = radiance[i].z;
    DevelopPixel(radiance[i], exposure, filmic, lut, &out->rgb.data[3 * i]);
  }
  out->rays = n;
  out->stopped = false;
}

}  // namespace penumbra::cuda
