#ifndef TILTCAL_STAGES_GRAVITY_GRAVITY_REFERENCE_H_
#define TILTCAL_STAGES_GRAVITY_GRAVITY_REFERENCE_H_

// A flat dataset's gravity reference g_f from its calibrations
// (docs/design.md §10). Each flat-ground calibration holds g_a, the gravity
// in the IMU frame at its first sample (gauge C_ab(t0) = 1), estimated with
// the accelerometer bias; a sequence that starts still on level ground has
// g_a = g_f. The static-window g_f of tiltcal_gravity carries the bias
// (a few tenths of a degree); this one does not.
//
// Combined: g_f = mean |g_a,i| · normalise(Σ g_a,i / |g_a,i|) over the used
// calibrations, i.e. the mean direction with the mean norm. A calibration is
// used when it started still (static_start), is level (it used the flat
// residual) and is not SUSPECT (unless flat_calibrations.use_suspect). A used
// g_a further than flat_calibrations.max_angle_from_combined_deg from g_f is
// an error naming it: the IMU moved on the vehicle between runs, or a run did
// not start on level ground. So are used g_a with no common direction within
// that angle (e.g. opposite ones, whose mean direction does not exist), and
// a g_a of any calibration that is not finite or whose norm lies outside
// [min_gravity_norm_mps2, max_gravity_norm_mps2]; each error line names the
// files and their g_a. A calibration whose g_a is zero has no estimate and is
// left out.

#include <ostream>
#include <string>
#include <vector>

#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/gravity_params.pb.h"

namespace tiltcal::gravity {

struct FlatCalibration {
  std::string path;  // names it in the output and in errors
  proto::CalibrationResult result;
};

// min_gravity_norm_mps2 < max_gravity_norm_mps2.
Status ValidateFlatCalibrationsParams(const proto::FlatCalibrationsParams& params);

// Fills gravity_flat_in_imu, has_gravity_flat, gravity_flat_source and
// flat_calibrations* of *out (I/O free).
Status CombineFlatCalibrations(const std::vector<FlatCalibration>& calibrations,
                               const proto::FlatCalibrationsParams& params,
                               proto::GravityReference* out);

// The file a rig's gravity_reference names, relative to the rig's folder: a
// gravity.txtpb, or a flat dataset folder, which means its
// out/gravity_reference.txtpb.
std::string ResolveGravityReferencePath(const std::string& rig_path,
                                        const std::string& gravity_reference);

// Paths of one tiltcal_gravity_reference run.
struct GravityReferencePaths {
  std::vector<std::string> calibrations;  // calibration.txtpb of each sequence
  std::string params;                     // provenance only; empty: the defaults
  std::string out;                        // gravity_reference.txtpb
  std::string command_line;
};

// Reads the calibrations, combines them, writes the reference atomically with
// its provenance and a summary to `log` (nullptr: silent).
Status RunGravityReference(const GravityReferencePaths& paths, const proto::GravityParams& params,
                           std::ostream* log);

}  // namespace tiltcal::gravity

#endif  // TILTCAL_STAGES_GRAVITY_GRAVITY_REFERENCE_H_
