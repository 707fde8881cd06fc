#ifndef TILTCAL_STAGES_VERIFY_VERIFY_H_
#define TILTCAL_STAGES_VERIFY_VERIFY_H_

// tiltcal_verify: does a stored calibration (the reference, e.g. a vehicle's
// out/calibration.txtpb of an earlier dataset) still hold for new recordings?
// Each sequence is calibrated again with tiltcal_calibrate's computation
// (calibrate.h Calibrate, the dataset's calibrate params), its estimate
// compared with the reference (reference_comparison.h) and the map of its
// scans on its final trajectory measured with its estimate and with the
// reference's extrinsic (map_sharpness.h). A sequence whose motion cannot
// decide the extrinsic (calibrate's Status::NotDetermined, e.g. too little
// turning) is CANNOT_TELL with calibrate's reason; any other failure of a
// sequence fails the run.

#include <ostream>
#include <string>
#include <vector>

#include "common/status.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/verify.pb.h"

namespace tiltcal::verify {

struct VerifyPaths {
  // out/<sequence> folders: imu.binpb, scans.binpb.lz4 and, when present,
  // ground.binpb and gravity.txtpb (what tiltcal_calibrate reads).
  std::vector<std::string> sequence_dirs;
  std::string reference;         // the stored calibration.txtpb
  // The dataset's rig.txtpb: for a sequence without its own rig.txtpb (the
  // starting extrinsic not found), the search is run again for its reason.
  std::string rig;
  std::string params;            // provenance only; empty: the defaults
  std::string calibrate_params;  // provenance only; empty: calibrate's defaults
  std::string out;               // out/verify.txtpb
  std::string command_line;
};

// Reads, verifies every sequence, writes *result atomically with provenance,
// progress to `log` and the table to `table` (either nullptr: silent).
Status Run(const VerifyPaths& paths, const proto::VerifyParams& params,
           const proto::CalibrateParams& calibrate_params, std::ostream* log, std::ostream* table,
           proto::VerifyResult* result);

// The table of the sequences, each sequence's reasons, and the dataset's
// verdict with its reasons.
std::string FormatTable(const proto::VerifyResult& result);

}  // namespace tiltcal::verify

#endif  // TILTCAL_STAGES_VERIFY_VERIFY_H_
