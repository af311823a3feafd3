// Camera paths: the file format's errors, and the camera between keys (through the keys, C1,
// no flip at north, constant speed on request).
#include "app/scene/camera_path.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace terravol::app::scene {
namespace {

using nlohmann::json;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

json key(double t, double lat, double lon, double alt, double heading, double pitch) {
  return {{"t", t}, {"lat", lat}, {"lon", lon}, {"alt", alt}, {"heading", heading}, {"pitch", pitch}};
}

json three_keys() {
  return {{"scene", "scene.json"},
          {"keys", {key(0, 45.1, 6.3, 3000, 30, -10), key(5, 45.12, 6.35, 3200, 60, -15), key(9, 45.15, 6.36, 3100, 80, -5)}}};
}

// The message of parse_camera_path's exception, or "" when it accepts the document.
std::string parse_error(const json& doc) {
  try {
    parse_camera_path(doc, "/data", "path.json");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CameraPath, ParsesSceneFileRelativeToThePathFile) {
  const CameraPathFile f = parse_camera_path(three_keys(), "/data/flights", "path.json");
  EXPECT_EQ(f.scene_file, std::filesystem::path("/data/flights/scene.json"));
  ASSERT_EQ(f.keys.size(), 3u);
  EXPECT_DOUBLE_EQ(f.keys[1].t, 5.0);
  EXPECT_DOUBLE_EQ(f.keys[1].heading_deg, 60.0);
  EXPECT_EQ(f.speed, PathSpeed::kKeys);
}

TEST(CameraPath, InlineSceneIsKeptAsADocument) {
  json doc = three_keys();
  doc["scene"] = {{"dem", "N45E006.hgt"}};
  const CameraPathFile f = parse_camera_path(doc, "/data", "path.json");
  EXPECT_TRUE(f.scene_file.empty());
  EXPECT_EQ(f.scene["dem"], "N45E006.hgt");
}

TEST(CameraPath, UnknownKeyFieldIsNamedWithItsIndex) {
  json doc = three_keys();
  doc["keys"][2]["heeding"] = 10;
  const std::string e = parse_error(doc);
  EXPECT_NE(e.find("path.json: keys[2].heeding: unknown field"), std::string::npos) << e;
}

TEST(CameraPath, BadValuesAreNamedWithIndexAndField) {
  const std::pair<const char*, json> cases[] = {
      {"keys[1].pitch", -95}, {"keys[1].lat", 89.0}, {"keys[1].fov", 0}, {"keys[1].threshold", -1},
      {"keys[1].alt", "high"}, {"keys[1].roll", 270}, {"keys[1].agl", 1}};
  for (const auto& [where, value] : cases) {
    json doc = three_keys();
    const std::string field = std::string(where).substr(std::string("keys[1].").size());
    doc["keys"][1][field] = value;
    const std::string e = parse_error(doc);
    EXPECT_NE(e.find(std::string("path.json: ") + where + ": "), std::string::npos) << where << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(CameraPath, AglAltitudeMustBeAboveTheGround) {
  json doc = three_keys();
  doc["keys"][0]["agl"] = true;
  doc["keys"][0]["alt"] = 0;
  EXPECT_NE(parse_error(doc).find("keys[0].alt: must be above the ground"), std::string::npos) << parse_error(doc);
}

TEST(CameraPath, KeysOutOfOrderOrTooCloseAreErrors) {
  json doc = three_keys();
  doc["keys"][2]["t"] = 4;
  std::string e = parse_error(doc);
  EXPECT_NE(e.find("keys[2].t: 4 is not after keys[1].t (5)"), std::string::npos) << e;
  doc["keys"][2]["t"] = 5.005;
  e = parse_error(doc);
  EXPECT_NE(e.find("keys[2].t: 5.005 is within 0.01 s of keys[1].t (5); keys too close"), std::string::npos) << e;
}

TEST(CameraPath, OrientationNeedsHeadingOrLookAtButNotBoth) {
  json doc = three_keys();
  doc["keys"][1].erase("heading");
  EXPECT_NE(parse_error(doc).find("keys[1]: needs \"heading\""), std::string::npos) << parse_error(doc);
  doc = three_keys();
  doc["keys"][1]["look_at"] = {{"lat", 45.2}, {"lon", 6.4}, {"alt", 2000}};
  EXPECT_NE(parse_error(doc).find("keys[1].heading: not allowed with look_at"), std::string::npos) << parse_error(doc);
  doc["keys"][1].erase("heading");
  doc["keys"][1].erase("pitch");
  doc["keys"][1]["look_at"]["altitude"] = 3;
  EXPECT_NE(parse_error(doc).find("keys[1].look_at.altitude: unknown field"), std::string::npos) << parse_error(doc);
}

TEST(CameraPath, DocumentLevelErrors) {
  EXPECT_NE(parse_error(json::array()).find("(top level): expected an object"), std::string::npos);
  json doc = three_keys();
  doc.erase("scene");
  EXPECT_NE(parse_error(doc).find("missing \"scene\""), std::string::npos);
  doc = three_keys();
  doc["speed"] = "fast";
  EXPECT_NE(parse_error(doc).find("speed: expected \"keys\" or \"constant\""), std::string::npos);
  doc = three_keys();
  doc["keys"] = json::array({key(0, 45, 6, 100, 0, 0)});
  EXPECT_NE(parse_error(doc).find("at least two keys, has 1"), std::string::npos);
  doc = three_keys();
  doc["fps"] = 30;
  EXPECT_NE(parse_error(doc).find("fps: unknown field"), std::string::npos);
}

TEST(CameraPath, PathToJsonReadsBackToTheSameKeys) {
  std::vector<PathKey> keys(3);
  keys[0] = PathKey{0.0, 45.1, 6.3, 250.0, true, 30.0, -10.0, 0.0, std::nullopt, 50.0, std::nullopt};
  keys[1] = PathKey{4.5, 45.12, 6.31, 2900.0, false, 0.0, 0.0, 5.0, LookAt{45.2, 6.4, 100.0, true}, std::nullopt, 1.5};
  keys[2] = PathKey{9.0, 45.13, 6.33, 2800.0, false, 359.0, -90.0, 0.0, std::nullopt, std::nullopt, std::nullopt};
  const json doc = path_to_json("scene.json", keys, PathSpeed::kConstant);
  const CameraPathFile f = parse_camera_path(json::parse(doc.dump()), "/p", "saved.json");
  EXPECT_EQ(f.scene_file, std::filesystem::path("/p/scene.json"));
  EXPECT_EQ(f.speed, PathSpeed::kConstant);
  ASSERT_EQ(f.keys.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const PathKey &a = keys[i], &b = f.keys[i];
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.lat, b.lat);
    EXPECT_EQ(a.lon, b.lon);
    EXPECT_EQ(a.alt, b.alt);
    EXPECT_EQ(a.agl, b.agl);
    EXPECT_EQ(a.heading_deg, b.heading_deg);
    EXPECT_EQ(a.pitch_deg, b.pitch_deg);
    EXPECT_EQ(a.roll_deg, b.roll_deg);
    EXPECT_EQ(a.look_at.has_value(), b.look_at.has_value());
    if (a.look_at) {
      EXPECT_EQ(a.look_at->lat, b.look_at->lat);
      EXPECT_EQ(a.look_at->agl, b.look_at->agl);
    }
    EXPECT_EQ(a.fov_y_deg, b.fov_y_deg);
    EXPECT_EQ(a.threshold, b.threshold);
  }
}

// --- interpolation ---

PathKey pk(double t, double lat, double lon, double alt, bool agl, double heading = 0.0, double pitch = 0.0) {
  PathKey k;
  k.t = t;
  k.lat = lat;
  k.lon = lon;
  k.alt = alt;
  k.agl = agl;
  k.heading_deg = heading;
  k.pitch_deg = pitch;
  return k;
}

const io::SceneFrame kFrame(45.2, 6.4);
double flat_ground(double, double) { return 500.0; }

// The camera's forward and up vectors in east-north-up, from its angles.
glm::dvec3 forward_of(const PathSample& s) {
  const double h = s.pose.heading_deg * kDeg, p = s.pose.pitch_deg * kDeg;
  return {std::sin(h) * std::cos(p), std::cos(h) * std::cos(p), std::sin(p)};
}
glm::dvec3 up_of(const PathSample& s) {
  const double h = s.pose.heading_deg * kDeg, p = s.pose.pitch_deg * kDeg, r = s.pose.roll_deg * kDeg;
  const glm::dvec3 level(std::sin(h), std::cos(h), 0.0), east(std::cos(h), -std::sin(h), 0.0);
  const glm::dvec3 up0 = std::cos(p) * glm::dvec3(0, 0, 1) - std::sin(p) * level;
  return std::cos(r) * up0 + std::sin(r) * east;
}
glm::dvec3 position_of(const PathSample& s) {
  return {kFrame.x_of_lon(s.pose.lon), kFrame.y_of_lat(s.pose.lat), s.pose.alt};
}

std::vector<PathKey> random_keys(std::mt19937& rng, int n, bool rolls) {
  std::uniform_real_distribution<double> dt(0.5, 6.0), dlat(-0.01, 0.01), alt(1500.0, 4000.0), heading(0.0, 360.0),
      pitch(-60.0, 20.0), roll(-30.0, 30.0);
  std::vector<PathKey> keys;
  double t = 0.0, lat = 45.2, lon = 6.4;
  for (int i = 0; i < n; ++i) {
    PathKey k;
    k.t = t;
    k.lat = lat;
    k.lon = lon;
    k.alt = alt(rng);
    k.heading_deg = heading(rng);
    k.pitch_deg = pitch(rng);
    k.roll_deg = rolls ? roll(rng) : 0.0;
    k.fov_y_deg = 30.0 + 20.0 * (i % 3);
    keys.push_back(k);
    t += dt(rng);
    lat += dlat(rng);
    lon += dlat(rng);
  }
  return keys;
}

TEST(CameraPath, PassesThroughEveryKeyAtItsTime) {
  std::mt19937 rng(12345);
  const std::vector<PathKey> keys = random_keys(rng, 7, true);
  const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0);
  for (const PathKey& k : keys) {
    const PathSample s = path.at(k.t);
    EXPECT_NEAR(s.pose.lat, k.lat, 1e-9);
    EXPECT_NEAR(s.pose.lon, k.lon, 1e-9);
    EXPECT_NEAR(s.pose.alt, k.alt, 1e-6);
    EXPECT_NEAR(std::remainder(s.pose.heading_deg - k.heading_deg, 360.0), 0.0, 1e-6);
    EXPECT_NEAR(s.pose.pitch_deg, k.pitch_deg, 1e-6);
    EXPECT_NEAR(s.pose.roll_deg, k.roll_deg, 1e-6);
    EXPECT_NEAR(s.fov_y_deg, *k.fov_y_deg, 1e-9);
    EXPECT_NEAR(s.threshold, 2.0, 1e-12);
  }
}

// At every interior key, the velocity and the rate of turn just before equal those just after
// (a C1 path; a plain Catmull-Rom with u linear in time per segment jumps in speed here).
TEST(CameraPath, VelocityAndTurnRateAreContinuousAtKeys) {
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    std::mt19937 rng(seed);
    const std::vector<PathKey> keys = random_keys(rng, 6, true);
    const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0);
    const double h = 1e-4;
    for (std::size_t i = 1; i + 1 < keys.size(); ++i) {
      const double t = keys[i].t;
      const PathSample before = path.at(t - h), here = path.at(t), after = path.at(t + h);
      const glm::dvec3 v_in = (position_of(here) - position_of(before)) / h;
      const glm::dvec3 v_out = (position_of(after) - position_of(here)) / h;
      EXPECT_LT(glm::length(v_in - v_out), 1e-2 * glm::length(v_in) + 1e-2) << "seed " << seed << " key " << i;
      for (auto vec : {forward_of, up_of}) {
        const glm::dvec3 w_in = (vec(here) - vec(before)) / h, w_out = (vec(after) - vec(here)) / h;
        EXPECT_LT(glm::length(w_in - w_out), 2e-3 + 1e-2 * glm::length(w_in)) << "seed " << seed << " key " << i;
      }
    }
  }
}

