#include "bag/merged_message_reader.h"

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <new>
#include <thread>
#include <unordered_map>

namespace tiltcal::bag {

namespace {

// A message copied out of its reader's callback, owned by the merge.
struct OwnedMessage {
  const std::string* topic = nullptr;  // the merged reader's topic name
  Encoding encoding = Encoding::kRos1;
  int64_t time_ns = 0;
  const std::string* file = nullptr;
  const char* position_name = "";
  uint64_t position = 0;
  std::vector<uint8_t> data;
};

// True when the reader's type names are ROS 2 ("pkg/msg/Type").
bool HasRos2TypeNames(const MessageReader& reader) {
  for (const TopicInfo& t : reader.topics()) {
    if (t.type.find("/msg/") != std::string::npos) return true;
  }
  return false;
}

}  // namespace

// One file's messages, read on its own thread into a bounded queue. The
// merge (the calling thread) takes them with Take(); Stop() ends the thread
// early.
class MergedMessageReader::Source {
 public:
  Source(MessageReader* reader, size_t index, const std::string& file,
         const std::unordered_map<std::string, const std::string*>* topic_names)
      : reader_(reader), index_(index), file_(file), topic_names_(topic_names) {}

  ~Source() {
    Stop();
  }

  size_t index() const { return index_; }
  bool started() const { return thread_.joinable() || finished_; }

  // Starts reading the messages of `selection` that this file has.
  void Start(MessageSelection selection) {
    thread_ = std::thread([this, selection = std::move(selection)] {
      Status status;
      try {  // an exception would end the process from this thread
        status = reader_->ReadMessages(selection, [this](const Message& m) { return Push(m); });
      } catch (const std::bad_alloc&) {
        status = Status::Error(file_ + ": out of memory reading its messages");
      }
      std::lock_guard<std::mutex> lock(mutex_);
      if (!stop_) status_ = status;
      done_ = true;
      cv_.notify_all();
    });
  }

  // Waits for the next message: true with it in *m, false at the end of the
  // file (or with the file's error in *status).
  bool Take(OwnedMessage* m, Status* status) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return !queue_.empty() || done_; });
    if (queue_.empty()) {
      *status = status_;
      lock.unlock();
      Stop();
      finished_ = true;
      return false;
    }
    *m = std::move(queue_.front());
    queue_.pop_front();
    queued_bytes_ -= m->data.size();
    cv_.notify_all();
    return true;
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      cv_.notify_all();
    }
    if (thread_.joinable()) thread_.join();
  }

 private:
  Status Push(const Message& m) {
    OwnedMessage owned;
    owned.topic = topic_names_->at(*m.topic);
    owned.encoding = m.encoding;
    owned.time_ns = m.time_ns;
    // Single-file readers leave `file` empty: the file is this source's.
    if (m.file == nullptr) {
      owned.file = &file_;
    } else {
      if (file_names_.empty() || file_names_.back() != *m.file) file_names_.push_back(*m.file);
      owned.file = &file_names_.back();
    }
    owned.position_name = m.position_name;
    owned.position = m.position;
    owned.data.assign(m.data, m.data + m.size);
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] {
      return stop_ || queue_.empty() ||
             (queued_bytes_ < kMaxQueuedBytes && queue_.size() < kMaxQueuedMessages);
    });
    if (stop_) return Status::Error(file_ + ": reading stopped");
    queued_bytes_ += owned.data.size();
    queue_.push_back(std::move(owned));
    cv_.notify_all();
    return Status::Ok();
  }

  MessageReader* reader_;
  size_t index_;
  std::string file_;
  const std::unordered_map<std::string, const std::string*>* topic_names_;
  std::deque<std::string> file_names_;  // stable addresses for OwnedMessage::file
  std::thread thread_;
  bool finished_ = false;  // Take() returned false
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<OwnedMessage> queue_;
  size_t queued_bytes_ = 0;
  bool done_ = false;
  bool stop_ = false;
  Status status_;
};

MergedMessageReader::MergedMessageReader() = default;
MergedMessageReader::~MergedMessageReader() = default;

