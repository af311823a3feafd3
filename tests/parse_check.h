// The contract every reader keeps on hostile input: a consistent grid, or a one-line
// FormatError that starts with the source's name. Shared by the reader tests and the
// truncation tests under AddressSanitizer.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "io/error.h"
#include "io/grid.h"

namespace terravol::test {

// Calls parse() (returning an io::Grid) and checks that contract; `context` goes into failures.
template <class Parse>
void expect_grid_or_one_line_error(Parse parse, const std::string& source, const std::string& context) {
  try {
    const io::Grid g = parse();
    EXPECT_EQ(g.heights.size(), g.size()) << context;
    EXPECT_EQ(g.mask.size(), g.size()) << context;
    EXPECT_GT(g.rows, 0) << context;
    EXPECT_GT(g.cols, 0) << context;
  } catch (const io::FormatError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(source + ": ", 0), 0u) << context << ": " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << context << ": " << what;
  }
}

// The message of the io::FormatError that f() throws, "" when it throws none.
template <class F>
std::string format_error_of(F f) {
  try {
    f();
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "";
}

// Every prefix of `text` (lengths 0, step, 2 step, ...) parsed by parse(prefix).
template <class Parse>
void expect_prefixes_handled(Parse parse, const std::string& text, std::size_t step, const std::string& source) {
  for (std::size_t n = 0; n < text.size(); n += step) {
    expect_grid_or_one_line_error([&] { return parse(text.substr(0, n)); }, source, "length " + std::to_string(n));
  }
}

}  // namespace terravol::test
