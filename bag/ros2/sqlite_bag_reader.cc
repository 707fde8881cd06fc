#include "bag/ros2/sqlite_bag_reader.h"

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <queue>
#include <sstream>

#include "bag/ros2/messages.h"
#include "bag/ros2/rosbag2_metadata.h"
#include "common/io/input_file.h"

namespace tiltcal::ros2 {

namespace fs = std::filesystem;

namespace {

constexpr char kMetadataFile[] = "metadata.yaml";
constexpr char kRowPosition[] = "row";

// "file:<path>?<query>" with the characters a URI path cannot hold
// percent-encoded.
std::string FileUri(const std::string& path, const char* query) {
  std::string uri = "file:";
  for (unsigned char c : path) {
    if (c == '%' || c == '?' || c == '#' || c < 0x20) {
      static const char kHex[] = "0123456789ABCDEF";
      uri += '%';
      uri += kHex[c >> 4];
      uri += kHex[c & 15];
    } else {
      uri += static_cast<char>(c);
    }
  }
  return uri + "?" + query;
}

}  // namespace

// One open .db3: its handle and its topic ids mapped to topics_ slots.
struct SqliteBagReader::Database {
  std::string file;
  sqlite3* db = nullptr;
  std::map<int64_t, std::string> topic_names;  // by topic id
  std::map<int64_t, size_t> slot_of_topic_id;   // into topics_, after Open()

  ~Database() {
    if (db != nullptr) sqlite3_close(db);
  }
  Status Error(const std::string& what) const {
    return Status::Error(file + ": " + what + ": " + sqlite3_errmsg(db));
  }
};

// The selected messages of one database in (timestamp, id) order.
class SqliteBagReader::Cursor {
 public:
  Cursor(Database* d, size_t file_index) : d_(d), file_index_(file_index) {}
  ~Cursor() { sqlite3_finalize(statement_); }
  Cursor(const Cursor&) = delete;
  Cursor& operator=(const Cursor&) = delete;

  Status Start(const std::vector<int64_t>& topic_ids, const bag::MessageSelection& selection) {
    std::string sql = "SELECT topic_id, timestamp, id, data FROM messages WHERE timestamp >= ?1 "
                      "AND timestamp < ?2 AND typeof(timestamp) = 'integer'";
    if (!selection.topics.empty()) {
      sql += " AND topic_id IN (";
      for (size_t i = 0; i < topic_ids.size(); ++i) {
        sql += (i ? "," : "") + std::to_string(topic_ids[i]);
      }
      sql += ")";
    }
    sql += " ORDER BY timestamp, id";
    if (sqlite3_prepare_v2(d_->db, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) {
      return d_->Error("cannot query the messages table");
    }
    sqlite3_bind_int64(statement_, 1, selection.start_ns);
    sqlite3_bind_int64(statement_, 2, selection.end_ns);
    return Step();
  }

  // Moves to the next row; done() after the last.
  Status Step() {
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_DONE) {
      done_ = true;
      return Status::Ok();
    }
    if (rc != SQLITE_ROW) {
      return d_->Error("reading the messages after row " + std::to_string(row_id_));
    }
    topic_id_ = sqlite3_column_int64(statement_, 0);
    time_ns_ = sqlite3_column_int64(statement_, 1);
    row_id_ = sqlite3_column_int64(statement_, 2);
    return Status::Ok();
  }

  bool done() const { return done_; }
  int64_t time_ns() const { return time_ns_; }
  int64_t row_id() const { return row_id_; }
  int64_t topic_id() const { return topic_id_; }
  size_t file_index() const { return file_index_; }
  Database* database() const { return d_; }
  // The blob of the current row, valid until the next Step().
  Status Data(const uint8_t** data, size_t* size) {
    const void* blob = sqlite3_column_blob(statement_, 3);
    const int bytes = sqlite3_column_bytes(statement_, 3);
    if (blob == nullptr && bytes > 0) return d_->Error("row " + std::to_string(row_id_));
    *data = static_cast<const uint8_t*>(blob);
    *size = static_cast<size_t>(bytes);
    return Status::Ok();
  }

