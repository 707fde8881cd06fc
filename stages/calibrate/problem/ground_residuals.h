#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_GROUND_RESIDUALS_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_GROUND_RESIDUALS_H_

// Which ground residuals the calibrator uses (docs/design.md §8) and the
// function that adds them to the ceres::Problem. The residuals themselves are
// in ground_cost_functions.h:
//   flat  e_flat = n_l - C_bl^T g~_b                  (3, level ground only)
//   dist  e_dist = d_l - d_b - n_l^T C_bl^T r_b^{lb}   (1, needs d_b)
//   incl  e_incl = g~_b^T (g~_f - C_bl n_l)            (1, needs g_f)
//   up    e_up   = C_bl n_l - g~_f                     (3, needs g_f)
//
// Selection (GroundResidualsParams.{flat,dist,incl,up}.mode; AUTO = default):
//   dist  AUTO -> on when d_b > 0 (Rig.imu_height_m);
//   flat  AUTO -> on when the sequence is level (GravityReference.is_level);
//   incl  AUTO -> on when the sequence is tilted and g_f is known;
//   up    AUTO -> off (our extension; ON turns it on).
// ON forces a residual on (an error when its input — d_b or g_f — is
// missing; flat ON on a tilted sequence is allowed and said in the reason),
// OFF forces it off.
//
// Weighting, per residual type and per plane (k = flat, dist, incl, up):
//   sigma_k = params.k.sigma (> 0);
//   without params.k.use_plane_covariance: W = I / sigma_k (w = 1 / sigma_k);
//   with it, the plane fit's covariance Sigma of (n_l, d_l)
//   (GroundPlane.covariance, 4x4) is propagated to the residual at the state
//   when the block is added and added to sigma_k^2, then whitened:
//     flat, up (use n_l only, resolved in l): C = sigma^2 I + Sigma_nn (3x3 block),
//                                             W = L^{-1}, C = L L^T;
//     dist: J = d e_dist / d(n_l, d_l) = [-(C_bl^T r_b^{lb})^T, 1],
//           w = (sigma^2 + J Sigma J^T)^{-1/2};
//     incl: J = d e_incl / d n_l = -(C_bl^T g~_b)^T,
//           w = (sigma^2 + J Sigma_nn J^T)^{-1/2}.
//   sigma_k is the floor (model error: ground not planar under the wheels,
//   suspension); the fit covariance alone can be near-singular (the normal's
//   covariance has no component along n_l, and e_incl is first-order
//   insensitive to n_l on level ground). A plane without a usable 4x4
//   covariance falls back to sigma_k alone (counted).
// Each residual type has its own robust loss (GroundLosses): Cauchy with
// params.k.cauchy_scale (in whitened units, i.e. of sigma_k), none when 0.
//
// Planes: skipped when invalid (valid = false, non-finite or non-unit normal,
// d_l <= 0 or non-finite), or when t_k + tau is outside the spline.

#include <cstdint>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>

#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::calibrate {

// What the dataset says about the sequence.
struct GroundSequenceInfo {
  double imu_height_m = 0.0;  // d_b, m; 0 = unknown
  bool is_level = false;      // the ground is level (gravity stage verdict)
  bool level_known = false;   // a gravity reference was given at all
  bool has_gravity_flat = false;
  Eigen::Vector3d gravity_flat_in_imu = Eigen::Vector3d::Zero();  // g_f, m/s^2, IMU frame, down
};

// d_b from the rig; is_level and g_f from the gravity reference (may be
// null); g_f from the rig's gravity_flat_in_imu when the reference has none.
GroundSequenceInfo MakeGroundSequenceInfo(const proto::Rig& rig,
                                          const proto::GravityReference* gravity);

struct GroundResidualSelection {
  bool flat = false;
  bool dist = false;
  bool incl = false;
  bool up = false;
  // One line: the chosen set and why, e.g.
  // "ground residuals dist+incl: dist AUTO on (d_b = 0.420 m); flat AUTO off (tilted); ..."
  std::string reason;
  // "flat+dist", "dist+incl", ... or "none".
  std::string Names() const;
  bool any() const { return flat || dist || incl || up; }
};

