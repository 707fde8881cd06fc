#ifndef TILTCAL_COMMON_SPLINE_KNOT_GRID_H_
#define TILTCAL_COMMON_SPLINE_KNOT_GRID_H_

// Uniform knot grid shared by the SO(3) and R^3 cubic B-splines.
//
// Knot spacing dt_s, start t0_s (seconds relative to the sequence start, not
// epoch time). With n knots there are n - 3 segments; segment s covers
// [t0 + s dt, t0 + (s+1) dt) and uses knots s..s+3, with
//   s = floor((t - t0)/dt),  u = (t - t0)/dt - s  in [0, 1).
// To cover a duration T:  n = ceil(T/dt) + 3.

namespace tiltcal::spline {

// Knots that one evaluation uses: knots first_knot .. first_knot + 3, at
// normalised time u (u may leave [0, 1] slightly for residuals whose time
// moves with the time offset; see stages/calibrate).
struct KnotWindow {
  int first_knot = 0;
  double u = 0.0;
};

class UniformKnotGrid {
 public:
  // num_knots >= 4, dt_s > 0.
  UniformKnotGrid(double t0_s, double dt_s, int num_knots);
  // The grid with n = ceil(duration/dt) + 3 knots starting at t0_s.
  static UniformKnotGrid ForDuration(double t0_s, double duration_s, double dt_s);
  static int NumKnotsForDuration(double duration_s, double dt_s);

  double t0_s() const { return t0_s_; }
  double dt_s() const { return dt_s_; }
  double inv_dt() const { return inv_dt_; }
  int num_knots() const { return num_knots_; }
  int num_segments() const { return num_knots_ - 3; }
  // Last time the spline is defined at: t0 + (n - 3) dt.
  double end_s() const { return t0_s_ + num_segments() * dt_s_; }
  // Start time of segment s.
  double SegmentStart(int segment) const { return t0_s_ + segment * dt_s_; }

  // Segment and u of time t_s. Returns false when t_s is outside
  // [t0, end]; t = end maps to the last segment with u = 1.
  bool Locate(double t_s, KnotWindow* window) const;

 private:
  double t0_s_;
  double dt_s_;
  double inv_dt_;
  int num_knots_;
};

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_KNOT_GRID_H_