TEST(CameraPath, HeadingAcrossNorthTurnsTheShortWay) {
  std::vector<PathKey> keys(3);
  keys[0] = pk(0.0, 45.2, 6.4, 3000.0, false, 350.0, -10.0);
  keys[1] = pk(5.0, 45.21, 6.4, 3000.0, false, 359.0, -10.0);
  keys[2] = pk(10.0, 45.22, 6.4, 3000.0, false, 1.0, -10.0);
  keys.push_back(pk(15.0, 45.23, 6.4, 3000.0, false, 12.0, -10.0));
  const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0);
  double previous = path.at(0.0).pose.heading_deg;
  for (int k = 1; k <= 3000; ++k) {
    const double heading = path.at(15.0 * k / 3000).pose.heading_deg;
    EXPECT_LT(std::abs(std::remainder(heading - previous, 360.0)), 0.1) << "at step " << k;
    const double from_north = std::remainder(heading, 360.0);
    EXPECT_GT(from_north, -10.5);
    EXPECT_LT(from_north, 12.5);
    EXPECT_GE(heading, 0.0);
    EXPECT_LT(heading, 360.0);
    previous = heading;
  }
}

TEST(CameraPath, ConstantSpeedCoversEqualDistancesInEqualTimes) {
  std::mt19937 rng(777);
  for (int trial = 0; trial < 10; ++trial) {
    const std::vector<PathKey> keys = random_keys(rng, 5, false);
    const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kConstant, 45.0, 2.0);
    const int n = 400;
    const double step_len = path.length_m() / n;
    glm::dvec3 last = position_of(path.at(path.start()));
    EXPECT_NEAR(glm::length(last - glm::dvec3(kFrame.x_of_lon(keys[0].lon), kFrame.y_of_lat(keys[0].lat), keys[0].alt)), 0.0, 1e-6);
    // The distance along the path in each time step (summed over 32 sub-steps, so that
    // chords across sharp turns do not count short).
    const double dt = (path.end() - path.start()) / n;
    for (int k = 1; k <= n; ++k) {
      double along = 0.0;
      for (int j = 1; j <= 32; ++j) {
        const glm::dvec3 p = position_of(path.at(path.start() + dt * (k - 1 + j / 32.0)));
        along += glm::length(p - last);
        last = p;
      }
      EXPECT_NEAR(along, step_len, 0.01 * step_len) << "trial " << trial << " step " << k;
    }
    const PathKey& end = keys.back();
    EXPECT_NEAR(glm::length(last - glm::dvec3(kFrame.x_of_lon(end.lon), kFrame.y_of_lat(end.lat), end.alt)), 0.0, 1e-6);
  }
}

