#include "penumbra/physics/scene_extractor.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

namespace penumbra {
namespace {

std::string Name(const mjModel* m, int type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? std::string(n) : std::string();
}

std::string RgbaLabel(const float rgba[4]) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), "rgba(%g %g %g %g)", rgba[0], rgba[1], rgba[2], rgba[3]);
  return buf;
}

GeomShape ShapeFromMujoco(int type) {
  switch (type) {
    case mjGEOM_PLANE:
      return GeomShape::kPlane;
    case mjGEOM_HFIELD:
      return GeomShape::kHeightField;
    case mjGEOM_SPHERE:
      return GeomShape::kSphere;
    case mjGEOM_CAPSULE:
      return GeomShape::kCapsule;
    case mjGEOM_ELLIPSOID:
      return GeomShape::kEllipsoid;
    case mjGEOM_CYLINDER:
      return GeomShape::kCylinder;
    case mjGEOM_BOX:
      return GeomShape::kBox;
    case mjGEOM_MESH:
      return GeomShape::kMesh;
    default:
      return GeomShape::kBox;
  }
}

// the material's base-colour texture: MJCF's `texture=` sets the rgb role, glTF-style
// materials the rgba one
int BaseColorTexture(const mjModel* m, int mat) {
  const int* ids = m->mat_texid + mjNTEXROLE * mat;
  return ids[mjTEXROLE_RGB] >= 0 ? ids[mjTEXROLE_RGB] : ids[mjTEXROLE_RGBA];
}

bool IsDefaultRgba(const float* rgba) {
  return rgba[0] == 0.5f && rgba[1] == 0.5f && rgba[2] == 0.5f && rgba[3] == 1.0f;
}

Light LightFromMjcf(const mjModel* m, const mjData* d, int i) {
  Light l;
  l.name = Name(m, mjOBJ_LIGHT, i);
  l.body = m->light_bodyid[i];
  l.mjcf_light = i;
  l.position_B =
      Eigen::Vector3d(m->light_pos[3 * i], m->light_pos[3 * i + 1], m->light_pos[3 * i + 2]);
  Eigen::Vector3d dir(m->light_dir[3 * i], m->light_dir[3 * i + 1], m->light_dir[3 * i + 2]);
  l.direction_B = dir.norm() > 0 ? dir.normalized() : Eigen::Vector3d(0, 0, -1);
  const float* diffuse = m->light_diffuse + 3 * i;
  const float peak = std::max({diffuse[0], diffuse[1], diffuse[2], 0.0f});
  l.color = peak > 0 ? Eigen::Vector3f(diffuse[0], diffuse[1], diffuse[2]) / peak
                     : Eigen::Vector3f(1, 1, 1);
  l.cast_shadow = m->light_castshadow[i] != 0;
  l.active = m->light_active[i] != 0;
  if (m->light_type[i] == mjLIGHT_DIRECTIONAL) {
    l.type = Light::Type::kDirectional;
    l.intensity = static_cast<float>(kMjcfDirectionalLux * peak);
    return l;
  }
  // distance to the model centre at qpos0 sizes the intensity (see header)
  const Eigen::Vector3d p_W(d->light_xpos[3 * i], d->light_xpos[3 * i + 1],
                            d->light_xpos[3 * i + 2]);
  const Eigen::Vector3d c_W(m->stat.center[0], m->stat.center[1], m->stat.center[2]);
  const double r = std::max((p_W - c_W).norm(), kMjcfLampMinDistance);
  l.intensity = static_cast<float>(kMjcfDirectionalLux * peak * r * r);
  const double cutoff = m->light_cutoff[i];
  if (m->light_type[i] != mjLIGHT_SPOT || !(cutoff < 90.0)) {
    l.type = Light::Type::kPoint;
    return l;
  }
  l.type = Light::Type::kSpot;
  l.spot_outer_deg = static_cast<float>(std::max(cutoff, 0.0));
  const double exponent = std::max<double>(m->light_exponent[i], 0.0);
  double half_deg = 90.0;
  if (exponent > 0) half_deg = std::acos(std::pow(0.5, 1.0 / exponent)) * 180.0 / M_PI;
  l.spot_inner_deg = static_cast<float>(std::min(half_deg, static_cast<double>(l.spot_outer_deg)));
  return l;
}

}  // namespace

Material MaterialFromMjcf(const std::string& name, const float rgba[4], float emission,
                          float specular, float shininess, float reflectance, int texture,
                          const float texrepeat[2], bool texuniform) {
  Material mat;
  mat.name = name;
  mat.base_color =
      Eigen::Vector3f(SrgbToLinear(rgba[0]), SrgbToLinear(rgba[1]), SrgbToLinear(rgba[2]));
  mat.alpha = std::clamp(rgba[3], 0.0f, 1.0f);
  mat.roughness = std::clamp(1.0f - shininess, kMjcfMinRoughness, 1.0f);
  mat.reflectance = std::clamp(reflectance, 0.0f, 1.0f);
  mat.metallic = 0.0f;
  mat.specular = std::clamp(specular, 0.0f, 1.0f);
  mat.emission =
      mat.base_color * static_cast<float>(std::max(emission, 0.0f) * kMjcfEmissionLuminance);
  mat.texture = texture;
  mat.texrepeat = Eigen::Vector2f(texrepeat[0], texrepeat[1]);
  mat.texuniform = texuniform;
  return mat;
}

