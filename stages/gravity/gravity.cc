#include "stages/gravity/gravity.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "common/checked_conversion.h"
#include "common/geometry/angles.h"
#include "common/imu/gyro_integrator.h"
#include "common/imu/imu_initialisation.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
#include "common/io/static_detection_params.h"
#include "common/io/text_proto.h"
#include "stages/gravity/gravity_reference.h"

namespace tiltcal::gravity {

namespace {

using geometry::AngleBetweenDeg;

// Linear-interpolated percentile (0..100) of non-empty `values`.
double Percentile(std::vector<double> values, double percentile) {
  std::sort(values.begin(), values.end());
  const double rank = percentile / 100.0 * static_cast<double>(values.size() - 1);
  const size_t low = static_cast<size_t>(std::floor(rank));
  const size_t high = std::min(low + 1, values.size() - 1);
  return values[low] + (rank - low) * (values[high] - values[low]);
}

// The specific force of the static windows (−g_b on level ground): summed
// over their samples.
struct StaticForce {
  Eigen::Vector3d sum_mps2 = Eigen::Vector3d::Zero();
  size_t num_samples = 0;
};

// Static windows of the accelerometer, added to `out`, and their specific
// force.
StaticForce AddStaticWindows(const GravityInputs& inputs,
                             const imu::StaticDetectionOptions& options,
                             proto::GravityReference* out) {
  StaticForce force;
  for (const imu::StaticInterval& interval : imu::DetectStaticIntervals(inputs.imu, options)) {
    proto::StaticWindow* window = out->add_static_windows();
    window->set_begin_ns(inputs.first_imu_stamp_ns + std::llround(interval.begin_s * 1e9));
    window->set_end_ns(inputs.first_imu_stamp_ns + std::llround(interval.end_s * 1e9));
    *window->mutable_mean_accel_mps2() = ToProto(interval.mean_accel_mps2);
    window->set_accel_std_mps2(interval.accel_std_mps2);
    window->set_gyro_std_radps(interval.gyro_std_radps);
    const size_t n = interval.end_index - interval.begin_index;
    force.sum_mps2 += interval.mean_accel_mps2 * static_cast<double>(n);
    force.num_samples += n;
  }
  return force;
}

// One inclination sample per ground plane: g̃_b = −C_ab(t)^T g_a / |g_a| at
// t = t_scan + τ (returned in *ups) and, for a valid plane, the ground slope
// ∠(g̃_b, C_bl n_l) (returned in *slopes).
void AddInclinationSamples(const GravityInputs& inputs, const imu::ImuInitialisation& init,
                           double time_offset_s, proto::GravityReference* out,
                           std::vector<Eigen::Vector3d>* ups, std::vector<double>* slopes) {
  const imu::GyroIntegrator attitude(inputs.imu, init.gyro_bias_radps);
  const Eigen::Vector3d up_in_world = -init.gravity_in_world_mps2.normalized();
  const Eigen::Quaterniond imu_from_lidar = ToEigen(inputs.rig.imu_from_lidar().rotation());
  for (const proto::GroundPlane& plane : inputs.ground) {
    const double t = DifferenceSeconds(plane.stamp_ns(), inputs.first_imu_stamp_ns) + time_offset_s;
    const Eigen::Vector3d up_in_imu = attitude.Rotation(t).conjugate() * up_in_world;
    proto::InclinationSample* sample = out->add_inclination();
    sample->set_stamp_ns(plane.stamp_ns());
    *sample->mutable_up_in_imu() = ToProto(up_in_imu);
    ups->push_back(up_in_imu);
    if (plane.valid()) {
      const double slope =
          AngleBetweenDeg(up_in_imu, imu_from_lidar * ToEigen(plane.normal_in_lidar()));
      sample->set_ground_slope_deg(slope);
      slopes->push_back(slope);
    }
  }
}

// Level when the percentile of the ground slopes is below the threshold; not
// level when no slope is known.
void SetLevelVerdict(const std::vector<double>& slopes, const proto::LevelVerdictParams& params,
                     proto::GravityReference* out) {
  if (slopes.empty()) {
    out->set_is_level(false);
    out->set_level_statistic(
        "no valid ground plane: the ground slope is unknown, so the sequence is not taken as "
        "level");
    return;
  }
  const double statistic = Percentile(slopes, params.percentile());
  out->set_level_statistic_deg(statistic);
  out->set_is_level(statistic < params.threshold_deg());
  out->set_level_statistic(
      fmt::format("{:.0f}th percentile of the ground slope over {} valid ground planes: {:.3f} "
                  "deg (level below {:.3f} deg)",
                  params.percentile(), slopes.size(), statistic, params.threshold_deg()));
}

// g_f: from the dataset when it names one; else on a level sequence from the
// static windows (−|g| times the direction of their mean specific force) and
// from a flat-ground calibration (its g_a), preferring the calibration.
void SetFlatGravity(const GravityInputs& inputs, double gravity_norm_mps2,
                    const StaticForce& static_force, proto::GravityReference* out) {
  if (inputs.dataset_reference.has_gravity_flat()) {
    out->set_has_gravity_flat(true);
    *out->mutable_gravity_flat_in_imu() = inputs.dataset_reference.gravity_flat_in_imu();
    out->set_gravity_flat_source(inputs.dataset_reference_source);
    return;
  }
  if (!out->is_level()) return;
  const bool from_static = static_force.num_samples > 0;
  const bool from_calibration = inputs.flat_calibration != nullptr;
  if (from_static) {
    *out->mutable_gravity_from_static() =
        ToProto(Eigen::Vector3d(-gravity_norm_mps2 * static_force.sum_mps2.normalized()));
  }
  if (from_calibration) {
    *out->mutable_gravity_from_calibration() = inputs.flat_calibration->gravity_in_world();
  }
  if (from_static && from_calibration) {
    out->set_sources_disagreement_deg(AngleBetweenDeg(ToEigen(out->gravity_from_static()),
                                               ToEigen(out->gravity_from_calibration())));
  }
  if (from_static || from_calibration) {
    out->set_has_gravity_flat(true);
    // The calibration's g_a is optimised with the accelerometer bias; prefer it.
    *out->mutable_gravity_flat_in_imu() =
        from_calibration ? out->gravity_from_calibration() : out->gravity_from_static();
    out->set_gravity_flat_source(from_static && from_calibration ? "both"
                                 : from_calibration          ? "calibration"
                                                             : "static_windows");
  }
}

}  // namespace

Status EstimateGravityReference(const GravityInputs& inputs, const proto::GravityParams& params,
                                proto::GravityReference* out) {
  imu::ImuInitialisationOptions init_options;
  init_options.static_detection = ToStaticDetectionOptions(params.static_detection());
  init_options.gravity_norm_mps2 = params.gravity_norm_mps2();
  init_options.fallback_window_s = params.fallback_window_s();
  imu::ImuInitialisation init;
  TILTCAL_RETURN_IF_ERROR(imu::InitialiseImu(inputs.imu, init_options, &init));
  *out->mutable_gravity_in_world() = ToProto(init.gravity_in_world_mps2);
  *out->mutable_gyro_bias_radps() = ToProto(init.gyro_bias_radps);
  const StaticForce static_force = AddStaticWindows(inputs, init_options.static_detection, out);

  std::vector<Eigen::Vector3d> ups;
  std::vector<double> slopes;
  AddInclinationSamples(inputs, init, params.time_offset_s(), out, &ups, &slopes);
  SetLevelVerdict(slopes, params.level_verdict(), out);
  SetFlatGravity(inputs, params.gravity_norm_mps2(), static_force, out);
  if (out->has_gravity_flat()) {
    const Eigen::Vector3d up_flat = -ToEigen(out->gravity_flat_in_imu()).normalized();
    for (int i = 0; i < out->inclination_size(); ++i) {
      out->mutable_inclination(i)->set_inclination_deg(AngleBetweenDeg(ups[i], up_flat));
    }
  }
  return Status::Ok();
}

namespace {

// g_f named by the rig: its own gravity_flat_in_imu, or the gravity
// reference at a path relative to the dataset (the rig's folder): a flat
// dataset folder (its out/gravity_reference.txtpb) or a flat run's
// gravity.txtpb.
Status ReadDatasetReference(const std::string& rig_path, const proto::Rig& rig,
                            proto::GravityReference* reference, std::string* source) {
  if (rig.has_gravity_flat_in_imu() && ToEigen(rig.gravity_flat_in_imu()).norm() > 0) {
    reference->set_has_gravity_flat(true);
    *reference->mutable_gravity_flat_in_imu() = rig.gravity_flat_in_imu();
    *source = "rig";
    return Status::Ok();
  }
  if (rig.gravity_reference().empty()) return Status::Ok();
  const std::string path = ResolveGravityReferencePath(rig_path, rig.gravity_reference());
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(path, reference));
  if (!reference->has_gravity_flat()) {
    return Status::Error(path + ": the gravity reference named by " + rig_path +
                         " has no gravity_flat_in_imu (was its sequence level?)");
  }
  TILTCAL_RETURN_IF_ERROR(
      ValidateGravityFlat(reference->gravity_flat_in_imu(), "gravity_flat_in_imu").WithContext(path));
  *source = "reference " + rig.gravity_reference();
  return Status::Ok();
}

// The summary of a run: static windows, verdict, g_f and its source, and a
// warning when the two sources of g_f disagree.
void LogSummary(const proto::GravityReference& out, const proto::GravityParams& params,
                std::ostream* log) {
  if (log == nullptr) return;
  *log << "tiltcal_gravity: " << out.static_windows_size() << " static windows; "
       << (out.is_level() ? "level" : "tilted") << ": " << out.level_statistic() << "\n";
  if (out.has_gravity_flat()) {
    const Eigen::Vector3d g_f = ToEigen(out.gravity_flat_in_imu());
    *log << fmt::format("tiltcal_gravity: g_f = ({:.4f}, {:.4f}, {:.4f}) m/s^2 from {}\n",
                        g_f.x(), g_f.y(), g_f.z(), out.gravity_flat_source());
  } else {
    *log << "tiltcal_gravity: no g_f (tilted sequence and none in the rig)\n";
  }
  if (out.sources_disagreement_deg() > params.max_sources_disagreement_deg()) {
    *log << fmt::format("tiltcal_gravity: warning: g_f from the static windows and from the "
                        "calibration disagree by {:.3f} deg\n",
                        out.sources_disagreement_deg());
  }
}

}  // namespace

