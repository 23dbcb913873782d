#include "penumbra/assets/height_field_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace penumbra {
namespace {

void Range(const SampledHeightField& f, double* lo, double* range) {
  const auto [mn, mx] = std::minmax_element(f.z.begin(), f.z.end());
  *lo = *mn;
  *range = std::max(*mx - *mn, 1e-3);
}

template <typename T>
void Append(std::string* out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out->append(b, sizeof(T));
}

}  // namespace

std::string HfieldFileBytes(const SampledHeightField& field) {
  double lo, range;
  Range(field, &lo, &range);
  std::string out;
  Append<int32_t>(&out, field.rows);
  Append<int32_t>(&out, field.cols);
  for (const double z : field.z) Append<float>(&out, static_cast<float>((z - lo) / range));
  return out;
}

std::string HfieldSizeAttribute(const SampledHeightField& field, double base_m) {
  double lo, range;
  Range(field, &lo, &range);
  return fmt::format("{:.6f} {:.6f} {:.6f} {:.6f}", (field.cols - 1) * field.cell_m / 2,
                     (field.rows - 1) * field.cell_m / 2, range, base_m);
}

Eigen::Vector3d HfieldGeomPosition(const SampledHeightField& field) {
  double lo, range;
  Range(field, &lo, &range);
  return {field.x0 + (field.cols - 1) * field.cell_m / 2,
          field.y0 + (field.rows - 1) * field.cell_m / 2, lo};
}

std::string HeightFieldMjcf(const std::string& model, const SampledHeightField& field,
                            const std::string& hfield_file, double base_m,
                            const Eigen::Vector3d& rgb) {
  const Eigen::Vector3d p = HfieldGeomPosition(field);
  return fmt::format(
      "<!-- a height field of {} x {} samples every {} m (penumbra heightfield) -->\n"
      "<mujoco model=\"{}\">\n"
      "  <asset>\n"
      "    <hfield name=\"terrain\" file=\"{}\" size=\"{}\"/>\n"
      "    <material name=\"terrain\" rgba=\"{:.4f} {:.4f} {:.4f} 1\"/>\n"
      "  </asset>\n"
      "  <worldbody>\n"
      "    <geom name=\"terrain\" type=\"hfield\" hfield=\"terrain\" pos=\"{:.6f} {:.6f} {:.6f}\" "
      "material=\"terrain\"/>\n"
      "  </worldbody>\n"
      "</mujoco>\n",
      field.cols, field.rows, field.cell_m, model, hfield_file, HfieldSizeAttribute(field, base_m),
      rgb.x(), rgb.y(), rgb.z(), p.x(), p.y(), p.z());
}

}  // namespace penumbra
