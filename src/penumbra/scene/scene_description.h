#pragma once
// the renderer's view of a world: everything that does not change while the
// simulation runs (shapes, materials, textures, lights, sky, cameras), extracted
// once from the compiled model (physics/scene_extractor) and the world file.
// the renderer never sees mjModel/mjData; moving parts are posed each frame by a
// WorldSnapshot (scene/world_snapshot.h) through body indices.
//
// units: metres, seconds, radians unless a name says _deg. colours are linear
// Rec.709/sRGB primaries unless a name says srgb.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/scene/image_kind.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra {

/// shape of a geom; sizes follow MuJoCo's geom_size convention (see Geom::size).
enum class GeomShape {
  kPlane,
  kSphere,
  kCapsule,
  kEllipsoid,
  kCylinder,
  kBox,
  kMesh,
  kHeightField
};

/// a rigid body of the compiled model. index 0 is the world body.
struct Body {
  std::string name;
  int parent = -1;         ///< parent body index, -1 for the world body
  bool is_static = false;  ///< welded to the world (no joints up to the root, not mocap)
};

/// triangle mesh in its own frame (MuJoCo has already centred/aligned it).
struct TriangleMesh {
  std::string name;
  std::vector<Eigen::Vector3f> vertices;   ///< (N) positions, m
  std::vector<Eigen::Vector3f> normals;    ///< (N) unit vertex normals, or empty
  std::vector<Eigen::Vector2f> texcoords;  ///< (N) uv per vertex, or empty
  std::vector<Eigen::Vector3i> faces;      ///< (F) counter-clockwise vertex indices
};

/// elevation grid, MuJoCo hfield semantics: the grid spans [-size_x, size_x] x
/// [-size_y, size_y] in the geom frame, height = elevation * size_z (elevation in
/// [0, 1]), and a base box goes down to -size_base.
struct HeightField {
  std::string name;
  int rows = 0;                  ///< samples along y
  int cols = 0;                  ///< samples along x
  std::vector<float> elevation;  ///< (rows x cols) row-major, row 0 at y = -size_y
  double size_x = 1, size_y = 1, size_z = 1, size_base = 0;
};

/// texture image. 2d textures map through uv; cube and skybox textures hold six
/// square faces stacked vertically in MuJoCo's order (+x, -x, +y, -y, +z, -z).
struct Texture {
  enum class Kind { k2D, kCube, kSkybox };
  std::string name;
  Kind kind = Kind::k2D;
  /// the pixels (8-bit sRGB RGB) and their mip levels (scene/texture_image.h); immutable and
  /// shared: by copies of the scene, and by textures whose pixels are identical. cube and
  /// skybox textures have 6 faces, 2d textures 1.
  std::shared_ptr<const TextureImage> image;
};

/// physically based material (metallic-roughness, as glTF 2.0 / Burley 2012).
/// MJCF materials are mapped by physics/scene_extractor (see its docs); the world
/// file can override any field by material name.
struct Material {
  std::string name;
  Eigen::Vector3f base_color{0.8f, 0.8f, 0.8f};  ///< linear albedo in [0, 1]
  float alpha = 1.0f;                            ///< opacity; < 0.5 is treated as invisible
  float roughness = 0.5f;                        ///< perceptual roughness in [0, 1]
  float metallic = 0.0f;                         ///< [0, 1]
  float specular = 0.5f;                         ///< dielectric specular scale, 0.5 -> F0 = 0.04
  /// MuJoCo's `reflectance` in [0, 1]: weight of a mirror layer over the surface, on planes
  /// and the local +z faces of boxes only, as MuJoCo draws it (render/material/material_eval.h).
  float reflectance = 0.0f;
  Eigen::Vector3f emission{0, 0, 0};  ///< emitted radiance, cd/m^2 (nits) per channel
  int texture = -1;                   ///< index into SceneDescription::textures, -1 none
  Eigen::Vector2f texrepeat{1, 1};    ///< MJCF texrepeat for 2d mapping
  bool texuniform = false;            ///< MJCF texuniform: repeat per metre, not per face
};

