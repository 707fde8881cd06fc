#include "stages/inspect/bag_info_report.h"

#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "common/io/escaping.h"

namespace tiltcal::inspect {
namespace {

// `text` with C0 controls and DEL as \xNN (a name cannot break a line).
std::string Printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    out += u < 0x20 || u == 0x7F ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  return out;
}

// ns since the epoch as seconds with nine decimals, exact.
std::string Seconds(int64_t ns) {
  const bool negative = ns < 0;
  const uint64_t magnitude = negative ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  return fmt::format("{}{}.{:09}", negative ? "-" : "", magnitude / 1000000000u,
                     magnitude % 1000000000u);
}

std::string Span(int64_t first_ns, int64_t last_ns) {
  return fmt::format("{} .. {} s ({} s)", Seconds(first_ns), Seconds(last_ns),
                     Seconds(last_ns - first_ns));
}

std::string Compressions(const BagInfo& info) {
  if (info.chunk_compressions.empty()) return "no chunks";
  std::string out;
  for (const auto& [name, count] : info.chunk_compressions) {
    out += fmt::format("{}{} ({} chunk{})", out.empty() ? "" : ", ", name, count,
                       count == 1 ? "" : "s");
  }
  return out;
}

std::string Decoded(const TopicFigures& t) {
  if (!t.sensor_type) return "-";
  if (t.decode_failures == 0) return fmt::format("all {}", t.count);
  return fmt::format("{} of {}", t.decoded, t.count);
}

// "label        value", the values aligned; `indent` before the label.
void Line(std::ostream& out, const std::string& label, const std::string& value,
          const std::string& indent = "") {
  out << fmt::format("{}{:<13}{}\n", indent, label, value);
}

// Rows of cells, each column as wide as its widest cell, two spaces apart.
void Table(std::ostream& out, const std::vector<std::vector<std::string>>& rows,
           const std::string& indent) {
  std::vector<size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()), 0);
    for (size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  for (const auto& row : rows) {
    std::string line = indent;
    for (size_t i = 0; i < row.size(); ++i) {
      line += i + 1 < row.size() ? fmt::format("{:<{}}  ", row[i], widths[i]) : row[i];
    }
    out << line << "\n";
  }
}

std::string Count(int64_t n) { return n < 0 ? "(not stated)" : fmt::format("{}", n); }

void WriteMetadataText(const BagInfo& info, std::ostream& out) {
  const ros2::Rosbag2Figures& m = info.metadata;
  out << "metadata.yaml (what the recorder states) " << Printable(info.metadata_path) << "\n";
  Line(out, "storage", Printable(m.storage_identifier), "  ");
  Line(out, "compression",
       m.compression_format.empty()
           ? "none"
           : Printable(m.compression_format + " (mode " + m.compression_mode + ")"),
       "  ");
  Line(out, "messages", Count(m.message_count), "  ");
  Line(out, "span",
       m.starting_time_ns < 0 || m.duration_ns < 0
           ? "(not stated)"
           : Span(m.starting_time_ns, m.starting_time_ns + m.duration_ns),
       "  ");
  std::vector<std::vector<std::string>> rows = {{"topic", "type", "messages", "serialization"}};
  for (const ros2::Rosbag2TopicFigures& t : m.topics) {
    rows.push_back({Printable(t.name), Printable(t.type), Count(t.message_count),
                    Printable(t.serialization_format)});
  }
  Line(out, "topics", fmt::format("{}", m.topics.size()), "  ");
  if (!m.topics.empty()) Table(out, rows, "    ");
}

std::string Json(const std::string& text) { return QuotedString(text); }
std::string JsonInt(int64_t v, bool present = true) {
  return present ? fmt::format("{}", v) : "null";
}
std::string JsonList(const std::vector<std::string>& items) {
  std::string out = "[";
  for (size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + Json(items[i]);
  return out + "]";
}

}  // namespace

