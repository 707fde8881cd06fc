#include "common/io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace tiltcal {

namespace {
std::string ErrnoText() { return std::strerror(errno); }
}  // namespace

AtomicFile::~AtomicFile() { Abandon(); }

Status AtomicFile::Open(const std::string& path) {
  Abandon();
  path_ = path;
  temp_path_ = path + ".tmp." + std::to_string(::getpid());
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (file_ == nullptr) {
    return Status::Error(path + ": cannot create output: " + ErrnoText());
  }
  return Status::Ok();
}

Status AtomicFile::Commit() {
  if (file_ == nullptr) return Status::Error(path_ + ": output is not open");
  bool ok = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  ok = (std::fclose(file_) == 0) && ok;
  file_ = nullptr;
  if (!ok) {
    const std::string error = ErrnoText();
    std::remove(temp_path_.c_str());
    return Status::Error(path_ + ": cannot write output: " + error);
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const std::string error = ErrnoText();
    std::remove(temp_path_.c_str());
    return Status::Error(path_ + ": cannot rename output into place: " + error);
  }
  temp_path_.clear();
  return Status::Ok();
}

void AtomicFile::Abandon() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!temp_path_.empty()) {
    std::remove(temp_path_.c_str());
    temp_path_.clear();
  }
}

Status WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile file;
  TILTCAL_RETURN_IF_ERROR(file.Open(path));
  if (std::fwrite(contents.data(), 1, contents.size(), file.file()) != contents.size()) {
    return Status::Error(path + ": cannot write output: " + ErrnoText());
  }
  return file.Commit();
}

Status ReadFileToString(const std::string& path, std::string* contents) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + ErrnoText());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  *contents = buffer.str();
  return Status::Ok();
}

Status ReadFileHead(const std::string& path, size_t max_bytes, std::string* contents) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + ErrnoText());
  contents->assign(max_bytes, '\0');
  in.read(contents->data(), static_cast<std::streamsize>(max_bytes));
  contents->resize(static_cast<size_t>(in.gcount()));
  return Status::Ok();
}

}  // namespace tiltcal