/// one piece of geometry attached to a body.
struct Geom {
  std::string name;  ///< MJCF name ("" if unnamed)
  int id = -1;       ///< MuJoCo geom id; segmentation stores id + 1
  int body = 0;      ///< index into SceneDescription::bodies
  GeomShape shape = GeomShape::kBox;
  /// MuJoCo geom_size: plane (half x, half y, grid spacing; 0 half-size = infinite),
  /// sphere (r), capsule (r, half length), ellipsoid (rx, ry, rz), cylinder (r, half
  /// length), box (half x, half y, half z); unused for mesh and hfield.
  Eigen::Vector3d size{0, 0, 0};
  Pose X_BG = Pose::Identity();  ///< pose of the geom in its body frame
  int material = -1;  ///< index into SceneDescription::materials (always valid after extraction)
  int mesh = -1;      ///< index into meshes for kMesh
  int hfield = -1;    ///< index into hfields for kHeightField
  int group = 0;      ///< MJCF visibility group
  int semantic_class = 0;  ///< class id for semantic segmentation (0 = unlabelled)
};

/// a visible spatial tendon (MJCF <spatial>), drawn as MuJoCo draws it: a capsule of radius
/// width_m around each segment between consecutive wrap points, except segments that touch a
/// pulley. the wrap points move with the model: WorldSnapshot::tendon_paths carries them.
/// tendons in MJCF groups > 2 and tendons whose material has alpha < 0.5 are not listed.
struct Tendon {
  std::string name;    ///< MJCF name ("" if unnamed)
  int id = -1;         ///< MuJoCo tendon id
  double width_m = 0;  ///< capsule radius (MuJoCo tendon_width), m, > 0
  /// index into SceneDescription::materials: the tendon's MJCF material if it has one, else one
  /// made from its rgba (as geoms, physics/scene_extractor.h).
  int material = -1;
};

/// a light source. photometric units: the renderer works in luminance-like units
/// (cd/m^2 per channel), so illuminance is lux and intensity is candela.
struct Light {
  enum class Type { kDirectional, kPoint, kSpot };
  std::string name;
  Type type = Type::kPoint;
  int body = 0;         ///< body the light is fixed to (0 = world)
  int mjcf_light = -1;  ///< MuJoCo light id if from MJCF (posed by the snapshot), else -1
  Eigen::Vector3d position_B{0, 0, 0};  ///< position in the body frame (point, spot)
  Eigen::Vector3d direction_B{
      0, 0, -1};                   ///< unit direction light travels, body frame (directional, spot)
  Eigen::Vector3f color{1, 1, 1};  ///< linear rgb tint, max component 1
  /// directional: illuminance in lux on a surface facing the light;
  /// point / spot: luminous intensity in candela (on the axis for spot).
  float intensity = 1.0f;
  float spot_inner_deg = 30.0f;     ///< full intensity inside this half-angle (spot)
  float spot_outer_deg = 45.0f;     ///< zero intensity outside this half-angle (spot)
  float radius_m = 0.0f;            ///< emitter radius for soft shadows (point, spot); 0 = hard
  float angular_radius_deg = 0.0f;  ///< angular radius of a directional source (sun: 0.2665)
  bool cast_shadow = true;
  bool active = true;
};

/// sky seen by rays that leave the scene, and lighting the scene.
struct Sky {
  enum class Type { kUniform, kDaylight };
  Type type = Type::kUniform;
  /// uniform: radiance in cd/m^2 per channel.
  Eigen::Vector3f radiance{0.2f, 0.22f, 0.25f};
  /// daylight (Preetham, Shirley, Smits, "A practical analytic model for daylight",
  /// SIGGRAPH 1999): unit direction to the sun in the world frame and turbidity.
  Eigen::Vector3d sun_direction_W{0.3, 0.2, 0.93};
  float turbidity = 3.0f;
  /// daylight: zenith luminance scale, cd/m^2 (the model's Y at the zenith is scaled to this).
  float zenith_luminance = 8000.0f;
};