namespace {

// A valid plane's normal is a unit vector: NaN or zero normals (a corrupt
// or hand-made file) are an error naming the file and the record, not a
// slope of NaN in the percentile or a level ground.
Status CheckGroundNormals(const std::string& path, const std::vector<proto::GroundPlane>& planes) {
  for (size_t i = 0; i < planes.size(); ++i) {
    if (!planes[i].valid()) continue;
    const double norm = ToEigen(planes[i].normal_in_lidar()).norm();
    if (!(std::fabs(norm - 1.0) <= 1e-3)) {
      return Status::Error(fmt::format(
          "{}: record {}: normal_in_lidar of a valid plane has norm {} (a unit vector expected)",
          path, i, norm));
    }
  }
  return Status::Ok();
}

// The flat calibration's g_a must be a gravity: present, finite, its norm
// within the rig's bounds for g_f.
Status CheckCalibrationGravity(const std::string& path,
                               const proto::CalibrationResult& calibration) {
  const double g = ToEigen(calibration.gravity_in_world()).norm();
  if (!calibration.has_gravity_in_world() || !(g >= kRigMinGravityMps2 && g <= kRigMaxGravityMps2)) {
    return Status::Error(fmt::format(
        "{}: gravity_in_world has norm {} (missing or not a gravity in m/s², expected {} to {})",
        path, g, kRigMinGravityMps2, kRigMaxGravityMps2));
  }
  return Status::Ok();
}

}  // namespace

