#ifndef TILTCAL_STAGES_SIMULATE_SIMULATE_H_
#define TILTCAL_STAGES_SIMULATE_SIMULATE_H_

#include <ostream>
#include <string>

#include "common/status.h"
#include "stages/simulate/scenario.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::simulate {

// Every path of one simulate run.
struct SimulatePaths {
  std::string params;     // the scenario file, for the provenance
  std::string out_bag;    // required
  std::string out_truth;  // required
  std::string out_rig;    // optional ("" = none)
  std::string command_line;
};

// Simulates the scenario and writes the bag (IMU + LiDAR), the truth file and
// optionally a rig file. The bag bytes depend only on `params` (same seed,
// same bytes, for any num_threads). `params` must have passed LoadParams.
// `log` receives the progress (only when it is a terminal) and a one-line
// summary; nullptr = silent.
Status Run(const SimulatePaths& paths, const proto::SimulateParams& params, std::ostream* log);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_SIMULATE_H_
