// `terravol fly` as a user runs it: PNG frames and video over the bundled DEM, interrupting
// and resuming, refusing to overwrite, and bad path files failing before any frame.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "temp_dir.h"

namespace terravol {
namespace {

using nlohmann::json;
using test::run_terravol;

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A 4 s flight 700-900 m above the ground over the bundled DEM, about 9 km north-east, in a
// 64-cell window so that the window slides several times on the way.
json flight(double seconds = 4.0) {
  json keys = json::array();
  keys.push_back({{"t", 0}, {"lat", 45.10}, {"lon", 6.30}, {"alt", 900}, {"agl", true}, {"heading", 40}, {"pitch", -12}});
  keys.push_back({{"t", seconds / 2}, {"lat", 45.13}, {"lon", 6.36}, {"alt", 700}, {"agl", true}, {"heading", 60}, {"pitch", -8}});
  keys.push_back({{"t", seconds}, {"lat", 45.16}, {"lon", 6.40}, {"alt", 800}, {"agl", true}, {"heading", 20}, {"pitch", -15}});
  return {{"scene", {{"dem", bundled_dem()}, {"render", {{"window", 64}}}}}, {"keys", keys}};
}

std::filesystem::path write_path(const test::TempDir& dir, const json& doc, const std::string& name = "path.json") {
  const auto p = dir.path() / name;
  std::ofstream(p) << doc.dump(2);
  return p;
}

std::vector<std::string> pngs(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  if (!std::filesystem::is_directory(folder)) return names;
  for (const auto& e : std::filesystem::directory_iterator(folder)) {
    if (e.path().extension() == ".png") names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The last line of a CSV file, split at commas.
std::vector<std::string> last_row(const std::filesystem::path& csv) {
  std::istringstream in(slurp(csv));
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  std::vector<std::string> cells;
  std::istringstream row(last);
  for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
  return cells;
}

void expect_same_frames(const std::filesystem::path& a, const std::filesystem::path& b) {
  const auto names = pngs(a);
  ASSERT_EQ(names, pngs(b));
  for (const auto& n : names) EXPECT_TRUE(slurp(a / n) == slurp(b / n)) << n << " differs";
}

TEST(FlyCli, PngExportWritesEveryFrameOfThePath) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = write_path(dir, flight());
  const auto frames = dir.path() / "frames";
  const auto stats = dir.path() / "stats.csv";
  const auto r = run_terravol("fly " + path.string() + " -o " + frames.string() + "/ --fps 10 --size 160x90 --stats " +
                              stats.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto names = pngs(frames);
  ASSERT_EQ(names.size(), 41u);  // 0 .. 4 s at 10 fps
  EXPECT_EQ(names.front(), "frame_000000.png");
  EXPECT_EQ(names.back(), "frame_000040.png");
  const auto img = test::read_png(frames / names[20]);
  EXPECT_EQ(img.width, 160);
  EXPECT_EQ(img.height, 90);
  EXPECT_LT(test::color_share(img, img.at(80, 89), 2), 0.5) << "the frame should not be one colour";
  EXPECT_NE(r.err.find("41/41 frames"), std::string::npos) << r.err;
  const auto row = last_row(stats);
  ASSERT_EQ(row.size(), 20u);
  EXPECT_EQ(row[0], "40");
  EXPECT_GE(std::stoi(row[18]), 1) << "the path should slide the 64-cell window";
}

// Share of sky pixels (blue well above red) in columns [x0, x1) of an image.
double sky_share(const test::Image& img, int x0, int x1) {
  int sky = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) sky += img.at(x, y)[2] > img.at(x, y)[0] + 30;
  return static_cast<double>(sky) / ((x1 - x0) * img.height);
}

TEST(FlyCli, RollBanksTheViewSoTheSkyMovesToTheLeft) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  auto frame0 = [&](double roll, const std::string& name) {
    json doc = flight(1.0);
    for (auto& k : doc["keys"]) {
      k["roll"] = roll;
      k["pitch"] = 5;  // looking a little up: sky over the top half
    }
    const auto frames = dir.path() / name;
    const auto r = run_terravol("fly " + write_path(dir, doc, name + ".json").string() + " -o " + frames.string() +
                                "/ --fps 2 --size 160x90");
    EXPECT_EQ(r.status, 0) << r.err;
    return test::read_png(frames / "frame_000000.png");
  };
  const test::Image level = frame0(0, "level"), banked = frame0(90, "banked");
  ASSERT_EQ(banked.width, 160);
  // Level: the sky is a band across the top, as much on the left as on the right.
  EXPECT_NEAR(sky_share(level, 0, 50), sky_share(level, 110, 160), 0.15);
  // Banked right by 90 degrees: the view's up is the old right, so the sky is on the left.
  EXPECT_GT(sky_share(banked, 0, 50), sky_share(banked, 110, 160) + 0.25);  // measured 0.71 against 0.37
}

TEST(FlyCli, ResumingAnInterruptedExportGivesTheSameFrames) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = write_path(dir, flight());
  const std::string common = "fly " + path.string() + " --fps 10 --size 160x90 -o ";
  const auto whole = dir.path() / "whole", parts = dir.path() / "parts";
  auto r = run_terravol(common + whole.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run_terravol(common + parts.string() + " --end 2.25");  // stopped early, after two slides
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(pngs(parts).size(), 23u);
  std::filesystem::remove(parts / "frame_000022.png");
  r = run_terravol(common + parts.string() + " --resume");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("(19 frames)"), std::string::npos) << r.out;
  expect_same_frames(whole, parts);
}

TEST(FlyCli, KilledExportResumesFromTheFirstMissingFrame) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = write_path(dir, flight(12.0));
  const std::string common = std::string(TERRAVOL_EXE) + " fly " + path.string() + " --fps 10 --size 160x90 -o ";
  const auto whole = dir.path() / "whole", parts = dir.path() / "parts";
  // SIGTERM once a few frames are written; the export stops after the frame it is drawing.
  const std::string script = common + parts.string() + " 2>" + (dir.path() / "err").string() +
                             " >/dev/null & p=$!; for i in $(seq 600); do n=$(ls " + parts.string() +
                             " 2>/dev/null | grep -c png); [ \"$n\" -ge 5 ] && break; sleep 0.02; done; kill -TERM $p; wait $p";
  const int raw = std::system(("timeout 30 sh -c '" + script + "'").c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 1);
  const std::string err = slurp(dir.path() / "err");
  EXPECT_NE(err.find("interrupted after frame"), std::string::npos) << err;
  const std::size_t written = pngs(parts).size();
  EXPECT_GE(written, 5u);
  ASSERT_LT(written, 121u) << "the export ended before it was killed";
  auto r = run_terravol("fly " + path.string() + " --fps 10 --size 160x90 -o " + parts.string() + " --resume");
  ASSERT_EQ(r.status, 0) << r.err;
  r = run_terravol("fly " + path.string() + " --fps 10 --size 160x90 -o " + whole.string());
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_frames(whole, parts);
}

