#ifndef TILTCAL_COMMON_STATUS_H_
#define TILTCAL_COMMON_STATUS_H_

#include <string>
#include <utility>

namespace tiltcal {

// Result of an operation that can fail on bad input. The message is one line
// meant for the user: it names the file and the record or field at fault.
// Programmer errors are not reported this way.
class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }
  // A failure that is not the input's fault: the data cannot determine the
  // result (e.g. a motion that turned too little to decide the extrinsic
  // rotation). Callers that compare results (tiltcal_verify) report it as
  // "cannot tell"; everyone else treats it as any error.
  static Status NotDetermined(std::string message) {
    Status s(std::move(message));
    s.not_determined_ = true;
    return s;
  }

  bool ok() const { return !failed_; }
  bool not_determined() const { return not_determined_; }
  const std::string& message() const { return message_; }

  // Prefixes the message with context, e.g. the file name: "file: message".
  Status WithContext(const std::string& context) const {
    if (ok()) return *this;
    Status s(context + ": " + message_);
    s.not_determined_ = not_determined_;
    return s;
  }

 private:
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  bool not_determined_ = false;
  std::string message_;
};

}  // namespace tiltcal

// Returns from the calling function when `expr` yields a failed Status.
#define TILTCAL_RETURN_IF_ERROR(expr)          \
  do {                                         \
    ::tiltcal::Status tiltcal_status_ = (expr); \
    if (!tiltcal_status_.ok()) return tiltcal_status_; \
  } while (0)

#endif  // TILTCAL_COMMON_STATUS_H_