Status Run(const GravityPaths& paths, const proto::GravityParams& params, std::ostream* log) {
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out));
  GravityInputs inputs;
  TILTCAL_RETURN_IF_ERROR(ReadImuReadings(paths.imu, &inputs.imu, &inputs.first_imu_stamp_ns));
  if (!paths.ground.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadAllRecords<proto::GroundPlane>(paths.ground, &inputs.ground));
    TILTCAL_RETURN_IF_ERROR(CheckGroundNormals(paths.ground, inputs.ground));
  }
  TILTCAL_RETURN_IF_ERROR(LoadRigWithExtrinsic(paths.rig, &inputs.rig));
  TILTCAL_RETURN_IF_ERROR(ReadDatasetReference(paths.rig, inputs.rig, &inputs.dataset_reference,
                                               &inputs.dataset_reference_source));
  proto::CalibrationResult calibration;
  if (!paths.calibration.empty()) {
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.calibration, &calibration));
    TILTCAL_RETURN_IF_ERROR(CheckCalibrationGravity(paths.calibration, calibration));
    inputs.flat_calibration = &calibration;
  }

  proto::GravityReference out;
  TILTCAL_RETURN_IF_ERROR(EstimateGravityReference(inputs, params, &out));
  std::vector<InputPath> input_paths = {{"imu", paths.imu}, {"rig", paths.rig}};
  if (!paths.ground.empty()) input_paths.push_back({"ground", paths.ground});
  if (!paths.calibration.empty()) input_paths.push_back({"calibration", paths.calibration});
  if (!paths.params.empty()) input_paths.push_back({"params", paths.params});
  *out.mutable_provenance() =
      MakeProvenance("tiltcal_gravity", params, input_paths, paths.command_line);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out, out));
  LogSummary(out, params, log);
  return Status::Ok();
}

}  // namespace tiltcal::gravity
