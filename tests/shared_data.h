// Finding ../shared/data from tests; tests that need it skip with a message when it is absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

namespace terravol::test {

inline std::filesystem::path shared_data() { return TERRAVOL_SHARED_DATA; }
inline std::filesystem::path shared_dem(const std::string& name) { return shared_data() / "dem" / name; }

}  // namespace terravol::test

// Skips the current test when the shared real-data file is missing.
#define TERRAVOL_REQUIRE_SHARED(path)                                                     \
  do {                                                                                    \
    if (!std::filesystem::exists(path)) {                                                 \
      GTEST_SKIP() << "shared data not found: " << (path).string() << " (needs ../shared/data)"; \
    }                                                                                     \
  } while (0)
