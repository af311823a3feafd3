// `terravol render --renderer tiler` and `fly --renderer tiler` as a user runs them: images
// without an X display, the tiler's images against the VTK path's (away from edges at 8 x 8;
// almost everywhere at one sample, translucent volumes included), and bad --renderer and --aa
// values failing with one line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>

#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "shared_data.h"
#include "temp_dir.h"

namespace terravol {
namespace {

using test::run_terravol;
using test::run_terravol_under;

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

// Renders `args` with -o DIR/NAME.png --force; expects success and reads the image.
test::Image render(const test::TempDir& dir, const std::string& args, const std::string& name, int timeout_s = 120) {
  const auto png = dir.path() / (name + ".png");
  const auto r = run_terravol("render " + args + " --force -o " + png.string(), timeout_s);
  EXPECT_EQ(r.status, 0) << r.err;
  return test::read_png(png);
}

// The share of pixels within `tolerance` of each other in every channel, over the pixels where
// `edges_of` is smooth: its 3 x 3 neighbourhood varies by at most `smooth` in every channel
// (smooth = 255: every pixel). `counted` gets how many pixels were compared.
double share_agreeing(const test::Image& a, const test::Image& b, const test::Image& edges_of, int tolerance, int smooth,
                      std::size_t& counted) {
  std::size_t same = 0;
  counted = 0;
  for (int y = 1; y + 1 < a.height; ++y) {
    for (int x = 1; x + 1 < a.width; ++x) {
      bool flat = true;
      const test::Rgb8 c = edges_of.at(x, y);
      for (int dy = -1; dy <= 1 && flat; ++dy)
        for (int dx = -1; dx <= 1 && flat; ++dx) flat = test::same_color(edges_of.at(x + dx, y + dy), c, smooth);
      if (!flat) continue;
      ++counted;
      same += test::same_color(a.at(x, y), b.at(x, y), tolerance) ? 1 : 0;
    }
  }
  return counted == 0 ? 0.0 : static_cast<double>(same) / static_cast<double>(counted);
}

std::size_t lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

TEST(TilerCli, RendersTheBundledDemWithoutAnXDisplay) {
  test::TempDir dir;
  const auto png = dir.path() / "tiled.png", stats = dir.path() / "stats.json";
  const auto r = run_terravol_under("env -u DISPLAY", "render " + bundled_dem() +
                                                          " --camera 45.1,6.3,4500,35,-20 --size 320x180 --renderer tiler "
                                                          "--aa 4 -o " + png.string() + " --stats " + stats.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const test::Image img = test::read_png(png);
  ASSERT_EQ(img.width, 320);
  ASSERT_EQ(img.height, 180);
  EXPECT_LT(test::color_share(img, img.at(160, 179), 2), 0.5) << "terrain, not one colour";
  EXPECT_LT(test::color_share(img, img.at(160, 0), 2), 0.5);
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["renderer"], "tiler");
  EXPECT_EQ(j["tiler"]["aa"], 4);
  // Every sample shaded once: by a triangle or by the sky.
  EXPECT_EQ(j["tiler"]["samples_covered"].get<std::uint64_t>() + j["tiler"]["samples_background"].get<std::uint64_t>(),
            320u * 180u * 16u);
}

// --texel-rate reaches the tiler: 0 shades every sample of the terrain on its own, so more
// shading points than the default, which shades a fragment once unless its pixel spans four
// texels or more.
TEST(TilerCli, TexelRateSetsHowFinelyTheTerrainTextureIsShaded) {
  test::TempDir dir;
  const auto shading = [&](const std::string& rate, const std::string& name) {
    const auto png = dir.path() / (name + ".png"), stats = dir.path() / (name + ".json");
    const auto r = run_terravol_under("env -u DISPLAY", "render " + bundled_dem() +
                                                            " --camera 45.1,6.3,1500,35,-8 --size 160x90 --renderer tiler "
                                                            "--aa 4" + rate + " -o " + png.string() + " --stats " + stats.string());
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(stats);
    return nlohmann::json::parse(in)["tiler"];
  };
  const nlohmann::json every = shading(" --texel-rate 0", "every"), usual = shading("", "usual");
  EXPECT_EQ(every["texel_rate"].get<double>(), 0.0);
  EXPECT_EQ(usual["texel_rate"].get<double>(), 0.25);
  // Every covered sample its own shading point at 0 (the view has no translucent triangles).
  EXPECT_EQ(every["shading_points"].get<std::uint64_t>(), every["samples_covered"].get<std::uint64_t>());
  EXPECT_LT(usual["shading_points"].get<std::uint64_t>(), every["shading_points"].get<std::uint64_t>() / 4);
}

// The same view drawn by VTK (one sample a pixel) and by the tiler: at one sample a pixel they
// sample the same centres with the same fill rule, so they agree almost everywhere; at 8 x 8
// they agree wherever the picture is smooth (away from edges), where antialiasing changes
// nothing but the texture's filtering over the pixel.
TEST(TilerCli, AgreesWithTheVtkPathAwayFromEdges) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const bool shared = std::filesystem::exists(test::shared_dem("N44W072.hgt"));
  const std::string dem = shared ? test::shared_dem("N44W072.hgt").string() : bundled_dem();
  const std::string view = shared ? " --camera 44.15,-71.45,2500,40,-15 --agl --size 640x360"
                                  : " --camera 45.1,6.3,4500,35,-20 --size 640x360";
  const test::Image vtk = render(dir, dem + view, "vtk");
  const test::Image one = render(dir, dem + view + " --renderer tiler --aa 1", "tiler1");
  const test::Image eight = render(dir, dem + view + " --renderer tiler --aa 8", "tiler8");
  std::size_t n = 0;
  // (Measured on N44W072: every pixel within 1/255, the interpolation's rounding.)
  const double at_one = share_agreeing(one, vtk, vtk, 1, 255, n);
  EXPECT_GT(at_one, 0.999) << "tiler --aa 1 against VTK, every pixel";
  const double smooth = share_agreeing(eight, vtk, vtk, 3, 6, n);
  EXPECT_GT(n, 640u * 360u / 3) << "smooth pixels compared";
  // (Measured: 99.94%; the rest are single pixels where a sub-pixel feature leaves VTK's samples
  // smooth and the tiler's not.)
  EXPECT_GT(smooth, 0.998) << "tiler --aa 8 against VTK where VTK's image is smooth";
  // And antialiasing did something: at the edges the two differ.
  EXPECT_LT(share_agreeing(eight, vtk, vtk, 0, 255, n), 0.9);
}

// Translucent isosurfaces and a slice of an RF volume over the bundled DEM: composited front to
// back by the tiler ("under"), back to front by VTK (blending in the tree's order).
TEST(TilerCli, TranslucentVolumesAgreeWithTheVtkPath) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  const auto rf = run_terravol("rf --quiet --tx 45.50,6.50,30 --dem " + bundled_dem() + " --radius-km 7 --heights 0:1500:100 -o " +
                               vdb.string(), 120);
  ASSERT_EQ(rf.status, 0) << rf.err;
  const std::string view = bundled_dem() + " --camera 45.44,6.44,2600,40,-18 --size 480x270 --no-legend --no-markers --volume " +
                           vdb.string() + " --slice agl=300";
  const test::Image vtk = render(dir, view, "vtk");
  const test::Image one = render(dir, view + " --renderer tiler --aa 1", "tiler1");
  const test::Image eight = render(dir, view + " --renderer tiler --aa 8", "tiler8");
  const test::Image terrain = render(dir, bundled_dem() + " --camera 45.44,6.44,2600,40,-18 --size 480x270", "terrain");
  std::size_t n = 0;
  EXPECT_LT(share_agreeing(vtk, terrain, vtk, 8, 255, n), 0.8) << "the volume shows";
  // (Measured: 99.998% within 3/255; the two outliers lie on the volume's silhouettes.)
  EXPECT_GT(share_agreeing(one, vtk, vtk, 3, 255, n), 0.999) << "tiler --aa 1 against VTK";
  // (Measured: 99.56%: the surfaces' thin slivers and crossings are edges that VTK's one sample
  // a pixel can miss, leaving its image smooth there.)
  EXPECT_GT(share_agreeing(eight, vtk, vtk, 3, 6, n), 0.99) << "tiler --aa 8 against VTK where VTK is smooth";
}

