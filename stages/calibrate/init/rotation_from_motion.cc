#include "stages/calibrate/init/rotation_from_motion.h"

#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "stages/calibrate/init/init_odometry.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/problem/calibration_state.h"

namespace tiltcal::calibrate {
namespace {

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return geometry::RadToDeg(Eigen::AngleAxisd(a * b.conjugate()).angle());
}

// The initialisation's params with the search's odometry (every
// rotation_search.scan_step-th scan at rotation_search.scan_voxel_m).
proto::CalibrateParams SearchParams(const proto::CalibrateParams& params) {
  proto::CalibrateParams search = params;
  search.mutable_odometry()->set_scan_step(params.rotation_search().scan_step());
  search.mutable_odometry()->set_scan_voxel_m(params.rotation_search().scan_voxel_m());
  return search;
}

// The poses the odometry used: their LiDAR times, positions r_{l0}^{lk l0}
// and C_{l0 lk}, and C_ab at each time + tau (the state's).
struct UsedPoses {
  std::vector<double> times_s;
  std::vector<Eigen::Vector3d> positions_l0;
  std::vector<Eigen::Quaterniond> lidar_rotations;
  std::vector<Eigen::Quaterniond> imu_rotations;
};

UsedPoses CollectUsedPoses(const OdometryRun& run, const std::vector<LidarScan>& scans,
                           const CalibrationState& state) {
  UsedPoses used;
  for (const size_t i : run.used) {
    const double t = scans[run.scan_of_pose[i]].stamp_s;
    spline::So3SplineSample rot;
    if (!state.trajectory.Evaluate(t + state.time_offset_s[0], spline::kSo3Rotation, &rot,
                                   nullptr)) {
      continue;
    }
    used.times_s.push_back(t);
    used.positions_l0.push_back(run.poses[i].l0_from_lidar.translation());
    used.lidar_rotations.push_back(Eigen::Quaterniond(run.poses[i].l0_from_lidar.rotation()));
    used.imu_rotations.push_back(Eigen::Quaterniond(rot.rotation));
  }
  return used;
}

// What every round of the search reads, and the state and report it
// updates.
struct RotationSearch {
  const std::vector<imu::ImuReading>& imu_samples;
  const std::vector<LidarScan>& scans;
  const proto::CalibrateParams& params;
  proto::CalibrateParams search;  // SearchParams(params)
  int pair_step;
  bool has_guess;
  CalibrationState* state;
  InitialisationReport* report;
};

// The motion of one round: the odometry's used poses and their rotation
// pairs.
struct RoundMotion {
  UsedPoses used;
  std::vector<RotationPair> pairs;
};

// The odometry with the state's C_bl (gyro-aided or not), tau from it, the
// rotation pairs and how much they turn; NotDetermined when too little.
Status MeasureRoundMotion(const RotationSearch& s, bool gyro_aided, RotationFromMotion* result,
                          RoundMotion* motion) {
  CalibrationState& state = *s.state;
  const OdometryRun run = RunOdometry(s.scans, state, s.search, gyro_aided, s.report);
  if (run.used.size() < 3) {
    return Status::Error(fmt::format(
        "the LiDAR odometry registered too few scans ({} of {}) to find the extrinsic "
        "rotation from the motion",
        run.used.size(), s.scans.size()));
  }
  TILTCAL_RETURN_IF_ERROR(
      EstimateCoarseTau(run, s.scans, s.imu_samples, s.search, state, s.report));
  state.time_offset_s[0] = s.report->time_offset_center_s;
  result->time_offset_s = s.report->time_offset_center_s;
  motion->used = CollectUsedPoses(run, s.scans, state);
  const UsedPoses& used = motion->used;
  motion->pairs = MakeRotationPairs(used.imu_rotations, used.lidar_rotations, s.pair_step);
  std::vector<std::pair<double, double>> pair_times_s;
  for (size_t k = 0; k + s.pair_step < used.times_s.size(); k += s.pair_step) {
    pair_times_s.emplace_back(used.times_s[k], used.times_s[k + s.pair_step]);
  }
  result->turning = MeasureTurning(motion->pairs, pair_times_s);
  const std::string missing = MissingTurning(result->turning, s.params.init());
  if (!missing.empty()) return Status::NotDetermined(missing);
  return Status::Ok();
}

// The round's next C_bl: hand-eye when the motion excites it; else
// (planar motion) the axes aligned first (any angle), then the rotation
// about the axis from the accelerations. NotDetermined when neither decides
// it and there is no guess.
Status NextRotation(const RotationSearch& s, const RoundMotion& motion,
                    const Eigen::Quaterniond& c_bl, RotationSearchRound* r,
                    RotationFromMotion* result, Eigen::Quaterniond* next) {
  const proto::CalibrateParams& params = s.params;
  result->hand_eye = EstimateHandEyeRotation(motion.pairs, params.hand_eye());
  if (result->hand_eye.excited) {
    r->from_hand_eye = true;
    *next = result->hand_eye.imu_from_lidar_rotation;
    result->about_axis_decided = true;
    return Status::Ok();
  }
  *next = AlignRotationAxes(motion.pairs, c_bl);
  r->axis_turn_deg = AngleDeg(*next, c_bl);
  s.state->SetImuFromLidarRotation(*next);
  r->acceleration = CheckRigYawByAccelerations(*s.state, s.imu_samples, motion.used.times_s,
                                               motion.used.positions_l0, result->axis_b,
                                               params.init());
  if (r->acceleration.decided) {
    *next = Eigen::AngleAxisd(geometry::DegToRad(r->acceleration.yaw_error_deg), result->axis_b) *
            *next;
    result->about_axis_decided = true;
  } else if (!s.has_guess) {
    return Status::NotDetermined(fmt::format(
        "the motion turns about one axis only (hand-eye excitation {:.4f} rad, at least "
        "hand_eye.min_excitation_rad = {} needed), and its horizontal accelerations "
        "(RMS {:.3f} m/s^2, at least init.min_check_acceleration_mps2 = {} needed) are "
        "too small to find the rotation about that axis: record driving with starts, "
        "stops and turns both ways, or give imu_from_lidar in the rig",
        result->hand_eye.excitation_rad, params.hand_eye().min_excitation_rad(),
        r->acceleration.rms_horizontal_acceleration_mps2,
        params.init().min_check_acceleration_mps2()));
  }
  return Status::Ok();
}

}  // namespace

