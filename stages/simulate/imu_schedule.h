#ifndef TILTCAL_STAGES_SIMULATE_IMU_SCHEDULE_H_
#define TILTCAL_STAGES_SIMULATE_IMU_SCHEDULE_H_

#include <cstdint>
#include <vector>

#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// When each simulated IMU sample appears in the bag. Sample i is taken at
// its nominal time start + round(i · 10⁹ / rate) ns (IMU clock); its header
// stamp is that time plus the stamp jitter of SimFaultParams, and it is left
// out when a random drop or a gap hits it.
struct ImuSchedule {
  std::vector<int64_t> stamp_ns;  // header stamp of every sample, strictly increasing
  std::vector<bool> kept;         // false: left out of the bag
  int num_dropped = 0;
};

// Nominal time of sample i, ns (IMU clock).
int64_t NominalImuStampNs(int64_t start_ns, double rate_hz, int i);

// The stamps and the samples kept for `num_samples` samples at `rate_hz`
// from `start_ns`. The jitter and the random drops each draw from their own
// stream of `seed` (random.h), every sample one number, so a setting of one
// leaves the other's numbers unchanged. Without faults: nominal stamps,
// every sample kept.
ImuSchedule MakeImuSchedule(int num_samples, double rate_hz, int64_t start_ns,
                            const proto::SimFaultParams& faults, uint64_t seed);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_IMU_SCHEDULE_H_
