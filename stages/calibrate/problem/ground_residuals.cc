#include "stages/calibrate/problem/ground_residuals.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include <ceres/loss_function.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "common/spline/so3_spline.h"
#include "stages/calibrate/problem/problem_builder.h"
#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"
#include "stages/calibrate/residuals/ground_cost_functions.h"

namespace tiltcal::calibrate {
namespace {

using Mode = proto::GroundResidualParams;

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

const char* ModeName(proto::GroundResidualParams::Mode mode) {
  switch (mode) {
    case proto::GroundResidualParams::ON:
      return "ON";
    case proto::GroundResidualParams::OFF:
      return "OFF";
    default:
      return "AUTO";
  }
}

std::unique_ptr<ceres::LossFunction> MakeLoss(const proto::GroundResidualParams& p) {
  if (!(p.cauchy_scale() > 0.0)) return nullptr;
  return std::make_unique<ceres::CauchyLoss>(p.cauchy_scale());
}

// n_l (unit) and d_l of a usable plane; false when the plane is invalid.
bool UsablePlane(const proto::GroundPlane& plane, Eigen::Vector3d* normal, double* height_m) {
  if (!plane.valid()) return false;
  const Eigen::Vector3d n(plane.normal_in_lidar().x(), plane.normal_in_lidar().y(),
                          plane.normal_in_lidar().z());
  const double d = plane.height_m();
  if (!n.allFinite() || !std::isfinite(d) || !(d > 0.0)) return false;
  if (std::abs(n.norm() - 1.0) > 1e-3) return false;
  *normal = n.normalized();
  *height_m = d;
  return true;
}

// The 4x4 covariance of (n, d), symmetrised; false when absent or unusable.
bool PlaneCovariance(const proto::GroundPlane& plane, Eigen::Matrix4d* covariance) {
  if (plane.covariance_size() != 16) return false;
  for (int i = 0; i < 16; ++i) (*covariance)(i / 4, i % 4) = plane.covariance(i);
  if (!covariance->allFinite()) return false;
  *covariance = 0.5 * (*covariance + covariance->transpose());
  // Positive semi-definite up to rounding.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(*covariance, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().minCoeff() >= -1e-9 * (1.0 + eig.eigenvalues().maxCoeff());
}

// W with W^T W = (sigma^2 I + extra)^{-1}: the inverse of the Cholesky factor.
Eigen::Matrix3d WhiteningMatrix(double sigma, const Eigen::Matrix3d& extra) {
  const Eigen::Matrix3d c = sigma * sigma * Eigen::Matrix3d::Identity() + extra;
  const Eigen::Matrix3d l = c.llt().matrixL();
  return l.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
}

}  // namespace

GroundLosses::GroundLosses(const proto::GroundResidualsParams& params)
    : flat_(MakeLoss(params.flat())),
      dist_(MakeLoss(params.dist())),
      incl_(MakeLoss(params.incl())),
      up_(MakeLoss(params.up())) {}

GroundSequenceInfo MakeGroundSequenceInfo(const proto::Rig& rig,
                                          const proto::GravityReference* gravity) {
  GroundSequenceInfo info;
  info.imu_height_m = rig.imu_height_m();
  if (gravity != nullptr) {
    info.level_known = true;
    info.is_level = gravity->is_level();
    if (gravity->has_gravity_flat()) {
      const auto& g = gravity->gravity_flat_in_imu();
      info.gravity_flat_in_imu = Eigen::Vector3d(g.x(), g.y(), g.z());
    }
  }
  if (info.gravity_flat_in_imu.norm() == 0.0 && rig.has_gravity_flat_in_imu()) {
    const auto& g = rig.gravity_flat_in_imu();
    info.gravity_flat_in_imu = Eigen::Vector3d(g.x(), g.y(), g.z());
  }
  info.has_gravity_flat =
      info.gravity_flat_in_imu.allFinite() && info.gravity_flat_in_imu.norm() > 0.0;
  if (!info.has_gravity_flat) info.gravity_flat_in_imu.setZero();
  return info;
}

std::string GroundResidualSelection::Names() const {
  std::string names;
  auto add = [&](bool on, const char* name) {
    if (!on) return;
    if (!names.empty()) names += "+";
    names += name;
  };
  add(flat, "flat");
  add(dist, "dist");
  add(incl, "incl");
  add(up, "up");
  return names.empty() ? "none" : names;
}

Status SelectGroundResiduals(const proto::GroundResidualsParams& params,
                             const GroundSequenceInfo& info,
                             GroundResidualSelection* selection) {
  *selection = GroundResidualSelection();
  const bool have_db = info.imu_height_m > 0.0;
  const bool have_gf = info.has_gravity_flat;
  const std::string level_text = !info.level_known ? "level unknown"
                                 : info.is_level   ? "level"
                                                   : "tilted";
  std::string why;
  auto note = [&](const char* name, Mode::Mode mode, bool on, const std::string& because) {
    if (!why.empty()) why += "; ";
    why += std::string(name) + " " + ModeName(mode) + (on ? " on" : " off") + " (" + because + ")";
  };

  // dist
  const Mode::Mode dist_mode = params.dist().mode();
  if (dist_mode == Mode::ON && !have_db) {
    return Status::Error(
        "params: ground.dist.mode = ON needs the IMU height d_b (rig imu_height_m > 0)");
  }
  selection->dist = dist_mode == Mode::ON || (dist_mode == Mode::AUTO && have_db);
  note("dist", dist_mode, selection->dist,
       have_db ? Format("d_b = %.3f m", info.imu_height_m) : "d_b unknown");

  // flat
  const Mode::Mode flat_mode = params.flat().mode();
  selection->flat = flat_mode == Mode::ON || (flat_mode == Mode::AUTO && info.is_level);
  note("flat", flat_mode, selection->flat,
       flat_mode == Mode::ON && !info.is_level ? level_text + ", forced: assumes level ground"
                                               : level_text);

  // incl
  const Mode::Mode incl_mode = params.incl().mode();
  if (incl_mode == Mode::ON && !have_gf) {
    return Status::Error(
        "params: ground.incl.mode = ON needs the flat-ground gravity g_f (gravity reference or rig "
        "gravity_flat_in_imu)");
  }
  const bool tilted = info.level_known && !info.is_level;
  selection->incl = incl_mode == Mode::ON || (incl_mode == Mode::AUTO && tilted && have_gf);
  note("incl", incl_mode, selection->incl,
       level_text + (have_gf ? ", g_f known" : ", g_f unknown"));

  // up
  const Mode::Mode up_mode = params.up().mode();
  if (up_mode == Mode::ON && !have_gf) {
    return Status::Error(
        "params: ground.up.mode = ON needs the flat-ground gravity g_f (gravity reference or rig "
        "gravity_flat_in_imu)");
  }
  selection->up = up_mode == Mode::ON;
  note("up", up_mode, selection->up, up_mode == Mode::AUTO ? "off unless ON" : "as set");

  selection->reason = "ground residuals " + selection->Names() + ": " + why;
  return Status::Ok();
}

std::string GroundResidualSummary::ToString() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "ground planes: %d given, %d used, %d invalid, %d outside the spline, %d without "
                "covariance; blocks flat %d dist %d incl %d up %d",
                num_planes, num_used, num_invalid, num_outside_spline, num_without_covariance,
                num_flat, num_dist, num_incl, num_up);
  return buffer;
}