 private:
  Database* d_;
  size_t file_index_;
  sqlite3_stmt* statement_ = nullptr;
  bool done_ = false;
  int64_t topic_id_ = 0;
  int64_t time_ns_ = 0;
  int64_t row_id_ = 0;
};

SqliteBagReader::SqliteBagReader() = default;
SqliteBagReader::~SqliteBagReader() = default;

Status SqliteBagReader::ListFiles(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) {
    if (!fs::exists(path, ec)) return Status::Error(path + ": no such file or folder");
    TILTCAL_RETURN_IF_ERROR(CheckInputFile(path));
    files_ = {path};
    return Status::Ok();
  }
  const std::string metadata = (fs::path(path) / kMetadataFile).string();
  std::vector<std::string> in_folder;  // the .db3 files of the folder, by name
  for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
    if (e.path().extension() == ".db3") in_folder.push_back(e.path().string());
  }
  std::sort(in_folder.begin(), in_folder.end());
  if (fs::exists(fs::symlink_status(metadata, ec))) {
    Rosbag2Metadata parsed;
    TILTCAL_RETURN_IF_ERROR(ReadRosbag2Metadata(metadata, &parsed));
    const std::vector<std::string>& relative = parsed.relative_file_paths;
    const std::string& compression = parsed.compression_format;
    if (!compression.empty()) {
      return Status::Error(metadata + ": compression_format '" + compression +
                           "': compressed rosbag2 bags are not supported (decompress them with "
                           "`ros2 bag convert`)");
    }
    if (relative.empty()) return Status::Error(metadata + ": no relative_file_paths");
    for (const std::string& r : relative) {
      const std::string file = (fs::path(path) / fs::path(r).filename()).string();
      if (!fs::exists(file, ec)) {
        return Status::Error(metadata + ": lists '" + r + "', which is not in " + path);
      }
      TILTCAL_RETURN_IF_ERROR(CheckInputFile(file));
      files_.push_back(file);
    }
    std::vector<std::string> unlisted;
    for (const std::string& file : in_folder) {
      if (std::find(files_.begin(), files_.end(), file) == files_.end()) {
        unlisted.push_back(fs::path(file).filename().string());
      }
    }
    if (!unlisted.empty()) {
      std::string names;
      for (const std::string& name : unlisted) names += (names.empty() ? "" : ", ") + name;
      warnings_.push_back(path + ": " + std::to_string(unlisted.size()) +
                          " .db3 file(s) of the folder not listed in metadata.yaml, not read: " +
                          names);
    }
    return Status::Ok();
  }
  files_ = in_folder;
  if (files_.empty()) return Status::Error(path + ": neither metadata.yaml nor .db3 files");
  return Status::Ok();
}

Status SqliteBagReader::Open(const std::string& path) {
  path_ = path;
  TILTCAL_RETURN_IF_ERROR(ListFiles(path));
  std::map<std::string, bag::TopicInfo> topics_by_name;
  for (const std::string& file : files_) {
    TILTCAL_RETURN_IF_ERROR(OpenDatabase(file, &topics_by_name));
  }
  std::map<std::string, size_t> slot_of_name;
  for (const auto& [name, topic] : topics_by_name) {
    slot_of_name[name] = topics_.size();
    topics_.push_back(topic);
  }
  for (auto& d : databases_) {
    for (const auto& [id, name] : d->topic_names) d->slot_of_topic_id[id] = slot_of_name[name];
  }
  return Status::Ok();
}

Status SqliteBagReader::OpenDatabase(const std::string& file,
                                     std::map<std::string, bag::TopicInfo>* topics) {
  auto d = std::make_unique<Database>();
  d->file = file;
  TILTCAL_RETURN_IF_ERROR(CheckInputFile(file));  // sqlite3 would block on a FIFO
  std::error_code ec;
  size_bytes_ += fs::file_size(file, ec);
  // With a WAL beside it, part of the messages may be in the WAL alone: the
  // database is opened read-only with its WAL (immutable would ignore it).
  const bool has_wal = fs::exists(file + "-wal", ec);
  if (sqlite3_open_v2(FileUri(file, has_wal ? "mode=ro" : "immutable=1").c_str(), &d->db,
                      SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) != SQLITE_OK) {
    return d->Error(has_wal ? "cannot open as sqlite3 with its -wal file" : "cannot open as sqlite3");
  }
  TILTCAL_RETURN_IF_ERROR(ReadTopics(d.get(), topics));
  databases_.push_back(std::move(d));
  return Status::Ok();
}

