#include "io/kmz_write.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "compress.h"
#include "io/compressed.h"

namespace terravol::io {
namespace {

KmzMap sample_map() {
  KmzMap m;
  m.name = "path_loss_db at 10 m <above> ground & \"more\"";
  m.description = "from a.vdb";
  m.north = 45.5;
  m.south = 45.4;
  m.west = 6.4;
  m.east = 6.55;
  m.overlay_png = {1, 2, 3};
  m.legend_png = {4, 5};
  return m;
}

TEST(KmzWrite, KmlHasTheBoxTheImagesAndEscapedNames) {
  const std::string kml = kml_document(sample_map());
  EXPECT_NE(kml.find("<kml xmlns=\"http://www.opengis.net/kml/2.2\">"), std::string::npos);
  EXPECT_NE(kml.find("<name>path_loss_db at 10 m &lt;above&gt; ground &amp; &quot;more&quot;</name>"), std::string::npos) << kml;
  EXPECT_NE(kml.find("<north>45.5000000000</north>"), std::string::npos);
  EXPECT_NE(kml.find("<south>45.4000000000</south>"), std::string::npos);
  EXPECT_NE(kml.find("<east>6.5500000000</east>"), std::string::npos);
  EXPECT_NE(kml.find("<west>6.4000000000</west>"), std::string::npos);
  EXPECT_NE(kml.find("<Icon><href>files/overlay.png</href></Icon>"), std::string::npos);
  EXPECT_NE(kml.find("<ScreenOverlay>"), std::string::npos);
  EXPECT_NE(kml.find("<Icon><href>files/legend.png</href></Icon>"), std::string::npos);
}

TEST(KmzWrite, LongitudesAreWrappedIntoKmlsRangeAcrossTheAntimeridian) {
  KmzMap m = sample_map();
  m.west = 179.5;
  m.east = 180.5;
  const std::string kml = kml_document(m);
  EXPECT_NE(kml.find("<west>179.5000000000</west>"), std::string::npos) << kml;
  EXPECT_NE(kml.find("<east>-179.5000000000</east>"), std::string::npos) << kml;
}

TEST(KmzWrite, ArchiveHoldsTheKmlFirstThenTheImages) {
  const KmzMap m = sample_map();
  const std::vector<std::uint8_t> kmz = encode_kmz(m);
  constexpr std::string_view kKml[] = {".kml", ".png"};
  const ZipEntry first = unzip_entry(kmz, "m.kmz", kKml);
  EXPECT_EQ(first.name, "doc.kml");
  EXPECT_EQ(std::string(first.bytes.begin(), first.bytes.end()), kml_document(m));
  EXPECT_EQ(unzip_named(kmz, "m.kmz", "files/overlay.png"), m.overlay_png);
  EXPECT_EQ(unzip_named(kmz, "m.kmz", "files/legend.png"), m.legend_png);
}

TEST(KmzWrite, WithoutALegendThereIsNoScreenOverlay) {
  KmzMap m = sample_map();
  m.legend_png.clear();
  EXPECT_EQ(kml_document(m).find("ScreenOverlay"), std::string::npos);
  EXPECT_FALSE(unzip_named(encode_kmz(m), "m.kmz", "files/legend.png"));
}

TEST(KmzWrite, AnEmptyOrNonFiniteBoxIsRefused) {
  KmzMap m = sample_map();
  m.south = m.north;
  EXPECT_THROW(encode_kmz(m), std::invalid_argument);
  m = sample_map();
  m.east = std::numeric_limits<double>::infinity();
  EXPECT_THROW(kml_document(m), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::io