namespace {

Status RequireBlock(const ceres::Problem& problem, const double* block, const char* name) {
  if (!problem.HasParameterBlock(block)) {
    return Status::Error(std::string("ground residuals: parameter block ") + name +
                         " is not in the problem");
  }
  return Status::Ok();
}

// The state's blocks the selected residuals use must already be in the
// problem with their manifolds.
Status RequireStateBlocks(const GroundResidualSelection& selection, const CalibrationState& state,
                          const ceres::Problem& problem) {
  TILTCAL_RETURN_IF_ERROR(
      RequireBlock(problem, state.imu_from_lidar_rotation, "imu_from_lidar_rotation"));
  if (selection.dist) {
    TILTCAL_RETURN_IF_ERROR(
        RequireBlock(problem, state.imu_from_lidar_translation, "imu_from_lidar_translation"));
  }
  if (selection.flat || selection.incl) {
    TILTCAL_RETURN_IF_ERROR(RequireBlock(problem, state.gravity_direction, "gravity_direction"));
    TILTCAL_RETURN_IF_ERROR(RequireBlock(problem, state.time_offset_s, "time_offset_s"));
  }
  return Status::Ok();
}

// What the residuals of every plane share within one AddGroundResiduals call.
struct GroundBuild {
  const GroundResidualSelection& selection;
  const proto::GroundResidualsParams& params;
  const GroundSequenceInfo& info;
  const GroundLosses& losses;
  // Current state values, for propagating the plane covariance: C_bl,
  // C_bl^T r_b^{lb} and the unit gravity direction n_g.
  Eigen::Matrix3d c_bl;
  Eigen::Vector3d r_l;
  Eigen::Vector3d gravity_dir;
};

// One usable plane of scan k: (n_l, d_l) at LiDAR time t_k, its knot window
// and, when asked for and usable, its fit covariance.
struct GroundPlaneSample {
  Eigen::Vector3d normal;
  double height_m = 0.0;
  double t_k = 0.0;
  spline::KnotWindow window;
  bool has_covariance = false;
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
};

// Adds a flat or inclination residual of scan time t_k (blocks: 4 rotation
// knots, n_g, C_bl, tau); with the clock drift in the problem, wrapped so
// that tau is tau(t_k) = tau0 + rho (t_k - t_ref) (rho appended,
// drifting_time_offset_cost_function.h).
void AddTimedResidual(ceres::CostFunction* cost, ceres::LossFunction* loss, double t_k,
                      double* const knots[4], CalibrationState* state, ceres::Problem* problem) {
  if (!ClockRateInProblem(*state, *problem)) {
    problem->AddResidualBlock(cost, loss, knots[0], knots[1], knots[2], knots[3],
                              state->gravity_direction, state->imu_from_lidar_rotation,
                              state->time_offset_s);
    return;
  }
  problem->AddResidualBlock(
      new DriftingTimeOffsetCostFunction(cost, 6, t_k - state->time_reference_s), loss,
      {knots[0], knots[1], knots[2], knots[3], state->gravity_direction,
       state->imu_from_lidar_rotation, state->time_offset_s, state->clock_rate});
}

// Adds the selected residuals of one plane.
Status AddPlaneResiduals(const GroundBuild& build, const GroundPlaneSample& plane,
                         CalibrationState* state, ceres::Problem* problem,
                         GroundResidualSummary* summary) {
  const GroundResidualSelection& selection = build.selection;
  const proto::GroundResidualsParams& params = build.params;
  const spline::UniformKnotGrid& grid = state->trajectory.grid();
  const Eigen::Matrix3d cov_nn = plane.covariance.topLeftCorner<3, 3>();
  double* knots[4] = {nullptr, nullptr, nullptr, nullptr};
  double segment_start_s = 0.0;
  if (selection.flat || selection.incl) {
    for (int i = 0; i < 4; ++i) {
      knots[i] = state->trajectory.rotation_knot(plane.window.first_knot + i);
      TILTCAL_RETURN_IF_ERROR(RequireBlock(*problem, knots[i], "rotation knot"));
    }
    segment_start_s = grid.SegmentStart(plane.window.first_knot);
  }
  if (selection.flat) {
    const Eigen::Matrix3d extra = plane.has_covariance && params.flat().use_plane_covariance()
                                      ? cov_nn
                                      : Eigen::Matrix3d::Zero();
    auto* cost = new FlatGroundCostFunction(segment_start_s, grid.inv_dt(), plane.t_k, plane.normal,
                                            WhiteningMatrix(params.flat().sigma(), extra));
    AddTimedResidual(cost, build.losses.flat(), plane.t_k, knots, state, problem);
    ++summary->num_flat;
  }
  if (selection.dist) {
    double variance = params.dist().sigma() * params.dist().sigma();
    if (plane.has_covariance && params.dist().use_plane_covariance()) {
      Eigen::Vector4d j;
      j << -build.r_l, 1.0;
      variance += j.dot(plane.covariance * j);
    }
    auto* cost = new DistanceCostFunction(plane.normal, plane.height_m, build.info.imu_height_m,
                                          1.0 / std::sqrt(variance));
    problem->AddResidualBlock(cost, build.losses.dist(), state->imu_from_lidar_rotation,
                              state->imu_from_lidar_translation);
    ++summary->num_dist;
  }
  if (selection.incl) {
    double variance = params.incl().sigma() * params.incl().sigma();
    if (plane.has_covariance && params.incl().use_plane_covariance()) {
      // g~_b at the current state: -C_ab(t)^T n_g.
      const double* const const_knots[4] = {knots[0], knots[1], knots[2], knots[3]};
      spline::So3SplineSample s;
      const double t = plane.t_k + state->TimeOffsetAt(plane.t_k);
      spline::EvaluateSo3Spline(const_knots, (t - segment_start_s) * grid.inv_dt(),
                                grid.inv_dt(), spline::kSo3Rotation, &s);
      const Eigen::Vector3d up_l =
          build.c_bl.transpose() * (-(s.rotation.transpose() * build.gravity_dir));
      variance += up_l.dot(cov_nn * up_l);
    }
    auto* cost = new InclinationCostFunction(segment_start_s, grid.inv_dt(), plane.t_k,
                                             plane.normal, build.info.gravity_flat_in_imu,
                                             1.0 / std::sqrt(variance));
    AddTimedResidual(cost, build.losses.incl(), plane.t_k, knots, state, problem);
    ++summary->num_incl;
  }
  if (selection.up) {
    const Eigen::Matrix3d extra = plane.has_covariance && params.up().use_plane_covariance()
                                      ? cov_nn
                                      : Eigen::Matrix3d::Zero();
    auto* cost = new UpCostFunction(plane.normal, build.info.gravity_flat_in_imu,
                                    WhiteningMatrix(params.up().sigma(), extra));
    problem->AddResidualBlock(cost, build.losses.up(), state->imu_from_lidar_rotation);
    ++summary->num_up;
  }
  return Status::Ok();
}

}  // namespace