Status FindImuFromLidarRotation(const std::vector<imu::ImuReading>& imu_samples,
                                const std::vector<LidarScan>& scans,
                                const std::optional<Eigen::Quaterniond>& guess,
                                const Eigen::Vector3d& translation_guess,
                                const proto::CalibrateParams& params, RotationFromMotion* result) {
  *result = RotationFromMotion();
  const auto start = std::chrono::steady_clock::now();
  const proto::RotationSearchParams& options = params.rotation_search();
  std::optional<CalibrationState> maybe_state;
  TILTCAL_RETURN_IF_ERROR(MakeStateOverImu(imu_samples, params, &maybe_state));
  CalibrationState& state = *maybe_state;
  InitialisationReport report;
  TILTCAL_RETURN_IF_ERROR(InitialiseImuAndRotationSpline(imu_samples, params, &state, &report));
  result->axis_b = report.rotation_axis_b;
  state.SetImuFromLidarTranslation(translation_guess);

  Eigen::Quaterniond c_bl = guess.value_or(Eigen::Quaterniond::Identity()).normalized();
  // Rotation pairs as far apart in time as the initialisation's (hand_eye.pair_step
  // registered scans), so that the turning check means the same in both.
  const int pair_step = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(params.hand_eye().pair_step()) /
                                      std::max<uint32_t>(options.scan_step(), 1))));
  const RotationSearch search{imu_samples, scans,           params, SearchParams(params),
                              pair_step,   guess.has_value(), &state, &report};
  for (uint32_t round = 0; round < options.max_rounds(); ++round) {
    RotationSearchRound r;
    // The first odometry uses neither the gyro's deskew nor its prediction:
    // with a guess off by tens of degrees both would turn the wrong way.
    r.gyro_aided = round > 0;
    state.SetImuFromLidarRotation(c_bl);
    RoundMotion motion;
    TILTCAL_RETURN_IF_ERROR(MeasureRoundMotion(search, r.gyro_aided, result, &motion));
    Eigen::Quaterniond next;
    TILTCAL_RETURN_IF_ERROR(NextRotation(search, motion, c_bl, &r, result, &next));
    r.change_deg = AngleDeg(next.normalized(), c_bl);
    c_bl = next.normalized();
    result->rounds.push_back(r);
    if (r.change_deg < options.converged_deg()) break;
  }
  result->imu_from_lidar = c_bl;
  result->seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result->rounds.back().change_deg >= options.converged_deg()) {
    return Status::Error(fmt::format(
        "the extrinsic rotation from the motion did not settle: the last of "
        "rotation_search.max_rounds = {} rounds still changed it by {:.2f} deg (at most "
        "rotation_search.converged_deg = {})",
        options.max_rounds(), result->rounds.back().change_deg, options.converged_deg()));
  }
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
