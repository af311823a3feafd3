// Render tests need an X display (VTK 9.1 on Debian renders through GLX): scripts/test.sh runs
// ctest under xvfb-run. Without one that can be opened, they skip with a message instead of
// failing (or letting VTK abort).
#pragma once

#include <gtest/gtest.h>

#include <stdexcept>

#include "app/render/terrain_renderer.h"

#define TERRAVOL_REQUIRE_DISPLAY()                                                         \
  do {                                                                                     \
    try {                                                                                  \
      ::terravol::app::render::require_x_display();                                                \
    } catch (const std::runtime_error& e) {                                                \
      GTEST_SKIP() << e.what();                                                            \
    }                                                                                      \
  } while (0)