Status MergedMessageReader::Open(const std::string& path,
                                 std::vector<std::unique_ptr<MessageReader>> files) {
  path_ = path;
  files_ = std::move(files);
  if (files_.empty()) return Status::Error(path + ": no bag files");
  std::map<std::string, TopicInfo> topics;
  std::map<std::string, std::string> file_of_topic;
  const MessageReader* ros1_file = nullptr;
  const MessageReader* ros2_file = nullptr;
  for (const auto& f : files_) {
    // The first file of each ROS version that holds messages (an empty
    // file has no version).
    const MessageReader*& first = HasRos2TypeNames(*f) ? ros2_file : ros1_file;
    if (first == nullptr && f->TotalMessageCount() > 0) first = f.get();
    for (const TopicInfo& t : f->topics()) {
      auto [it, inserted] = topics.emplace(t.name, TopicInfo{t.name, t.type, 0});
      if (inserted) file_of_topic[t.name] = f->path();
      if (it->second.type != t.type) {
        return Status::Error(f->path() + ": topic '" + t.name + "' has type " + t.type + ", but " +
                             it->second.type + " in " + file_of_topic[t.name]);
      }
      it->second.message_count += t.message_count;
    }
  }
  if (ros1_file != nullptr && ros2_file != nullptr) {
    return Status::Error(path + ": " + ros1_file->path() + " holds ROS 1 messages and " +
                         ros2_file->path() +
                         " ROS 2 ones; the files of one sequence must come from one ROS version");
  }
  topics_.clear();
  for (auto& [name, topic] : topics) topics_.push_back(topic);
  return Status::Ok();
}

std::vector<std::string> MergedMessageReader::input_files() const {
  std::vector<std::string> out;
  for (const auto& f : files_) {
    for (std::string& file : f->input_files()) out.push_back(std::move(file));
  }
  return out;
}

uint64_t MergedMessageReader::size_bytes() const {
  uint64_t total = 0;
  for (const auto& f : files_) total += f->size_bytes();
  return total;
}

std::string MergedMessageReader::format_name() const {
  std::vector<std::string> formats;
  for (const auto& f : files_) {
    if (std::find(formats.begin(), formats.end(), f->format_name()) == formats.end()) {
      formats.push_back(f->format_name());
    }
  }
  std::string out = std::to_string(files_.size()) + " files (";
  for (size_t i = 0; i < formats.size(); ++i) out += (i > 0 ? ", " : "") + formats[i];
  return out + ")";
}

bool MergedMessageReader::indexed() const {
  return std::all_of(files_.begin(), files_.end(), [](const auto& f) { return f->indexed(); });
}

int64_t MergedMessageReader::num_salvaged_messages() const {
  int64_t total = 0;
  for (const auto& f : files_) total += f->num_salvaged_messages();
  return total;
}

std::string MergedMessageReader::salvage_note() const {
  std::string out;
  for (const auto& f : files_) {
    const std::string note = f->salvage_note();
    if (!note.empty()) out += (out.empty() ? "" : "; ") + f->path() + ": " + note;
  }
  return out;
}

std::vector<std::string> MergedMessageReader::warnings() const {
  std::vector<std::string> out;
  for (const auto& f : files_) {
    for (std::string& w : f->warnings()) out.push_back(std::move(w));
  }
  return out;
}

uint64_t MergedMessageReader::chunks_decompressed() const {
  uint64_t total = 0;
  for (const auto& f : files_) total += f->chunks_decompressed();
  return total;
}

Status MergedMessageReader::ChunkCompressions(std::map<std::string, int64_t>* compressions) const {
  compressions->clear();
  for (const auto& f : files_) {
    std::map<std::string, int64_t> of_file;
    TILTCAL_RETURN_IF_ERROR(f->ChunkCompressions(&of_file));
    for (const auto& [name, count] : of_file) (*compressions)[name] += count;
  }
  return Status::Ok();
}

bool MergedMessageReader::TimeRange(int64_t* start_ns, int64_t* end_ns) const {
  bool any = false;
  for (const auto& f : files_) {
    int64_t s = 0, e = 0;
    if (!f->TimeRange(&s, &e)) continue;
    *start_ns = any ? std::min(*start_ns, s) : s;
    *end_ns = any ? std::max(*end_ns, e) : e;
    any = true;
  }
  return any;
}

