// mujoco_offscreen: renders an MJCF model with MuJoCo's own OpenGL renderer (MuJoCo 4,
// mjr_render into the offscreen buffer of a hidden GLFW window; run it under Xvfb on a machine
// without a display) from a given camera, for scripts/compare_with_mujoco.py.
//
//   mujoco_offscreen MODEL.xml OUT_PREFIX WIDTH HEIGHT PX PY PZ FX FY FZ UX UY UZ FOVY_DEG
//
// the camera sits at P (world, m), looks along F and has U as its up direction (both world
// vectors; U is made orthogonal to F), vertical field of view FOVY_DEG, square pixels. the model
// is shown at its initial state (mj_resetData + mj_forward), as MuJoCo's viewer opens it.
// writes OUT_PREFIX.ppm (8-bit RGB, top row first), OUT_PREFIX.seg (int32 little-endian MuJoCo
// geom id per pixel, top row first, -1 where no geom: background, decor) and OUT_PREFIX.json
// (every geom: id, name, body, type, rgba as MuJoCo draws it: the material's where the geom's
// rgba is the default). exit status 1 with a message on stderr for bad arguments, a model that
// does not load or no OpenGL context.
#include <GLFW/glfw3.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "mujoco_offscreen: %s\n", message.c_str());
  return 1;
}

bool ParseDouble(const char* s, double* out) {
  char* end = nullptr;
  *out = std::strtod(s, &end);
  return end != s && *end == '\0' && std::isfinite(*out);
}

std::string JsonString(const char* s) {
  std::string out = "\"";
  for (const char* p = s; *p != '\0'; ++p) {
    if (*p == '"' || *p == '\\') out += '\\';
    if (static_cast<unsigned char>(*p) >= 0x20) out += *p;
  }
  return out + "\"";
}

