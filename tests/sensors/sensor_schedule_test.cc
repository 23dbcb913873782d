// SensorSchedule: exact firing times and counts over 10 s, no drift.
#include "penumbra/sensors/sensor_schedule.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(SensorScheduleTest, FiresAtFirstStepAtOrAfterEachSampleTimeWithoutDrift) {
  for (double dt : {0.002, 0.0015}) {
    SensorSchedule s;
    const double rates[] = {30, 10, 200};
    for (double r : rates) s.Add("s" + std::to_string(static_cast<int>(r)), r, 0.05);
    std::vector<std::vector<SensorFiring>> fired(3);
    // MuJoCo accumulates time as time += timestep
    double t = 0;
    std::vector<double> times;
    while (true) {
      times.push_back(t);
      std::vector<SensorFiring> due;
      s.Due(t, &due);
      for (const SensorFiring& f : due) fired[f.sensor].push_back(f);
      if (t >= 10.0 - 1e-9) break;
      t += dt;
    }
    for (int i = 0; i < 3; ++i) {
      const double rate = rates[i];
      // samples k = 0 .. 10 rate, all within [0, 10 s]
      const int64_t expected = static_cast<int64_t>(std::floor(10.0 * rate + 1e-9)) + 1;
      ASSERT_EQ(static_cast<int64_t>(fired[i].size()), expected) << "rate " << rate << " dt " << dt;
      EXPECT_EQ(s.skipped(i), 0);
      for (int64_t k = 0; k < expected; ++k) {
        const SensorFiring& f = fired[i][k];
        ASSERT_EQ(f.index, k);
        const double tk = k / rate;
        // the first step time >= tk (within the tolerance), independent of previous frames
        size_t n = 0;
        while (times[n] < tk - SensorSchedule::kToleranceSec) ++n;
        ASSERT_EQ(f.capture_time_sec, times[n]) << "k " << k;
        ASSERT_GE(f.capture_time_sec, tk - 1e-9);
        ASSERT_LT(f.capture_time_sec - tk, dt);
        ASSERT_DOUBLE_EQ(f.delivery_time_sec, f.capture_time_sec + 0.05);
      }
    }
  }
}

TEST(SensorScheduleTest, SameStepSameTimeAndFasterThanPhysicsSkips) {
  SensorSchedule s;
  s.Add("a", 100, 0);
  s.Add("b", 50, 0);
  s.Add("fast", 1000, 0);
  int both = 0;
  double t = 0;
  for (int step = 0; step <= 100; ++step, t += 0.002) {
    std::vector<SensorFiring> due;
    s.Due(t, &due);
    bool a = false, b = false;
    for (const SensorFiring& f : due) {
      if (f.sensor == 0) a = true;
      if (f.sensor == 1) b = true;
      EXPECT_EQ(f.capture_time_sec, t);
    }
    both += a && b;
  }
  EXPECT_EQ(both, 11);         // 50 Hz frames coincide with 100 Hz frames over 0.2 s
  EXPECT_GT(s.skipped(2), 0);  // 1 kHz at a 500 Hz physics rate
  EXPECT_THROW(s.Add("zero", 0, 0), Error);
  EXPECT_THROW(s.Add("neg", 10, -1), Error);
}

}  // namespace
}  // namespace penumbra