Status SqliteBagReader::ReadTopics(Database* d, std::map<std::string, bag::TopicInfo>* topics) {
  TILTCAL_RETURN_IF_ERROR(ReadTopicsTable(d, topics));
  std::map<std::string, int64_t> unusable_by_topic;
  TILTCAL_RETURN_IF_ERROR(CountMessages(d, topics, &unusable_by_topic));
  if (start_ns_ < 0) return NegativeTimestampError(*d);
  if (!unusable_by_topic.empty()) WarnUnusableTimestamps(*d, unusable_by_topic);
  return Status::Ok();
}

Status SqliteBagReader::ReadTopicsTable(Database* d,
                                        std::map<std::string, bag::TopicInfo>* topics) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(d->db, "SELECT id, name, type, serialization_format FROM topics", -1,
                         &s, nullptr) != SQLITE_OK) {
    return d->Error("not a rosbag2 sqlite3 file (no topics table)");
  }
  std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> guard(s, sqlite3_finalize);
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    const int64_t id = sqlite3_column_int64(s, 0);
    auto text = [&](int column) {
      const unsigned char* t = sqlite3_column_text(s, column);
      return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
    };
    const std::string name = text(1), type = text(2), format = text(3);
    if (format != kCdrEncoding) {
      return Status::Error(d->file + ": topic '" + name + "' has serialization_format '" +
                           format + "', only cdr is supported");
    }
    auto [it, inserted] = topics->emplace(name, bag::TopicInfo{name, type, 0});
    if (!inserted && it->second.type != type) {
      return Status::Error(d->file + ": topic '" + name + "' has type " + type +
                           ", another file of the bag says " + it->second.type);
    }
    d->topic_names[id] = name;
  }
  if (rc != SQLITE_DONE) return d->Error("reading the topics table");
  return Status::Ok();
}

Status SqliteBagReader::CountMessages(const Database* d,
                                      std::map<std::string, bag::TopicInfo>* topics,
                                      std::map<std::string, int64_t>* unusable_by_topic) {
  // Counts and time range of the rows with an integer timestamp; the
  // others (NULL, text, real) are counted apart and left out.
  sqlite3_stmt* c = nullptr;
  if (sqlite3_prepare_v2(d->db,
                         "SELECT topic_id, typeof(timestamp) = 'integer', COUNT(*), "
                         "MIN(timestamp), MAX(timestamp) FROM messages GROUP BY 1, 2",
                         -1, &c, nullptr) != SQLITE_OK) {
    return d->Error("not a rosbag2 sqlite3 file (no messages table)");
  }
  std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> count_guard(c, sqlite3_finalize);
  int rc;
  while ((rc = sqlite3_step(c)) == SQLITE_ROW) {
    const int64_t id = sqlite3_column_int64(c, 0);
    const auto name = d->topic_names.find(id);
    if (name == d->topic_names.end()) {
      return Status::Error(d->file + ": messages of topic id " + std::to_string(id) +
                           ", which the topics table does not have");
    }
    const int64_t count = sqlite3_column_int64(c, 2);
    if (sqlite3_column_int(c, 1) == 0) {
      (*unusable_by_topic)[name->second] += count;
      continue;
    }
    (*topics)[name->second].message_count += count;
    start_ns_ = std::min<int64_t>(start_ns_, sqlite3_column_int64(c, 3));
    end_ns_ = std::max<int64_t>(end_ns_, sqlite3_column_int64(c, 4));
  }
  if (rc != SQLITE_DONE) return d->Error("counting the messages");
  return Status::Ok();
}

Status SqliteBagReader::NegativeTimestampError(const Database& d) {
  sqlite3_stmt* n = nullptr;
  int64_t row = 0;
  if (sqlite3_prepare_v2(d.db,
                         "SELECT id FROM messages WHERE typeof(timestamp) = 'integer' AND "
                         "timestamp < 0 ORDER BY id LIMIT 1",
                         -1, &n, nullptr) == SQLITE_OK &&
      sqlite3_step(n) == SQLITE_ROW) {
    row = sqlite3_column_int64(n, 0);
  }
  sqlite3_finalize(n);
  return Status::Error(d.file + ": row " + std::to_string(row) +
                       " has a negative timestamp (before 1970): rosbag2 record times are "
                       "nanoseconds since the epoch, and messages are read in their order");
}

