#pragma once

#include <stdexcept>
#include <string>

namespace tubepick {

/// A caller mistake: bad input, out-of-range parameter, unreadable file. The message names the
/// offending field and value; the server maps it to gRPC INVALID_ARGUMENT.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The caller cancelled the work or its deadline passed (see StopToken).
class Cancelled : public std::runtime_error {
 public:
  explicit Cancelled(const std::string& what, bool deadline_exceeded)
      : std::runtime_error(what), deadline_exceeded_(deadline_exceeded) {}
  bool deadline_exceeded() const { return deadline_exceeded_; }

 private:
  bool deadline_exceeded_;
};

}  // namespace tubepick
