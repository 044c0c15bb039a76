// Status: the result of reading a file or validating input. Readers never exit or throw on
// bad input: they return a Status whose message names the file, the field or line, and what
// is wrong, in one line. The CLI maps a failed Status to exit code 2.
#pragma once

#include <string>
#include <utility>

namespace fresco {

class Status {
 public:
  Status() = default;  // ok
  static Status Ok() { return Status(); }
  // `message` is one line: "FILE: FIELD: what is wrong".
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !failed_; }
  const std::string& message() const { return message_; }
  explicit operator bool() const { return ok(); }

 private:
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

// Returns early from the enclosing function when `expr` yields a failed Status.
#define FRESCO_RETURN_IF_ERROR(expr)            \
  do {                                          \
    ::fresco::Status fresco_status_ = (expr);   \
    if (!fresco_status_.ok()) return fresco_status_; \
  } while (0)

}  // namespace fresco