void WriteBagInfoText(const BagInfo& info, std::ostream& out) {
  Line(out, "bag", Printable(info.path));
  Line(out, "format", info.format + (info.indexed ? "" : ", no index (the file was scanned)"));
  Line(out, "files", fmt::format("{}, {} bytes", info.files.size(), info.size_bytes));
  if (info.files.size() > 1) {
    for (const std::string& file : info.files) out << "  " << Printable(file) << "\n";
  }
  Line(out, "compression", Compressions(info));
  Line(out, "messages", fmt::format("{}", info.message_count));
  Line(out, "span", info.message_count == 0 ? "(no messages)" : Span(info.first_ns, info.last_ns));
  Line(out, "topics", fmt::format("{}", info.topics.size()));
  if (!info.topics.empty()) {
    std::vector<std::vector<std::string>> rows = {
        {"topic", "type", "messages", "encoding", "rate_hz", "first_s", "last_s", "decoded"}};
    for (const TopicFigures& t : info.topics) {
      rows.push_back({Printable(t.name), Printable(t.type), fmt::format("{}", t.count),
                      t.encoding.empty() ? "-" : t.encoding,
                      t.count < 2 ? "-" : fmt::format("{:.2f}", t.rate_hz),
                      t.count == 0 ? "-" : Seconds(t.first_ns),
                      t.count == 0 ? "-" : Seconds(t.last_ns), Decoded(t)});
    }
    Table(out, rows, "  ");
  }
  if (info.has_metadata) WriteMetadataText(info, out);
  Line(out, "warnings", info.warnings.empty() ? "none" : fmt::format("{}", info.warnings.size()));
  for (const std::string& w : info.warnings) out << "warning: " << Printable(w) << "\n";
}

void WriteBagInfoJson(const BagInfo& info, std::ostream& out) {
  const bool any = info.message_count > 0;
  out << "{\n";
  out << "  \"path\": " << Json(info.path) << ",\n";
  out << "  \"format\": " << Json(info.format) << ",\n";
  out << "  \"files\": " << JsonList(info.files) << ",\n";
  out << "  \"size_bytes\": " << info.size_bytes << ",\n";
  out << "  \"indexed\": " << (info.indexed ? "true" : "false") << ",\n";
  out << "  \"salvage_note\": " << Json(info.salvage_note) << ",\n";
  out << "  \"chunk_compressions\": {";
  bool first = true;
  for (const auto& [name, count] : info.chunk_compressions) {
    out << (first ? "" : ", ") << Json(name) << ": " << count;
    first = false;
  }
  out << "},\n";
  out << "  \"duplicates_dropped\": " << info.duplicates_dropped << ",\n";
  out << "  \"message_count\": " << info.message_count << ",\n";
  out << "  \"start_ns\": " << JsonInt(info.first_ns, any) << ",\n";
  out << "  \"end_ns\": " << JsonInt(info.last_ns, any) << ",\n";
  out << "  \"duration_ns\": " << JsonInt(info.last_ns - info.first_ns, any) << ",\n";
  out << "  \"topics\": [";
  for (size_t i = 0; i < info.topics.size(); ++i) {
    const TopicFigures& t = info.topics[i];
    const bool some = t.count > 0;
    out << (i ? "," : "") << "\n    {\"name\": " << Json(t.name) << ", \"type\": " << Json(t.type)
        << ", \"encoding\": " << Json(t.encoding) << ", \"message_count\": " << t.count
        << ", \"indexed_message_count\": " << t.indexed_count
        << ", \"start_ns\": " << JsonInt(t.first_ns, some)
        << ", \"end_ns\": " << JsonInt(t.last_ns, some)
        << ", \"rate_hz\": " << fmt::format("{}", t.rate_hz)
        << ", \"sensor_type\": " << (t.sensor_type ? "true" : "false")
        << ", \"decoded\": " << t.decoded << ", \"decode_failures\": " << t.decode_failures
        << ", \"decode_error\": " << Json(t.decode_error) << "}";
  }
  out << (info.topics.empty() ? "" : "\n  ") << "],\n";
  out << "  \"rosbag2_metadata\": ";
  if (!info.has_metadata) {
    out << "null";
  } else {
    const ros2::Rosbag2Figures& m = info.metadata;
    auto stated = [](int64_t v) { return JsonInt(v, v >= 0); };
    out << "{\"path\": " << Json(info.metadata_path) << ", \"version\": " << stated(m.version)
        << ", \"storage_identifier\": " << Json(m.storage_identifier)
        << ", \"compression_format\": " << Json(m.compression_format)
        << ", \"compression_mode\": " << Json(m.compression_mode)
        << ", \"starting_time_ns\": " << stated(m.starting_time_ns)
        << ", \"duration_ns\": " << stated(m.duration_ns)
        << ", \"message_count\": " << stated(m.message_count) << ", \"topics\": [";
    for (size_t i = 0; i < m.topics.size(); ++i) {
      const ros2::Rosbag2TopicFigures& t = m.topics[i];
      out << (i ? ", " : "") << "{\"name\": " << Json(t.name) << ", \"type\": " << Json(t.type)
          << ", \"serialization_format\": " << Json(t.serialization_format)
          << ", \"message_count\": " << stated(t.message_count) << "}";
    }
    out << "]}";
  }
  out << ",\n";
  out << "  \"warnings\": " << JsonList(info.warnings) << "\n";
  out << "}\n";
}

}  // namespace tiltcal::inspect
