#include "stages/inspect/calibration_notes.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace tiltcal::inspect {
namespace {

// Vibration the calibration's white-noise model does not hold
// (ImuCheckParams.vibration_*).
void AddVibrationNote(const proto::CheckParams& params, const ImuFindings& imu,
                      std::vector<std::string>* notes) {
  const imu::ImuVibration& v = imu.vibration;
  const proto::ImuCheckParams& p = params.imu();
  if (!imu.gyro_vibrates && !imu.accel_vibrates) return;
  const double gyro_ratio = v.gyro.rms.maxCoeff() / p.gyro_noise_radps();
  const double accel_ratio = v.accel.rms.maxCoeff() / p.accel_noise_mps2();
  auto peak = [&](const imu::TriadVibration& t) {
    return t.peak_frequency_hz > 0.0 ? fmt::format(", peak {:.1f} Hz", t.peak_frequency_hz)
                                     : std::string();
  };
  // A peak within the low-pass's transition (about 5.5 / span above the
  // cut-off) is not removed whole.
  const double stop_hz = p.vibration_cutoff_hz() + 5.5 / p.vibration_filter_span_s();
  const double lowest_peak_hz = std::min(imu.gyro_vibrates ? v.gyro.peak_frequency_hz : 1e9,
                                         imu.accel_vibrates ? v.accel.peak_frequency_hz : 1e9);
  notes->push_back(fmt::format(
      "IMU vibration above the motion's band (as sampled at {:.0f} Hz; above {:.0f} Hz it shows "
      "aliased): accelerometer RMS up to {:.3f} m/s² ({:.0f} × the {:g} m/s² white noise the "
      "calibration assumes{}), gyro up to {:.4f} rad/s ({:.0f} × {:g} rad/s{}). The calibration "
      "low-passes the IMU at {:g} Hz before the fit (calibrate params imu_vibration, AUTO){}{}",
      v.sample_rate_hz, 0.5 * v.sample_rate_hz, v.accel.rms.maxCoeff(), accel_ratio,
      p.accel_noise_mps2(), peak(v.accel), v.gyro.rms.maxCoeff(), gyro_ratio,
      p.gyro_noise_radps(), peak(v.gyro), p.vibration_cutoff_hz(),
      lowest_peak_hz > 0.0 && lowest_peak_hz < stop_hz
          ? fmt::format("; at {:.1f} Hz the vibration is too near that cut-off to be removed "
                        "whole: expect IMU residuals above their model",
                        lowest_peak_hz)
          : std::string(),
      imu.static_start_after_low_pass ? "; the static start shows only after that low-pass"
                                      : ""));
}

void AddImuNotes(const proto::CheckParams& params, CheckFindings* f) {
  const ImuFindings& imu = f->imu;
  if (imu.stamps.count < 2) return;
  auto& notes = f->notes;
  if (imu.accel.unit == imu::AccelUnit::kStandardGravity) {
    notes.push_back("IMU accelerometer in g: it will be converted to m/s² (× 9.80665)");
  }
  if (imu.gyro_unit == imu::GyroUnit::kDegreesPerSecond) {
    notes.push_back(fmt::format(
        "IMU gyro in deg/s ({:g}th percentile |ω| {:.1f}, more than a vehicle turns in rad/s): "
        "it will be converted to rad/s (× π/180)",
        imu.gyro.percentile, imu.gyro.rate_at_percentile));
  }
  if (!imu.static_start.found) {
    notes.push_back(
        "no static start: the gyro bias starts at zero and gravity comes from the mean of the "
        "first seconds (calibrate params: init.fallback_window_s); start the recording with "
        "the vehicle still for a few seconds if you can");
  }
  if (imu.stamps.num_gaps > 0) {
    notes.push_back(
        fmt::format("{} gap(s) in the IMU stamps (longest {:.3f} s): the "
                    "trajectory has no IMU data there",
                    imu.stamps.num_gaps, imu.stamps.longest_gap_s));
  }
  if (imu.stamps.num_duplicates > 0) {
    notes.push_back(
        fmt::format("{} repeated IMU stamp(s): tiltcal_decode keeps the first "
                    "sample of each stamp",
                    imu.stamps.num_duplicates));
  }
  if (imu.stamps.num_backwards > 0) {
    notes.push_back(
        fmt::format("{} IMU stamp(s) earlier than the one before: tiltcal_decode "
                    "sorts the samples by stamp",
                    imu.stamps.num_backwards));
  }
  AddVibrationNote(params, imu, &notes);
  const ImuExcitation& e = imu.excitation;
  if (imu.stamps.count >= 2 && imu.accel.unit &&
      e.rotation_speed_p95_radps < params.imu().min_rotation_radps()) {
    f->problems.push_back(fmt::format(
        "no rotation: 95th percentile of |ω| is {:.4f} rad/s (below {:.4f}); the extrinsic "
        "rotation cannot be determined from this motion",
        e.rotation_speed_p95_radps, params.imu().min_rotation_radps()));
  } else if (imu.stamps.count >= 2 && imu.accel.unit &&
             e.yaw_rate_sign_changes <
                 static_cast<int>(params.excitation().min_yaw_rate_sign_changes())) {
    notes.push_back(
        fmt::format("only {} yaw-rate sign change(s): turns mostly one way; the rotation about the "
                    "vertical and τ are weakly determined (drive both left and right turns)",
                    e.yaw_rate_sign_changes));
  }
}

void AddLidarNotes(const proto::CheckParams& params, CheckFindings* f) {
  const LidarFindings& lidar = f->lidar;
  auto& notes = f->notes;
  if (lidar.stamps.count == 0) return;
  if (lidar.layout.time_field.empty()) {
    notes.push_back(
        "no per-point time field: scans are not deskewed, motion within a sweep "
        "becomes error (slow down, or use a driver that publishes point times)");
  }
  if (lidar.stamps.num_gaps > 0) {
    notes.push_back(fmt::format("{} gap(s) between scans, about {} scan(s) dropped (longest {:.3f} s)",
                                lidar.stamps.num_gaps, lidar.stamps.num_missing,
                                lidar.stamps.longest_gap_s));
  }
  if (lidar.stamps.num_duplicates + lidar.stamps.num_backwards > 0) {
    notes.push_back(
        fmt::format("{} scan stamp(s) not after the one before: tiltcal_decode drops "
                    "them (drop_non_monotonic)",
                    lidar.stamps.num_duplicates + lidar.stamps.num_backwards));
  }
  if (lidar.sampled_scans > 0) {
    const double share = static_cast<double>(lidar.scans_with_ground) / lidar.sampled_scans;
    if (share < params.excitation().min_ground_scan_share()) {
      notes.push_back(
          fmt::format("ground in only {:.0f} % of the scans: few ground residuals; the vertical "
                      "translation and the roll/pitch of the extrinsic rest on the motion alone",
                      100.0 * share));
    }
  }
  if (!f->have_rig) {
    notes.push_back(
        "no --rig: topics found by type, and up taken as the LiDAR z axis for the "
        "ground statistics");
  } else if (f->rig_imu_height_m <= 0.0) {
    notes.push_back(
        "translation along the vertical will come from the rig (no imu_height_m: "
        "the ground distance residual is off, and planar motion does not "
        "determine it)");
  }
}

void AddClockNotes(const proto::CheckParams& params, CheckFindings* f) {
  const ClockFindings& c = f->clock;
  if (!c.both || c.overlap_s < params.clock().min_overlap_s()) return;
  if (std::abs(c.stamp_offset_difference_s) > params.clock().time_offset_window_s()) {
    f->notes.push_back(fmt::format(
        "τ may be beyond ±{:.3g} s: LiDAR stamp − record time differs from the IMU's by "
        "{:+.3f} s (τ ≈ {:.3f} s); set the calibrate params' init.coarse_time_offset_window_s to cover it",
        params.clock().time_offset_window_s(), c.stamp_offset_difference_s,
        -c.stamp_offset_difference_s));
  }
  const std::string drift = timing::DescribeClockDrift(c.lidar_vs_imu, c.overlap_s,
                                                       params.clock().max_time_offset_drift_s());
  if (!drift.empty()) f->notes.push_back(drift);
}

// The extrinsic of /tf_static, when there is one: a starting value the user
// can take into the rig.
void AddTfStaticNote(CheckFindings* f) {
  if (!f->tf_static.found) return;
  f->notes.push_back(
      "the bag's /tf_static gives an IMU-from-LiDAR extrinsic: `tiltcal_inspect rig --bag=...` "
      "drafts a rig.txtpb with it as imu_from_lidar (the calibration's starting value)");
}

}  // namespace

void AddCalibrationNotes(const proto::CheckParams& params, CheckFindings* f) {
  AddTfStaticNote(f);
  AddImuNotes(params, f);
  AddLidarNotes(params, f);
  AddClockNotes(params, f);
}

}  // namespace tiltcal::inspect