/// pinhole intrinsics in the OpenCV convention: pixel centres at integer
/// coordinates, (u, v) = (fx x/z + cx, fy y/z + cy) for a point (x, y, z) in the
/// optical frame (x right, y down, z forward).
struct CameraIntrinsics {
  int width = 640;
  int height = 480;
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< pixels
  /// Brown-Conrady lens distortion in OpenCV's order and names (plumb_bob: k1 k2 p1 p2 k3), on
  /// normalised coordinates (x, y) = (X/Z, Y/Z): r2 = x^2 + y^2,
  /// x_d = x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2),
  /// y_d = y (1 + k1 r2 + k2 r2^2 + k3 r2^3) + p1 (r2 + 2 y^2) + 2 p2 x y, then
  /// (u, v) = (fx x_d + cx, fy y_d + cy). all 0 = ideal pinhole (render/camera/camera.h traces it
  /// exactly).
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  /// true if any distortion coefficient is non-zero.
  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }

  /// square pixels, principal point at the image centre, vertical field of view fovy_deg.
  static CameraIntrinsics FromFovy(int width, int height, double fovy_deg);
  /// vertical field of view (deg) of these intrinsics, 2 atan(height / (2 fy)): FromFovy's
  /// inverse; infinite or NaN when fy is not positive.
  double fovy_deg() const;
};

/// which images a camera produces, one flag per ImageKind (scene/image_kind.h): rgb only unless
/// set otherwise.
struct CameraOutputs : ImageKindSet {
  CameraOutputs() : ImageKindSet{ImageKind::kRgb} {}
  CameraOutputs(std::initializer_list<ImageKind> kinds) : ImageKindSet(kinds) {}
  /// no image at all (the start of a list read from a file or flag).
  static CameraOutputs None() { return CameraOutputs({}); }
};

/// a camera: rigidly attached to a body, or an MJCF camera posed by the snapshot.
struct CameraSpec {
  std::string name;
  int body = 0;          ///< body it is fixed to (0 = world); ignored when mjcf_camera >= 0
  int mjcf_camera = -1;  ///< MuJoCo camera id (posed by WorldSnapshot::X_W_mjcam), else -1
  Pose X_BO =
      Pose::Identity();  ///< optical frame (OpenCV: x right, y down, z forward) in the body frame
  CameraIntrinsics intrinsics;
  double rate_hz = 10.0;            ///< frames per second of simulated time
  double exposure_time_sec = 0.01;  ///< shutter open time (motion blur, particle streaks)
  CameraOutputs outputs;
  double near_m = 0.01;  ///< near clipping distance, z-depth, m (render/renderer.h CameraView)
};

/// the static part of a scene, shared by every frame.
struct SceneDescription {
  std::vector<Body> bodies;
  std::vector<Geom> geoms;
  /// visible spatial tendons; hits on them report geom -1 (segmentation: background id).
  std::vector<Tendon> tendons;
  std::vector<TriangleMesh> meshes;
  std::vector<HeightField> hfields;
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Light> lights;
  Sky sky;
  std::vector<CameraSpec> cameras;
  /// bounding sphere of the model (from MuJoCo's stat.center / stat.extent), for default views.
  Eigen::Vector3d center_W{0, 0, 0};
  double extent_m = 1.0;

  /// index of the material / body / camera with that name, or -1.
  int FindMaterial(const std::string& name) const;
  int FindBody(const std::string& name) const;
  int FindCamera(const std::string& name) const;
};

/// the memory of the texture images of `textures`, each distinct image counted once (textures
/// without an image are not counted).
TextureMemory CountTextureMemory(const std::vector<Texture>& textures);

}  // namespace penumbra
