#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_INTERVAL_MANIFOLD_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_INTERVAL_MANIFOLD_H_

// A scalar held in [lower, upper] by projecting every step onto the
// interval (the time offset tau, s; docs/design.md §13):
//   Plus(x, delta)   = clamp(x + delta, lower, upper),  PlusJacobian  = 1,
//   Minus(y, x)      = y - x,                           MinusJacobian = 1.
// Ceres' own parameter bounds project each step the same way, but a problem
// with bounds also runs a projected line search in every LM iteration, one
// more cost evaluation per iteration. Minus inverts Plus only inside the
// interval; the solver does not use it.

#include <ceres/manifold.h>

#include <algorithm>

namespace tiltcal::calibrate {

class IntervalManifold final : public ceres::Manifold {
 public:
  IntervalManifold(double lower, double upper) : lower_(lower), upper_(upper) {}

  int AmbientSize() const override { return 1; }
  int TangentSize() const override { return 1; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    *x_plus_delta = std::clamp(*x + *delta, lower_, upper_);
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    *jacobian = 1.0;
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    *y_minus_x = *y - *x;
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    *jacobian = 1.0;
    return true;
  }

  double lower() const { return lower_; }
  double upper() const { return upper_; }

 private:
  double lower_;
  double upper_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_INTERVAL_MANIFOLD_H_
