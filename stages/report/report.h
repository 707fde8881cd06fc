#ifndef TILTCAL_STAGES_REPORT_REPORT_H_
#define TILTCAL_STAGES_REPORT_REPORT_H_

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/report_params.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::report {

// One calibrated sequence: out/<sequence>/calibration.txtpb and, for a
// simulated sequence, the truth.txtpb beside it.
struct SequenceResult {
  std::string name;
  proto::CalibrationResult calibration;
  std::optional<proto::SimulationTruth> truth;
};

// One row of the table: the estimate, and its errors when the truth is known.
struct Row {
  std::string label;
  Eigen::Vector3d translation_cm = Eigen::Vector3d::Zero();  // r_b^{lb}
  Eigen::Vector3d euler123_deg = Eigen::Vector3d::Zero();    // C_bl, 1-2-3 Euler
  double time_offset_ms = 0;                                 // τ
  bool has_errors = false;
  double rotation_error_deg = 0;                             // |Log(C_true^T C_est)|
  Eigen::Vector3d translation_error_cm = Eigen::Vector3d::Zero();  // est − true
  double time_offset_error_ms = 0;
  // The calibration's verdict ("OK", "WEAK", "SUSPECT"; "" for files
  // written before the verdict existed and for the mean, sigma and measured rows).
  std::string verdict;
  // With a dataset calibration: the sequence's consistency with the joint
  // value, "chi2 12.7 / 22.7" (or "... left out" when it was not used).
  std::string consistency;
};

// Repeatability over the sequences of a dataset, as the paper's Metrics
// section: rotation mean on SO(3) (Manton), σ per component of the Lie
// algebra deviations (deg); translation and τ mean and sample σ.
struct Repeatability {
  std::vector<Row> sequences;
  Row mean;   // rotation: Euler of the SO(3) mean; errors: mean of the errors
  Row sigma;  // euler123_deg holds σ of the deviations ξ (not an Euler triple)
  std::optional<Row> measured;  // the rig's measured extrinsic
  std::optional<Row> joint;     // the dataset's calibration (tiltcal_dataset_calibration)
  bool rotation_mean_converged = true;
  // Sequences whose calibration was SUSPECT and set aside by the pipeline
  // (only <dir>/calibration.suspect.txtpb): listed, not in the rows or the mean.
  std::vector<std::string> suspect_set_aside;
};

Repeatability ComputeRepeatability(const std::vector<SequenceResult>& results,
                                   const proto::Rig* rig);

// The dataset's calibration as the "joint" row (errors against the truth of
// the first sequence that has one) and each sequence's consistency column,
// matched by name.
void AddDatasetCalibration(const proto::CalibrationResult& dataset,
                           const std::vector<SequenceResult>& results, Repeatability* r);

// Text table for people and CSV for scripts.
std::string FormatTable(const Repeatability& repeatability, const std::string& title);
std::string FormatCsv(const Repeatability& repeatability);

// What tiltcal_report reads and writes.
struct ReportPaths {
  std::vector<std::string> sequence_dirs;  // each holds calibration.txtpb [+ truth.txtpb]
  std::string rig;                         // optional: the measured extrinsic row
  std::string out;                         // the table (text)
  std::string out_csv;                     // optional: the same as CSV
  // Optional: the dataset's page (report_page.h), with links relative to it.
  std::string out_html;
  std::string title;                       // first line of the table
  std::string dataset_calibration;         // optional: out/calibration.txtpb of the dataset
  std::string verify;                      // optional: out/verify.txtpb (tiltcal_verify), page only
};

// Reads <dir>/calibration.txtpb and <dir>/truth.txtpb (if present) for each
// directory (a directory with only calibration.suspect.txtpb, a SUSPECT
// result Makefile.pipeline set aside, is listed as such and left out of the
// rows), computes the repeatability, writes the table, the CSV and the page
// (where the set-aside sequences have their section too: with the wall
// snapshots of <dir>/map_rig.pcd and map_calibrated.pcd when both exist,
// drawn with params.wall_snapshot, and the exports of each calibration and
// of the dataset's), and prints the table to `log` (nullptr: silent).
Status Run(const ReportPaths& paths, const proto::ReportParams& params, std::ostream* log);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_REPORT_H_
