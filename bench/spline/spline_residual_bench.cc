// Micro-benchmark of the calibrator's spline residuals: evaluations per
// second of each analytic cost function with all Jacobians, against
// fixed-size ceres::AutoDiffCostFunction twins measured in the same run
// (tests/testing/cost_function_twins.h):
//   anchor     = autodiff of the same Sommer-recursion formulas (what a
//                careful Ceres-autodiff implementation would run);
//   prod-rule  = autodiff of the quaternion product-rule derivatives
//                (Lovegrove-style, as in Kontiki / LI-Calib).
// Times are CPU time per evaluation (the machine is shared; wall time is
// noisy). Prints the autodiff / analytic ratios per residual, and the
// Jacobian-evaluation time one LM iteration of the target problem (60 s,
// 200 Hz IMU, 20k point-to-plane residuals) would spend in these cost
// functions alone.
//
// Run: build/bench/spline/spline_residual_bench [--benchmark_min_time=0.2]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/spline/knot_grid.h"
#include "common/spline/quaternion_manifold.h"
#include "common/spline/spline_trajectory.h"
#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "tests/testing/cost_function_twins.h"

namespace tiltcal {
namespace {

constexpr double kDt = 0.05;
constexpr int kNumCosts = 64;  // cost functions at different u, cycled

// Parameter blocks of one window: a vehicle-like motion (~1 rad/s, ~3 m/s).
struct State {
  Eigen::Quaterniond q[4];
  Eigen::Vector3d p[4];
  Eigen::Vector3d gyro_bias{0.001, -0.002, 0.0005};
  Eigen::Vector3d accel_bias{0.02, 0.01, -0.03};
  // IMU triad errors (row-major; the accelerometer's lower triangular).
  double gyro_triad_errors[9] = {0.004, 0.001, -0.002, 0.0, -0.003, 0.001, 0.002, -0.001, 0.005};
  double accel_triad_errors[9] = {-0.004, 0, 0, 0.002, 0.003, 0, -0.001, 0.002, 0.001};
  Eigen::Vector3d gravity_dir{0.01, -0.02, -1.0};
  Eigen::Quaterniond q_bl;
  Eigen::Vector3d r_b_lb{0.1, -0.05, 0.3};
  double tau = 0.002;

  State() {
    std::mt19937 rng(1);
    std::normal_distribution<double> n(0.0, 1.0);
    q[0] = geometry::ExpQuaternion(Eigen::Vector3d(0.1, -0.2, 0.8));
    p[0] = Eigen::Vector3d(3.0, -1.0, 0.2);
    for (int i = 1; i < 4; ++i) {
      q[i] = q[i - 1] * geometry::ExpQuaternion(Eigen::Vector3d(kDt * Eigen::Vector3d(0.2 * n(rng), 0.2 * n(rng), 1.0)));
      p[i] = p[i - 1] + kDt * Eigen::Vector3d(3.0 + 0.3 * n(rng), 0.3 * n(rng), 0.05 * n(rng));
    }
    gravity_dir.normalize();
    q_bl = geometry::ExpQuaternion(Eigen::Vector3d(0.02, -0.01, 1.57));
  }