// Applies the modes of params to info. Errors (one line, naming the param)
// when a residual is forced ON without its input.
Status SelectGroundResiduals(const proto::GroundResidualsParams& params,
                             const GroundSequenceInfo& info,
                             GroundResidualSelection* selection);

// The robust losses of the four residual types, each shared by all blocks of
// its type (Cauchy losses hold no per-residual state). Owned here, not by the
// Problem: the Problem must be built with
// Options::loss_function_ownership = DO_NOT_TAKE_OWNERSHIP (as
// CalibrationProblem does), and this object must outlive it.
class GroundLosses {
 public:
  explicit GroundLosses(const proto::GroundResidualsParams& params);
  ceres::LossFunction* flat() const { return flat_.get(); }  // null = no robust loss
  ceres::LossFunction* dist() const { return dist_.get(); }
  ceres::LossFunction* incl() const { return incl_.get(); }
  ceres::LossFunction* up() const { return up_.get(); }

 private:
  std::unique_ptr<ceres::LossFunction> flat_, dist_, incl_, up_;
};

struct GroundResidualSummary {
  int num_planes = 0;            // planes given
  int num_invalid = 0;           // skipped: invalid plane
  int num_outside_spline = 0;    // skipped: t_k + tau outside the spline
  int num_used = 0;              // planes that got residual blocks
  int num_without_covariance = 0;  // covariance asked for but unusable: sigma only
  int num_flat = 0, num_dist = 0, num_incl = 0, num_up = 0;  // residual blocks added
  std::string ToString() const;  // one line
};

// Adds the selected residuals of every usable plane to problem. The state's
// parameter blocks must already be in the problem with their manifolds
// (calibration_state.h); this function only adds residual blocks (an error
// when a needed block is missing). Knot windows are chosen from the current
// tau (CalibrationState::TimeWindow) and stay frozen. LiDAR stamps become
// solver time as t_k = (stamp_ns - time_origin_ns) * 1e-9 s, the same origin
// as the spline grid (the first IMU stamp).
struct GroundResidualInputs {
  const std::vector<proto::GroundPlane>& planes;
  const GroundResidualSelection& selection;
  const proto::GroundResidualsParams& params;
  const GroundSequenceInfo& info;
  const GroundLosses& losses;
  int64_t time_origin_ns;
};
Status AddGroundResiduals(const GroundResidualInputs& inputs, CalibrationState* state,
                          ceres::Problem* problem, GroundResidualSummary* summary);

// What MakeGroundResidualAdder selects from and what the adder reads:
// planes, params and losses (and gravity, rig) are referenced by the adder
// and must outlive it. LiDAR stamps become solver time from time_origin_ns
// (the first IMU stamp). log (may be null) gets one line per call of the
// adder with the GroundResidualSummary.
struct GroundAdderInputs {
  const std::vector<proto::GroundPlane>* planes = nullptr;
  int64_t time_origin_ns = 0;
  const proto::Rig* rig = nullptr;
  const proto::GravityReference* gravity = nullptr;  // may be null
  const proto::GroundResidualsParams* params = nullptr;
  const GroundLosses* losses = nullptr;
  std::ostream* log = nullptr;
};

// What it gives: the selected residuals' names ("flat", "dist", ...), the
// reason (one line) and the adder for CalibrationProblem::AddExtraResiduals
// (same signature as ExtraResidualAdder), which calls AddGroundResiduals on
// the current state and reports the number of blocks added; empty when
// nothing is selected or there are no planes.
struct GroundAdder {
  std::function<Status(CalibrationState*, ceres::Problem*, int*)> add;
  std::vector<std::string> used;
  std::string reason;
};

// For tiltcal_calibrate: selects the residuals (SelectGroundResiduals on
// MakeGroundSequenceInfo(rig, gravity)) and makes the adder.
Status MakeGroundResidualAdder(const GroundAdderInputs& inputs, GroundAdder* out);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_GROUND_RESIDUALS_H_
