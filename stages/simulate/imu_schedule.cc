#include "stages/simulate/imu_schedule.h"

#include <algorithm>
#include <cmath>

#include "stages/simulate/random.h"

namespace tiltcal::simulate {

namespace {

// A jittered stamp is at least this much later than the previous sample's.
constexpr int64_t kMinStampStepNs = 1000;

// True when the nominal time t_s (s since the first sample) is in a gap.
bool InGap(const proto::SimFaultParams& faults, double t_s) {
  for (const proto::SimImuGap& gap : faults.imu_gaps()) {
    if (t_s >= gap.start_s() && t_s < gap.start_s() + gap.duration_s()) return true;
  }
  return false;
}

}  // namespace

int64_t NominalImuStampNs(int64_t start_ns, double rate_hz, int i) {
  return start_ns + std::llround(static_cast<double>(i) * 1e9 / rate_hz);
}

ImuSchedule MakeImuSchedule(int num_samples, double rate_hz, int64_t start_ns,
                            const proto::SimFaultParams& faults, uint64_t seed) {
  ImuSchedule schedule;
  schedule.stamp_ns.resize(static_cast<size_t>(num_samples));
  schedule.kept.assign(static_cast<size_t>(num_samples), true);
  const double jitter_s = faults.imu_stamp_jitter_s();
  const double drop_fraction = faults.imu_drop_fraction();
  Rng jitter_rng(seed, kImuStampJitterStream);
  Rng drop_rng(seed, kImuDropStream);
  for (int i = 0; i < num_samples; ++i) {
    int64_t stamp = NominalImuStampNs(start_ns, rate_hz, i);
    if (jitter_s > 0) {
      stamp += std::llround(jitter_s * 1e9 * jitter_rng.Gaussian());
      if (i > 0) stamp = std::max(stamp, schedule.stamp_ns[i - 1] + kMinStampStepNs);
    }
    schedule.stamp_ns[i] = stamp;
    const bool dropped_at_random = drop_fraction > 0 && drop_rng.Uniform() < drop_fraction;
    const bool first_or_last = i == 0 || i == num_samples - 1;
    if (!first_or_last && (dropped_at_random || InGap(faults, i / rate_hz))) {
      schedule.kept[i] = false;
      ++schedule.num_dropped;
    }
  }
  return schedule;
}

}  // namespace tiltcal::simulate