TEST(CameraPath, ConstantSpeedRejectsAKeyThatDoesNotMove) {
  std::vector<PathKey> keys(3);
  keys[0] = pk(0.0, 45.2, 6.4, 3000.0, false, 0.0, 0.0);
  keys[1] = pk(5.0, 45.21, 6.4, 3000.0, false, 0.0, 0.0);
  keys[2] = pk(8.0, 45.21, 6.4, 3000.0, false, 90.0, 0.0);
  EXPECT_NO_THROW(CameraPath(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0));
  try {
    CameraPath(keys, kFrame, flat_ground, PathSpeed::kConstant, 45.0, 2.0);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("keys[2]: at the position of keys[1]"), std::string::npos) << e.what();
  }
}

TEST(CameraPath, LookAtAimsAtTheTargetAtItsKey) {
  std::vector<PathKey> keys(2);
  keys[0] = pk(0.0, 45.2, 6.4, 3000.0, false, 0.0, 0.0);
  keys[1] = pk(5.0, 45.2, 6.45, 1000.0, true);  // 1000 m above the 500 m ground
  // A target 1500 m lower and as far south as east: heading 135, pitch -asin(1500 / distance).
  const double d = 2000.0;
  keys[1].look_at = LookAt{45.2 - d / kFrame.metres_per_degree_lat(), 6.45 + d / kFrame.metres_per_degree_lon(), 0.0, false};
  const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0);
  EXPECT_FALSE(path.agl());
  const PathSample s = path.at(5.0);
  EXPECT_NEAR(s.pose.alt, 1500.0, 1e-9);  // resolved over the ground
  EXPECT_NEAR(s.pose.heading_deg, 135.0, 0.2);
  EXPECT_NEAR(s.pose.pitch_deg, -std::asin(1500.0 / std::sqrt(2 * d * d + 1500.0 * 1500.0)) / kDeg, 0.2);
}

