// The error type of bad input: library code throws, only app/ decides to exit.
#pragma once

#include <stdexcept>
#include <string>

namespace terravol::io {

// Thrown by every reader for input it cannot accept (truncated, wrong size, bad header,
// absurd dimensions, unknown format). what() is one line: "SOURCE: what is wrong".
class FormatError : public std::runtime_error {
 public:
  FormatError(const std::string& source, const std::string& problem)
      : std::runtime_error(source + ": " + problem), source_(source) {}
  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

}  // namespace terravol::io