// reads the current offscreen buffer (bottom row first) into top-row-first rgb.
std::vector<unsigned char> ReadRgb(const mjrRect& viewport, const mjrContext& con) {
  const int w = viewport.width, h = viewport.height;
  std::vector<unsigned char> raw(static_cast<size_t>(w) * h * 3), out(raw.size());
  mjr_readPixels(raw.data(), nullptr, viewport, &con);
  for (int r = 0; r < h; ++r)
    std::memcpy(&out[static_cast<size_t>(r) * w * 3], &raw[static_cast<size_t>(h - 1 - r) * w * 3],
                static_cast<size_t>(w) * 3);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 15)
    return Fail(
        "usage: mujoco_offscreen MODEL.xml OUT_PREFIX WIDTH HEIGHT PX PY PZ FX FY FZ UX UY UZ "
        "FOVY_DEG");
  const std::string model_path = argv[1], prefix = argv[2];
  const int width = std::atoi(argv[3]), height = std::atoi(argv[4]);
  if (width < 1 || height < 1 || width > 8192 || height > 8192)
    return Fail("WIDTH and HEIGHT: expected integers in [1, 8192]");
  double v[10];
  for (int i = 0; i < 10; ++i)
    if (!ParseDouble(argv[5 + i], &v[i]))
      return Fail(std::string("argument ") + std::to_string(5 + i) + " '" + argv[5 + i] +
                  "': expected a finite number");
  if (!(v[9] > 0 && v[9] < 180)) return Fail("FOVY_DEG: expected a value in (0, 180)");

  char error[1000] = "";
  mjModel* m = mj_loadXML(model_path.c_str(), nullptr, error, sizeof(error));
  if (m == nullptr) return Fail(model_path + ": " + error);
  mjData* d = mj_makeData(m);
  mj_resetData(m, d);
  mj_forward(m, d);

  if (!glfwInit()) return Fail("glfwInit failed (no display? run under xvfb-run)");
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(64, 64, "mujoco_offscreen", nullptr, nullptr);
  if (window == nullptr) return Fail("glfwCreateWindow failed (no OpenGL context)");
  glfwMakeContextCurrent(window);

  // the offscreen buffer must hold the image.
  m->vis.global.offwidth = std::max(m->vis.global.offwidth, width);
  m->vis.global.offheight = std::max(m->vis.global.offheight, height);
  mjvScene scn;
  mjvOption opt;
  mjvCamera cam;
  mjrContext con;
  mjv_defaultScene(&scn);
  mjv_defaultOption(&opt);
  mjv_defaultCamera(&cam);
  mjr_defaultContext(&con);
  mjv_makeScene(m, &scn, 2000);
  mjr_makeContext(m, &con, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &con);
  const mjrRect viewport = {0, 0, width, height};

  // camera frame: forward f, up u orthogonal to f.
  double f[3] = {v[3], v[4], v[5]}, u[3] = {v[6], v[7], v[8]};
  const double fn = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (!(fn > 0)) return Fail("F: expected a non-zero forward direction");
  for (double& c : f) c /= fn;
  const double fu = f[0] * u[0] + f[1] * u[1] + f[2] * u[2];
  for (int i = 0; i < 3; ++i) u[i] -= fu * f[i];
  const double un = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  if (!(un > 0)) return Fail("U: expected an up direction not parallel to F");
  for (double& c : u) c /= un;

  const auto render = [&](bool segment) {
    scn.flags[mjRND_SEGMENT] = segment ? 1 : 0;
    scn.flags[mjRND_IDCOLOR] = segment ? 1 : 0;
    mjv_updateScene(m, d, &opt, nullptr, &cam, mjCAT_ALL, &scn);
    const float near_m = static_cast<float>(m->vis.map.znear * m->stat.extent);
    for (mjvGLCamera& c : scn.camera) {
      for (int i = 0; i < 3; ++i) {
        c.pos[i] = static_cast<float>(v[i]);
        c.forward[i] = static_cast<float>(f[i]);
        c.up[i] = static_cast<float>(u[i]);
      }
      c.frustum_near = near_m;
      c.frustum_far = static_cast<float>(m->vis.map.zfar * m->stat.extent);
      c.frustum_top = near_m * static_cast<float>(std::tan(v[9] * M_PI / 360.0));
      c.frustum_bottom = -c.frustum_top;
      c.frustum_center = 0;
    }
    mjr_render(viewport, &scn, &con);
    return ReadRgb(viewport, con);
  };

  const std::vector<unsigned char> rgb = render(false);
  const std::vector<unsigned char> seg_rgb = render(true);
  // segid + 1 in the colour: the index of the mjvGeom in scn.geoms.
  std::vector<int32_t> seg(static_cast<size_t>(width) * height, -1);
  for (size_t i = 0; i < seg.size(); ++i) {
    const int id = seg_rgb[3 * i] + 256 * seg_rgb[3 * i + 1] + 65536 * seg_rgb[3 * i + 2] - 1;
    if (id >= 0 && id < scn.ngeom && scn.geoms[id].objtype == mjOBJ_GEOM)
      seg[i] = scn.geoms[id].objid;
  }

  FILE* ppm = std::fopen((prefix + ".ppm").c_str(), "wb");
  if (ppm == nullptr) return Fail("cannot write " + prefix + ".ppm");
  std::fprintf(ppm, "P6\n%d %d\n255\n", width, height);
  std::fwrite(rgb.data(), 1, rgb.size(), ppm);
  std::fclose(ppm);
  FILE* sf = std::fopen((prefix + ".seg").c_str(), "wb");
  if (sf == nullptr) return Fail("cannot write " + prefix + ".seg");
  std::fwrite(seg.data(), sizeof(int32_t), seg.size(), sf);
  std::fclose(sf);
  FILE* jf = std::fopen((prefix + ".json").c_str(), "w");
  if (jf == nullptr) return Fail("cannot write " + prefix + ".json");
  std::fprintf(jf, "{\"geoms\": [");
  for (int i = 0; i < m->ngeom; ++i) {
    const float* rgba = m->geom_rgba + 4 * i;
    const int mat = m->geom_matid[i];
    const bool default_rgba = rgba[0] == 0.5f && rgba[1] == 0.5f && rgba[2] == 0.5f && rgba[3] == 1;
    if (mat >= 0 && default_rgba) rgba = m->mat_rgba + 4 * mat;
    const char* name = mj_id2name(m, mjOBJ_GEOM, i);
    std::fprintf(jf,
                 "%s\n  {\"id\": %d, \"name\": %s, \"body\": %d, \"type\": %d, "
                 "\"rgba\": [%g, %g, %g, %g], \"textured\": %s}",
                 i > 0 ? "," : "", i, JsonString(name != nullptr ? name : "").c_str(),
                 m->geom_bodyid[i], m->geom_type[i], rgba[0], rgba[1], rgba[2], rgba[3],
                 mat >= 0 && m->mat_texid[mat] >= 0 ? "true" : "false");
  }
  std::fprintf(jf, "\n]}\n");
  std::fclose(jf);

  mjr_freeContext(&con);
  mjv_freeScene(&scn);
  mj_deleteData(d);
  mj_deleteModel(m);
  glfwDestroyWindow(window);
  glfwTerminate();
  return 0;
}
