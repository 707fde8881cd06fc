#ifndef TILTCAL_STAGES_VERIFY_REFERENCE_COMPARISON_H_
#define TILTCAL_STAGES_VERIFY_REFERENCE_COMPARISON_H_

// Does a sequence's own calibration agree with a stored one (the
// reference)? (docs/design.md §11, stages/verify/README.md.)
//
// Tangent space (design §11), re-expressed in frame b for people:
//   d = (theta, r_est - r_ref[, tau_est - tau_ref]),
//   C_est = Exp(theta) C_ref  (theta = C_ref Log(C_ref^T C_est), rad, frame b),
// with the information of the difference
//   W = (Lambda^-1 + P_ref)^-1 = (I + Lambda P_ref)^-1 Lambda,
// where Lambda = P_est^-1 - L_prior is the sequence's data information (its
// solve's prior on r_b^{lb} is not data and is removed: a direction only the
// prior held stays undecided) and P_ref the reference's covariance (both
// rotated into b). Lambda may be singular; W is then singular along the
// same directions.
//
// The test: chi^2 = d^T W d against the upper p_value quantile of chi^2 with
// rank(W) degrees of freedom. The smallest move the test detects along a
// unit direction u of one group (rotation, translation, tau) with the rest
// unchanged is sqrt(limit / u^T W u).
//
// Verdict of a sequence:
//   MOVED        chi^2 > limit; the reasons name each group whose own test
//                (its marginal, d_g^T S_gg^+ d_g with S = W^+) exceeds its
//                limit, else the group farthest in sigma: its size (deg,
//                mm, ms), direction in b and sigma;
//   CANNOT_TELL  chi^2 <= limit, and along some direction of a group the
//                smallest detected move exceeds params.detectable (named,
//                with that move); also a calibration that is SUSPECT or
//                cannot be compared (calibration_checks.h);
//   HOLDS        otherwise.

#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/verify.pb.h"

namespace tiltcal::verify {

// Fills *out (all but name and the map sharpness) from the sequence's
// calibration and the reference; the reference must pass
// calibration::ReasonRefused with n = 6 and params.input().
void CompareWithReference(const proto::CalibrationResult& estimate,
                          const proto::CalibrationResult& reference,
                          const proto::VerifyParams& params, proto::SequenceVerification* out);

// The dataset's verdict and reasons from its sequences': MOVED when one
// moved, else HOLDS when one holds, else CANNOT_TELL (and with no sequence).
void DecideDatasetVerdict(proto::VerifyResult* result);

}  // namespace tiltcal::verify

#endif  // TILTCAL_STAGES_VERIFY_REFERENCE_COMPARISON_H_
