#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_IMU_VIBRATION_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_IMU_VIBRATION_H_

// Vibration of the IMU (docs/design.md §6, "IMU vibration"): an engine or
// wheels the IMU feels put power far above the band the spline follows
// (its knots 0.05 s apart). The calibration's noise model is white noise of
// imu_noise's sigmas; vibration of 50 times that makes every IMU residual
// far above the model, and an idling engine hides the static start.
//
// The readings are measured (common/imu/vibration.h); when vibration is
// found (AUTO) or always (ON), they are replaced by their zero-phase
// low-pass, thinned to every m-th sample of the grid at the recorded rate
// f_s, m = floor(f_s / max(thinned_rate_hz, 2 f_c)) (4 at 200 Hz: 50 Hz, two
// samples per knot interval, so the spline cannot fit them exactly). The
// residuals' sigmas become imu_noise's / sqrt(m): weighted as independent,
// f_s / m samples per second of sigma / sqrt(m) carry the information per
// second of in-band motion that f_s samples of white noise sigma carried,
// and there are m times fewer IMU residuals.

#include <string>
#include <vector>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// Measures the vibration of *readings (SI, time order) against `noise` and,
// when filtering, replaces *readings and divides noise's two sigmas. An
// error when filtering leaves fewer than 2 readings or the cut-off is not
// below the Nyquist frequency.
Status HandleImuVibration(const proto::ImuVibrationParams& params,
                          std::vector<imu::ImuReading>* readings, proto::ImuNoiseParams* noise,
                          proto::ImuVibrationReport* report);

// How much the residuals of the low-passed, thinned readings understate
// their noise at the low frequencies the extrinsic is taken from: white
// noise of sigma low-passed at f_c keeps 2 f_c / f_s of its variance in each
// sample, modelled as sigma^2 / m, while the variance of its mean over a
// second is that of the raw readings: f_s / (2 f_c m), the tau of
// error_correlation.h for these residuals (2.08 at 200 Hz, f_c 12 Hz,
// m 4). 1 when not filtered.
double LowPassCorrelation(const proto::ImuVibrationReport& report);

// One sentence for the verdict notes and stderr ("" when nothing was found
// or done).
std::string DescribeImuVibration(const proto::ImuVibrationReport& report);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_IMU_VIBRATION_H_
