#ifndef TILTCAL_STAGES_INSPECT_CSV_TABLE_H_
#define TILTCAL_STAGES_INSPECT_CSV_TABLE_H_

#include <string>
#include <vector>

#include <google/protobuf/message.h>

namespace tiltcal::inspect {

// Flattens the singular scalar fields of a message type, recursing into
// singular sub-messages, into CSV columns named by dotted paths
// (`normal_in_lidar.x`). Repeated fields are left out, except that a Scan
// gets a computed `num_points` column. Enums print by name, doubles in their
// shortest round-trip form, unset `optional` fields as empty cells.
class CsvTable {
 public:
  explicit CsvTable(const google::protobuf::Descriptor* type);

  std::string HeaderRow() const;
  std::string Row(const google::protobuf::Message& record) const;

 private:
  struct Column {
    std::string name;
    std::vector<const google::protobuf::FieldDescriptor*> path;
  };
  void AddColumns(const google::protobuf::Descriptor* type, const std::string& prefix,
                  std::vector<const google::protobuf::FieldDescriptor*> path);

  std::vector<Column> columns_;
  bool is_scan_ = false;
};

// Shortest decimal text that parses back to the same double.
std::string FormatDouble(double value);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CSV_TABLE_H_
