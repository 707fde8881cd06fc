#include "stages/inspect/inspect.h"

#include <algorithm>
#include <map>

#include <google/protobuf/text_format.h>

#include "common/checked_conversion.h"
#include "stages/inspect/any_file.h"
#include "stages/inspect/csv_table.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::inspect {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// Accumulates what `info` prints beyond the header.
class StreamStats {
 public:
  void Add(const Message& record) {
    ++count_;
    const FieldDescriptor* stamp = record.GetDescriptor()->FindFieldByName("stamp_ns");
    if (stamp != nullptr && stamp->cpp_type() == FieldDescriptor::CPPTYPE_INT64) {
      const int64_t stamp_ns = record.GetReflection()->GetInt64(record, stamp);
      first_ns_ = std::min(first_ns_, stamp_ns);
      last_ns_ = std::max(last_ns_, stamp_ns);
      has_stamps_ = true;
    }
    if (const auto* scan = dynamic_cast<const proto::Scan*>(&record)) {
      const int64_t n = scan->x_size();
      points_ += n;
      min_points_ = std::min(min_points_, n);
      max_points_ = std::max(max_points_, n);
      dropped_ += scan->num_dropped_invalid() + scan->num_dropped_zero_range();
      ++time_sources_[proto::PointTimeSource_Name(scan->time_source())];
    }
    if (const auto* plane = dynamic_cast<const proto::GroundPlane*>(&record)) {
      ++reasons_[proto::GroundRejectReason_Name(plane->reject_reason())];
    }
  }

  void Print(std::ostream& out) const {
    out << "records: " << count_ << "\n";
    if (has_stamps_ && count_ > 0) {
      const double span_s = DifferenceSeconds(last_ns_, first_ns_);
      out << "stamps: " << first_ns_ << " .. " << last_ns_ << " ns (span "
          << FormatDouble(span_s) << " s";
      if (count_ > 1 && span_s > 0) out << ", " << FormatDouble((count_ - 1) / span_s) << " Hz";
      out << ")\n";
    }
    if (!time_sources_.empty()) {
      out << "points: " << points_ << " (per scan min " << min_points_ << ", mean "
          << FormatDouble(static_cast<double>(points_) / count_) << ", max " << max_points_
          << "), dropped " << dropped_ << "\n";
      for (const auto& [name, n] : time_sources_) out << "point time: " << name << " x" << n << "\n";
    }
    for (const auto& [name, n] : reasons_) out << "ground: " << name << " x" << n << "\n";
  }

 private:
  int64_t count_ = 0;
  bool has_stamps_ = false;
  int64_t first_ns_ = INT64_MAX;
  int64_t last_ns_ = INT64_MIN;
  int64_t points_ = 0;
  int64_t min_points_ = INT64_MAX;
  int64_t max_points_ = 0;
  int64_t dropped_ = 0;
  std::map<std::string, int64_t> time_sources_;
  std::map<std::string, int64_t> reasons_;
};

std::string ToText(const Message& message, bool single_line) {
  std::string text;
  google::protobuf::TextFormat::Printer printer;
  printer.SetSingleLineMode(single_line);
  printer.PrintToString(message, &text);
  return text;
}

// The repeated message field of a text file that `csv` tabulates: `requested`,
// or else the longest one (the per-scan list of gravity.txtpb / truth.txtpb).
Status FindTableField(const AnyFile& file, const std::string& requested,
                      const FieldDescriptor** field) {
  const Message& message = *file.message;
  const auto* type = message.GetDescriptor();
  int longest = 0;
  for (int i = 0; i < type->field_count(); ++i) {
    const FieldDescriptor* candidate = type->field(i);
    if (!candidate->is_repeated() ||
        candidate->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE) {
      continue;
    }
    const int size = message.GetReflection()->FieldSize(message, candidate);
    if (requested.empty() ? size > longest : candidate->name() == requested) {
      *field = candidate;
      longest = size;
      if (!requested.empty()) return Status::Ok();
    }
  }
  if (requested.empty() && longest > 0) return Status::Ok();
  return Status::Error(file.path + ": " + type->full_name() + " has no " +
                       (requested.empty() ? "non-empty repeated message field to tabulate"
                                          : "repeated message field '" + requested + "'"));
}