SceneDescription ExtractScene(const mjModel* m, const mjData* d) {
  SceneDescription s;

  // bodies
  s.bodies.resize(m->nbody);
  for (int b = 0; b < m->nbody; ++b) {
    Body& body = s.bodies[b];
    body.name = Name(m, mjOBJ_BODY, b);
    body.parent = b == 0 ? -1 : m->body_parentid[b];
    body.is_static = m->body_weldid[b] == 0 && m->body_mocapid[b] < 0;
  }

  // meshes
  s.meshes.resize(m->nmesh);
  for (int i = 0; i < m->nmesh; ++i) {
    TriangleMesh& mesh = s.meshes[i];
    mesh.name = Name(m, mjOBJ_MESH, i);
    // MuJoCo indexes positions, normals and texcoords separately per face corner; the renderer
    // takes one index per corner, so each distinct (position, normal, texcoord) becomes a vertex
    const int v0 = m->mesh_vertadr[i], n0 = m->mesh_normaladr[i], t0 = m->mesh_texcoordadr[i];
    const bool textured = t0 >= 0 && m->mesh_texcoordnum[i] > 0;
    const int f0 = m->mesh_faceadr[i], nf = m->mesh_facenum[i];
    std::map<std::tuple<int, int, int>, int> corner_vertex;
    mesh.faces.reserve(nf);
    for (int f = f0; f < f0 + nf; ++f) {
      int corner[3];
      for (int k = 0; k < 3; ++k) {
        const int v = m->mesh_face[3 * f + k], n = m->mesh_facenormal[3 * f + k];
        const int t = textured ? m->mesh_facetexcoord[3 * f + k] : -1;
        auto [it, added] =
            corner_vertex.emplace(std::make_tuple(v, n, t), static_cast<int>(mesh.vertices.size()));
        if (added) {
          const float* p = m->mesh_vert + 3 * (v0 + v);
          const float* nn = m->mesh_normal + 3 * (n0 + n);
          mesh.vertices.emplace_back(p[0], p[1], p[2]);
          mesh.normals.emplace_back(nn[0], nn[1], nn[2]);
          if (textured) {
            const float* uv = m->mesh_texcoord + 2 * (t0 + t);
            mesh.texcoords.emplace_back(uv[0], uv[1]);
          }
        }
        corner[k] = it->second;
      }
      mesh.faces.emplace_back(corner[0], corner[1], corner[2]);
    }
  }

  // height fields
  s.hfields.resize(m->nhfield);
  for (int i = 0; i < m->nhfield; ++i) {
    HeightField& h = s.hfields[i];
    h.name = Name(m, mjOBJ_HFIELD, i);
    h.rows = m->hfield_nrow[i];
    h.cols = m->hfield_ncol[i];
    const float* data = m->hfield_data + m->hfield_adr[i];
    h.elevation.assign(data, data + static_cast<size_t>(h.rows) * h.cols);
    h.size_x = m->hfield_size[4 * i];
    h.size_y = m->hfield_size[4 * i + 1];
    h.size_z = m->hfield_size[4 * i + 2];
    h.size_base = m->hfield_size[4 * i + 3];
  }

  // textures: one shared image (with mip levels) per distinct set of pixels
  s.textures.resize(m->ntex);
  std::vector<TextureSource> sources(m->ntex);
  std::vector<std::vector<uint8_t>> rgb(m->ntex);  // 1- and 4-channel textures as RGB
  for (int i = 0; i < m->ntex; ++i) {
    Texture& t = s.textures[i];
    t.name = Name(m, mjOBJ_TEXTURE, i);
    t.kind = m->tex_type[i] == mjTEXTURE_2D     ? Texture::Kind::k2D
             : m->tex_type[i] == mjTEXTURE_CUBE ? Texture::Kind::kCube
                                                : Texture::Kind::kSkybox;
    TextureSource& src = sources[i];
    src.width = m->tex_width[i];
    src.height = m->tex_height[i];
    src.faces = t.kind == Texture::Kind::k2D ? 1 : 6;
    src.size = static_cast<size_t>(src.width) * src.height * 3;
    const int channels = m->tex_nchannel[i];
    const uint8_t* data = m->tex_data + m->tex_adr[i];
    if (channels == 3) {
      src.rgb_srgb = data;
    } else {
      rgb[i].resize(src.size);
      for (size_t p = 0; p < src.size / 3; ++p)
        for (int c = 0; c < 3; ++c)
          rgb[i][3 * p + c] = data[p * channels + std::min(c, channels - 1)];
      src.rgb_srgb = rgb[i].data();
    }
  }
  TextureStore store;
  const std::vector<std::shared_ptr<const TextureImage>> images = store.AddAll(sources);
  for (int i = 0; i < m->ntex; ++i) s.textures[i].image = images[i];

  // MJCF materials keep their ids
  s.materials.reserve(m->nmat);
  for (int i = 0; i < m->nmat; ++i) {
    s.materials.push_back(MaterialFromMjcf(
        Name(m, mjOBJ_MATERIAL, i), m->mat_rgba + 4 * i, m->mat_emission[i], m->mat_specular[i],
        m->mat_shininess[i], m->mat_reflectance[i], BaseColorTexture(m, i),
        m->mat_texrepeat + 2 * i, m->mat_texuniform[i] != 0));
  }

  // geoms (and tendons), with generated materials deduplicated by (material id, rgba)
  std::map<std::tuple<int, float, float, float, float>, int> generated;
  const auto material_of = [&](int mat, const float* rgba) {
    if (mat >= 0 && IsDefaultRgba(rgba)) return mat;
    const auto key = std::make_tuple(mat, rgba[0], rgba[1], rgba[2], rgba[3]);
    auto it = generated.find(key);
    if (it == generated.end()) {
      Material made;
      if (mat >= 0) {
        made = MaterialFromMjcf(s.materials[mat].name + "#" + RgbaLabel(rgba), rgba,
                                m->mat_emission[mat], m->mat_specular[mat], m->mat_shininess[mat],
                                m->mat_reflectance[mat], BaseColorTexture(m, mat),
                                m->mat_texrepeat + 2 * mat, m->mat_texuniform[mat] != 0);
      } else {
        // MuJoCo's material defaults: emission 0, specular 0.5, shininess 0.5, reflectance 0
        const float repeat[2] = {1, 1};
        made = MaterialFromMjcf(RgbaLabel(rgba), rgba, 0.0f, 0.5f, 0.5f, 0.0f, -1, repeat, false);
      }
      it = generated.emplace(key, static_cast<int>(s.materials.size())).first;
      s.materials.push_back(std::move(made));
    }
    return it->second;
  };
  s.geoms.resize(m->ngeom);
  for (int g = 0; g < m->ngeom; ++g) {
    Geom& geom = s.geoms[g];
    geom.name = Name(m, mjOBJ_GEOM, g);
    geom.id = g;
    geom.body = m->geom_bodyid[g];
    geom.shape = ShapeFromMujoco(m->geom_type[g]);
    geom.size =
        Eigen::Vector3d(m->geom_size[3 * g], m->geom_size[3 * g + 1], m->geom_size[3 * g + 2]);
    geom.X_BG = PoseFromPosQuat(m->geom_pos + 3 * g, m->geom_quat + 4 * g);
    geom.group = m->geom_group[g];
    if (geom.shape == GeomShape::kMesh) geom.mesh = m->geom_dataid[g];
    if (geom.shape == GeomShape::kHeightField) geom.hfield = m->geom_dataid[g];
    geom.material = material_of(m->geom_matid[g], m->geom_rgba + 4 * g);
  }

  // spatial tendons that MuJoCo shows (groups 0-2, a width, not transparent); fixed tendons
  // (joint wraps) have no path
  for (int t = 0; t < m->ntendon; ++t) {
    if (m->tendon_num[t] < 2 || m->wrap_type[m->tendon_adr[t]] == mjWRAP_JOINT) continue;
    if (m->tendon_group[t] > 2 || !(m->tendon_width[t] > 0)) continue;
    Tendon tendon;
    tendon.name = Name(m, mjOBJ_TENDON, t);
    tendon.id = t;
    tendon.width_m = m->tendon_width[t];
    tendon.material = material_of(m->tendon_matid[t], m->tendon_rgba + 4 * t);
    if (s.materials[tendon.material].alpha < 0.5f) continue;
    s.tendons.push_back(std::move(tendon));
  }

  // lights
  s.lights.reserve(m->nlight);
  for (int i = 0; i < m->nlight; ++i) s.lights.push_back(LightFromMjcf(m, d, i));

  // MJCF cameras: optical frame = MuJoCo camera frame rotated by X_mjcam_optical
  const Eigen::Matrix3d R_mjcam_optical = RotationMujocoCameraFromOptical();
  s.cameras.resize(m->ncam);
  for (int i = 0; i < m->ncam; ++i) {
    CameraSpec& c = s.cameras[i];
    c.name = Name(m, mjOBJ_CAMERA, i);
    if (c.name.empty()) c.name = "camera" + std::to_string(i);
    c.body = m->cam_bodyid[i];
    c.mjcf_camera = i;
    Pose X_B_mjcam = PoseFromPosQuat(m->cam_pos + 3 * i, m->cam_quat + 4 * i);
    c.X_BO = X_B_mjcam;
    c.X_BO.linear() = X_B_mjcam.linear() * R_mjcam_optical;
    c.intrinsics = CameraIntrinsics::FromFovy(640, 480, m->cam_fovy[i]);
  }

  s.center_W = Eigen::Vector3d(m->stat.center[0], m->stat.center[1], m->stat.center[2]);
  s.extent_m = m->stat.extent;
  return s;
}

}  // namespace penumbra
