// The real test models of Debian's assimp-testmodels (/usr/share/assimp/models); tests that need
// them skip with a message when the package is absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace terravol::test {

inline std::filesystem::path assimp_model(const std::string& relative) {
  return std::filesystem::path("/usr/share/assimp/models") / relative;
}

}  // namespace terravol::test

// Skips the test when the model is not installed.
#define REQUIRE_ASSIMP_MODEL(relative)                                                               \
  do {                                                                                               \
    if (!std::filesystem::exists(terravol::test::assimp_model(relative))) {                          \
      GTEST_SKIP() << "assimp-testmodels is not installed (" << terravol::test::assimp_model(relative) \
                   << " is missing); apt-get install assimp-testmodels";                             \
    }                                                                                                \
  } while (0)
