#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "density/transfer.h"
#include "volume/colormap.h"

namespace terravol::density {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_density(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Transfer, ParsesKeysInAnyOrder) {
  const DensitySpec s = parse_density("opacity=2.5, colormap=plasma,range=80:160,ramp=down");
  EXPECT_EQ(s.lo, 80.0f);
  EXPECT_EQ(s.hi, 160.0f);
  EXPECT_EQ(s.colormap, "plasma");
  EXPECT_EQ(s.sigma_per_km, 2.5);
  EXPECT_EQ(s.ramp, Ramp::kDown);
  EXPECT_EQ(parse_density(format_density(s)), s);
  EXPECT_EQ(parse_density("range=-140:-60,colourmap=gray,opacity=1").colormap, "grey");
  EXPECT_EQ(parse_density("range=0:1,colormap=viridis,opacity=1").ramp, Ramp::kFlat);
}

TEST(Transfer, RejectsBadTextWithOneLineNamingThePart) {
  const std::pair<const char*, const char*> cases[] = {
      {"colormap=viridis,opacity=1", "no range"},
      {"range=80:160,opacity=1", "no colour map"},
      {"range=80:160,colormap=viridis", "no opacity"},
      {"range=160:80,colormap=viridis,opacity=1", "needs LO < HI"},
      {"range=80,colormap=viridis,opacity=1", "is not LO:HI"},
      {"range=a:b,colormap=viridis,opacity=1", "not two numbers"},
      {"range=80:160,colormap=rainbow,opacity=1", "unknown colour map 'rainbow'"},
      {"range=80:160,colormap=viridis,opacity=0", "opacity '0'"},
      {"range=80:160,colormap=viridis,opacity=-2", "opacity '-2'"},
      {"range=80:160,colormap=viridis,opacity=nan", "opacity 'nan'"},
      {"range=80:160,colormap=viridis,opacity=1,ramp=sideways", "unknown ramp 'sideways'"},
      {"range=80:160,colormap=viridis,opacity=1,range=1:2", "range given twice"},
      {"range=80:160,colormap=viridis,opacity=1,glow=3", "unknown key 'glow'"},
      {"range=80:160,,colormap=viridis,opacity=1", "an empty part"},
      {"range=80:160,colormap,opacity=1", "is not KEY=VALUE"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string e = error_of(text);
    EXPECT_NE(e.find(std::string("density '") + text + "': "), std::string::npos) << e;
    EXPECT_NE(e.find(expected), std::string::npos) << text << " -> " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Transfer, TableMapsTheRangeToTheColourMapAndOutsideToClear) {
  const DensitySpec s = parse_density("range=100:200,colormap=viridis,opacity=4,ramp=up");
  const TransferTable t(s, glm::dvec3(50.0, 100.0, 25.0));
  EXPECT_EQ(t.entry(100.0f), 0);
  EXPECT_EQ(t.entry(200.0f), TransferTable::kEntries - 1);
  EXPECT_EQ(t.entry(99.9f), -1);
  EXPECT_EQ(t.entry(200.1f), -1);
  EXPECT_EQ(t.entry(std::numeric_limits<float>::quiet_NaN()), -1);
  const int mid = t.entry(150.0f);
  EXPECT_NEAR(mid, (TransferTable::kEntries - 1) / 2.0, 0.51);
  const glm::u8vec3 c = volume::colormap_by_name("viridis").map(static_cast<double>(mid) / (TransferTable::kEntries - 1));
  EXPECT_NEAR(t.color(mid).g, c.g / 255.0f, 1e-6f);
  // ramp=up: clear at lo, 4 per km at hi; half a box along z is 25 m.
  EXPECT_EQ(t.sigma(0), 0.0f);
  EXPECT_NEAR(t.sigma(TransferTable::kEntries - 1), 0.004f, 1e-9f);
  EXPECT_NEAR(t.half_alpha(TransferTable::kEntries - 1, 2), 1.0 - std::exp(-0.004 * 25.0), 1e-6);
  EXPECT_NEAR(t.half_alpha(TransferTable::kEntries - 1, 1), 1.0 - std::exp(-0.004 * 100.0), 1e-6);
  const TransferTable down(parse_density("range=100:200,colormap=viridis,opacity=4,ramp=down"), glm::dvec3(1.0));
  EXPECT_NEAR(down.sigma(0), 0.004f, 1e-9f);
  EXPECT_EQ(down.sigma(TransferTable::kEntries - 1), 0.0f);
}

}  // namespace
}  // namespace terravol::density
