#include "stages/inspect/check_findings.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "common/checked_conversion.h"
#include "common/io/eigen_proto.h"
#include "common/io/static_detection_params.h"
#include "stages/inspect/calibration_notes.h"
#include "stages/inspect/scan_geometry.h"

namespace tiltcal::inspect {
namespace {

// Seconds between two ns stamps.
double SecondsBetween(int64_t from_ns, int64_t to_ns) {
  return DifferenceSeconds(to_ns, from_ns);
}

double MedianDifferenceS(const std::vector<int64_t>& a_ns, const std::vector<int64_t>& b_ns) {
  std::vector<double> d(a_ns.size());
  for (size_t i = 0; i < a_ns.size(); ++i) d[i] = SecondsBetween(b_ns[i], a_ns[i]);
  return Median(std::move(d));
}

// The IMU messages in stamp order, one per stamp (as tiltcal_decode keeps
// them), in the published units; time_s from the first stamp.
std::vector<imu::ImuReading> ReadingsInStampOrder(const BagSurvey& survey) {
  std::vector<size_t> order(survey.imu_stamp_ns.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return survey.imu_stamp_ns[a] < survey.imu_stamp_ns[b];
  });
  std::vector<imu::ImuReading> readings;
  readings.reserve(order.size());
  int64_t previous_ns = 0;
  for (size_t i : order) {
    const int64_t stamp_ns = survey.imu_stamp_ns[i];
    if (!readings.empty() && stamp_ns == previous_ns) continue;
    if (!survey.gyro[i].allFinite() || !survey.accel[i].allFinite()) continue;
    previous_ns = stamp_ns;
    imu::ImuReading r;
    r.time_s = SecondsBetween(survey.imu_stamp_ns[order[0]], stamp_ns);
    r.angular_velocity_radps = survey.gyro[i];
    r.linear_acceleration_mps2 = survey.accel[i];
    readings.push_back(r);
  }
  return readings;
}

void AnalyseImu(const BagSurvey& survey, const proto::CheckParams& params, CheckFindings* f) {
  ImuFindings& imu = f->imu;
  imu.stamps = ComputeStampStatistics(survey.imu_stamp_ns, params.imu().gap_factor());
  imu.stamp_minus_record_s = MedianDifferenceS(survey.imu_stamp_ns, survey.imu_record_ns);
  std::vector<imu::ImuReading> readings = ReadingsInStampOrder(survey);
  if (readings.size() < 2) {
    f->problems.push_back(
        fmt::format("IMU: {} usable sample(s) on '{}'", readings.size(), f->imu_topic));
    return;
  }
  imu.gyro = imu::DetectGyroUnitFromRates(readings, params.imu().gyro_rate_percentile(),
                                          params.imu().max_vehicle_turn_rate_radps());
  if (!imu.gyro.unit) {
    f->problems.push_back(fmt::format(
        "IMU: {:g}th percentile of |ω| {:.1f} is more than a vehicle turns even in deg/s: "
        "the gyro's unit or scale is unknown",
        imu.gyro.percentile, imu.gyro.rate_at_percentile));
    return;
  }
  imu.gyro_unit = *imu.gyro.unit;
  imu.accel = imu::DetectAccelUnit(readings, {});
  if (!imu.accel.unit) {
    f->problems.push_back(
        fmt::format("IMU: median |specific force| {:.3f} is neither m/s² (≈9.81) nor g (≈1): "
                    "the accelerometer's unit or scale is unknown",
                    imu.accel.median_norm));
    return;
  }
  const std::vector<imu::ImuReading> published = readings;
  imu::ConvertToSi(*imu.accel.unit, imu.gyro_unit, &readings);
  imu::VibrationOptions vibration;
  vibration.low_pass.cutoff_hz = params.imu().vibration_cutoff_hz();
  vibration.low_pass.span_s = params.imu().vibration_filter_span_s();
  vibration.low_pass.max_gap_s = params.imu().vibration_max_gap_s();
  vibration.spectrum_segment_s = params.imu().vibration_spectrum_segment_s();
  vibration.max_segments = static_cast<int>(params.imu().vibration_max_segments());
  imu.vibration = imu::MeasureImuVibration(readings, vibration);
  const proto::ImuCheckParams& p = params.imu();
  if (imu.vibration.num_samples > 0) {
    imu.gyro_vibrates =
        imu.vibration.gyro.rms.maxCoeff() > p.vibration_factor() * p.gyro_noise_radps();
    imu.accel_vibrates =
        imu.vibration.accel.rms.maxCoeff() > p.vibration_factor() * p.accel_noise_mps2();
  }
  // The static start as the calibration finds it: on the low-pass when it
  // filters (vibration of an idling engine hides it in the readings).
  const imu::StaticDetectionOptions static_options =
      ToStaticDetectionOptions(params.static_detection());
  imu.static_start = imu::DetectStaticStart(readings, static_options);
  if (!imu.static_start.found && (imu.gyro_vibrates || imu.accel_vibrates)) {
    imu.static_start = imu::DetectStaticStart(
        imu::LowPassAndDecimateImu(readings, vibration.low_pass, 1), static_options);
    imu.static_start_after_low_pass = imu.static_start.found;
  }
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  if (imu.static_start.found) {
    imu.accel = imu::DetectAccelUnit(published, {imu.static_start});
    gyro_bias = imu.static_start.mean_gyro_radps;
    imu.specific_force_at_rest_mps2 = imu.static_start.mean_accel_mps2;
  } else {
    for (const imu::ImuReading& r : readings) {
      imu.specific_force_at_rest_mps2 += r.linear_acceleration_mps2;
    }
    imu.specific_force_at_rest_mps2 /= static_cast<double>(readings.size());
  }
  ExcitationOptions excitation;
  excitation.smoothing_window_s = params.excitation().smoothing_window_s();
  excitation.yaw_rate_hysteresis_radps = params.excitation().yaw_rate_hysteresis_radps();
  excitation.lateral_accel_hysteresis_mps2 = params.excitation().lateral_accel_hysteresis_mps2();
  imu.excitation =
      MeasureImuExcitation(readings, gyro_bias, imu.specific_force_at_rest_mps2, excitation);
}

ScanGeometryOptions ToScanGeometryOptions(const proto::LidarCheckParams& p) {
  ScanGeometryOptions o;
  o.ground_min_depth_m = p.ground_min_depth_m();
  o.ground_max_range_m = p.ground_max_range_m();
  o.ground_inlier_distance_m = p.ground_inlier_distance_m();
  o.ground_max_tilt_deg = p.ground_max_tilt_deg();
  o.min_ground_fraction = p.min_ground_fraction();
  o.ground_fit_max_iterations =
      p.has_ground_fit_max_iterations() ? static_cast<int>(p.ground_fit_max_iterations()) : 5;
  o.structure_min_height_m = p.structure_min_height_m();
  o.structure_max_range_m = p.structure_max_range_m();
  return o;
}

void AnalyseLidar(const BagSurvey& survey, const proto::Rig* rig, const proto::CheckParams& params,
                  CheckFindings* f) {
  LidarFindings& lidar = f->lidar;
  lidar.stamps = ComputeStampStatistics(survey.scan_stamp_ns, params.lidar().gap_factor());
  lidar.stamp_minus_record_s = MedianDifferenceS(survey.scan_stamp_ns, survey.scan_record_ns);
  lidar.layout = survey.layout;
  if (!survey.scan_num_points.empty()) {
    std::vector<int64_t> points = survey.scan_num_points;
    std::sort(points.begin(), points.end());
    lidar.min_points = points.front();
    lidar.max_points = points.back();
    lidar.median_points = points[points.size() / 2];
  }
  // Up in the LiDAR frame: the specific force at rest (up in b) through C_bl^T.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d& f_rest = f->imu.specific_force_at_rest_mps2;
  if (rig && rig->has_imu_from_lidar() && HasValidRotation(rig->imu_from_lidar()) &&
      f_rest.norm() > 0.0) {
    up = ToEigen(rig->imu_from_lidar()).rotation.conjugate() * f_rest.normalized();
    lidar.up_from_rig = true;
  }
  const ScanGeometryOptions geometry = ToScanGeometryOptions(params.lidar());
  lidar.structure_max_range_m = geometry.structure_max_range_m;
  double structure_sum = 0.0;
  lidar.min_time_offset_s = std::numeric_limits<double>::infinity();
  lidar.max_time_offset_s = -lidar.min_time_offset_s;
  for (const CloudSample& scan : survey.sampled_scans) {
    const ScanGeometry g = MeasureScanGeometry(scan.x, scan.y, scan.z, up, geometry);
    ++lidar.sampled_scans;
    lidar.scans_with_ground += g.has_ground ? 1 : 0;
    structure_sum += g.structure_fraction;
    if (!scan.has_time) continue;
    lidar.has_time_offsets = true;
    lidar.min_time_offset_s = std::min(lidar.min_time_offset_s, scan.min_time_offset_s);
    lidar.max_time_offset_s = std::max(lidar.max_time_offset_s, scan.max_time_offset_s);
  }
  if (!lidar.has_time_offsets) lidar.min_time_offset_s = lidar.max_time_offset_s = 0.0;
  if (lidar.sampled_scans > 0) lidar.structure_fraction = structure_sum / lidar.sampled_scans;
  if (survey.scan_stamp_ns.empty()) {
    f->problems.push_back(fmt::format("LiDAR: no message on '{}'", f->lidar_topic));
  } else if (!survey.layout.has_xyz) {
    f->problems.push_back(
        fmt::format("LiDAR: the clouds on '{}' have no x, y, z fields", f->lidar_topic));
  }
}

void AnalyseClock(const BagSurvey& survey, const proto::CheckParams& params, CheckFindings* f) {
  const StampStatistics& i = f->imu.stamps;
  const StampStatistics& l = f->lidar.stamps;
  if (i.count == 0 || l.count == 0) return;
  ClockFindings& c = f->clock;
  c.both = true;
  c.overlap_s = SecondsBetween(std::max(i.first_ns, l.first_ns), std::min(i.last_ns, l.last_ns));
  c.stamp_offset_difference_s = f->lidar.stamp_minus_record_s - f->imu.stamp_minus_record_s;
  if (c.overlap_s < params.clock().min_overlap_s()) {
    f->problems.push_back(fmt::format(
        "clock: the IMU stamps ({:.3f} .. {:.3f} s) and the LiDAR stamps ({:.3f} .. {:.3f} s) "
        "{} (different clock domains?): restamp one stream, or set the decode params' "
        "lidar_stamp_shift_s (s added to every LiDAR stamp) to cover the offset",
        1e-9 * i.first_ns, 1e-9 * i.last_ns, 1e-9 * l.first_ns, 1e-9 * l.last_ns,
        c.overlap_s < 0.0 ? fmt::format("do not overlap (apart by {:.3f} s)", -c.overlap_s)
                          : fmt::format("overlap only {:.3f} s", c.overlap_s)));
  }
  const double window_s = params.clock().rate_window_s();
  c.imu_rate = timing::EstimateClockRate(survey.imu_stamp_ns, survey.imu_record_ns, window_s);
  c.lidar_rate = timing::EstimateClockRate(survey.scan_stamp_ns, survey.scan_record_ns, window_s);
  c.lidar_vs_imu = timing::ClockRateBetween(c.lidar_rate, c.imu_rate, c.overlap_s);
}

}  // namespace

CheckFindings AnalyseSurvey(const BagSurvey& survey, const proto::Rig* rig,
                            const proto::CheckParams& params) {
  CheckFindings f;
  f.bag = survey.path;
  f.format = survey.format;
  f.tf_static = survey.tf_static;
  f.file_size = survey.file_size;
  f.indexed = survey.indexed;
  f.imu_topic = survey.imu_topic;
  f.lidar_topic = survey.lidar_topic;
  f.have_rig = rig != nullptr;
  f.rig_imu_height_m = rig ? rig->imu_height_m() : 0.0;
  if (!survey.imu_problem.empty()) f.problems.push_back("IMU: " + survey.imu_problem);
  if (!survey.lidar_problem.empty()) f.problems.push_back("LiDAR: " + survey.lidar_problem);
  if (!survey.imu_topic.empty()) AnalyseImu(survey, params, &f);
  if (!survey.lidar_topic.empty()) AnalyseLidar(survey, rig, params, &f);
  AnalyseClock(survey, params, &f);
  AddCalibrationNotes(params, &f);
  return f;
}

}  // namespace tiltcal::inspect
