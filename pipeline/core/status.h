// Status: the result of reading a file, validating input, or doing work that can fail.
// Library code never exits or throws on bad input: it returns a Status whose message names
// the file, the field or line, and what is wrong, in one line, and whose kind says whose
// fault it is. The CLI maps the kind to the exit code in one place (app/commands.h
// ExitCodeFor): bad input 2, everything else 1.
#pragma once

#include <string>
#include <utility>

namespace fresco {

enum class StatusKind {
  kOk,
  kBadInput,  // a file or value the user gave is wrong (exit 2)
  kOutput,    // a file could not be written: no such folder, no permission, disk full (exit 1)
  kFailed,    // the input was fine but the work could not be done: a solve that did not
              // converge, an external program that failed (exit 1)
  kInternal,  // a broken invariant: a bug in Fresco (exit 1)
};

class Status {
 public:
  Status() = default;  // ok
  static Status Ok() { return Status(); }
  // `message` is one line: "FILE: FIELD: what is wrong". Bad input: every reader's error.
  static Status Error(std::string message) {
    return Status(StatusKind::kBadInput, std::move(message));
  }
  // A file could not be written; `message` names it.
  static Status OutputError(std::string message) {
    return Status(StatusKind::kOutput, std::move(message));
  }
  // The work could not be done on good input.
  static Status Failed(std::string message) {
    return Status(StatusKind::kFailed, std::move(message));
  }
  // A broken invariant.
  static Status Internal(std::string message) {
    return Status(StatusKind::kInternal, std::move(message));
  }

  bool ok() const { return kind_ == StatusKind::kOk; }
  StatusKind kind() const { return kind_; }
  const std::string& message() const { return message_; }
  explicit operator bool() const { return ok(); }

  // The same kind with another message, e.g. one prefixed with the file it concerns.
  Status WithMessage(std::string message) const {
    return ok() ? Status() : Status(kind_, std::move(message));
  }
  // This status with a bad-input kind replaced by `kind`, other kinds unchanged. For
  // functions whose input was checked before they run, so that what fails in them is not
  // the user's input (e.g. a writer: whatever fails is output).
  Status Reclassified(StatusKind kind) const {
    return kind_ == StatusKind::kBadInput ? Status(kind, message_) : *this;
  }

 private:
  Status(StatusKind kind, std::string message) : kind_(kind), message_(std::move(message)) {}
  StatusKind kind_ = StatusKind::kOk;
  std::string message_;
};

// Returns early from the enclosing function when `expr` yields a failed Status.
#define FRESCO_RETURN_IF_ERROR(expr)            \
  do {                                          \
    ::fresco::Status fresco_status_ = (expr);   \
    if (!fresco_status_.ok()) return fresco_status_; \
  } while (0)

}  // namespace fresco