TEST(CameraPath, AllAglKeysInterpolateHeightAboveGround) {
  std::vector<PathKey> keys(2);
  keys[0] = pk(0.0, 45.2, 6.4, 100.0, true, 0.0, 0.0);
  keys[1] = pk(5.0, 45.21, 6.4, 300.0, true, 0.0, 0.0);
  const CameraPath path(keys, kFrame, CameraPath::Ground{}, PathSpeed::kKeys, 45.0, 2.0);  // no ground needed
  EXPECT_TRUE(path.agl());
  EXPECT_NEAR(path.at(0.0).pose.alt, 100.0, 1e-9);
  EXPECT_NEAR(path.at(5.0).pose.alt, 300.0, 1e-9);
}

TEST(CameraPath, FovBetweenKeysStaysWithinTheirRange) {
  std::vector<PathKey> keys(4);
  const double fovs[] = {60.0, 20.0, 20.5, 80.0};
  for (int i = 0; i < 4; ++i) {
    keys[static_cast<std::size_t>(i)] = pk(i * 2.0, 45.2 + i * 0.01, 6.4, 3000.0, false, 0.0, 0.0);
    keys[static_cast<std::size_t>(i)].fov_y_deg = fovs[i];
  }
  const CameraPath path(keys, kFrame, flat_ground, PathSpeed::kKeys, 45.0, 2.0);
  for (int k = 0; k <= 600; ++k) {
    const double t = 6.0 * k / 600;
    const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(t / 2.0), 2);
    const double fov = path.at(t).fov_y_deg;
    EXPECT_GE(fov, std::min(fovs[i], fovs[i + 1]) - 1e-9) << t;
    EXPECT_LE(fov, std::max(fovs[i], fovs[i + 1]) + 1e-9) << t;
  }
}

}  // namespace
}  // namespace terravol::app::scene
