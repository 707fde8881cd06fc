#include "stages/calibrate/report/imu_vibration.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/imu/vibration.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::calibrate {

Status HandleImuVibration(const proto::ImuVibrationParams& params,
                          std::vector<imu::ImuReading>* readings, proto::ImuNoiseParams* noise,
                          proto::ImuVibrationReport* report) {
  *report = proto::ImuVibrationReport();
  report->set_mode(proto::ImuVibrationParams::Mode_Name(params.mode()));
  report->set_readings_recorded(static_cast<int32_t>(readings->size()));
  report->set_readings_used(static_cast<int32_t>(readings->size()));
  report->set_decimation(1);
  report->set_gyro_sigma_radps(noise->gyro_sigma_radps());
  report->set_accel_sigma_mps2(noise->accel_sigma_mps2());
  imu::VibrationOptions options;
  options.low_pass.cutoff_hz = params.cutoff_hz();
  options.low_pass.span_s = params.filter_span_s();
  options.low_pass.max_gap_s = params.max_gap_s();
  options.spectrum_segment_s = params.spectrum_segment_s();
  options.max_segments = static_cast<int>(params.spectrum_max_segments());
  const imu::ImuVibration v = imu::MeasureImuVibration(*readings, options);
  *report->mutable_gyro_rms_radps() = ToProto(v.gyro.rms);
  *report->mutable_accel_rms_mps2() = ToProto(v.accel.rms);
  report->set_gyro_peak_hz(v.gyro.peak_frequency_hz);
  report->set_accel_peak_hz(v.accel.peak_frequency_hz);
  report->set_sample_rate_hz(v.sample_rate_hz);
  report->set_found(v.num_samples > 0 &&
                    (v.gyro.rms.maxCoeff() > params.min_noise_factor() * noise->gyro_sigma_radps() ||
                     v.accel.rms.maxCoeff() > params.min_noise_factor() * noise->accel_sigma_mps2()));
  const bool filter = params.mode() == proto::ImuVibrationParams::ON ||
                      (params.mode() == proto::ImuVibrationParams::AUTO && report->found());
  if (!filter) return Status::Ok();
  if (!(2.0 * params.cutoff_hz() < v.sample_rate_hz)) {
    return Status::Error(fmt::format(
        "imu_vibration.cutoff_hz {:g} is not below the IMU's Nyquist frequency {:g} Hz",
        params.cutoff_hz(), 0.5 * v.sample_rate_hz));
  }
  const double thinned_rate_hz = std::max(params.thinned_rate_hz(), 2.0 * params.cutoff_hz());
  const int m = std::max(1, static_cast<int>(std::floor(v.sample_rate_hz / thinned_rate_hz)));
  std::vector<imu::ImuReading> filtered = imu::LowPassAndDecimateImu(*readings, options.low_pass, m);
  if (filtered.size() < 2) {
    return Status::Error(fmt::format(
        "IMU vibration filter: {} of {} readings have a low-pass (gaps over "
        "imu_vibration.max_gap_s = {:g} s everywhere?)",
        filtered.size(), readings->size(), params.max_gap_s()));
  }
  *readings = std::move(filtered);
  const double scale = 1.0 / std::sqrt(static_cast<double>(m));
  noise->set_gyro_sigma_radps(noise->gyro_sigma_radps() * scale);
  noise->set_accel_sigma_mps2(noise->accel_sigma_mps2() * scale);
  report->set_filtered(true);
  report->set_cutoff_hz(params.cutoff_hz());
  report->set_decimation(m);
  report->set_readings_used(static_cast<int32_t>(readings->size()));
  report->set_gyro_sigma_radps(noise->gyro_sigma_radps());
  report->set_accel_sigma_mps2(noise->accel_sigma_mps2());
  return Status::Ok();
}

double LowPassCorrelation(const proto::ImuVibrationReport& report) {
  if (!report.filtered() || !(report.cutoff_hz() > 0.0) || report.decimation() < 1) return 1.0;
  return std::max(1.0, report.sample_rate_hz() / (2.0 * report.cutoff_hz() *
                                                  static_cast<double>(report.decimation())));
}

std::string DescribeImuVibration(const proto::ImuVibrationReport& r) {
  if (!r.found() && !r.filtered()) return "";
  auto peak = [](double hz) { return hz > 0.0 ? fmt::format(", peak {:.1f} Hz", hz) : std::string(); };
  const std::string measured = fmt::format(
      "{}: gyro RMS up to {:.4f} rad/s{}, accelerometer up to {:.3f} m/s²{} (as sampled at "
      "{:.0f} Hz)",
      r.found() ? "IMU vibration above the spline's band"
                : "IMU above the spline's band (imu_vibration.mode ON)",
      std::max({r.gyro_rms_radps().x(), r.gyro_rms_radps().y(), r.gyro_rms_radps().z()}),
      peak(r.gyro_peak_hz()),
      std::max({r.accel_rms_mps2().x(), r.accel_rms_mps2().y(), r.accel_rms_mps2().z()}),
      peak(r.accel_peak_hz()), r.sample_rate_hz());
  if (!r.filtered()) {
    return measured + " (imu_vibration.mode OFF: not filtered; the IMU residuals carry it)";
  }
  return measured + fmt::format(
      "; the readings were low-passed at {:g} Hz (zero phase: τ unchanged) and every {}th kept "
      "({} of {}), the IMU sigmas divided by sqrt({}) to {:.5f} rad/s and {:.4f} m/s²",
      r.cutoff_hz(), r.decimation(), r.readings_used(), r.readings_recorded(), r.decimation(),
      r.gyro_sigma_radps(), r.accel_sigma_mps2());
}

}  // namespace tiltcal::calibrate