void SqliteBagReader::WarnUnusableTimestamps(
    const Database& d, const std::map<std::string, int64_t>& unusable_by_topic) {
  int64_t unusable = 0;
  for (const auto& [topic, count] : unusable_by_topic) unusable += count;
  // The first rows named, with what their timestamp is.
  sqlite3_stmt* u = nullptr;
  std::string rows;
  if (sqlite3_prepare_v2(d.db,
                         "SELECT id, typeof(timestamp) FROM messages WHERE typeof(timestamp) "
                         "!= 'integer' ORDER BY id LIMIT 5",
                         -1, &u, nullptr) == SQLITE_OK) {
    while (sqlite3_step(u) == SQLITE_ROW) {
      const unsigned char* type = sqlite3_column_text(u, 1);
      rows += (rows.empty() ? "" : ", ") + std::to_string(sqlite3_column_int64(u, 0)) + " (" +
              (type == nullptr ? "?" : reinterpret_cast<const char*>(type)) + ")";
    }
  }
  sqlite3_finalize(u);
  std::string by_topic;
  for (const auto& [topic, count] : unusable_by_topic) {
    by_topic += (by_topic.empty() ? "" : ", ") + topic + " " + std::to_string(count);
  }
  warnings_.push_back(d.file + ": " + std::to_string(unusable) +
                      " message(s) without an integer timestamp left out (" + by_topic +
                      "; rows " + rows + (unusable > 5 ? ", ..." : "") + ")");
}

bool SqliteBagReader::TimeRange(int64_t* start_ns, int64_t* end_ns) const {
  if (start_ns_ > end_ns_) return false;
  *start_ns = start_ns_;
  *end_ns = end_ns_;
  return true;
}

Status SqliteBagReader::ReadMessages(const bag::MessageSelection& selection,
                                     const std::function<Status(const bag::Message&)>& fn) {
  std::vector<std::unique_ptr<Cursor>> cursors;
  for (size_t i = 0; i < databases_.size(); ++i) {
    Database* d = databases_[i].get();
    std::vector<int64_t> ids;
    for (const auto& [id, name] : d->topic_names) {
      if (std::find(selection.topics.begin(), selection.topics.end(), name) !=
          selection.topics.end()) {
        ids.push_back(id);
      }
    }
    if (!selection.topics.empty() && ids.empty()) continue;
    cursors.push_back(std::make_unique<Cursor>(d, i));
    TILTCAL_RETURN_IF_ERROR(cursors.back()->Start(ids, selection));
  }
  // The cursor with the earliest (time, file, row) first.
  auto later = [](const Cursor* a, const Cursor* b) {
    if (a->time_ns() != b->time_ns()) return a->time_ns() > b->time_ns();
    if (a->file_index() != b->file_index()) return a->file_index() > b->file_index();
    return a->row_id() > b->row_id();
  };
  std::priority_queue<Cursor*, std::vector<Cursor*>, decltype(later)> queue(later);
  for (auto& c : cursors) {
    if (!c->done()) queue.push(c.get());
  }
  bag::Message m;
  m.encoding = bag::Encoding::kCdr;
  m.position_name = kRowPosition;
  while (!queue.empty()) {
    Cursor* c = queue.top();
    queue.pop();
    m.topic = &topics_[c->database()->slot_of_topic_id.at(c->topic_id())].name;
    m.time_ns = c->time_ns();
    m.file = &c->database()->file;
    m.position = static_cast<uint64_t>(c->row_id());
    TILTCAL_RETURN_IF_ERROR(c->Data(&m.data, &m.size));
    TILTCAL_RETURN_IF_ERROR(fn(m));
    ++m.sequence;
    TILTCAL_RETURN_IF_ERROR(c->Step());
    if (!c->done()) queue.push(c);
  }
  return Status::Ok();
}

}  // namespace tiltcal::ros2
