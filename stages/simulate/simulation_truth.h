#ifndef TILTCAL_STAGES_SIMULATE_SIMULATION_TRUTH_H_
#define TILTCAL_STAGES_SIMULATE_SIMULATION_TRUTH_H_

// What the simulation knows and the calibration must find: the truth file
// (per scan and for the sequence) and the rig file a user would have written.

#include <cstdint>

#include <Eigen/Core>

#include "stages/simulate/imu_simulator.h"
#include "stages/simulate/scan_simulator.h"
#include "stages/simulate/scenario.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::simulate {


// Frames of the truth: world a = the IMU frame at the first sample, the
// simulator's world w, the plane normal and the flat-ground gravity.
struct TruthFrames {
  TruthFrames(const proto::SimulateParams& params, const Scenario& scenario);
  Eigen::Matrix3d c_wb0;
  Eigen::Vector3d r_wb0;
  Eigen::Matrix3d c_aw;                                    // C_aw = C_wb(0)^T
  Eigen::Vector3d n_w;                                     // ground normal in w
  const Eigen::Vector3d up_w = Eigen::Vector3d::UnitZ();  // level up in w
  Eigen::Vector3d g_f;                                     // gravity in b on flat ground
  Eigen::Vector3d up_f;
};

// The truth of one written scan with bag stamp `stamp_ns`.
void FillTruthScan(const Scenario& scenario, const TruthFrames& f, const SimulatedScan& scan,
                   int64_t start_ns, int64_t stamp_ns, proto::TruthScan* ts);

// The sequence-level truth, after every scan is in.
void FillSequenceTruth(const proto::SimulateParams& params, const Scenario& scenario,
                       const TruthFrames& f, const ImuSimulator& imu,
                       proto::SimulationTruth* truth);

// The rig a user would have measured: the true extrinsic with the errors of
// params.rig_file, C_meas = C(rotation_error_in_imu_deg) C_bl C(rotation_error_deg).
proto::Rig MakeRig(const proto::SimulateParams& params, const Scenario& scenario,
                   const TruthFrames& f);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_SIMULATION_TRUTH_H_
