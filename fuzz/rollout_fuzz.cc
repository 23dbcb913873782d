// libFuzzer target: the arguments of the rollout module (rollout/rollout_args.h, the checks the
// Python module _penumbra_rollout calls) and, for counts it accepts, a BatchStepper on a tiny
// built-in model stepped and reset with the input's numbers. layout: three 8-byte counts
// (num_copies, num_threads, substeps; read raw when the mode byte's bit 0 is set, else folded
// into small values), a mode byte, two 8-byte memory sizes (bytes per copy, cap), then float64
// values (gains, inputs, states: NaN and infinities included). the documented failure is
// penumbra::Error (ConfigError for a bad argument, PhysicsError for MuJoCo's errors); any other
// exception, a crash, a sanitizer report, an accepted non-finite value or a count above its
// bound accepted is a finding. docs/fuzzing.md.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/rollout/batch_stepper.h"
#include "penumbra/rollout/rollout_args.h"

namespace {

// a hinge arm with a slide joint: two actuators, two joints, one sensor
constexpr char kModel[] = R"(<mujoco model="fuzz">
  <option timestep="0.002"/>
  <worldbody>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0" limited="true" range="-2 2"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body pos="0.3 0 0">
        <joint name="slide" type="slide" axis="1 0 0"/>
        <geom type="sphere" size="0.05"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="hinge" ctrllimited="true" ctrlrange="-5 5"/>
    <motor joint="slide"/>
  </actuator>
  <sensor><jointpos joint="hinge"/></sensor>
</mujoco>)";

// at most this many threads in the fuzzer (the bound itself is fuzzed through max_threads)
constexpr int64_t kFuzzMaxThreads = 4;

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : p_(data), n_(size) {}
  template <typename T>
  T Get() {
    T v{};
    const size_t k = std::min(sizeof(T), n_);
    std::memcpy(&v, p_, k);
    p_ += k;
    n_ -= k;
    return v;
  }
  size_t left() const { return n_; }

 private:
  const uint8_t* p_;
  size_t n_;
};

int64_t Fold(int64_t raw, bool keep_raw, int64_t range) {
  if (keep_raw) return raw;
  return static_cast<int64_t>(static_cast<uint64_t>(raw) % static_cast<uint64_t>(range)) - 1;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  Reader r(data, size);
  const int64_t raw_copies = r.Get<int64_t>(), raw_threads = r.Get<int64_t>(),
                raw_substeps = r.Get<int64_t>();
  const uint8_t mode = r.Get<uint8_t>();
  const uint64_t bytes_per_copy = r.Get<uint64_t>(), cap = r.Get<uint64_t>();
  std::vector<double> values;
  while (r.left() > 0) values.push_back(r.Get<double>());

  const bool raw = (mode & 1) != 0;
  const int64_t copies = Fold(raw_copies, raw, 6);
  const int64_t threads = Fold(raw_threads, raw, kFuzzMaxThreads + 2);
  const int64_t substeps = Fold(raw_substeps, raw, 6);

  try {
    CheckRolloutMemory(copies, bytes_per_copy, cap);
    if (copies < 0 || (bytes_per_copy > 0 &&
                       static_cast<uint64_t>(copies) > cap / std::max<uint64_t>(bytes_per_copy, 1)))
      __builtin_trap();
  } catch (const ConfigError&) {
  }
  try {
    CheckFiniteValues(values.data(), values.size(), mode % 4, "input");
    for (double v : values)
      if (!std::isfinite(v)) __builtin_trap();
  } catch (const ConfigError&) {
  }
  try {
    ValidateRolloutCounts(copies, threads, substeps, kFuzzMaxThreads);
  } catch (const ConfigError&) {
    return 0;
  }
  if (copies < 1 || copies > kMaxRolloutCopies || threads < 0 || threads > kFuzzMaxThreads ||
      substeps < 1 || substeps > kMaxRolloutSubsteps)
    __builtin_trap();
  // the stepper itself only on small counts (the fuzzer's time, not the bounds, limits these)
  if (copies > 4 || substeps > 8) return 0;

  size_t next = 0;
  auto take = [&](size_t k) {
    std::vector<double> out(k, 0.0);
    for (size_t i = 0; i < k && next < values.size(); ++i) out[i] = values[next++];
    return out;
  };
  BatchStepperConfig config;
  config.num_copies = static_cast<int>(copies);
  config.num_threads = static_cast<int>(std::max<int64_t>(threads, 1));
  config.substeps = static_cast<int>(substeps);
  if (mode & 2) {
    config.actuation = BatchActuation::kJointPd;
    config.kp = take(2);
    config.kd = take(2);
  }
  try {
    BatchStepper stepper(MjcfText{"fuzz.xml", kModel}, config);
    const int nu = stepper.nu(), nq = stepper.nq(), nv = stepper.nv();
    std::vector<double> qpos(static_cast<size_t>(copies) * nq),
        qvel(static_cast<size_t>(copies) * nv), ctrl(static_cast<size_t>(copies) * nu),
        sens(static_cast<size_t>(copies) * stepper.nsensordata());
    for (int round = 0; round < 3 && next < values.size(); ++round) {
      try {
        const std::vector<double> input = take(static_cast<size_t>(copies) * nu);
        stepper.Step(input.data());
      } catch (const Error&) {
      }
      try {
        const std::vector<double> q = take(nq), v = take(nv);
        stepper.Reset(round % static_cast<int>(copies), q.data(), v.data());
      } catch (const Error&) {
      }
      stepper.ReadState(qpos.data(), qvel.data(), ctrl.data(), sens.data());
    }
  } catch (const Error&) {
  }
  return 0;
}
