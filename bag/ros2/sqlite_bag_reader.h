#ifndef TILTCAL_BAG_ROS2_SQLITE_BAG_READER_H_
#define TILTCAL_BAG_ROS2_SQLITE_BAG_READER_H_

// Reader of rosbag2 bags in the sqlite3 storage, through libsqlite3 and
// without ROS. A bag is a folder with metadata.yaml and the .db3 files it
// lists under relative_file_paths (a folder without metadata.yaml: its *.db3
// files in name order), or a single .db3 file. Every .db3 holds
//   topics(id, name, type, serialization_format, offered_qos_profiles, ...)
//   messages(id, topic_id, timestamp, data)   timestamp = record time, ns
// Topic ids are per file; topics are matched across files by name (the type
// must agree). Messages come in record-time order across all files (ties in
// file order, then by row id), read by one cursor per file: memory does not
// grow with the bag. The files are opened read-only and immutable (no
// journal, no lock), except a file with a "-wal" file beside it (a recorder
// stopped before its last checkpoint): it is opened read-only without
// immutable, so that the messages still in the WAL are read too.
// What is not read is said in warnings(), with counts and names: .db3 files
// of the folder that metadata.yaml does not list, and rows whose timestamp
// is not an integer (NULL, text, real; left out of the counts and the time
// range too). A negative timestamp (before 1970) is an error naming the
// row: the record-time order of such a bag is not the order of recording.
// Compressed bags (compression_format in the metadata) and serialization
// formats other than cdr are errors naming the file.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bag/message_reader.h"
#include "common/status.h"

namespace tiltcal::ros2 {

class SqliteBagReader : public bag::MessageReader {
 public:
  SqliteBagReader();
  ~SqliteBagReader() override;
  SqliteBagReader(const SqliteBagReader&) = delete;
  SqliteBagReader& operator=(const SqliteBagReader&) = delete;

  // Opens the folder or .db3 at `path`: the files, their topics, message
  // counts and time range. Errors name the file.
  Status Open(const std::string& path);

  // The .db3 files, in the order of the metadata.
  const std::vector<std::string>& files() const { return files_; }

  const std::string& path() const override { return path_; }
  std::vector<std::string> input_files() const override { return files_; }
  uint64_t size_bytes() const override { return size_bytes_; }
  std::string format_name() const override { return "rosbag2 sqlite3"; }
  bool indexed() const override { return true; }
  std::vector<std::string> warnings() const override { return warnings_; }
  const std::vector<bag::TopicInfo>& topics() const override { return topics_; }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override;
  Status ReadMessages(const bag::MessageSelection& selection,
                      const std::function<Status(const bag::Message&)>& fn) override;

 private:
  struct Database;
  class Cursor;

  Status ListFiles(const std::string& path);
  // Opens one .db3 and adds its topics and counts to *topics (by name).
  Status OpenDatabase(const std::string& file, std::map<std::string, bag::TopicInfo>* topics);
  Status ReadTopics(Database* d, std::map<std::string, bag::TopicInfo>* topics);
  // The topics table: names, types, and the ids of the database.
  Status ReadTopicsTable(Database* d, std::map<std::string, bag::TopicInfo>* topics);
  // Message counts and the time range of the rows with an integer timestamp;
  // the others counted by topic in *unusable_by_topic.
  Status CountMessages(const Database* d, std::map<std::string, bag::TopicInfo>* topics,
                       std::map<std::string, int64_t>* unusable_by_topic);
  // The error naming the first row with a negative timestamp.
  static Status NegativeTimestampError(const Database& d);
  // The warning of the rows left out for want of an integer timestamp.
  void WarnUnusableTimestamps(const Database& d,
                              const std::map<std::string, int64_t>& unusable_by_topic);

  std::string path_;
  std::vector<std::string> files_;
  std::vector<std::unique_ptr<Database>> databases_;
  std::vector<bag::TopicInfo> topics_;
  std::vector<std::string> warnings_;
  uint64_t size_bytes_ = 0;
  int64_t start_ns_ = INT64_MAX;
  int64_t end_ns_ = INT64_MIN;
};

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_SQLITE_BAG_READER_H_