TEST(FlyCli, ExistingFramesAreNotOverwrittenWithoutForce) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = write_path(dir, flight(1.0));
  const auto frames = dir.path() / "frames";
  const std::string cmd = "fly " + path.string() + " --fps 5 -o " + frames.string() + " --size ";
  const std::string same = cmd + "64x36";
  ASSERT_EQ(run_terravol(same).status, 0);
  auto r = run_terravol(same);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("holds 6 frames of this range (use --resume to continue or --force to overwrite)"),
            std::string::npos) << r.err;
  r = run_terravol(same + " --resume");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("all 6 frames present"), std::string::npos) << r.out;
  r = run_terravol(cmd + "64x38 --resume");  // another size: not the same export
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("made with another size"), std::string::npos) << r.err;
  EXPECT_EQ(run_terravol(same + " --force").status, 0);
}

// Frames drawn with other command-line additions to the scene (an --object, a --density)
// are other frames: --resume refuses them, as it refuses another size.
TEST(FlyCli, ResumeRefusesFramesMadeWithOtherObjectsOrDensity) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = write_path(dir, flight(0.4));
  std::ofstream(dir.path() / "mast.obj") << "v -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\nv 0 0 300\n"
                                            "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
  const auto frames = dir.path() / "frames";
  const std::string cmd = "fly " + path.string() + " --fps 5 --size 64x36 -o " + frames.string();
  const std::string mast = " --object " + (dir.path() / "mast.obj").string() + "@45.12,6.33,0,up=z";
  ASSERT_EQ(run_terravol(cmd + mast).status, 0);
  auto r = run_terravol(cmd + mast + " --resume");
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_terravol(cmd + " --resume");  // the same flight without the mast
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("made with another objects"), std::string::npos) << r.err;
  r = run_terravol(cmd + mast + " --density range=80:150,colormap=viridis,opacity=0.5 --resume");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("made with another density"), std::string::npos) << r.err;
}

