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

/// A request over a configured size limit (points, bytes): a caller mistake, so it is an
/// InvalidArgument to code that catches those, but the server answers RESOURCE_EXHAUSTED, the code
/// gRPC itself gives a message over its size limit, so that every oversize request (unary or
/// streamed, over the byte or the point limit) gets the one code.
class TooLarge : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

/// The input is well formed but does not fit the cell it is meant for: e.g. a cloud whose unit or
/// sensor pose is wrong, so that it misses the bin. The message gives the evidence and the likely
/// cause; the server maps it to gRPC FAILED_PRECONDITION, the CLI to exit code 4.
class FailedPrecondition : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
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
