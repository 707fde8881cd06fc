#include "common/io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "common/io/direct_file_output.h"

namespace tiltcal {

namespace fs = std::filesystem;

namespace {

std::string ErrnoText() { return std::strerror(errno); }

// stdio's side of a stream over a DirectFileOutput (glibc fopencookie).
ssize_t WriteToDirectFileOutput(void* cookie, const char* data, size_t size) {
  return static_cast<DirectFileOutput*>(cookie)->Write(data, size) ? static_cast<ssize_t>(size)
                                                                   : 0;
}

// A stdio stream whose writes go to `output`; closing it leaves `output`
// open (AtomicFile closes it). Unbuffered: `output` gathers the bytes.
std::FILE* OpenStdioStream(DirectFileOutput* output) {
  cookie_io_functions_t functions{};
  functions.write = WriteToDirectFileOutput;
  std::FILE* file = ::fopencookie(output, "w", functions);
  if (file != nullptr) std::setvbuf(file, nullptr, _IONBF, 0);
  return file;
}

// True when no process `pid` exists (kill(pid, 0) fails with ESRCH).
bool ProcessIsGone(long long pid) {
  if (pid <= 0 || pid == ::getpid()) return false;
  return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// Removes `<path>.tmp.<pid>` files whose process no longer runs.
void RemoveStaleTemporaries(const std::string& path) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".tmp.";
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.size() > 18 ||
        !std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    if (ProcessIsGone(std::stoll(pid))) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
}

}  // namespace

AtomicFile::AtomicFile() = default;
AtomicFile::~AtomicFile() { Abandon(); }

Status AtomicFile::Open(const std::string& path, const AtomicFileOptions& options) {
  Abandon();
  write_behind_end_ = 0;
  path_ = path;
  RemoveStaleTemporaries(path);
  temp_path_ = path + ".tmp." + std::to_string(::getpid());
  if (options.bypass_page_cache) {
    direct_ = std::make_unique<DirectFileOutput>();
    if (direct_->Open(temp_path_)) {
      file_ = OpenStdioStream(direct_.get());
      if (file_ == nullptr) direct_->Abandon();
    }
  } else {
    file_ = std::fopen(temp_path_.c_str(), "wb");
  }
  if (file_ == nullptr) {
    const std::string error = ErrnoText();
    std::remove(temp_path_.c_str());
    direct_.reset();
    temp_path_.clear();
    return Status::Error(path + ": cannot create output: " + error);
  }
  return Status::Ok();
}

Status AtomicFile::Finish() {
  if (file_ == nullptr) {
    return temp_path_.empty() ? Status::Error(path_ + ": output is not open") : Status::Ok();
  }
  bool ok = std::fflush(file_) == 0 && (direct_ != nullptr || ::fsync(::fileno(file_)) == 0);
  std::string error = ok ? "" : ErrnoText();
  if (std::fclose(file_) != 0 && ok) {
    ok = false;
    error = ErrnoText();
  }
  file_ = nullptr;
  if (direct_ != nullptr) {
    // Writes what it holds, syncs and closes.
    if (ok && !direct_->Close()) {
      ok = false;
      error = ErrnoText();
    }
    direct_.reset();
  }
  if (!ok) {
    std::remove(temp_path_.c_str());
    temp_path_.clear();
    return Status::Error(path_ + ": cannot write output: " + error);
  }
  return Status::Ok();
}

Status AtomicFile::Commit() {
  TILTCAL_RETURN_IF_ERROR(Finish());
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
  direct_.reset();  // stops its writes, closes the file
  if (!temp_path_.empty()) {
    std::remove(temp_path_.c_str());
    temp_path_.clear();
  }
}

void AtomicFile::WriteBehind() {
#ifdef __linux__
  if (file_ == nullptr || direct_ != nullptr) return;
  const int fd = ::fileno(file_);
  const off_t in_kernel = ::lseek(fd, 0, SEEK_CUR);
  while (in_kernel >= write_behind_end_ + kWriteBehindBytes) {
    ::sync_file_range(fd, write_behind_end_, kWriteBehindBytes, SYNC_FILE_RANGE_WRITE);
    if (write_behind_end_ >= 2 * kWriteBehindBytes) {
      ::sync_file_range(fd, write_behind_end_ - 2 * kWriteBehindBytes, kWriteBehindBytes,
                        SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE |
                            SYNC_FILE_RANGE_WAIT_AFTER);
    }
    write_behind_end_ += kWriteBehindBytes;
  }
#endif
}

std::string CommitManifestPath(const std::string& path) { return path + ".commit"; }

Status CommitTogether(const std::vector<AtomicFile*>& files) {
  std::string manifest;
  for (AtomicFile* file : files) {
    TILTCAL_RETURN_IF_ERROR(file->Finish());
    std::error_code error;
    const fs::path temp = fs::absolute(file->temp_path(), error);
    const fs::path final_path = fs::absolute(file->path(), error);
    if (error) return Status::Error(file->path() + ": " + error.message());
    manifest += temp.string() + "\t" + final_path.string() + "\n";
  }
  for (AtomicFile* file : files) {
    TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(CommitManifestPath(file->path()), manifest));
  }
  for (AtomicFile* file : files) TILTCAL_RETURN_IF_ERROR(file->Commit());
  for (auto it = files.rbegin(); it != files.rend(); ++it) {
    if (std::remove(CommitManifestPath((*it)->path()).c_str()) != 0) {
      return Status::Error(CommitManifestPath((*it)->path()) + ": cannot remove: " + ErrnoText());
    }
  }
  return Status::Ok();
}

