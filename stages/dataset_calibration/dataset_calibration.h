#ifndef TILTCAL_STAGES_DATASET_CALIBRATION_DATASET_CALIBRATION_H_
#define TILTCAL_STAGES_DATASET_CALIBRATION_DATASET_CALIBRATION_H_

// One calibration per dataset (docs/design.md §11): the sequences'
// calibrations fused into one extrinsic (common/geometry/extrinsic_fusion.h:
// the joint problem with each sequence's trajectory, biases, gravity and tau
// marginalised, linearised at the per-sequence optima), each sequence tested
// against the joint value, inconsistent ones left out by the params' rule.
//
// Usable: a calibration not excluded by the user, not refused by the input
// checks (common/calibration/calibration_checks.h: non-finite numbers, non-unit quaternions, a
// covariance that is not symmetric positive definite with bounded sigmas and
// condition; the reason names the file) and OK or WEAK. The result is a
// CalibrationResult: imu_from_lidar, its covariance (7x7; the tau row and
// column are the fused tau when time_offset_shared, else the weighted mean
// of the sequences' tau with the larger of its sigma and their spread), the
// observability report, the verdict and one DatasetSequence per input.
// Verdict: with one usable sequence, that sequence's (its value, and WEAK
// also from the joint directions) with the reason "one sequence: no
// consistency check between sequences"; with two or more, SUSPECT when fewer
// than consistency.min_sequences are used, when a used sequence fails the
// consistency test (named, with its chi2, the limit and the largest angle
// between two used extrinsics) or when the joint solve does not converge,
// else WEAK or OK from the joint covariance's directions.

#include <ostream>
#include <string>
#include <vector>

#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/dataset_params.pb.h"

namespace tiltcal::dataset {

struct SequenceCalibration {
  std::string name;  // the sequence (its folder's name)
  std::string path;
  proto::CalibrationResult result;
};

// I/O free; an error when no sequence can be used (or, which the input
// checks rule out, the joint values are not finite).
Status CalibrateDataset(const std::vector<SequenceCalibration>& sequences,
                        const proto::DatasetCalibrationParams& params,
                        proto::CalibrationResult* out);

struct DatasetCalibrationPaths {
  std::vector<std::string> calibrations;  // out/<sequence>/calibration.txtpb
  std::string params;                     // provenance only; empty: the defaults
  std::string out;                        // out/calibration.txtpb
  std::string command_line;
};

// Reads, combines, writes *result atomically with provenance; a table of the
// sequences and the verdict to `log` (nullptr: silent).
Status Run(const DatasetCalibrationPaths& paths, const proto::DatasetCalibrationParams& params,
           std::ostream* log, proto::CalibrationResult* result);

}  // namespace tiltcal::dataset

#endif  // TILTCAL_STAGES_DATASET_CALIBRATION_DATASET_CALIBRATION_H_