Status PrintPoints(const AnyFile& file, int64_t wanted, std::ostream& out) {
  if (file.type != proto::Scan::descriptor()) {
    return Status::Error(file.path + ": --points needs a scan stream, this holds " +
                         file.type->full_name());
  }
  bool found = false;
  TILTCAL_RETURN_IF_ERROR(ForEachRecord(file, [&](int64_t index, const Message& record) {
    if (index < wanted) return true;
    const auto& scan = static_cast<const proto::Scan&>(record);
    out << "x,y,z,intensity,ring,time_offset_ns\n";
    for (int i = 0; i < scan.x_size(); ++i) {
      out << FormatDouble(scan.x(i)) << ',' << FormatDouble(scan.y(i)) << ','
          << FormatDouble(scan.z(i)) << ','
          << (i < scan.intensity_size() ? FormatDouble(scan.intensity(i)) : "") << ','
          << (i < scan.ring_size() ? std::to_string(scan.ring(i)) : "") << ','
          << (i < scan.time_offset_ns_size() ? std::to_string(scan.time_offset_ns(i)) : "")
          << '\n';
    }
    found = true;
    return false;
  }));
  if (!found) {
    return Status::Error(file.path + ": no record " + std::to_string(wanted));
  }
  return Status::Ok();
}

}  // namespace

Status RunInfo(const std::string& path, std::ostream& out) {
  AnyFile file;
  TILTCAL_RETURN_IF_ERROR(OpenAnyFile(path, &file));
  out << "file: " << path << "\n";
  if (!file.is_stream) {
    out << "text message: " << file.type->full_name() << "\n";
    const FieldDescriptor* provenance = file.type->FindFieldByName("provenance");
    if (provenance != nullptr &&
        file.message->GetReflection()->HasField(*file.message, provenance)) {
      out << "provenance:\n"
          << ToText(file.message->GetReflection()->GetMessage(*file.message, provenance), false);
    }
    return Status::Ok();
  }
  out << "record stream: " << file.header.payload_type() << " (format "
      << file.header.format_version() << ")\n";
  out << "provenance:\n" << ToText(file.header.provenance(), false);
  StreamStats stats;
  TILTCAL_RETURN_IF_ERROR(ForEachRecord(file, [&](int64_t, const Message& record) {
    stats.Add(record);
    return true;
  }));
  stats.Print(out);
  return Status::Ok();
}

Status RunCat(const std::string& path, const CatOptions& options, std::ostream& out) {
  AnyFile file;
  TILTCAL_RETURN_IF_ERROR(OpenAnyFile(path, &file));
  return ForEachRecord(file, [&](int64_t index, const Message& record) {
    if (index < options.from) return true;
    if (options.count >= 0 && index >= options.from + options.count) return false;
    if (options.single_line) {
      out << ToText(record, true) << '\n';
    } else {
      out << "# record " << index << "\n" << ToText(record, false);
    }
    return true;
  });
}

Status RunCsv(const std::string& path, const CsvOptions& options, std::ostream& out) {
  AnyFile file;
  TILTCAL_RETURN_IF_ERROR(OpenAnyFile(path, &file));
  if (options.points) return PrintPoints(file, options.record, out);
  if (!file.is_stream) {
    const FieldDescriptor* field = nullptr;
    TILTCAL_RETURN_IF_ERROR(FindTableField(file, options.field, &field));
    const CsvTable table(field->message_type());
    out << table.HeaderRow() << '\n';
    const auto* reflection = file.message->GetReflection();
    for (int i = 0; i < reflection->FieldSize(*file.message, field); ++i) {
      out << table.Row(reflection->GetRepeatedMessage(*file.message, field, i)) << '\n';
    }
    return Status::Ok();
  }
  const CsvTable table(file.type);
  out << table.HeaderRow() << '\n';
  return ForEachRecord(file, [&](int64_t, const Message& record) {
    out << table.Row(record) << '\n';
    return true;
  });
}

}  // namespace tiltcal::inspect