  std::vector<double*> Gyro() {
    return {q[0].coeffs().data(), q[1].coeffs().data(), q[2].coeffs().data(), q[3].coeffs().data(),
            gyro_bias.data(), gyro_triad_errors};
  }
  std::vector<double*> Accel() {
    return {q[0].coeffs().data(), q[1].coeffs().data(), q[2].coeffs().data(), q[3].coeffs().data(),
            p[0].data(), p[1].data(), p[2].data(), p[3].data(), gravity_dir.data(), accel_bias.data(),
            accel_triad_errors};
  }
  std::vector<double*> Plane() {
    return {q[0].coeffs().data(), q[1].coeffs().data(), q[2].coeffs().data(), q[3].coeffs().data(),
            p[0].data(), p[1].data(), p[2].data(), p[3].data(), q_bl.coeffs().data(), r_b_lb.data(),
            &tau};
  }
};

double U(int k) { return (k + 0.5) / kNumCosts; }

enum Variant { kAnalytic, kSommerAutoDiff, kProductRuleAutoDiff };

std::vector<std::unique_ptr<ceres::CostFunction>> MakeGyro(int variant) {
  std::vector<std::unique_ptr<ceres::CostFunction>> out;
  const Eigen::Vector3d m(0.1, 0.2, 1.0);
  for (int k = 0; k < kNumCosts; ++k) {
    if (variant == kAnalytic) {
      out.emplace_back(new calibrate::GyroCostFunction(spline::KnotWindow{0, U(k)}, 1 / kDt, m, 0.01));
    } else if (variant == kSommerAutoDiff) {
      using F = testing::GyroTwinT<true>;
      out.emplace_back(new F::AutoDiff(new F{U(k), 1 / kDt, 0.01, m}));
    } else {
      using F = testing::GyroTwinT<false>;
      out.emplace_back(new F::AutoDiff(new F{U(k), 1 / kDt, 0.01, m}));
    }
  }
  return out;
}

std::vector<std::unique_ptr<ceres::CostFunction>> MakeAccel(int variant) {
  std::vector<std::unique_ptr<ceres::CostFunction>> out;
  const Eigen::Vector3d m(0.3, -0.1, 9.8);
  for (int k = 0; k < kNumCosts; ++k) {
    if (variant == kAnalytic) {
      out.emplace_back(new calibrate::AccelCostFunction(spline::KnotWindow{0, U(k)}, 1 / kDt, m, 0.05, 9.81));
    } else if (variant == kSommerAutoDiff) {
      using F = testing::AccelTwinT<true>;
      out.emplace_back(new F::AutoDiff(new F{U(k), 1 / kDt, 0.05, 9.81, m}));
    } else {
      using F = testing::AccelTwinT<false>;
      out.emplace_back(new F::AutoDiff(new F{U(k), 1 / kDt, 0.05, 9.81, m}));
    }
  }
  return out;
}

std::vector<std::unique_ptr<ceres::CostFunction>> MakePlane(int variant) {
  std::vector<std::unique_ptr<ceres::CostFunction>> out;
  const Eigen::Vector3d point(7.0, 2.0, -0.8);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.1, 0.2, 0.97).normalized();
  for (int k = 0; k < kNumCosts; ++k) {
    const double t = U(k) * kDt - 0.002;  // segment start 0, tau = 0.002
    if (variant == kAnalytic) {
      out.emplace_back(new calibrate::PointToPlaneCostFunction(0.0, 1 / kDt, t, point, normal, 0.4, 0.05));
    } else if (variant == kSommerAutoDiff) {
      using F = testing::PointToPlaneTwinT<true>;
      out.emplace_back(new F::AutoDiff(new F{t, 1 / kDt, 0.05, 0.4, point, normal}));
    } else {
      using F = testing::PointToPlaneTwinT<false>;
      out.emplace_back(new F::AutoDiff(new F{t, 1 / kDt, 0.05, 0.4, point, normal}));
    }
  }
  return out;
}

void RunEvaluate(benchmark::State& bm, std::vector<std::unique_ptr<ceres::CostFunction>> costs,
                 std::vector<double*> params) {
  const ceres::CostFunction& first = *costs.front();
  std::vector<std::vector<double>> jac_storage;
  std::vector<double*> jacobians;
  for (int size : first.parameter_block_sizes()) {
    jac_storage.emplace_back(size * first.num_residuals());
  }
  for (auto& j : jac_storage) jacobians.push_back(j.data());
  std::vector<double> residuals(first.num_residuals());
  int k = 0;
  for (auto _ : bm) {
    costs[k]->Evaluate(params.data(), residuals.data(), jacobians.data());
    benchmark::DoNotOptimize(residuals.data());
    benchmark::DoNotOptimize(jacobians.front());
    benchmark::ClobberMemory();
    k = (k + 1) % kNumCosts;
  }
  bm.SetItemsProcessed(bm.iterations());
}

State g_state;

void BM_Gyro(benchmark::State& bm) { RunEvaluate(bm, MakeGyro(bm.range(0)), g_state.Gyro()); }
void BM_Accel(benchmark::State& bm) { RunEvaluate(bm, MakeAccel(bm.range(0)), g_state.Accel()); }
void BM_PointToPlane(benchmark::State& bm) { RunEvaluate(bm, MakePlane(bm.range(0)), g_state.Plane()); }

// Argument: 0 analytic, 1 autodiff (Sommer, the anchor), 2 autodiff (product rule).
BENCHMARK(BM_Gyro)->Arg(kAnalytic)->Arg(kSommerAutoDiff)->Arg(kProductRuleAutoDiff)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_Accel)->Arg(kAnalytic)->Arg(kSommerAutoDiff)->Arg(kProductRuleAutoDiff)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_PointToPlane)->Arg(kAnalytic)->Arg(kSommerAutoDiff)->Arg(kProductRuleAutoDiff)->Unit(benchmark::kNanosecond);

