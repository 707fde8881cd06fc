#ifndef TILTCAL_STAGES_INSPECT_INSPECT_H_
#define TILTCAL_STAGES_INSPECT_INSPECT_H_

#include <cstdint>
#include <ostream>
#include <string>

#include "common/status.h"

namespace tiltcal::inspect {

// `tiltcal_inspect info FILE`: type, provenance, record count, time span and
// per-type statistics (points per scan, IMU rate, ground planes by reason).
Status RunInfo(const std::string& path, std::ostream& out);

struct CatOptions {
  int64_t from = 0;
  int64_t count = -1;  // all
  bool single_line = false;
};
// `tiltcal_inspect cat FILE`: records in text format, one per line with
// single_line (so grep / wc -l / head work).
Status RunCat(const std::string& path, const CatOptions& options, std::ostream& out);

struct CsvOptions {
  bool points = false;     // the points of one scan instead of one row per scan
  int64_t record = 0;      // with points
  std::string field;       // text files: which repeated field to tabulate
};
// `tiltcal_inspect csv FILE`: a header row of dotted field paths and one row per
// record (the column names are a fixed interface, docs/design.md §4). For a
// text file (e.g. gravity.txtpb, truth.txtpb) the rows are the elements of its
// longest repeated message field (the per-scan list), or of `field`.
// With `points`: x,y,z,intensity,ring,time_offset_ns of scan `record`.
Status RunCsv(const std::string& path, const CsvOptions& options, std::ostream& out);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_INSPECT_H_