// A file that holds a selected topic, with its lower bound: its first
// record time until its first message is taken, then that message.
struct MergedMessageReader::Head {
  std::unique_ptr<Source> source;
  MessageSelection selection;
  int64_t key_ns;
  bool has_message = false;
  OwnedMessage message;

  bool finished() const { return source->started() && !has_message; }
  // Takes the next message of the file into `message`.
  Status Advance() {
    Status status;
    has_message = source->Take(&message, &status);
    if (!status.ok()) return status;
    if (has_message) key_ns = message.time_ns;
    return Status::Ok();
  }
};

namespace {

// The messages given at the latest record time, to recognise the same
// message in a later file.
class GivenAtTime {
 public:
  bool IsDuplicate(const OwnedMessage& m) {
    if (!given_.empty() && given_.front().time_ns != m.time_ns) given_.clear();
    for (const OwnedMessage& g : given_) {
      if (g.topic == m.topic && g.file != m.file && g.data == m.data) return true;
    }
    return false;
  }
  void Add(OwnedMessage&& m) { given_.push_back(std::move(m)); }

 private:
  std::vector<OwnedMessage> given_;
};

// `m` as the message handed out (`sequence` is the caller's).
void ViewOf(const OwnedMessage& m, Message* out) {
  out->topic = m.topic;
  out->encoding = m.encoding;
  out->time_ns = m.time_ns;
  out->file = m.file;
  out->position_name = m.position_name;
  out->position = m.position;
  out->data = m.data.data();
  out->size = m.data.size();
}

}  // namespace

std::vector<MergedMessageReader::Head> MergedMessageReader::OpenHeads(
    const MessageSelection& selection,
    const std::unordered_map<std::string, const std::string*>* topic_names) const {
  std::vector<Head> heads;
  for (size_t i = 0; i < files_.size(); ++i) {
    MessageReader* f = files_[i].get();
    MessageSelection own = selection;
    if (!selection.topics.empty()) {
      own.topics.clear();
      for (const std::string& t : selection.topics) {
        if (f->MessageCount(t) > 0) own.topics.push_back(t);
      }
      if (own.topics.empty()) continue;
    }
    int64_t start_ns = 0, end_ns = 0;
    if (!f->TimeRange(&start_ns, &end_ns) || end_ns < selection.start_ns ||
        start_ns >= selection.end_ns) {
      continue;
    }
    Head h;
    h.source = std::make_unique<Source>(f, i, f->path(), topic_names);
    h.selection = std::move(own);
    h.key_ns = std::max(start_ns, selection.start_ns);
    heads.push_back(std::move(h));
  }
  return heads;
}

Status MergedMessageReader::ReadMessages(const MessageSelection& selection,
                                         const std::function<Status(const Message&)>& fn) {
  duplicates_dropped_ = 0;
  std::unordered_map<std::string, const std::string*> topic_names;
  for (const TopicInfo& t : topics_) topic_names[t.name] = &t.name;
  std::vector<Head> heads = OpenHeads(selection, &topic_names);
  GivenAtTime given;
  Message out;
  while (true) {
    // The head with the smallest (key, file index); sources not started
    // yet have their first record time as key, never after their message.
    Head* next = nullptr;
    for (Head& h : heads) {
      if (h.finished()) continue;
      if (next == nullptr || h.key_ns < next->key_ns) next = &h;
    }
    if (next == nullptr) break;
    if (!next->has_message) {
      if (!next->source->started()) next->source->Start(next->selection);
      TILTCAL_RETURN_IF_ERROR(next->Advance());
      continue;
    }
    OwnedMessage& m = next->message;
    if (given.IsDuplicate(m)) {
      ++duplicates_dropped_;
    } else {
      ViewOf(m, &out);
      TILTCAL_RETURN_IF_ERROR(fn(out));
      ++out.sequence;
      given.Add(std::move(m));
    }
    TILTCAL_RETURN_IF_ERROR(next->Advance());
  }
  return Status::Ok();
}

}  // namespace tiltcal::bag