// ---- Whole LM iterations on the target problem ----
// 60 s, knots every 0.05 s (1203 + 1203), 200 Hz IMU (12k gyro + 12k accel
// blocks), 20k point-to-plane blocks with free extrinsic and tau, Cauchy loss
// on the planes, SPARSE_NORMAL_CHOLESKY, 1 thread, 5 LM iterations. The data
// are generated from a smooth spline (+ noise) and the knots perturbed, so
// LM has real steps to take.
void BM_LmIterations(benchmark::State& bm) {
  const bool analytic = bm.range(0) == kAnalytic;
  const double duration = 60.0, rate_hz = 200.0;
  const int num_planes = 20000;
  const spline::UniformKnotGrid grid = spline::UniformKnotGrid::ForDuration(0.0, duration, kDt);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  spline::SplineTrajectory truth(grid);
  for (int i = 0; i < grid.num_knots(); ++i) {
    const double t = (i - 1) * kDt;
    truth.SetRotationKnot(i, geometry::ExpQuaternion(Eigen::Vector3d(
                                 0.1 * std::sin(0.7 * t), 0.1 * std::sin(0.5 * t + 1.0), 0.4 * t)));
    truth.SetPositionKnot(i, Eigen::Vector3d(8.0 * std::sin(0.05 * t), 8.0 * std::cos(0.05 * t), 0.2 * std::sin(0.3 * t)));
  }
  const Eigen::Quaterniond q_bl_true = geometry::ExpQuaternion(Eigen::Vector3d(0.01, -0.02, 1.5));
  const Eigen::Vector3d r_b_true(0.1, 0.05, 0.3);
  const double tau_true = 0.004;
  const double gravity_norm = 9.81;

  for (auto _ : bm) {
    bm.PauseTiming();
    spline::SplineTrajectory traj = truth;
    for (int i = 0; i < grid.num_knots(); ++i) {
      traj.SetRotationKnot(i, geometry::BoxPlus(truth.RotationKnot(i), Eigen::Vector3d(0.01 * n(rng), 0.01 * n(rng), 0.01 * n(rng))));
      traj.SetPositionKnot(i, truth.PositionKnot(i) + 0.02 * Eigen::Vector3d(n(rng), n(rng), n(rng)));
    }
    Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero(), accel_bias = Eigen::Vector3d::Zero();
    double gyro_triad_errors[9] = {}, accel_triad_errors[9] = {};  // held at zero
    Eigen::Vector3d gravity_dir(0.0, 0.0, -1.0);
    Eigen::Quaterniond q_bl = geometry::BoxPlus(q_bl_true, Eigen::Vector3d(0.02, -0.02, 0.03));
    Eigen::Vector3d r_b = r_b_true + Eigen::Vector3d(0.03, -0.02, 0.02);
    double tau = 0.0;

    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    spline::RightQuaternionManifold quaternion_manifold;
    ceres::SphereManifold<3> sphere;
    ceres::CauchyLoss cauchy(1.0);
    for (int i = 0; i < grid.num_knots(); ++i) {
      problem.AddParameterBlock(traj.rotation_knot(i), 4, &quaternion_manifold);
    }
    problem.AddParameterBlock(q_bl.coeffs().data(), 4, &quaternion_manifold);
    problem.AddParameterBlock(gravity_dir.data(), 3, &sphere);
    const int num_imu = static_cast<int>(duration * rate_hz);
    for (int k = 0; k < num_imu; ++k) {
      const double t = (k + 0.5) / rate_hz;
      spline::KnotWindow w;
      grid.Locate(t, &w);
      spline::So3SplineSample r;
      spline::R3SplineSample p;
      truth.Evaluate(t, spline::kSo3Rotation | spline::kSo3AngularVelocity, &r, &p);
      const Eigen::Vector3d omega = r.angular_velocity + 0.01 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      const Eigen::Vector3d f = r.rotation.transpose() * (p.acceleration - gravity_norm * Eigen::Vector3d(0, 0, -1)) +
                                0.05 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      double* q[4];
      double* x[4];
      for (int j = 0; j < 4; ++j) {
        q[j] = traj.rotation_knot(w.first_knot + j);
        x[j] = traj.position_knot(w.first_knot + j);
      }
      ceres::CostFunction* gyro;
      ceres::CostFunction* accel;
      if (analytic) {
        gyro = new calibrate::GyroCostFunction(w, grid.inv_dt(), omega, 0.01);
        accel = new calibrate::AccelCostFunction(w, grid.inv_dt(), f, 0.05, gravity_norm);
      } else {
        gyro = new testing::GyroTwinT<true>::AutoDiff(new testing::GyroTwinT<true>{w.u, grid.inv_dt(), 0.01, omega});
        accel = new testing::AccelTwinT<true>::AutoDiff(
            new testing::AccelTwinT<true>{w.u, grid.inv_dt(), 0.05, gravity_norm, f});
      }
      problem.AddResidualBlock(gyro, nullptr, q[0], q[1], q[2], q[3], gyro_bias.data(),
                               gyro_triad_errors);
      problem.AddResidualBlock(accel, nullptr, q[0], q[1], q[2], q[3], x[0], x[1], x[2], x[3],
                               gravity_dir.data(), accel_bias.data(), accel_triad_errors);
    }
    problem.SetParameterBlockConstant(gyro_triad_errors);
    problem.SetParameterBlockConstant(accel_triad_errors);
    for (int k = 0; k < num_planes; ++k) {
      const double t_lidar = 0.05 + uni(rng) * (duration - 0.1);
      spline::KnotWindow w;
      grid.Locate(t_lidar + tau, &w);  // binned with the current tau
      const Eigen::Vector3d p_l = 10.0 * Eigen::Vector3d(n(rng), n(rng), 0.2 * n(rng));
      spline::So3SplineSample r;
      spline::R3SplineSample p;
      truth.Evaluate(t_lidar + tau_true, spline::kSo3Rotation, &r, &p);
      const Eigen::Vector3d p_a = r.rotation * (q_bl_true * p_l + r_b_true) + p.position;
      const Eigen::Vector3d normal = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      const double d = -normal.dot(p_a) + 0.02 * n(rng);
      double* q[4];
      double* x[4];
      for (int j = 0; j < 4; ++j) {
        q[j] = traj.rotation_knot(w.first_knot + j);
        x[j] = traj.position_knot(w.first_knot + j);
      }
      const double segment_start = grid.SegmentStart(w.first_knot);
      ceres::CostFunction* cost;
      if (analytic) {
        cost = new calibrate::PointToPlaneCostFunction(segment_start, grid.inv_dt(), t_lidar, p_l, normal, d, 0.05);
      } else {
        cost = new testing::PointToPlaneTwinT<true>::AutoDiff(new testing::PointToPlaneTwinT<true>{
            t_lidar - segment_start, grid.inv_dt(), 0.05, d, p_l, normal});
      }
      problem.AddResidualBlock(cost, &cauchy, q[0], q[1], q[2], q[3], x[0], x[1], x[2], x[3],
                               q_bl.coeffs().data(), r_b.data(), &tau);
    }
    problem.SetParameterLowerBound(&tau, 0, -0.5 * kDt);
    problem.SetParameterUpperBound(&tau, 0, 0.5 * kDt);

    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.num_threads = 1;
    options.max_num_iterations = 5;
    options.function_tolerance = 0.0;
    options.gradient_tolerance = 0.0;
    options.parameter_tolerance = 0.0;
    ceres::Solver::Summary summary;
    bm.ResumeTiming();
    const std::clock_t cpu_start = std::clock();
    ceres::Solve(options, &problem, &summary);
    const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    bm.PauseTiming();
    const double iterations = std::max<double>(1.0, summary.iterations.size() - 1);
    bm.counters["s_per_iter"] = summary.minimizer_time_in_seconds / iterations;  // wall
    bm.counters["cpu_s_per_iter"] = cpu_s / iterations;  // whole Solve incl. preprocessing
    bm.counters["jac_s_per_iter"] = summary.jacobian_evaluation_time_in_seconds / iterations;
    bm.counters["linsolve_s_per_iter"] = summary.linear_solver_time_in_seconds / iterations;
    bm.counters["iterations"] = iterations;
    bm.counters["cost_ratio"] = summary.final_cost / summary.initial_cost;
    bm.ResumeTiming();
  }
}
BENCHMARK(BM_LmIterations)->Arg(kAnalytic)->Arg(kSommerAutoDiff)->Iterations(1)->Unit(benchmark::kMillisecond);