TEST(TilerCli, FlyWritesAntialiasedFramesWithoutAnXDisplay) {
  test::TempDir dir;
  nlohmann::json keys = nlohmann::json::array();
  keys.push_back({{"t", 0}, {"lat", 45.10}, {"lon", 6.30}, {"alt", 900}, {"agl", true}, {"heading", 40}, {"pitch", -12}});
  keys.push_back({{"t", 1}, {"lat", 45.12}, {"lon", 6.33}, {"alt", 800}, {"agl", true}, {"heading", 50}, {"pitch", -10}});
  const nlohmann::json doc = {{"scene", {{"dem", bundled_dem()}, {"render", {{"window", 64}}}}}, {"keys", keys}};
  const auto path = dir.path() / "path.json";
  std::ofstream(path) << doc.dump(2);
  const auto frames = dir.path() / "frames";
  const auto r = run_terravol_under("env -u DISPLAY", "fly " + path.string() + " -o " + frames.string() +
                                                          "/ --fps 2 --size 160x90 --renderer tiler --aa 2",
                                    120);
  ASSERT_EQ(r.status, 0) << r.err;
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(frames)) n += e.path().extension() == ".png" ? 1 : 0;
  EXPECT_EQ(n, 3u);
  std::ifstream in(frames / ".terravol-fly.json");
  const nlohmann::json manifest = nlohmann::json::parse(in);
  EXPECT_EQ(manifest["renderer"], "tiler");
  EXPECT_EQ(manifest["aa"], 2);
  EXPECT_EQ(manifest["texel_rate"].get<double>(), 0.25);
  // Resuming with other samples, or with VTK, would mix frames of two renderings.
  const std::string again = "fly " + path.string() + " -o " + frames.string() + "/ --fps 2 --size 160x90 --resume";
  auto other = run_terravol_under("env -u DISPLAY", again + " --renderer tiler --aa 4");
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.err.find("made with another aa (2, now 4)"), std::string::npos) << other.err;
  if (std::getenv("DISPLAY") != nullptr) {  // VTK needs a display before it reads the folder
    other = run_terravol(again);
    EXPECT_EQ(other.status, 1);
    EXPECT_NE(other.err.find("made with another"), std::string::npos) << other.err;
  }
}

