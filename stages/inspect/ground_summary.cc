#include "stages/inspect/ground_summary.h"

#include <algorithm>
#include <cctype>
#include <map>

#include "common/io/record_stream.h"
#include "tiltcal/proto/ground.pb.h"

namespace tiltcal::inspect {

Status PrintGroundSummary(const std::string& path, std::ostream& out) {
  RecordReader reader;
  // Not a record stream (e.g. a text result): nothing to summarise.
  if (!reader.Open(path).ok()) return Status::Ok();
  if (reader.header().payload_type() != proto::GroundPlane::descriptor()->full_name()) {
    return Status::Ok();
  }
  int64_t scans = 0, valid = 0;
  std::map<int, int64_t> rejected;
  proto::GroundPlane plane;
  for (;;) {
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(reader.Read(&plane, &end));
    if (end) break;
    ++scans;
    if (plane.valid()) {
      ++valid;
    } else {
      ++rejected[plane.reject_reason()];
    }
  }
  out << path << ": " << scans << " scans, " << valid << " valid";
  if (!rejected.empty()) {
    out << "; rejected:";
    for (const auto& [reason, count] : rejected) {
      std::string name =
          proto::GroundRejectReason_Name(static_cast<proto::GroundRejectReason>(reason));
      if (name.rfind("GROUND_", 0) == 0) name = name.substr(7);
      std::transform(name.begin(), name.end(), name.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      out << " " << (name.empty() ? std::to_string(reason) : name) << "=" << count;
    }
  }
  out << "\n";
  return Status::Ok();
}

}  // namespace tiltcal::inspect
