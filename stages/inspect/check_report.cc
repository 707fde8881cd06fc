#include "stages/inspect/check_report.h"

#include <cmath>
#include <string>

#include <fmt/format.h>

namespace tiltcal::inspect {
namespace {

// One aligned "  label   value" line.
void Line(std::ostream& out, const std::string& label, const std::string& value) {
  out << fmt::format("  {:<24} {}\n", label, value);
}

std::string Seconds(int64_t ns) { return fmt::format("{:.3f}", 1e-9 * static_cast<double>(ns)); }

std::string Gaps(const StampStatistics& s) {
  if (s.num_gaps == 0) return fmt::format("none (> {:g} nominal intervals)", s.gap_factor);
  return fmt::format("{} (> {:g} nominal intervals), about {} message(s) missing, longest {:.3f} s",
                     s.num_gaps, s.gap_factor, s.num_missing, s.longest_gap_s);
}

void WriteStampLines(const StampStatistics& s, const char* count_label, std::ostream& out) {
  Line(out, count_label, fmt::format("{}", s.count));
  if (s.count < 2) return;
  Line(out, "rate",
       fmt::format("{:.2f} Hz (median interval {:.3f} ms)", s.rate_hz, 1e3 * s.nominal_interval_s));
  Line(out, "stamp jitter",
       fmt::format("{:.3f} ms (σ of the intervals)", 1e3 * s.interval_stddev_s));
  Line(out, "gaps", Gaps(s));
  Line(out, "non-increasing",
       fmt::format("{} repeated, {} backwards", s.num_duplicates, s.num_backwards));
}

void WriteImu(const CheckFindings& f, std::ostream& out) {
  out << "IMU      " << (f.imu_topic.empty() ? "(none)" : f.imu_topic) << "\n";
  if (f.imu_topic.empty()) return;
  const ImuFindings& imu = f.imu;
  WriteStampLines(imu.stamps, "samples", out);
  if (imu.stamps.count < 2) return;
  Line(out, "accelerometer",
       fmt::format("{} (median |f| {:.3f}{})",
                   imu.accel.unit ? imu::UnitName(*imu.accel.unit) : std::string("unknown"),
                   imu.accel.median_norm,
                   imu.accel.from_static_samples ? ", static start" : ", all samples"));
  Line(out, "gyro",
       fmt::format("{} ({:g}th percentile |ω| {:.3f} as published)",
                   imu::UnitName(imu.gyro_unit), imu.gyro.percentile, imu.gyro.rate_at_percentile));
  const imu::ImuVibration& v = imu.vibration;
  if (v.num_samples > 0) {
    Line(out, "above the motion's band",
         fmt::format("gyro RMS {:.4f} {:.4f} {:.4f} rad/s{}; accel RMS {:.3f} {:.3f} {:.3f} m/s²{}",
                     v.gyro.rms.x(), v.gyro.rms.y(), v.gyro.rms.z(),
                     imu.gyro_vibrates && v.gyro.peak_frequency_hz > 0.0
                         ? fmt::format(" (vibration, peak {:.1f} Hz)", v.gyro.peak_frequency_hz)
                         : std::string(),
                     v.accel.rms.x(), v.accel.rms.y(), v.accel.rms.z(),
                     imu.accel_vibrates && v.accel.peak_frequency_hz > 0.0
                         ? fmt::format(" (vibration, peak {:.1f} Hz)", v.accel.peak_frequency_hz)
                         : std::string()));
  }
  const imu::StaticInterval& st = imu.static_start;
  Line(out, "static start",
       st.found ? fmt::format("yes, {:.2f} s (gyro bias {:.4f} {:.4f} {:.4f} rad/s{})",
                              st.end_s - st.begin_s, st.mean_gyro_radps.x(), st.mean_gyro_radps.y(),
                              st.mean_gyro_radps.z(),
                              imu.static_start_after_low_pass ? "; after the low-pass" : "")
                : std::string("no"));
}

void WriteLidar(const CheckFindings& f, std::ostream& out) {
  out << "LiDAR    " << (f.lidar_topic.empty() ? "(none)" : f.lidar_topic) << "\n";
  const LidarFindings& l = f.lidar;
  if (f.lidar_topic.empty() || l.stamps.count == 0) return;
  WriteStampLines(l.stamps, "scans", out);
  Line(out, "points per scan",
       fmt::format("{} (median; {} .. {})", l.median_points, l.min_points, l.max_points));
  Line(out, "point time",
       l.layout.time_field.empty() ? std::string("none")
                                   : fmt::format("{} {} ({})", l.layout.time_field,
                                                 l.layout.time_type, l.layout.time_meaning));
  if (l.has_time_offsets) {
    const char* where = l.max_time_offset_s <= 0.0   ? "stamps at the end of the sweep"
                        : l.min_time_offset_s >= 0.0 ? "stamps at the start of the sweep"
                                                     : "stamps inside the sweep";
    // Offsets below 50 µs print as 0 (float32 times are not exact).
    auto offset = [](double s) { return std::abs(s) < 5e-5 ? 0.0 : s; };
    Line(out, "sweep",
         fmt::format("{:+.4f} .. {:+.4f} s from the stamp ({:.1f} ms, {})",
                     offset(l.min_time_offset_s), offset(l.max_time_offset_s),
                     1e3 * (l.max_time_offset_s - l.min_time_offset_s), where));
  }
  Line(out, "ring",
       l.layout.ring_field.empty() ? std::string("none")
                                   : fmt::format("{} {}", l.layout.ring_field, l.layout.ring_type));
}

void WriteClock(const CheckFindings& f, std::ostream& out) {
  if (!f.clock.both) return;
  const StampStatistics& i = f.imu.stamps;
  const StampStatistics& l = f.lidar.stamps;
  out << "clock    header stamps, s\n";
  Line(out, "IMU",
       fmt::format("{} .. {} ({:.3f} s)", Seconds(i.first_ns), Seconds(i.last_ns), i.span_s()));
  Line(out, "LiDAR",
       fmt::format("{} .. {} ({:.3f} s)", Seconds(l.first_ns), Seconds(l.last_ns), l.span_s()));
  Line(out, "overlap",
       f.clock.overlap_s >= 0.0
           ? fmt::format("{:.3f} s", f.clock.overlap_s)
           : fmt::format("NONE: the spans are {:.3f} s apart", -f.clock.overlap_s));
  Line(out, "stamp − record time",
       fmt::format("IMU {:+.4f} s, LiDAR {:+.4f} s (medians)", f.imu.stamp_minus_record_s,
                   f.lidar.stamp_minus_record_s));
  const ClockFindings& c = f.clock;
  Line(out, "LiDAR clock vs IMU's",
       c.lidar_vs_imu.measured
           ? fmt::format("{:+.1f} ± {:.1f} ppm (stamps against the record times; τ drifts "
                         "{:.2f} ms over the overlap)",
                         c.lidar_vs_imu.rate_ppm, c.lidar_vs_imu.sigma_ppm,
                         1e3 * c.lidar_vs_imu.time_offset_drift_s)
           : std::string("not measurable (the record times are the stamps, or too short)"));
}

void WriteExcitation(const CheckFindings& f, std::ostream& out) {
  const bool imu = f.imu.stamps.count >= 2 && f.imu.accel.unit;
  const bool lidar = f.lidar.sampled_scans > 0;
  if (!imu && !lidar) return;
  out << "excitation\n";
  if (imu) {
    const ImuExcitation& e = f.imu.excitation;
    Line(out, "rotation",
         fmt::format("95th percentile |ω| {:.3f} rad/s", e.rotation_speed_p95_radps));
    Line(out, "yaw-rate sign changes",
         fmt::format("{} (peak |yaw rate| {:.3f} rad/s)", e.yaw_rate_sign_changes,
                     e.max_abs_yaw_rate_radps));
    Line(out, "lateral-accel. reversals",
         fmt::format("{} (peak |a_lat| {:.3f} m/s², along IMU {})", e.lateral_accel_reversals,
                     e.max_abs_lateral_accel_mps2, e.lateral_axis_is_x ? "x" : "y"));
  }
  if (lidar) {
    const LidarFindings& l = f.lidar;
    Line(out, "scans with ground",
         fmt::format("{:.0f} % ({} of {} sampled scans; up from {})",
                     100.0 * l.scans_with_ground / l.sampled_scans, l.scans_with_ground,
                     l.sampled_scans, l.up_from_rig ? "the rig and gravity" : "the LiDAR z axis"));
    Line(out, "vertical structure",
         fmt::format("{:.1f} % of the points above the sensor within {:g} m",
                     100.0 * l.structure_fraction, l.structure_max_range_m));
  }
}

}  // namespace

void WriteCheckReport(const CheckFindings& f, std::ostream& out) {
  out << fmt::format("bag      {} ({}, {:.1f} MB, {})\n", f.bag, f.format,
                     1e-6 * static_cast<double>(f.file_size),
                     f.indexed ? "indexed" : "no index: read record by record");
  out << "tf_static " << f.tf_static.summary << "\n";
  for (const std::string& warning : f.tf_static.warnings) out << "  WARNING: " << warning << "\n";
  WriteImu(f, out);
  WriteLidar(f, out);
  WriteClock(f, out);
  WriteExcitation(f, out);
  out << "for the calibration\n";
  if (f.notes.empty()) out << "  - nothing to add\n";
  for (const std::string& note : f.notes) out << "  - " << note << "\n";
  if (f.problems.empty()) {
    out << "verdict: can be calibrated\n";
    return;
  }
  out << "verdict: cannot be calibrated\n";
  for (const std::string& problem : f.problems) out << "  - " << problem << "\n";
}

}  // namespace tiltcal::inspect
