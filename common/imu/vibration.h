#ifndef TILTCAL_COMMON_IMU_VIBRATION_H_
#define TILTCAL_COMMON_IMU_VIBRATION_H_

// What an IMU reads above the band a vehicle's motion (and the calibration's
// spline) lives in: engine and wheel vibration, or a noisier sensor than the
// noise model says (docs/design.md §6).
//
// High-pass: each reading minus its low-pass, a Blackman-windowed sinc of
// cut-off cutoff_hz over filter_span_s (for 12 Hz over 0.5 s: gain 1 up to
// about 7 Hz, 0 from about 17 Hz, the transition 5.5 / span wide), on the
// sample grid (the median interval). A vibration above the transition
// passes whole, white noise of σ per sample as about σ, a vehicle's sway of
// a few Hz not at all. Samples whose filter span reaches past the ends or
// holds a gap (an interval over 1.5 median ones) are left out.
//
// Spectrum: Welch's average of Hann-windowed periodograms of the high-passed
// signal over segments of spectrum_segment_s without a gap (at most
// max_segments of them, spread evenly), summed over the triad's axes; the
// peak is its strongest bin above cutoff_hz, in Hz as sampled (a vibration
// above the Nyquist frequency shows aliased).

#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"

namespace tiltcal::imu {

struct VibrationOptions {
  double cutoff_hz = 0.0;
  double filter_span_s = 0.0;
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
  int num_samples = 0;   // high-passed samples (0: too few for a window)
  int num_segments = 0;  // spectrum segments
  double sample_rate_hz = 0.0;  // 1 / median interval
};

// The readings in time order (ValidateImuReadings), in SI units.
ImuVibration MeasureImuVibration(const std::vector<ImuReading>& readings,
                                 const VibrationOptions& options);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_VIBRATION_H_
