#ifndef TILTCAL_COMMON_IMU_ANGULAR_SPEED_ALIGNMENT_H_
#define TILTCAL_COMMON_IMU_ANGULAR_SPEED_ALIGNMENT_H_

#include <vector>

#include "common/status.h"

namespace tiltcal::imu {

// A scalar signal sampled at increasing times (s), e.g. the angular speed
// |ω| of the gyro or of the LiDAR odometry, each on its own clock.
struct TimedValue {
  double time_s = 0.0;
  double value = 0.0;
};

struct AngularSpeedAlignmentOptions {
  // τ is searched in [-max_time_offset_s, +max_time_offset_s], s.
  double max_time_offset_s = 0.0;
  // Resolution of the search grid, s; the peak is refined to a fraction of it
  // by a parabola through the three best lags.
  double grid_step_s = 0.0;
  // Lags whose overlap is shorter than this are not considered, s.
  double min_overlap_s = 0.0;
  // Reference samples slower than this take no part in the scale, rad/s in
  // the reference's unit (the ratio of two small speeds is noise).
  double min_reference_speed = 0.0;
};

// The clock offset and the scale between the gyro's angular speed and a
// reference angular speed (the LiDAR odometry's), with the time convention of
// the calibration: a reference stamp t_l happened at gyro time t_l + τ, so
// s_gyro(t_l + τ) ≈ scale · s_reference(t_l). Both speeds are resampled on one
// grid (linear interpolation) and τ maximises their normalised
// cross-correlation (Pearson's r over the overlap); the correlation does not
// depend on the units, so τ is found whatever unit the gyro publishes.
// scale = Σ s_g s_r / Σ s_r² over the overlap at τ (reference samples faster
// than min_reference_speed): about 1 for a gyro in rad/s against a reference
// in rad/s, about 180/π = 57.3 for a gyro in deg/s.
struct AngularSpeedAlignment {
  double time_offset_s = 0.0;   // τ
  double correlation = 0.0;     // Pearson's r at τ, in [-1, 1]
  double scale = 0.0;           // gyro / reference at τ
  // r at the best lag outside the main peak's lobe (the lags around τ over
  // which r falls from its maximum); a main peak that does not stand out
  // from it (periodic motion) makes τ ambiguous. -1 when there is none.
  double second_peak_correlation = 0.0;
  bool at_search_bound = false;  // τ is within one grid step of ±max_time_offset_s
};

// Errors name what is missing: too few samples, no overlap at any lag, a
// signal without variation (no rotation, nothing to correlate).
Status AlignAngularSpeeds(const std::vector<TimedValue>& gyro_speed,
                          const std::vector<TimedValue>& reference_speed,
                          const AngularSpeedAlignmentOptions& options,
                          AngularSpeedAlignment* alignment);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_ANGULAR_SPEED_ALIGNMENT_H_