Status CompleteInterruptedCommit(const std::string& path) {
  const std::string manifest_path = CommitManifestPath(path);
  std::error_code error;
  if (!fs::exists(manifest_path, error)) return Status::Ok();
  std::string manifest;
  TILTCAL_RETURN_IF_ERROR(ReadFileToString(manifest_path, &manifest));
  std::istringstream lines(manifest);
  std::vector<std::string> finals;
  for (std::string line; std::getline(lines, line);) {
    const size_t tab = line.find('\t');
    if (tab == std::string::npos) {
      return Status::Error(manifest_path + ": not a commit manifest (a line without a tab)");
    }
    const std::string temp = line.substr(0, tab);
    finals.push_back(line.substr(tab + 1));
    // A missing temporary was renamed before the interruption.
    if (fs::exists(temp, error) && std::rename(temp.c_str(), finals.back().c_str()) != 0) {
      return Status::Error(manifest_path + ": cannot complete the commit of " + finals.back() +
                           ": " + ErrnoText());
    }
  }
  // Every other manifest first, this one (which lists them) last.
  const fs::path own = fs::absolute(manifest_path, error);
  for (const std::string& final_path : finals) {
    const fs::path other = fs::absolute(CommitManifestPath(final_path), error);
    if (other != own) fs::remove(other, error);
  }
  error.clear();
  fs::remove(manifest_path, error);
  if (error) return Status::Error(manifest_path + ": cannot remove: " + error.message());
  return Status::Ok();
}

Status CheckOutputPath(const std::string& path) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code error;
  if (!fs::is_directory(dir, error)) {
    return Status::Error(path + ": cannot write output: directory " + dir.string() +
                         (fs::exists(dir, error) ? " is not a directory" : " does not exist"));
  }
  if (fs::is_directory(target, error)) {
    return Status::Error(path + ": cannot write output: it is a directory");
  }
  return Status::Ok();
}

Status WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile file;
  TILTCAL_RETURN_IF_ERROR(file.Open(path));
  if (std::fwrite(contents.data(), 1, contents.size(), file.file()) != contents.size()) {
    return Status::Error(path + ": cannot write output: " + ErrnoText());
  }
  return file.Commit();
}

// An error unless `path` is a regular file (after symlinks): a directory
// opens as an empty stream, and a device may never end.
Status CheckRegularFile(const std::string& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) return Status::Error(path + ": cannot open: No such file or directory");
  if (fs::is_directory(status)) return Status::Error(path + ": is a directory, not a file");
  if (!fs::is_regular_file(status)) return Status::Error(path + ": not a regular file");
  return Status::Ok();
}

Status ReadFileToString(const std::string& path, std::string* contents) {
  TILTCAL_RETURN_IF_ERROR(CheckRegularFile(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + ErrnoText());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  *contents = buffer.str();
  return Status::Ok();
}

Status ReadFileHead(const std::string& path, size_t max_bytes, std::string* contents) {
  TILTCAL_RETURN_IF_ERROR(CheckRegularFile(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + ErrnoText());
  contents->assign(max_bytes, '\0');
  in.read(contents->data(), static_cast<std::streamsize>(max_bytes));
  contents->resize(static_cast<size_t>(in.gcount()));
  return Status::Ok();
}

}  // namespace tiltcal