// Bad values: one line naming what is wrong, a non-zero exit, and no image.
TEST(TilerCli, BadRendererAndAaValuesFailWithOneLine) {
  test::TempDir dir;
  const auto png = dir.path() / "x.png";
  const std::string base = "render " + bundled_dem() + " --camera 45.1,6.3,4500,35,-20 -o " + png.string();
  const std::pair<std::string, std::string> cases[] = {
      {" --renderer tiler --aa 3", "--aa 3"},
      {" --renderer tiler --aa eight", "--aa eight"},
      {" --renderer tiler --aa 16", "--aa 16"},
      {" --renderer opengl", "--renderer opengl"},
      {" --aa 4", "--aa"},
      {" --renderer tiler --order peel", "--order"},
      {" --renderer tiler --wireframe", "--wireframe"},
      {" --renderer tiler --lod-colors", "--lod-colors"},
      {" --renderer tiler --export-vtp " + (dir.path() / "x.vtp").string(), "--export-vtp"},
      {" --renderer tiler --aa 8 --size 2100x100", "--size 2100x100"},
      {" --renderer tiler --texel-rate -1", "--texel-rate"},
      {" --renderer tiler --texel-rate inf", "--texel-rate"},
      {" --renderer tiler --texel-rate nan", "--texel-rate"},
      {" --renderer tiler --texel-rate fine", "--texel-rate"},
      {" --texel-rate 1", "--texel-rate"},
  };
  for (const auto& [args, names] : cases) {
    const auto r = run_terravol_under("env -u DISPLAY", base + args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(png)) << args;
  }
  const auto path = dir.path() / "path.json";
  std::ofstream(path) << R"({"scene": {"dem": ")" + bundled_dem() +
                             R"("}, "keys": [{"t": 0, "lat": 45.1, "lon": 6.3, "alt": 900, "agl": true}, {"t": 1, "lat": 45.12, "lon": 6.33, "alt": 900, "agl": true}]})";
  const std::pair<std::string, std::string> fly_cases[] = {
      {" --renderer tiler --aa 5", "--aa 5"},
      {" --renderer vulkan", "--renderer vulkan"},
      {" --renderer tiler --samples 4", "--samples 4"},
      {" --aa 2", "--aa"},
  };
  for (const auto& [args, names] : fly_cases) {
    const auto r = run_terravol_under("env -u DISPLAY", "fly " + path.string() + " -o " + (dir.path() / "f").string() + "/" + args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "f")) << args;
  }
}

}  // namespace
}  // namespace terravol
