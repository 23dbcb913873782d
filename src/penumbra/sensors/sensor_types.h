#pragma once
// the sensor registry: every sensor type, in one list. adding a sensor type = its own
// sensors/types/<name>.{h,cc} (the contract is in sensor_type.h), its enumerator at the END of
// SensorKind and its entry at the END of SensorParams below, and its model in
// sinks/sensor_sink.cc. nothing else compares type names: the world reader, the run
// description, the bridges and the output folders go through the list.

#include <array>
#include <optional>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

#include "penumbra/sensors/sensor_type.h"
#include "penumbra/sensors/types/ground_truth.h"
#include "penumbra/sensors/types/imu.h"
#include "penumbra/sensors/types/lidar.h"
#include "penumbra/sensors/types/mujoco.h"

namespace penumbra {

/// the parameters of one sensor; the alternative held is the sensor's type.
using SensorParams =
    std::variant<LidarSensorParams, ImuSensorParams, MujocoSensorParams, GroundTruthSensorParams>;

/// the number of sensor types.
inline constexpr int kSensorKindCount = static_cast<int>(std::variant_size_v<SensorParams>);

/// what the registry knows of a sensor type without its parameters.
struct SensorTypeInfo {
  SensorKind kind;
  std::string_view name;           ///< world-file `type:`
  std::string_view output_folder;  ///< its folder in a run
  SensorAttach attach;
  double default_rate_hz;
  bool rate_from_model;
};

namespace sensor_types_detail {
template <size_t... I>
constexpr std::array<SensorTypeInfo, sizeof...(I)> MakeInfos(std::index_sequence<I...>) {
  return {{SensorTypeInfo{std::variant_alternative_t<I, SensorParams>::kKind,
                          std::variant_alternative_t<I, SensorParams>::kTypeName,
                          std::variant_alternative_t<I, SensorParams>::kOutputFolder,
                          std::variant_alternative_t<I, SensorParams>::kAttach,
                          std::variant_alternative_t<I, SensorParams>::kDefaultRateHz,
                          std::variant_alternative_t<I, SensorParams>::kRateFromModel}...}};
}
}  // namespace sensor_types_detail

/// the sensor types, in SensorKind order.
inline constexpr std::array<SensorTypeInfo, kSensorKindCount> kSensorTypes =
    sensor_types_detail::MakeInfos(std::make_index_sequence<kSensorKindCount>{});

// each type sits at its kind's index
constexpr bool SensorTypesInOrder() {
  for (int i = 0; i < kSensorKindCount; ++i)
    if (static_cast<int>(kSensorTypes[i].kind) != i) return false;
  return true;
}
static_assert(SensorTypesInOrder(), "SensorParams must list the types in SensorKind order");

/// the registry's row of `kind`.
constexpr const SensorTypeInfo& Info(SensorKind kind) {
  return kSensorTypes[static_cast<int>(kind)];
}

/// the world-file name of `kind` ("lidar", "imu", "mujoco", "ground_truth").
constexpr std::string_view SensorKindName(SensorKind kind) { return Info(kind).name; }

/// the kind named `name`, or nullopt for any other name.
constexpr std::optional<SensorKind> SensorKindFromName(std::string_view name) {
  for (const SensorTypeInfo& t : kSensorTypes)
    if (t.name == name) return t.kind;
  return std::nullopt;
}

/// the kind of `params` (the alternative it holds).
inline SensorKind KindOf(const SensorParams& params) {
  return static_cast<SensorKind>(params.index());
}

namespace sensor_types_detail {
template <size_t I>
SensorParams DefaultFrom(int kind) {
  if constexpr (I + 1 < std::variant_size_v<SensorParams>) {
    if (kind != static_cast<int>(I)) return DefaultFrom<I + 1>(kind);
  }
  return SensorParams(std::in_place_index<I>);
}
}  // namespace sensor_types_detail

/// default parameters of `kind` (what a world entry of that type holds before its keys are
/// read).
inline SensorParams DefaultSensorParams(SensorKind kind) {
  return sensor_types_detail::DefaultFrom<0>(static_cast<int>(kind));
}

}  // namespace penumbra
