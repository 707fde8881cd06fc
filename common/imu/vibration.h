#ifndef TILTCAL_COMMON_IMU_VIBRATION_H_
#define TILTCAL_COMMON_IMU_VIBRATION_H_

// What an IMU reads above the band a vehicle's motion (and the calibration's
// spline) lives in: engine and wheel vibration, or a noisier sensor than the
// noise model says; and the low-pass that takes it out (docs/design.md §6).
//
// Grid: the readings linearly interpolated onto a uniform grid at their
// median interval from the first reading (jitter and single missing
// readings need nothing more); a grid time whose bracketing readings are
// more than max_gap_s apart gets no value.
//
// Low-pass: a Blackman-windowed sinc of cut-off f_c over a span T on the
// grid, taps h_k = sinc(2 f_c k Δt) w(k Δt) for |k Δt| ≤ T / 2,
//   w(τ) = 0.42 + 0.5 cos(2πτ/T) + 0.08 cos(4πτ/T),
// normalised to sum 1 (gain 1 at 0 Hz). Symmetric, so no delay (τ of the
// calibration is unchanged). For 12 Hz over 0.5 s: gain 1 up to about 7 Hz,
// 0 from about 17 Hz (the transition is about 5.5 / T wide). A grid sample
// gets a value only when every tap has one.
//
// Vibration: each grid sample minus its low-pass (the high-pass), per axis
// its RMS; a vibration above the transition passes whole, white noise of σ per
// sample as σ·sqrt(1 − 2 f_c / f_s), a vehicle's sway of a few Hz not at
// all. Its spectrum: Welch's average of Hann-windowed periodograms over
// segments of spectrum_segment_s of consecutive high-passed samples (at
// most max_segments, spread evenly), summed over a triad's axes; the peak is
// its strongest bin above f_c, in Hz as sampled (a vibration above the
// Nyquist frequency shows aliased).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"

namespace tiltcal::imu {

struct LowPassOptions {
  double cutoff_hz = 0.0;
  double span_s = 0.0;
  double max_gap_s = 0.0;
};

// The readings on the grid (time order, ValidateImuReadings).
struct ImuGrid {
  double start_s = 0.0;
  double interval_s = 0.0;  // 0: fewer than 2 readings
  std::vector<std::optional<ImuReading>> samples;  // time start_s + k interval_s
};
ImuGrid ResampleImu(const std::vector<ImuReading>& readings, double max_gap_s);

// The low-pass of a grid: the same grid, a value where every tap has one.
ImuGrid LowPassImu(const ImuGrid& grid, double cutoff_hz, double span_s);

// The readings resampled, low-passed and thinned to every step-th grid
// sample (those with a value).
std::vector<ImuReading> LowPassAndDecimateImu(const std::vector<ImuReading>& readings,
                                              const LowPassOptions& options, int step);

struct VibrationOptions {
  LowPassOptions low_pass;
  double spectrum_segment_s = 0.0;
  int max_segments = 0;
};

struct TriadVibration {
  Eigen::Vector3d rms = Eigen::Vector3d::Zero();  // of the high-passed signal, per axis
  double peak_frequency_hz = 0.0;                 // 0 when no segment was long enough
};

struct ImuVibration {
  TriadVibration gyro;   // rad/s
  TriadVibration accel;  // m/s^2
  int num_samples = 0;   // high-passed grid samples (0: none)
  int num_segments = 0;  // spectrum segments
  double sample_rate_hz = 0.0;  // 1 / the grid's interval
};

// The readings in time order (ValidateImuReadings), in SI units.
ImuVibration MeasureImuVibration(const std::vector<ImuReading>& readings,
                                 const VibrationOptions& options);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_VIBRATION_H_