// Console output plus a record of each run's time per iteration (ns).
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration) continue;
      ns_[run.benchmark_name()] = run.GetAdjustedCPUTime();
      for (const auto& [key, counter] : run.counters) {
        counters_[run.benchmark_name() + ":" + key] = counter.value;
      }
    }
  }
  double Counter(const std::string& name) const {
    const auto it = counters_.find(name);
    return it == counters_.end() ? 0.0 : it->second;
  }
  double Ns(const std::string& name) const {
    const auto it = ns_.find(name);
    return it == ns_.end() ? 0.0 : it->second;
  }

 private:
  std::map<std::string, double> ns_;
  std::map<std::string, double> counters_;
};

}  // namespace
}  // namespace tiltcal

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  tiltcal::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  std::printf("\nCPU ns per evaluation with all Jacobians (dt %.2f s)\n", tiltcal::kDt);
  std::printf("residual         analytic  autodiff(anchor)  autodiff(prod-rule)  anchor/analytic  prod-rule/analytic\n");
  struct Row {
    const char* label;
    const char* name;
    double count;  // blocks per LM iteration in the target problem
  };
  const Row rows[] = {{"gyro", "BM_Gyro", 12000}, {"accel", "BM_Accel", 12000},
                      {"point_to_plane", "BM_PointToPlane", 20000}};
  double analytic_s = 0.0, anchor_s = 0.0;
  for (const Row& row : rows) {
    const std::string base(row.name);
    const double a = reporter.Ns(base + "/0");
    const double d = reporter.Ns(base + "/1");
    const double p = reporter.Ns(base + "/2");
    if (a <= 0.0 || d <= 0.0 || p <= 0.0) continue;  // filtered out
    std::printf("%-15s %9.0f  %16.0f  %19.0f  %15.1f  %18.1f\n", row.label, a, d, p, d / a, p / a);
    analytic_s += row.count * a * 1e-9;
    anchor_s += row.count * d * 1e-9;
  }
  if (analytic_s > 0.0) {
    std::printf(
        "\nJacobian evaluation per LM iteration, 60 s @ 200 Hz (12k gyro + 12k accel) + 20k planes,\n"
        "cost functions only (no Ceres block overhead, no J^T J, no factorisation), 1 thread:\n"
        "  analytic %.3f s   autodiff anchor %.3f s   (budget for the whole iteration: 0.25 s)\n",
        analytic_s, anchor_s);
  }
  const double lm_a = reporter.Counter("BM_LmIterations/0/iterations:1:s_per_iter");
  const double lm_d = reporter.Counter("BM_LmIterations/1/iterations:1:s_per_iter");
  if (lm_a > 0.0) {
    std::printf("\nWhole LM iterations (Ceres, SPARSE_NORMAL_CHOLESKY, 1 thread), seconds per iteration\n"
                "(wall, from the Ceres summary; CPU = process CPU time of the whole Solve / iterations):\n");
    std::printf("  analytic: %.3f s wall, %.3f s CPU (Jacobians %.3f s, linear solver %.3f s)\n", lm_a,
                reporter.Counter("BM_LmIterations/0/iterations:1:cpu_s_per_iter"),
                reporter.Counter("BM_LmIterations/0/iterations:1:jac_s_per_iter"),
                reporter.Counter("BM_LmIterations/0/iterations:1:linsolve_s_per_iter"));
    if (lm_d > 0.0) {
      std::printf("  autodiff anchor: %.3f s wall, %.3f s CPU (Jacobians %.3f s, linear solver %.3f s)   ratio %.1f\n",
                  lm_d, reporter.Counter("BM_LmIterations/1/iterations:1:cpu_s_per_iter"),
                  reporter.Counter("BM_LmIterations/1/iterations:1:jac_s_per_iter"),
                  reporter.Counter("BM_LmIterations/1/iterations:1:linsolve_s_per_iter"), lm_d / lm_a);
    }
    std::printf("  target: <= 0.25 s per iteration\n");
  }
  benchmark::Shutdown();
  return 0;
}
