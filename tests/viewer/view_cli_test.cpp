// `terravol view` as a person uses it: the real window on the X display, driven with xdotool
// (keys held and tapped, mouse drags on the view and on the slider), observed through the
// viewer's --status file and its screenshots. Each test starts its own viewer and kills it in
// teardown. The viewers of different tests (ctest runs them in parallel) take turns through a
// lock file, since keyboard focus is one per display.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "app/scene/camera_path.h"
#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "temp_dir.h"

namespace terravol {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs a shell command with a time limit; returns its exit status and stdout.
int shell(const std::string& command, std::string* out = nullptr) {
  FILE* pipe = popen(("timeout 20 " + command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  std::string text;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) text += buffer;
  const int raw = pclose(pipe);
  if (out != nullptr) *out = text;
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

bool have_xdotool() { return shell("xdotool version") == 0; }

#define TERRAVOL_REQUIRE_XDOTOOL()                                                                  \
  do {                                                                                              \
    TERRAVOL_REQUIRE_DISPLAY();                                                                     \
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/packages.txt lists it)"; \
  } while (0)

// One viewer process on $DISPLAY, its status file and the keys and buttons the test holds.
class Viewer {
 public:
  // Starts `terravol view ARGS --status F --screenshot P` and waits for its window and first
  // frame; puts the pointer in the middle of the window and gives it the keyboard focus.
  explicit Viewer(const std::string& args) {
    lock_ = ::open(("/tmp/terravol-view-test" + display_tag() + ".lock").c_str(), O_CREAT | O_RDWR, 0666);
    if (lock_ >= 0) ::flock(lock_, LOCK_EX);  // one viewer on the display at a time
    status_path_ = dir_.path() / "status.json";
    shot_path_ = dir_.path() / "shot.png";
    std::vector<std::string> argv{TERRAVOL_EXE, "view"};
    std::istringstream words(args + " --status " + status_path_.string() + " --screenshot " + shot_path_.string());
    for (std::string w; words >> w;) argv.push_back(w);
    const std::string out = (dir_.path() / "stdout").string(), err = (dir_.path() / "stderr").string();
    pid_ = fork();
    if (pid_ == 0) {
      std::vector<char*> cargv;
      for (auto& a : argv) cargv.push_back(a.data());
      cargv.push_back(nullptr);
      if (!std::freopen(out.c_str(), "w", stdout) || !std::freopen(err.c_str(), "w", stderr)) _exit(126);
      execv(cargv[0], cargv.data());
      _exit(127);
    }
  }

  ~Viewer() {
    for (const auto& k : keys_down_) shell("xdotool keyup " + k);
    if (button_down_) shell("xdotool mouseup 1");
    if (running()) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (lock_ >= 0) ::close(lock_);
  }
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // Waits for the first frame and the window; false (with a message) when they do not come.
  ::testing::AssertionResult start() {
    if (pid_ <= 0) return ::testing::AssertionFailure() << "fork failed";
    if (!wait_for([](const json& s) { return s["frame"].get<int>() >= 1; }, 30.0)) {
      return ::testing::AssertionFailure() << "no status after 30 s; stderr: " << slurp(dir_.path() / "stderr");
    }
    std::string ids;
    for (int attempt = 0; attempt < 50 && ids.empty(); ++attempt) {
      shell("xdotool search --onlyvisible --name '^Terravol view'", &ids);
      if (ids.find_first_not_of("0123456789\n") != std::string::npos) ids.clear();
      if (ids.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::istringstream lines(ids);
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty()) window_ = line;  // the newest is listed last
    }
    if (window_.empty()) return ::testing::AssertionFailure() << "no window named 'Terravol view'";
    const json s = status();
    width_ = s["size"][0].get<int>();
    height_ = s["size"][1].get<int>();
    xdo("mousemove --window " + window_ + " " + std::to_string(width_ / 2) + " " + std::to_string(height_ / 2));
    xdo("windowfocus --sync " + window_);
    return ::testing::AssertionSuccess();
  }

  bool running() {
    if (exited_) return false;
    int raw = 0;
    if (waitpid(pid_, &raw, WNOHANG) == pid_) {
      exited_ = true;
      exit_status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
      return false;
    }
    return true;
  }

  // The exit status once the process has ended, or -1 after `seconds`.
  int wait_exit(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (running() && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return exited_ ? exit_status_ : -1;
  }

  // The last status written (an empty object before the first).
  json status() const {
    std::ifstream in(status_path_);
    if (!in) return json::object();
    try {
      return json::parse(in);
    } catch (const json::exception&) {
      return json::object();
    }
  }

  // Polls the status file until `pred` holds (true) or `seconds` pass (false). Every distinct
  // frame seen is passed to `seen` if given.
  bool wait_for(const std::function<bool(const json&)>& pred, double seconds,
                const std::function<void(const json&)>& seen = nullptr) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    int last = -1;
    while (Clock::now() < end) {
      const json s = status();
      if (s.contains("frame")) {
        if (seen && s["frame"].get<int>() != last) seen(s);
        last = s["frame"].get<int>();
        if (pred(s)) return true;
      }
      if (!running()) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }

  // Waits for a frame after the current one: the effect of what was just done.
  json next_frame(double seconds = 10.0) {
    const int now = status().value("frame", 0);
    json got;
    wait_for(
        [&](const json& s) {
          got = s;
          return s["frame"].get<int>() > now;
        },
        seconds);
    return got;
  }

  // Waits until the viewer is idle (no key held, nothing more to draw) and its frame count
  // has stayed put for a moment (events still in flight are handled).
  json settle() {
    json last = status();
    auto still_since = Clock::now();
    const auto end = Clock::now() + std::chrono::seconds(15);
    while (Clock::now() < end && running()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      const json s = status();
      if (s.value("frame", -1) != last.value("frame", -1)) {
        last = s;
        still_since = Clock::now();
      } else if (last.value("idle", false) && Clock::now() - still_since > std::chrono::milliseconds(80)) {
        break;
      }
    }
    return last;
  }

  void xdo(const std::string& args) {
    std::string out;
    const int rc = shell("xdotool " + args, &out);
    EXPECT_EQ(rc, 0) << "xdotool " << args << ": " << out;
  }
  // Taps a bound key and waits for the first frame drawn after the viewer handled it (a frame
  // that merely follows the tap may have been asked for before it).
  void tap(const std::string& key) {
    const int before = status().value("key_presses", 0);
    xdo("key " + key);
    wait_for([&](const json& s) { return s.value("key_presses", 0) > before; }, 10.0);
  }
  void key_down(const std::string& key) {
    xdo("keydown " + key);
    keys_down_.insert(key);
  }
  void key_up(const std::string& key) {
    xdo("keyup " + key);
    keys_down_.erase(key);
  }
  // Holds `key` until `pred` holds or `seconds` pass; returns whether it held.
  bool hold_until(const std::string& key, const std::function<bool(const json&)>& pred, double seconds,
                  const std::function<void(const json&)>& seen = nullptr) {
    key_down(key);
    const bool ok = wait_for(pred, seconds, seen);
    key_up(key);
    return ok;
  }
  // A left-button drag in window pixels (from the top left), in small steps as a hand moves,
  // ending inside the window. The pointer stays where the drag ended until the viewer has
  // handled it (motion events read the pointer's position when they are handled).
  void drag(int x0, int y0, int x1, int y1) {
    x1 = std::clamp(x1, 1, width_ - 2);
    y1 = std::clamp(y1, 1, height_ - 2);
    xdo("mousemove --window " + window_ + " " + std::to_string(x0) + " " + std::to_string(y0));
    xdo("mousedown 1");
    button_down_ = true;
    const int steps = 8;
    for (int k = 1; k <= steps; ++k) {
      const int x = x0 + (x1 - x0) * k / steps, y = y0 + (y1 - y0) * k / steps;
      xdo("mousemove --window " + window_ + " " + std::to_string(x) + " " + std::to_string(y));
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
    }
    xdo("mouseup 1");
    button_down_ = false;
    settle();
  }

  // Presses the screenshot key and returns the image written.
  test::Image screenshot() {
    const int before = status().value("screenshots", 0);
    xdo("key p");
    EXPECT_TRUE(wait_for([&](const json& s) { return s["screenshots"].get<int>() > before; }, 10.0));
    return test::read_png(shot_path_);
  }

  std::string stdout_text() const { return slurp(dir_.path() / "stdout"); }
  std::string stderr_text() const { return slurp(dir_.path() / "stderr"); }
  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& window() const { return window_; }  // the X window id

 private:
  static std::string display_tag() {
    const char* d = std::getenv("DISPLAY");
    std::string tag = d != nullptr ? d : "";
    for (char& c : tag)
      if (c == ':' || c == '/' || c == '.') c = '_';
    return tag;
  }

  test::TempDir dir_;
  std::filesystem::path status_path_, shot_path_;
  pid_t pid_ = -1;
  int lock_ = -1;
  bool exited_ = false;
  int exit_status_ = -1;
  std::string window_;
  int width_ = 0, height_ = 0;
  std::set<std::string> keys_down_;
  bool button_down_ = false;
};

// Common options: a 256-cell window and a small window on screen, so that each test starts in
// about a second.
const std::string kSmall = " --window 256 --size 800x450";

struct Vec3 {
  double x, y, z;
};
Vec3 eye(const json& s) {
  const auto& e = s["camera"]["eye"];
  return {e[0].get<double>(), e[1].get<double>(), e[2].get<double>()};
}
double heading(const json& s) { return s["camera"]["heading"].get<double>(); }
double pitch(const json& s) { return s["camera"]["pitch"].get<double>(); }

// Share of differing pixels (tolerance 8 per channel) in the rows [y0, y1) of two images.
double differing_rows(const test::Image& a, const test::Image& b, int y0, int y1) {
  std::size_t differ = 0, total = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < a.width; ++x) {
      differ += !test::same_color(a.at(x, y), b.at(x, y), 8);
      ++total;
    }
  }
  return total == 0 ? 0.0 : static_cast<double>(differ) / static_cast<double>(total);
}

// A small path-loss volume over the bundled DEM (5 km around 45.5 N, 6.5 E), by terravol rf.
::testing::AssertionResult make_volume(const std::filesystem::path& vdb) {
  const auto r = test::run_terravol("rf --quiet --tx 45.5,6.5,30 --dem " + bundled_dem() +
                                    " --radius-km 5 --heights 0:1000:100 -o " + vdb.string());
  if (r.status == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "terravol rf: " << r.err;
}

TEST(ViewCli, ForwardFliesAlongTheViewAtTheHeightScaledSpeedAndBackReturns) {
  TERRAVOL_REQUIRE_XDOTOOL();
  Viewer v(bundled_dem() + " --camera 45.5,6.5,4500,30,-20" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  std::vector<json> seen;
  ASSERT_TRUE(v.hold_until(
      "w",
      [&](const json& s) {
        const Vec3 a = eye(s0), b = eye(s);
        return std::hypot(b.x - a.x, b.y - a.y) > 600.0;
      },
      15.0, [&](const json& s) { seen.push_back(s); }))
      << v.stderr_text();
  const json s1 = v.settle();
  const Vec3 a = eye(s0), b = eye(s1);
  const double horizontal = std::hypot(b.x - a.x, b.y - a.y);
  EXPECT_NEAR(std::atan2(b.x - a.x, b.y - a.y) * 180.0 / kPi, 30.0, 1.0) << "along the heading";
  EXPECT_NEAR(std::atan2(b.z - a.z, horizontal) * 180.0 / kPi, -20.0, 1.0) << "down the view's pitch";
  EXPECT_DOUBLE_EQ(heading(s1), 30.0);
  EXPECT_DOUBLE_EQ(pitch(s1), -20.0);
  // Speed: about one height above the ground per second (--speed 1), between two frames seen.
  ASSERT_GE(seen.size(), 3u);
  const json& f0 = seen[1];
  const json& f1 = seen.back();
  const Vec3 p0 = eye(f0), p1 = eye(f1);
  const double metres = std::sqrt(std::pow(p1.x - p0.x, 2) + std::pow(p1.y - p0.y, 2) + std::pow(p1.z - p0.z, 2));
  const double seconds = f1["time_s"].get<double>() - f0["time_s"].get<double>();
  const double agl = 0.5 * (f0["camera"]["agl"].get<double>() + f1["camera"]["agl"].get<double>());
  ASSERT_GT(seconds, 0.0);
  EXPECT_GT(metres / seconds, 0.5 * agl) << metres << " m in " << seconds << " s at about " << agl << " m AGL";
  EXPECT_LT(metres / seconds, 1.6 * agl) << metres << " m in " << seconds << " s at about " << agl << " m AGL";

  // S flies back along the same line.
  ASSERT_TRUE(v.hold_until(
      "s",
      [&](const json& s) {
        const Vec3 c = eye(s);
        return std::hypot(c.x - b.x, c.y - b.y) > 300.0;
      },
      15.0));
  const Vec3 c = eye(v.settle());
  EXPECT_NEAR(std::atan2(c.x - b.x, c.y - b.y) * 180.0 / kPi, 30.0 - 180.0, 1.0);
  EXPECT_GT(c.z, b.z) << "backing up a downward view climbs";
}

TEST(ViewCli, ArrowKeysAndMouseDragsTurnTheView) {
  TERRAVOL_REQUIRE_XDOTOOL();
  Viewer v(bundled_dem() + " --camera 45.5,6.5,4500,30,-20" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  const test::Image before = v.screenshot();
  ASSERT_TRUE(v.hold_until("Right", [&](const json& s) { return heading(s) > 45.0; }, 15.0));
  json s = v.settle();
  EXPECT_GT(heading(s), 45.0);
  EXPECT_LT(heading(s), 120.0);
  EXPECT_DOUBLE_EQ(pitch(s), pitch(s0));
  const Vec3 a = eye(s0), b = eye(s);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  const test::Image turned = v.screenshot();
  ASSERT_EQ(turned.width, before.width);
  EXPECT_GT(test::differing_share(before, turned, 8), 0.2) << "the view should change when turning";

  ASSERT_TRUE(v.hold_until("Left", [&](const json& st) { return heading(st) < 40.0; }, 15.0));
  EXPECT_LT(heading(v.settle()), 40.0);

  // Drag right 120 px and up 40 px: heading +18 degrees, pitch +6 (0.15 degree per pixel).
  s = v.settle();
  const int cx = v.width() / 2, cy = v.height() / 2;
  v.drag(cx - 60, cy + 20, cx + 60, cy - 20);
  const json d = v.settle();
  EXPECT_NEAR(heading(d) - heading(s), 18.0, 0.5);
  EXPECT_NEAR(pitch(d) - pitch(s), 6.0, 0.5);
}

TEST(ViewCli, DraggingTheThresholdSliderChangesTheTriangleCount) {
  TERRAVOL_REQUIRE_XDOTOOL();
  Viewer v(bundled_dem() + " --camera 45.3,6.3,3500,45,-15" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  ASSERT_DOUBLE_EQ(s0["threshold"].get<double>(), 2.0);
  auto knob = [](const json& s) {
    const json& k = s["slider"];
    const double t = (k["value"].get<double>() - k["value_min"].get<double>()) /
                     (k["value_max"].get<double>() - k["value_min"].get<double>());
    const double x = k["x_min"].get<double>() + t * (k["x_max"].get<double>() - k["x_min"].get<double>());
    return std::pair<int, int>{static_cast<int>(std::lround(x)), static_cast<int>(std::lround(k["y"].get<double>()))};
  };
  // Finer: drag the knob to the left end.
  int x = 0, y = 0;
  std::tie(x, y) = knob(s0);
  v.drag(x, y, static_cast<int>(s0["slider"]["x_min"].get<double>()) - 40, y);
  const json fine = v.settle();
  EXPECT_NEAR(fine["threshold"].get<double>(), 0.25, 1e-9);
  EXPECT_GT(fine["triangles"].get<int>(), 2 * s0["triangles"].get<int>()) << "finer threshold, more triangles";
  // Coarser: all the way right.
  std::tie(x, y) = knob(fine);
  v.drag(x, y, static_cast<int>(fine["slider"]["x_max"].get<double>()) + 40, y);
  const json coarse = v.settle();
  EXPECT_NEAR(coarse["threshold"].get<double>(), 16.0, 1e-9);
  EXPECT_LT(coarse["triangles"].get<int>(), s0["triangles"].get<int>()) << "coarser threshold, fewer triangles";
  // Halfway back, by hand: a threshold in between, a triangle count in between.
  std::tie(x, y) = knob(coarse);
  const int mid = static_cast<int>(std::lround(0.5 * (coarse["slider"]["x_min"].get<double>() +
                                                      coarse["slider"]["x_max"].get<double>())));
  v.drag(x, y, mid, y);
  const json middle = v.settle();
  EXPECT_GT(middle["threshold"].get<double>(), 0.25);
  EXPECT_LT(middle["threshold"].get<double>(), 16.0);
  EXPECT_GT(middle["triangles"].get<int>(), coarse["triangles"].get<int>());
  EXPECT_LT(middle["triangles"].get<int>(), fine["triangles"].get<int>());
  // The keys step it too: - is coarser, + (=) finer.
  const double t = middle["threshold"].get<double>();
  v.tap("minus");
  EXPECT_NEAR(v.settle()["threshold"].get<double>(), t * std::sqrt(2.0), 1e-6);
  v.tap("equal");
  EXPECT_NEAR(v.settle()["threshold"].get<double>(), t, 1e-6);
}

TEST(ViewCli, KeysToggleLodColoursWireframeMetricAndSlidingAndVtkDefaultsStayOff) {
  TERRAVOL_REQUIRE_XDOTOOL();
  Viewer v(bundled_dem() + " --camera 45.3,6.3,3500,45,-15" + kSmall);
  ASSERT_TRUE(v.start());
  json s = v.settle();
  EXPECT_FALSE(s["lod_colors"].get<bool>());
  EXPECT_FALSE(s["wireframe"].get<bool>());
  EXPECT_EQ(s["metric"], "error");
  EXPECT_TRUE(s["auto_slide"].get<bool>());
  const test::Image plain = v.screenshot();

  v.tap("l");
  s = v.settle();
  EXPECT_TRUE(s["lod_colors"].get<bool>());
  const test::Image lod = v.screenshot();
  EXPECT_GT(test::differing_share(plain, lod, 8), 0.3) << "LOD colours should recolour the terrain";

  v.tap("t");
  s = v.settle();
  EXPECT_TRUE(s["wireframe"].get<bool>());
  const test::Image wire = v.screenshot();
  EXPECT_GT(test::differing_share(lod, wire, 8), 0.2) << "wireframe should show the sky between edges";

  const int triangles = s["triangles"].get<int>();
  v.tap("m");
  s = v.settle();
  EXPECT_EQ(s["metric"], "area");
  EXPECT_DOUBLE_EQ(s["threshold"].get<double>(), 500.0);
  EXPECT_NE(s["triangles"].get<int>(), triangles);
  v.tap("g");
  EXPECT_FALSE(v.settle()["auto_slide"].get<bool>());

  // VTK's default bindings do nothing here: e (exit), 3 (stereo), j and u are not bound, f
  // (VTK's fly-to) moves down, and w (VTK's wireframe) flies forward instead.
  for (const char* key : {"e", "3", "j", "u", "f"}) {
    v.xdo(std::string("key ") + key);
  }
  v.tap("t");
  s = v.settle();
  EXPECT_TRUE(v.running()) << "VTK's e key must not exit";
  EXPECT_FALSE(s["wireframe"].get<bool>());
  v.tap("w");
  EXPECT_FALSE(v.settle()["wireframe"].get<bool>());

  v.tap("l");
  v.tap("m");
  v.tap("g");
  s = v.settle();
  EXPECT_FALSE(s["lod_colors"].get<bool>());
  EXPECT_EQ(s["metric"], "error");
  EXPECT_TRUE(s["auto_slide"].get<bool>());

  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

TEST(ViewCli, FlyingTowardTheEdgeSlidesTheWindowWithoutMovingTheCamera) {
  TERRAVOL_REQUIRE_XDOTOOL();
  // North, level, 1 height per second: the window's north quarter is about 6 km away, the
  // DEM's north edge 55 km.
  Viewer v(bundled_dem() + " --camera 45.5,6.5,4500,0,0 --speed 1" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  ASSERT_EQ(s0["slides"], 0);
  std::vector<json> seen;
  ASSERT_TRUE(v.hold_until(
      "w", [](const json& s) { return s["slides"].get<int>() >= 1; }, 20.0,
      [&](const json& s) { seen.push_back(s); }))
      << "no slide; last status " << v.status().dump();
  const json s1 = v.settle();
  // The window moved north by whole cells of the coarsest level (6 levels over 256 cells: a
  // coarsest cell is 32 samples wide), and the scene frame stayed.
  const int moved = s0["window"]["row0"].get<int>() - s1["window"]["row0"].get<int>();
  EXPECT_GT(moved, 0) << "north is toward row 0";
  EXPECT_EQ(moved % 32, 0) << moved;
  EXPECT_EQ(s1["window"]["col0"], s0["window"]["col0"]);
  EXPECT_EQ(s1["window"]["origin_lat"], s0["window"]["origin_lat"]);
  EXPECT_EQ(s1["window"]["origin_lon"], s0["window"]["origin_lon"]);
  EXPECT_GT(s1["last_slide_ms"].get<double>(), 0.0);
  // No jump: from frame to frame the eye moved no farther than the speed allows.
  for (std::size_t k = 1; k < seen.size(); ++k) {
    const Vec3 a = eye(seen[k - 1]), b = eye(seen[k]);
    const double metres = std::sqrt(std::pow(b.x - a.x, 2) + std::pow(b.y - a.y, 2) + std::pow(b.z - a.z, 2));
    const double dt = seen[k]["time_s"].get<double>() - seen[k - 1]["time_s"].get<double>();
    const double speed = std::max(seen[k]["speed_mps"].get<double>(), seen[k - 1]["speed_mps"].get<double>());
    EXPECT_LE(metres, speed * (dt + 0.3) + 1.0)
        << "frame " << seen[k]["frame"] << " (slides " << seen[k]["slides"] << "): " << metres << " m in " << dt << " s";
    EXPECT_NEAR(b.x, a.x, 1e-6) << "flying north: x stays";
  }
}

TEST(ViewCli, ASlideLeavesTheViewInPlace) {
  TERRAVOL_REQUIRE_XDOTOOL();
  // Sliding off: fly north past the window's north quarter, look down at ground that lies in
  // the window before and after the slide, then turn sliding on, standing still.
  Viewer v(bundled_dem() + " --camera 45.5,6.5,4500,0,0 --speed 4 --no-slide" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  const double south = s0["window"]["south"].get<double>(), north = s0["window"]["north"].get<double>();
  ASSERT_TRUE(v.hold_until(
      "w", [&](const json& s) { return s["camera"]["lat"].get<double>() > south + 0.8 * (north - south); }, 20.0));
  ASSERT_TRUE(v.hold_until("Down", [](const json& s) { return pitch(s) < -70.0; }, 10.0));
  const json before = v.settle();
  ASSERT_EQ(before["slides"], 0);
  const test::Image a = v.screenshot();
  v.tap("g");
  ASSERT_TRUE(v.wait_for([](const json& s) { return s["slides"].get<int>() == 1; }, 10.0));
  const json after = v.settle();
  EXPECT_LT(after["window"]["row0"].get<int>(), before["window"]["row0"].get<int>());
  for (const char* k : {"lat", "lon", "alt", "heading", "pitch"}) {
    EXPECT_EQ(after["camera"][k], before["camera"][k]) << k;
  }
  EXPECT_EQ(after["camera"]["eye"], before["camera"]["eye"]);
  EXPECT_EQ(after["triangles"], before["triangles"]) << "the same ground at the same LOD";
  const test::Image b = v.screenshot();
  ASSERT_EQ(a.width, b.width);
  // Between the overlay (top) and the slider (bottom), the picture is the same.
  const double diff = differing_rows(a, b, b.height / 5, b.height * 4 / 5);
  EXPECT_LT(diff, 0.01) << diff * 100 << "% of the terrain's pixels differ";
}

TEST(ViewCli, EscapeQuitsWithStatusZeroAndATimingSummary) {
  TERRAVOL_REQUIRE_XDOTOOL();
  Viewer v(bundled_dem() + kSmall);
  ASSERT_TRUE(v.start());
  const json s = v.settle();
  EXPECT_NEAR(s["camera"]["agl"].get<double>(), 1500.0, 1e-6) << "default pose: 1500 m above the centre";
  v.xdo("key Escape");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
  EXPECT_NE(v.stdout_text().find("frames "), std::string::npos) << v.stdout_text();
}

TEST(ViewCli, VolumeKeysToggleMoveTheSliceAndChangeTheIsovalueAndSayHowLong) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  ASSERT_TRUE(make_volume(vdb));
  Viewer v(bundled_dem() + " --camera 45.44,6.44,2600,40,-18 --volume " + vdb.string() +
           " --iso 110 --slice agl=300" + kSmall);
  ASSERT_TRUE(v.start());
  json s = v.settle();
  ASSERT_EQ(s["volumes"].size(), 1u);
  EXPECT_TRUE(s["volumes"][0]["visible"].get<bool>());
  const auto merged = s["merged_triangles"].get<std::size_t>();
  EXPECT_GT(merged, 0u);

  v.tap("1");
  s = v.settle();
  EXPECT_FALSE(s["volumes"][0]["visible"].get<bool>());
  EXPECT_EQ(s["merged_triangles"].get<std::size_t>(), 0u) << "a hidden volume is not in the tree";
  EXPECT_GT(s["last_merge_ms"].get<double>(), 0.0);
  EXPECT_NE(s["message"].get<std::string>().find("volume 1 hidden"), std::string::npos) << s["message"];

  v.tap("1");
  v.tap("bracketright");
  s = v.settle();
  EXPECT_TRUE(s["volumes"][0]["visible"].get<bool>());
  EXPECT_DOUBLE_EQ(s["volumes"][0]["slices"][0]["value"].get<double>(), 350.0);
  EXPECT_NE(s["message"].get<std::string>().find(" ms"), std::string::npos) << s["message"];

  v.tap("period");
  s = v.settle();
  EXPECT_DOUBLE_EQ(s["volumes"][0]["isovalues"][0].get<double>(), 112.0);
  EXPECT_GT(s["merged_triangles"].get<std::size_t>(), 0u);

  // Edits wear small BSPs; once the keys rest the viewer tidies them (TerrainTree::tidy).
  for (const char* key : {"bracketright", "period", "bracketleft", "comma", "bracketright", "period"}) v.tap(key);
  s = v.settle();
  EXPECT_EQ(s["worn_slots"].get<std::size_t>(), 0u) << "settled means tidied";
  EXPECT_GT(s["tidied_slots"].get<std::size_t>(), 0u);
  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

// Ctrl+click picks the point under the cursor. Looking straight down, the window's centre
// pixel is the camera's nadir: on the terrain, at the camera's latitude and longitude; the
// volume's value there is what `terravol query` gives at that point. With a slice 300 m above
// the ground in the way, the pick lands on it instead.
TEST(ViewCli, CtrlClickPicksTheTerrainOrTheSliceInFrontAndShowsTheVolumesValue) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  ASSERT_TRUE(make_volume(vdb));
  for (const bool with_slice : {false, true}) {
    Viewer v(bundled_dem() + " --camera 45.51,6.52,6000,0,-90 --volume " + vdb.string() +
             (with_slice ? " --slice agl=300" : "") + kSmall);
    ASSERT_TRUE(v.start());
    v.settle();
    // The centre of the window: pixel (w/2 - 1/2, h/2 - 1/2) from the bottom is (w/2, h/2) here
    // to within half a pixel, a few metres on the ground from 3 km up.
    v.xdo("keydown ctrl");
    v.xdo("mousemove --window " + v.window() + " " + std::to_string(v.width() / 2) + " " + std::to_string(v.height() / 2));
    v.xdo("click 1");
    v.xdo("keyup ctrl");
    ASSERT_TRUE(v.wait_for([](const json& s) { return s.contains("pick"); }, 10.0)) << v.stderr_text();
    const json p = v.status()["pick"];
    EXPECT_NEAR(p["lat"].get<double>(), 45.51, 1e-4) << p;
    EXPECT_NEAR(p["lon"].get<double>(), 6.52, 1.5e-4) << p;
    const double agl = p["height"].get<double>() - p["ground"].get<double>();
    EXPECT_EQ(p["on_surface"].get<bool>(), with_slice) << p;
    if (with_slice) {
      EXPECT_NEAR(agl, 300.0, 25.0) << p;  // the slice's sheet between its lattice columns
    } else {
      EXPECT_NEAR(agl, 0.0, 0.01) << p;
    }
    ASSERT_EQ(p["values"].size(), 1u) << p;
    char at[96];
    std::snprintf(at, sizeof at, "%.8f,%.8f,%.4f", p["lat"].get<double>(), p["lon"].get<double>(), agl);
    const auto q = test::run_terravol("query --volume " + vdb.string() + " --dem " + bundled_dem() + " --at " + at);
    ASSERT_EQ(q.status, 0) << q.err;
    const std::string row = q.out.substr(q.out.find('\n') + 1);
    const double expected = std::stod(row.substr(row.rfind(',') + 1));
    EXPECT_NEAR(p["values"][0]["value"].get<double>(), expected, 1e-3) << p << "\n" << q.out;
    // What the pick costs, and the frame that shows it in the overlay (for docs/rf-model.md).
    const json shown = v.settle();
    // From the click's handling to the end of the draw of the first frame that shows it.
    const double to_overlay = shown["pick"]["to_overlay_ms"].get<double>();
    EXPECT_GE(to_overlay, p["ms"].get<double>());
    std::printf("pick on the %s: %.2f ms, then the frame %.1f ms (overlay %.1f, draw %.1f); pick to overlay %.1f ms\n",
                with_slice ? "slice" : "terrain", p["ms"].get<double>(), shown["frame_ms"].get<double>(),
                shown["overlay_ms"].get<double>(), shown["draw_ms"].get<double>(), to_overlay);
    const std::string message = shown["message"].get<std::string>();
    EXPECT_EQ(message.rfind("pick ", 0), 0u) << message;
    EXPECT_NE(message.find("rf.vdb path_loss_db: "), std::string::npos) << message;
    v.xdo("key q");
    EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
  }
}

// Pixels of a screenshot near any of `colors` (tolerance per channel).
std::size_t pixels_near(const test::Image& img, std::initializer_list<test::Rgb8> colors, int tolerance) {
  std::size_t n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (const auto& c : colors) {
        if (test::same_color(img.at(x, y), c, tolerance)) {
          ++n;
          break;
        }
      }
  return n;
}

// Pixels redder than red_above with green and blue under the other two bounds.
std::size_t reddish(const test::Image& img, int red_above, int green_below, int blue_below) {
  std::size_t n = 0;
  for (const auto& p : img.pixels) n += p[0] > red_above && p[1] < green_below && p[2] < blue_below;
  return n;
}

// X hides the transmitter's red mast and shows it again, re-merging the marker surface alone.
TEST(ViewCli, XTogglesTheTransmitterMarkersMergingOnlyTheirSurface) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  ASSERT_TRUE(make_volume(vdb));
  // The volume's transmitter (45.5 N, 6.5 E) from 3 km south-west, 400 m up (as the render
  // test's markers); an isosurface too, which the toggle must leave alone.
  Viewer v(bundled_dem() + " --agl --camera 45.47,6.47,400,45,-8 --volume " + vdb.string() + " --iso 150" + kSmall);
  ASSERT_TRUE(v.start());
  const auto red = [](const test::Image& img) { return reddish(img, 180, 80, 90); };
  json s = v.settle();
  EXPECT_TRUE(s["markers"].get<bool>());
  const std::size_t shown = red(v.screenshot());
  EXPECT_GT(shown, 20u) << "a mast and its diamond";
  v.tap("x");
  s = v.settle();
  EXPECT_FALSE(s["markers"].get<bool>());
  EXPECT_EQ(s["merge"]["merged_surfaces"].get<int>(), 1) << "the marker surface alone";
  EXPECT_NE(s["message"].get<std::string>().find("transmitter markers off"), std::string::npos) << s["message"];
  EXPECT_EQ(red(v.screenshot()), 0u);
  v.tap("x");
  s = v.settle();
  EXPECT_TRUE(s["markers"].get<bool>());
  EXPECT_EQ(s["merge"]["merged_surfaces"].get<int>(), 1);
  EXPECT_GT(red(v.screenshot()), shown / 2);
  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

// B takes the objects out of the picture and brings them back: a red tower 3 km ahead.
TEST(ViewCli, BTogglesTheObjects) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto obj = dir.path() / "tower.obj";
  std::ofstream(dir.path() / "tower.mtl") << "newmtl red\nKd 1 0 0\n";
  std::ofstream(obj) << "mtllib tower.mtl\nusemtl red\n"
                        "v -150 -150 0\nv 150 -150 0\nv 150 150 0\nv -150 150 0\n"
                        "v -150 -150 600\nv 150 -150 600\nv 150 150 600\nv -150 150 600\n"
                        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  Viewer v(bundled_dem() + " --agl --camera 45.47,6.47,400,45,-8 --object " + obj.string() + "@45.49,6.495,0,up=z" + kSmall);
  ASSERT_TRUE(v.start());
  const auto red = [](const test::Image& img) { return reddish(img, 60, 30, 30); };
  json s = v.settle();
  EXPECT_TRUE(s["objects"].get<bool>());
  const std::size_t shown = red(v.screenshot());
  EXPECT_GT(shown, 100u) << "the tower, lit on its faces";
  v.tap("b");
  s = v.settle();
  EXPECT_FALSE(s["objects"].get<bool>());
  EXPECT_NE(s["message"].get<std::string>().find("objects off"), std::string::npos) << s["message"];
  EXPECT_EQ(red(v.screenshot()), 0u);
  v.tap("b");
  s = v.settle();
  EXPECT_TRUE(s["objects"].get<bool>());
  EXPECT_EQ(red(v.screenshot()), shown);
  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

// Two Shift-clicks, a quarter of the window left and right of the centre looking straight
// down: the link between the two picked points is drawn over the terrain in the path's
// colours and its plot is written where --profile-plot says. The plot and the loss are what
// `terravol profile` gives for the same two points; the status names the file.
TEST(ViewCli, TwoShiftClicksDrawTheProfilePathAndWriteTheProfilesPlot) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto plot = dir.path() / "link.png";
  Viewer v(bundled_dem() + " --camera 45.51,6.52,6000,0,-90 --profile-plot " + plot.string() + kSmall);
  ASSERT_TRUE(v.start());
  v.settle();
  const std::initializer_list<test::Rgb8> path_colors = {{0, 200, 255}, {255, 200, 0}, {255, 0, 200}};
  const std::size_t before = pixels_near(v.screenshot(), path_colors, 30);
  const int y = v.height() / 2;
  v.xdo("keydown shift");
  v.xdo("mousemove --window " + v.window() + " " + std::to_string(v.width() / 4) + " " + std::to_string(y));
  v.xdo("click 1");
  ASSERT_TRUE(v.wait_for([](const json& s) { return s.contains("profile") && s["profile"]["to"].is_null(); }, 10.0))
      << v.stderr_text();
  EXPECT_EQ(v.status()["message"].get<std::string>().rfind("profile from ", 0), 0u);
  v.xdo("mousemove --window " + v.window() + " " + std::to_string(3 * v.width() / 4) + " " + std::to_string(y));
  v.xdo("click 1");
  v.xdo("keyup shift");
  ASSERT_TRUE(v.wait_for([](const json& s) { return s.contains("profile") && s["profile"].contains("file"); }, 20.0))
      << v.stderr_text() << v.status().dump();
  const json s = v.settle();
  const json p = s["profile"];
  EXPECT_EQ(p["file"].get<std::string>(), plot.string());
  EXPECT_NE(s["message"].get<std::string>().find("wrote " + plot.string()), std::string::npos) << s["message"];
  // West to east across the centre, at the camera's latitude.
  EXPECT_NEAR(p["from"]["lat"].get<double>(), 45.51, 2e-3) << p;
  EXPECT_NEAR(p["to"]["lat"].get<double>(), 45.51, 2e-3) << p;
  EXPECT_LT(p["from"]["lon"].get<double>(), 6.52);
  EXPECT_GT(p["to"]["lon"].get<double>(), 6.52);
  EXPECT_GT(p["path_triangles"].get<int>(), 0);
  // The path is drawn in its colours (the bundled terrain has none of them).
  const std::size_t after = pixels_near(v.screenshot(), path_colors, 30);
  EXPECT_GT(after, before + 200) << before << " before, " << after << " after";
  std::printf("profile path: %.2f km, %d triangles, link %.0f ms, merge %.0f ms, plot %.0f ms; %zu path pixels\n",
              p["distance_km"].get<double>(), p["path_triangles"].get<int>(), p["profile_ms"].get<double>(),
              p["merge_ms"].get<double>(), p["plot_ms"].get<double>(), after - before);
  // terravol profile between the same two points: the same loss and verdict, the same plot.
  char args[256];
  std::snprintf(args, sizeof args, " --from %.17g,%.17g,30 --to %.17g,%.17g,10 ", p["from"]["lat"].get<double>(),
                p["from"]["lon"].get<double>(), p["to"]["lat"].get<double>(), p["to"]["lon"].get<double>());
  const auto cli_png = dir.path() / "cli.png";
  const auto r = test::run_terravol("profile" + std::string(args) + "--dem " + bundled_dem() + " -o " + cli_png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::size_t at = r.out.find("  path loss ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NEAR(std::strtod(r.out.c_str() + at + 12, nullptr), p["path_loss_db"].get<double>(), 0.01);
  EXPECT_NE(r.out.find("verdict: " + p["verdict"].get<std::string>() + "\n"), std::string::npos) << r.out << p;
  const test::Image mine = test::read_png(plot), theirs = test::read_png(cli_png);
  ASSERT_EQ(mine.width, 1200);
  ASSERT_EQ(mine.height, 600);
  ASSERT_EQ(theirs.width, mine.width);
  ASSERT_EQ(theirs.height, mine.height);
  EXPECT_LT(test::differing_share(mine, theirs, 8), 0.001) << "pixels differing from terravol profile's plot";
  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

// The overlay's parts as the status gives them: {x, y, w, h} in window pixels, or none.
struct Part {
  std::string name;
  int x = 0, y = 0, w = 0, h = 0;
};
std::vector<Part> overlay_parts(const json& s) {
  std::vector<Part> parts;
  for (const char* name : {"slider", "legend", "text", "keys"}) {
    const json& b = s["overlay"][name];
    if (b.is_null()) continue;
    parts.push_back({name, b["x"].get<int>(), b["y"].get<int>(), b["w"].get<int>(), b["h"].get<int>()});
  }
  return parts;
}

// Every part drawn, inside the window, no two sharing a pixel.
::testing::AssertionResult parts_apart(const json& s, const std::vector<std::string>& expected) {
  const int W = s["size"][0].get<int>(), H = s["size"][1].get<int>();
  const std::vector<Part> parts = overlay_parts(s);
  for (const std::string& want : expected) {
    if (std::none_of(parts.begin(), parts.end(), [&](const Part& p) { return p.name == want; })) {
      return ::testing::AssertionFailure() << W << "x" << H << ": no " << want << " in " << s["overlay"].dump();
    }
  }
  for (std::size_t a = 0; a < parts.size(); ++a) {
    const Part& p = parts[a];
    if (p.w <= 0 || p.h <= 0 || p.x < 0 || p.y < 0 || p.x + p.w > W || p.y + p.h > H) {
      return ::testing::AssertionFailure() << W << "x" << H << ": " << p.name << " leaves the window: " << s["overlay"].dump();
    }
    for (std::size_t b = 0; b < a; ++b) {
      const Part& q = parts[b];
      if (std::min(p.x + p.w, q.x + q.w) > std::max(p.x, q.x) && std::min(p.y + p.h, q.y + q.h) > std::max(p.y, q.y)) {
        return ::testing::AssertionFailure() << W << "x" << H << ": " << p.name << " overlaps " << q.name << ": "
                                             << s["overlay"].dump();
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Pixels of the knob's orange (vtkSliderRepresentation2D, 255, 158, 38) outside the slider's box
// and inside it, in a screenshot: the box holds what is drawn.
std::pair<int, int> knob_pixels(const test::Image& img, const json& s) {
  const json& b = s["overlay"]["slider"];
  const int x0 = b["x"].get<int>(), y0 = b["y"].get<int>(), x1 = x0 + b["w"].get<int>(), y1 = y0 + b["h"].get<int>();
  int inside = 0, outside = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (!test::same_color(img.at(x, y), {255, 158, 38}, 2)) continue;
      (x >= x0 && x < x1 && y >= y0 && y < y1 ? inside : outside) += 1;
    }
  return {inside, outside};
}

// The legend (the slice's map and both isosurface levels), the LOD slider, the overlay text and
// the key list: at 1280 x 720 and 800 x 600, after the window is resized with xdotool, and
// after a metric change widens the slider's title, no two share a pixel (issue 18: at
// 1280 x 720 the slider used to cover the legend's lowest label).
TEST(ViewCli, TheOverlaysPartsNeverOverlapAtEitherSizeOrAfterAResize) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  ASSERT_TRUE(make_volume(vdb));
  const std::vector<std::string> all{"slider", "legend", "text", "keys"};
  for (const std::string size : {"1280x720", "800x600"}) {
    Viewer v(bundled_dem() + " --camera 45.44,6.44,2600,40,-18 --window 256 --volume " + vdb.string() +
             " --iso 110 --iso 130 --slice agl=300,colormap=viridis,range=80:160 --size " + size);
    ASSERT_TRUE(v.start());
    json s = v.settle();
    EXPECT_TRUE(parts_apart(s, {"slider", "legend", "text"}));
    EXPECT_FALSE(s["overlay"]["keys_shown"].get<bool>());
    v.tap("h");  // the key list
    s = v.settle();
    EXPECT_TRUE(s["overlay"]["keys_shown"].get<bool>());
    EXPECT_TRUE(parts_apart(s, all));
    EXPECT_GE(s["overlay"]["keys_font"].get<int>(), 7) << "readable";
    const auto [inside, outside] = knob_pixels(v.screenshot(), v.status());
    EXPECT_GT(inside, 50) << size << ": the knob is drawn inside the slider's box";
    EXPECT_EQ(outside, 0) << size;
    v.tap("m");  // the projected-area metric: another title and end labels
    s = v.settle();
    EXPECT_EQ(s["metric"], "area");
    EXPECT_TRUE(parts_apart(s, all));
    if (size == "800x600") {
      v.xdo("windowsize --sync " + v.window() + " 1000 640");
      ASSERT_TRUE(v.wait_for([](const json& st) { return st["size"][0] == 1000 && st["size"][1] == 640; }, 15.0))
          << "the resize reaches the viewer";
      s = v.settle();
      EXPECT_TRUE(parts_apart(s, all));
      v.xdo("windowsize --sync " + v.window() + " 700 520");
      ASSERT_TRUE(v.wait_for([](const json& st) { return st["size"][0] == 700 && st["size"][1] == 520; }, 15.0));
      s = v.settle();
      EXPECT_TRUE(parts_apart(s, all));
    }
    v.xdo("key q");
    EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
  }
}

// Isosurfaces are reduced to --surface-triangles each (12000 by default), or to the scene
// file's "surface_triangles"; the option wins over the file. Slices keep the volume's
// resolution whatever the budget.
TEST(ViewCli, SurfaceTrianglesBudgetsEachIsosurfaceFromTheOptionOrTheSceneFileAndNeverASlice) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  ASSERT_TRUE(make_volume(vdb));
  const auto write_scene = [&](const std::string& name, const std::string& styles) {
    const auto scene = dir.path() / name;
    std::ofstream(scene) << R"({"dem": ")" << bundled_dem() << R"(", "volumes": [{"file": ")" << vdb.string()
                         << R"(", )" << styles << R"(}],
    "camera": {"lat": 45.44, "lon": 6.44, "alt": 2600, "heading": 40, "pitch": -18},
    "render": {"surface_triangles": 2000}})";
    return scene;
  };
  const auto input_triangles = [&](const std::filesystem::path& scene, const std::string& args) -> std::size_t {
    Viewer v("--scene " + scene.string() + args + kSmall);
    if (!v.start()) return 0;
    const json s = v.settle();
    v.xdo("key q");
    EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
    EXPECT_GT(s["merged_triangles"].get<std::size_t>(), 0u);
    return s["merge"]["input_triangles"].get<std::size_t>();
  };
  const auto isos = write_scene("isos.json", R"("isosurfaces": [{"value": 105}, {"value": 110}])");
  const std::size_t from_file = input_triangles(isos, "");
  EXPECT_GT(from_file, 0u);
  EXPECT_LE(from_file, 2u * 2000u) << "the scene file's budget, for each isosurface";
  const std::size_t from_option = input_triangles(isos, " --surface-triangles 4000");
  EXPECT_GT(from_option, from_file) << "the option wins over the file";
  EXPECT_LE(from_option, 2u * 4000u);
  // A slice keeps the volume's resolution whatever the budget.
  const auto slice = write_scene("slice.json", R"("slices": [{"agl": 300}])");
  const std::size_t slice_small = input_triangles(slice, " --surface-triangles 100");
  EXPECT_GT(slice_small, 100u);
  EXPECT_EQ(slice_small, input_triangles(slice, " --surface-triangles 0"));
}

TEST(ViewCli, RecordedKeyframesSaveACameraPathThatLoadsBack) {
  TERRAVOL_REQUIRE_XDOTOOL();
  test::TempDir dir;
  const auto path = dir.path() / "flight.json";
  Viewer v(bundled_dem() + " --camera 45.5,6.5,4500,0,-10 --record " + path.string() + kSmall);
  ASSERT_TRUE(v.start());
  v.settle();
  v.tap("k");
  ASSERT_TRUE(v.hold_until("Right", [](const json& s) { return s["camera"]["heading"].get<double>() > 20.0; }, 10.0));
  v.tap("k");
  const json before = v.settle();
  v.tap("j");
  const json s = v.settle();
  EXPECT_NE(s["message"].get<std::string>().find("saved 2 keyframes"), std::string::npos) << s["message"];
  const app::scene::CameraPathFile loaded = app::scene::load_camera_path(path);
  ASSERT_EQ(loaded.keys.size(), 2u);
  EXPECT_DOUBLE_EQ(loaded.keys[0].heading_deg, 0.0);
  EXPECT_NEAR(loaded.keys[1].heading_deg, before["camera"]["heading"].get<double>(), 1e-9);
  EXPECT_GT(loaded.keys[1].t, loaded.keys[0].t);
  v.xdo("key q");
  EXPECT_EQ(v.wait_exit(15.0), 0) << v.stderr_text();
}

TEST(ViewCli, HelpListsTheKeyBindings) {
  const auto r = test::run_terravol("view --help");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* text : {"W / S", "wireframe", "LOD colours", "sliding", "Esc", "--status", "--threshold",
                           "Shift+click", "transmitter markers", "--profile-plot"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
  }
}

TEST(ViewCli, ACameraFarBeyondTheDemFailsWithOneLine) {
  const auto r = test::run_terravol("view " + bundled_dem() + " --camera 48.5,6.5,4000,0,0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("terravol: camera 48.50000 N, 6.50000 E is 278.0 km beyond the DEM"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(ViewCli, ACameraBeyondTheDemSeesTheTileAndFlyingAwayStopsAt200Km) {
  TERRAVOL_REQUIRE_XDOTOOL();
  // 11 km south of the tile, looking north over it; then backwards (south) at 1000 heights per
  // second, far faster than 200 km in a few seconds.
  Viewer v(bundled_dem() + " --camera 44.9,6.5,4000,0,-10 --speed 1000" + kSmall);
  ASSERT_TRUE(v.start());
  const json s0 = v.settle();
  EXPECT_GT(s0["triangles"].get<long>(), 1000) << "the tile is drawn";
  ASSERT_TRUE(v.hold_until(
      "s", [](const json& s) { return s["camera"]["lat"].get<double>() < 43.21; }, 40.0))
      << "last status " << v.status().dump();
  v.hold_until("s", [](const json&) { return false; }, 1.0);  // on against the limit for a second
  const json s1 = v.settle();
  EXPECT_NEAR(s1["camera"]["lat"].get<double>(), 45.0 - 199.8 / 111.2, 1e-3) << "stopped 200 km south of the tile";
}

// The profile options' bad values, and no display: one line each, before any window opens.
TEST(ViewCli, BadProfileOptionsOrNoDisplayFailWithOneLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"view " + bundled_dem() + " --profile-agl 30", "terravol: --profile-agl 30: expected TX,RX"},
      {"view " + bundled_dem() + " --profile-agl 30,-1", "terravol: --profile-agl 30,-1: expected TX,RX"},
      {"view " + bundled_dem() + " --profile-freq 0", "terravol: --profile-freq: must be within (0, 100000] MHz"},
      {"view " + bundled_dem() + " --profile-plot /nonexistent-folder/p.png",
       "terravol: --profile-plot /nonexistent-folder/p.png: folder /nonexistent-folder does not exist"},
  };
  for (const auto& [args, prefix] : cases) {
    const auto r = test::run_terravol(args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  const auto r = test::run_terravol_under("env -u DISPLAY", "view " + bundled_dem());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.rfind("terravol: view needs an X display", 0), 0u) << r.err;
}

}  // namespace
}  // namespace terravol