Status AddGroundResiduals(const GroundResidualInputs& inputs, CalibrationState* state,
                          ceres::Problem* problem, GroundResidualSummary* summary) {
  const std::vector<proto::GroundPlane>& planes = inputs.planes;
  const GroundResidualSelection& selection = inputs.selection;
  const proto::GroundResidualsParams& params = inputs.params;
  const GroundSequenceInfo& info = inputs.info;
  const GroundLosses& losses = inputs.losses;
  const int64_t time_origin_ns = inputs.time_origin_ns;
  *summary = GroundResidualSummary();
  summary->num_planes = static_cast<int>(planes.size());
  if (!selection.any()) return Status::Ok();
  if (selection.dist && !(info.imu_height_m > 0.0)) {
    return Status::Error("ground residuals: dist selected without the IMU height d_b");
  }
  if ((selection.incl || selection.up) && !info.has_gravity_flat) {
    return Status::Error("ground residuals: incl/up selected without the flat-ground gravity g_f");
  }
  TILTCAL_RETURN_IF_ERROR(RequireStateBlocks(selection, *state, *problem));
  const bool want_covariance =
      (selection.flat && params.flat().use_plane_covariance()) ||
      (selection.dist && params.dist().use_plane_covariance()) ||
      (selection.incl && params.incl().use_plane_covariance()) ||
      (selection.up && params.up().use_plane_covariance());
  GroundBuild build{selection, params, info, losses, Eigen::Matrix3d::Zero(),
                    Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  build.c_bl = state->ImuFromLidarRotation().toRotationMatrix();
  build.r_l = build.c_bl.transpose() * state->ImuFromLidarTranslation();
  build.gravity_dir = Eigen::Vector3d(state->gravity_direction[0], state->gravity_direction[1],
                                      state->gravity_direction[2])
                          .normalized();

  for (const proto::GroundPlane& plane : planes) {
    GroundPlaneSample sample;
    if (!UsablePlane(plane, &sample.normal, &sample.height_m)) {
      ++summary->num_invalid;
      continue;
    }
    sample.t_k = static_cast<double>(plane.stamp_ns() - time_origin_ns) * 1e-9;
    if (!state->TimeWindow(sample.t_k, &sample.window)) {
      ++summary->num_outside_spline;
      continue;
    }
    sample.has_covariance = want_covariance && PlaneCovariance(plane, &sample.covariance);
    if (want_covariance && !sample.has_covariance) ++summary->num_without_covariance;
    ++summary->num_used;
    TILTCAL_RETURN_IF_ERROR(AddPlaneResiduals(build, sample, state, problem, summary));
  }
  return Status::Ok();
}

Status MakeGroundResidualAdder(const GroundAdderInputs& inputs, GroundAdder* out) {
  *out = GroundAdder();
  const GroundSequenceInfo info = MakeGroundSequenceInfo(*inputs.rig, inputs.gravity);
  GroundResidualSelection selection;
  TILTCAL_RETURN_IF_ERROR(SelectGroundResiduals(*inputs.params, info, &selection));
  if (inputs.planes->empty()) {
    out->reason = "ground residuals none: no ground planes given (with planes: " +
                  selection.Names() + ")";
    return Status::Ok();
  }
  out->reason = selection.reason;
  if (!selection.any()) return Status::Ok();
  if (selection.flat) out->used.push_back("flat");
  if (selection.dist) out->used.push_back("dist");
  if (selection.incl) out->used.push_back("incl");
  if (selection.up) out->used.push_back("up");
  out->add = [planes = inputs.planes, params = inputs.params, losses = inputs.losses,
              log = inputs.log, selection, info, time_origin_ns = inputs.time_origin_ns](
                 CalibrationState* state, ceres::Problem* problem, int* num_added) -> Status {
    GroundResidualSummary summary;
    TILTCAL_RETURN_IF_ERROR(AddGroundResiduals(
        {*planes, selection, *params, info, *losses, time_origin_ns}, state, problem, &summary));
    *num_added = summary.num_flat + summary.num_dist + summary.num_incl + summary.num_up;
    if (log != nullptr) *log << "tiltcal_calibrate: " << summary.ToString() << "\n" << std::flush;
    return Status::Ok();
  };
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