TEST(FlyCli, Mp4HasTheRightFrameCountAndNoTemporaryFileRemains) {
  TERRAVOL_REQUIRE_DISPLAY();
  if (std::system("command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null") != 0) {
    GTEST_SKIP() << "ffmpeg or ffprobe not found";
  }
  test::TempDir dir;
  const auto path = write_path(dir, flight(2.0));
  const auto mp4 = dir.path() / "flight.mp4";
  auto r = run_terravol("fly " + path.string() + " --fps 12 --size 160x90 --samples 4 -o " + mp4.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto probe = dir.path() / "probe.txt";
  const std::string cmd = "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                          "stream=codec_name,width,height,nb_read_frames -of csv=p=0 " + mp4.string() + " >" + probe.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(slurp(probe), "h264,160,90,25\n");
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
  r = run_terravol("fly " + path.string() + " --fps 12 --size 160x90 -o " + mp4.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("flight.mp4: exists (use --force to overwrite)"), std::string::npos) << r.err;
}

// Exit status 1, one line on stderr containing `expected`, nothing written.
void expect_rejected(const test::TempDir& dir, const std::string& path_text, const std::string& expected,
                     const std::string& extra = "", const std::string& out_name = "out") {
  const auto path = dir.path() / "bad.json";
  std::ofstream(path) << path_text;
  const auto out = dir.path() / out_name;
  const auto r = run_terravol("fly " + path.string() + " -o " + out.string() + " --size 64x36 " + extra);
  EXPECT_EQ(r.status, 1) << path_text;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing may be written for " << expected;
}

TEST(FlyCli, BadPathFilesFailWithOneLineBeforeAnyFrame) {
  test::TempDir dir;
  json doc = flight();
  doc["keys"][1]["heeding"] = 3;
  expect_rejected(dir, doc.dump(), "bad.json: keys[1].heeding: unknown field");
  doc = flight();
  doc["keys"][2]["t"] = 1.0;
  expect_rejected(dir, doc.dump(), "bad.json: keys[2].t: 1 is not after keys[1].t (2)");
  doc = flight();
  doc["keys"][0]["pitch"] = -100;
  expect_rejected(dir, doc.dump(), "bad.json: keys[0].pitch: must be within [-90, 90], is -100");
  doc = flight();
  doc["scene"] = "missing-scene.json";
  expect_rejected(dir, doc.dump(), "missing-scene.json: cannot read");
  doc = flight();
  doc["scene"]["dem"] = "nowhere.hgt";
  expect_rejected(dir, doc.dump(), "nowhere.hgt: no such file");
  doc = flight();
  doc["keys"][0]["roll"] = 200;
  expect_rejected(dir, doc.dump(), "bad.json: keys[0].roll: must be within [-180, 180], is 200");
  expect_rejected(dir, "{\"scene\": ", "bad.json: not valid JSON (byte 11)");
  expect_rejected(dir, flight().dump(), "--end 9.000: must be within --start .. 4.000 s", "--end 9");
  expect_rejected(dir, flight().dump(), "--samples 3: must be 1, 4, 9 or 16", "--samples 3");
  expect_rejected(dir, flight().dump(), "--png-level 10: must be within 0..9", "--png-level 10");
  expect_rejected(dir, flight().dump(), "--png-level: for PNG frames; ", "--png-level 3", "out.mp4");
  expect_rejected(dir, flight().dump(), "out.avi: not a video", "", "out.avi");
}

// --object places models along the flight: a 400 m magenta box floating 800 m above the ground
// 1.2 km ahead of the first key shows in its frame (faded a little by the haze), and not without
// it; bad ones fail first.
TEST(FlyCli, ObjectsAppearInTheFramesAndBadOnesFailBeforeAnyFrame) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto box = dir.path() / "box.obj";
  std::ofstream(dir.path() / "box.mtl") << "newmtl m\nKd 1 0 1\n";
  {
    std::ofstream o(box);
    o << "mtllib box.mtl\n";
    for (int c = 0; c < 8; ++c) o << "v " << (c & 1 ? 200 : -200) << " " << (c & 2 ? 400 : 0) << " " << (c & 4 ? 200 : -200) << "\n";
    o << "usemtl m\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  }
  const auto path = write_path(dir, flight());
  const auto magenta = [](const test::Image& img) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) n += img.at(x, y)[0] > 200 && img.at(x, y)[1] < 60 && img.at(x, y)[2] > 200;
    return n;
  };
  int counts[2] = {0, 0};
  for (int with = 0; with < 2; ++with) {
    const auto frames = dir.path() / (with ? "with" : "without");
    const auto r = run_terravol("fly " + path.string() + " -o " + frames.string() + "/ --fps 10 --end 0.1 --size 320x180" +
                                (with ? " --object " + box.string() + "@45.108,6.312,800" : ""));
    ASSERT_EQ(r.status, 0) << r.err;
    counts[with] = magenta(test::read_png(frames / "frame_000000.png"));
  }
  EXPECT_EQ(counts[0], 0);
  EXPECT_GT(counts[1], 1000);  // about 90 x 80 pixels of the 320 x 180
  expect_rejected(dir, flight().dump(), "--object 'x.glb': expected FILE@LAT,LON,AGL", "--object x.glb");
  expect_rejected(dir, flight().dump(), "missing.glb: no such file", "--object " + (dir.path() / "missing.glb").string() + "@45.1,6.3,0");
}

TEST(FlyCli, CameraUnderGroundOrFarBeyondTheDemFailsBeforeAnyFrame) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  json doc = flight();
  doc["keys"][1]["agl"] = false;
  doc["keys"][1]["alt"] = 200;  // far below the Alps
  expect_rejected(dir, doc.dump(), "bad.json: at t=");
  doc = flight();
  doc["keys"][2]["lat"] = 48.5;  // 278 km north of the tile
  expect_rejected(dir, doc.dump(), "km beyond the DEM (at most 200 km)");
}

}  // namespace
}  // namespace terravol
