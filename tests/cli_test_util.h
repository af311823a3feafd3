// Helpers of the command-line tests: the bundled DEM and the one-line error contract.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "run_command.h"

namespace terravol::test {

// The DEM in the project's own data/ (generated, always there).
inline std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

// Bad input's contract: exit status 1 and one line on stderr, "terravol: PREFIX...", soon.
inline void expect_one_line_error(const CommandResult& r, const std::string& prefix, double max_seconds = 5.0) {
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("terravol: " + prefix, 0), 0u) << r.err;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_LT(r.seconds, max_seconds);
}

}  // namespace terravol::test
