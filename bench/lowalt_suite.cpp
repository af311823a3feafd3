// 9. Low altitude (issue 12): frames near the floor, where most of what the tree draws is hidden
// behind nearer ridges. Coverage-mask occlusion culling (Greene 1996) on and off side by side,
// hidden triangles counted by an item buffer (bench/item_buffer.h), and the occlusion tests a
// long low flight makes under Bittner and Havran's (2001) coherence against testing every node.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <optional>
#include <unordered_set>

#include "bench/item_buffer.h"
#include "bench/stats.h"
#include "bench/suite_common.h"
#include "bench/suites.h"

namespace terravol::bench {

namespace {

using nlohmann::json;

// A low view anchor: where, looking which way (the suite varies the height and the pitch).
struct Anchor {
  double lat, lon, heading;
};

// The terrains with hand-placed views: valley floors and notches, looking up them or at the
// ridges above. The window is centred on `centre`.
struct Place {
  double lat, lon;               // the window's centre
  std::vector<Anchor> anchors;   // low views
  Anchor flight_from, flight_to; // the flight's ends (headings unused)
};

std::optional<Place> named_place(std::string terrain) {
  std::transform(terrain.begin(), terrain.end(), terrain.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (terrain == "utah") {
    // The Salt Lake valley toward the Wasatch front, up its canyons, and back west.
    return Place{40.62,
                 -111.85,
                 {{40.62, -111.95, 90},  {40.70, -111.98, 100}, {40.55, -111.92, 75},  {40.572, -111.80, 90},
                  {40.62, -111.76, 100}, {40.71, -111.76, 80},  {40.33, -111.68, 60},  {40.60, -111.88, 270},
                  {40.76, -111.90, 120}, {40.45, -111.85, 45}},
                 {40.66, -112.02, 0},
                 {40.57, -111.79, 0}};
  }
  if (terrain == "n44w072") {
    // The White Mountains' notches: Franconia, Crawford, Pinkham, Kinsman, and the Pemigewasset.
    return Place{44.2,
                 -71.5,
                 {{44.13, -71.683, 0},  {44.19, -71.69, 180}, {44.18, -71.38, 320}, {44.22, -71.41, 150},
                  {44.22, -71.25, 0},   {44.26, -71.25, 270}, {44.10, -71.55, 45},  {44.04, -71.79, 0},
                  {44.15, -71.60, 90},  {44.25, -71.33, 200}},
                 {44.27, -71.47, 0},
                 {44.12, -71.33, 0}};
  }
  return std::nullopt;
}

double bearing_deg(double lat0, double lon0, double lat1, double lon1) {
  const double k = std::cos(lat0 * std::numbers::pi / 180.0);
  return std::fmod(std::atan2((lon1 - lon0) * k, lat1 - lat0) * 180.0 / std::numbers::pi + 360.0, 360.0);
}

// Any other terrain: the lowest points of the window's central half (on a 24 x 24 grid, at
// least 3 grid steps apart), each looking toward the highest; the flight from the lowest toward
// the highest.
Place generic_place(const app::render::SceneRenderer& scene) {
  const app::scene::WindowBounds b = scene.terrain().bounds();
  const double clat = 0.5 * (b.south + b.north), clon = 0.5 * (b.west + b.east);
  const double hlat = 0.25 * (b.north - b.south), hlon = 0.25 * (b.east - b.west);
  struct Sample {
    double lat, lon, z;
  };
  std::vector<Sample> grid;
  constexpr int kSide = 24;
  for (int j = 0; j < kSide; ++j)
    for (int i = 0; i < kSide; ++i) {
      const double lat = clat - hlat + 2.0 * hlat * (j + 0.5) / kSide, lon = clon - hlon + 2.0 * hlon * (i + 0.5) / kSide;
      grid.push_back({lat, lon, scene.ground_height(lat, lon)});
    }
  const Sample high = *std::max_element(grid.begin(), grid.end(), [](const Sample& a, const Sample& c) { return a.z < c.z; });
  std::sort(grid.begin(), grid.end(), [](const Sample& a, const Sample& c) { return a.z < c.z; });
  Place p{clat, clon, {}, {}, {}};
  const double min_sep = 3.0 * 2.0 * hlat / kSide;
  for (const Sample& s : grid) {
    if (p.anchors.size() == 10) break;
    const bool near = std::any_of(p.anchors.begin(), p.anchors.end(), [&](const Anchor& a) {
      return std::abs(a.lat - s.lat) < min_sep && std::abs(a.lon - s.lon) < min_sep * hlon / hlat;
    });
    if (!near) p.anchors.push_back({s.lat, s.lon, bearing_deg(s.lat, s.lon, high.lat, high.lon)});
  }
  p.flight_from = p.anchors.front();
  p.flight_to = {p.anchors.front().lat + 0.8 * (high.lat - p.anchors.front().lat),
                 p.anchors.front().lon + 0.8 * (high.lon - p.anchors.front().lon), 0};
  return p;
}

// The low views: each anchor at 100, 250 and 500 m above the ground (in turn), pitch 0 to -6.
std::vector<View> low_views(const Place& p, int count) {
  std::vector<View> views;
  for (int k = 0; k < count; ++k) {
    const Anchor& a = p.anchors[static_cast<std::size_t>(k) % p.anchors.size()];
    View v;
    v.pose.lat = a.lat;
    v.pose.lon = a.lon;
    v.pose.heading_deg = std::fmod(a.heading + 15.0 * static_cast<double>(k / static_cast<int>(p.anchors.size())), 360.0);
    v.pose.alt = std::array{100.0, 250.0, 500.0}[static_cast<std::size_t>(k) % 3];
    v.pose.pitch_deg = std::array{-3.0, 0.0, -6.0}[static_cast<std::size_t>(k) % 3];
    views.push_back(v);
  }
  return views;
}

// High views over the window's centre: 3000 m pitch -25, 5000 m pitch -35, 8000 m pitch -45.
std::vector<View> high_views(const app::scene::WindowBounds& b, int count) {
  const double clat = 0.5 * (b.south + b.north), clon = 0.5 * (b.west + b.east);
  std::vector<View> views;
  for (int k = 0; k < count; ++k) {
    View v;
    v.overview = true;
    v.pose.lat = clat + 0.1 * (b.north - b.south) * std::sin(2.1 * k);
    v.pose.lon = clon + 0.1 * (b.east - b.west) * std::cos(2.1 * k);
    v.pose.heading_deg = std::fmod(70.0 * k, 360.0);
    v.pose.alt = std::array{3000.0, 5000.0, 8000.0}[static_cast<std::size_t>(k) % 3];
    v.pose.pitch_deg = std::array{-25.0, -35.0, -45.0}[static_cast<std::size_t>(k) % 3];
    views.push_back(v);
  }
  return views;
}

// The flight: `frames` poses from one end to the other, 100 to 500 m above the ground (a slow
// swell), heading along the way with a sway of +-25 degrees, pitch -2 to -8.
std::vector<app::scene::CameraPose> low_flight(const Place& p, int frames) {
  const double heading = bearing_deg(p.flight_from.lat, p.flight_from.lon, p.flight_to.lat, p.flight_to.lon);
  std::vector<app::scene::CameraPose> poses;
  for (int k = 0; k < frames; ++k) {
    const double t = frames > 1 ? static_cast<double>(k) / (frames - 1) : 0.0;
    app::scene::CameraPose pose;
    pose.lat = p.flight_from.lat + t * (p.flight_to.lat - p.flight_from.lat);
    pose.lon = p.flight_from.lon + t * (p.flight_to.lon - p.flight_from.lon);
    pose.alt = 300.0 - 200.0 * std::cos(2.0 * std::numbers::pi * 3.0 * t);
    pose.heading_deg = std::fmod(heading + 25.0 * std::sin(2.0 * std::numbers::pi * 2.0 * t) + 360.0, 360.0);
    pose.pitch_deg = -5.0 + 3.0 * std::sin(2.0 * std::numbers::pi * 5.0 * t);
    poses.push_back(pose);
  }
  return poses;
}

// A triangle as its three vertex indices, for matching triangles between frames.
struct TriangleKey {
  std::uint32_t a, b, c;
  bool operator==(const TriangleKey&) const = default;
};
struct TriangleHash {
  std::size_t operator()(const TriangleKey& t) const {
    std::uint64_t h = (static_cast<std::uint64_t>(t.a) << 32 | t.b) * 0x9E3779B97F4A7C15ull;
    h ^= (h >> 29) + static_cast<std::uint64_t>(t.c) * 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
};
std::unordered_set<TriangleKey, TriangleHash> triangle_set(const mrbsp::Frame& f) {
  std::unordered_set<TriangleKey, TriangleHash> s;
  s.reserve(f.indices.size() / 3);
  for (std::size_t t = 0; t + 2 < f.indices.size(); t += 3) s.insert({f.indices[t], f.indices[t + 1], f.indices[t + 2]});
  return s;
}

double share(double part, double whole) { return whole > 0 ? part / whole : 0.0; }

}  // namespace

json lowalt_suite(const BenchConfig& c, const Terrain& terrain) {
  const std::optional<Place> named = named_place(terrain.name);
  say(c, "lowalt " + terrain.name + ": building the 1024-cell window");
  app::render::SceneRenderer scene(named ? terrain_spec(terrain, named->lat, named->lon) : terrain_spec(terrain),
                                   plain_settings(c), bench_scene_options());
  const Place place = named ? *named : generic_place(scene);
  const int low_count = c.quick ? std::min<int>(c.views, 4) : std::min<int>(c.views, 20);
  const int high_count = c.quick ? 2 : 6;
  std::vector<View> views = low_views(place, std::max(1, low_count));
  for (const View& v : high_views(scene.terrain().bounds(), high_count)) views.push_back(v);
  ItemBuffer items(scene);
  mrbsp::Frame forced;

  // Per view and threshold: occlusion off, then on, one after the other.
  struct Side {
    std::vector<double> frame, traversal, draw, triangles;
  };
  struct Config {
    double t = 1.0;
    bool high = false;
    Side off, on;
    std::vector<double> ratio, identical, forced_identical, forced_triangles, pass_ms, probe_ms, ran, tested, culled_nodes, culled_triangles, extra_triangles;
    std::vector<double> hidden, hidden_share, hidden_culled_share, visible_culled, crack_pixel_share, crack_triangle_share;
  };
  std::vector<Config> configs;
  for (bool high : {false, true})
    for (double t : {1.0, 2.0}) {
      Config k;
      k.t = t;
      k.high = high;
      configs.push_back(std::move(k));
    }
  int slides_in_timing = 0;

  for (std::size_t v = 0; v < views.size(); ++v) {
    const app::scene::CameraPose& pose = views[v].pose;
    for (Config& k : configs) {
      if (k.high != views[v].overview) continue;
      double ran = 0;  // timed frames in which the pass ran (occlusion_adaptive may leave it out)
      const auto time = [&](bool occlusion, Side& side) {
        mrbsp::TraversalOptions o = lod(mrbsp::LodMetric::kError, k.t);
        o.occlusion = occlusion;
        scene.render(pose, true, 45.0, o);  // warm-up (and the view's slide, if any)
        if (occlusion && scene.last_frame().occlusion.ran) k.probe_ms.push_back(scene.last_frame().occlusion.pass_ms);
        const int slides = scene.slides();
        std::vector<double> fr, tr, dr;
        app::render::FrameStats s;
        for (int r = 0; r < c.repeats; ++r) {
          s = scene.render(pose, true, 45.0, o);
          fr.push_back(frame_ms(s));
          tr.push_back(s.traversal_ms);
          dr.push_back(s.draw_ms);
          if (occlusion) ran += scene.last_frame().occlusion.ran ? 1 : 0;
        }
        slides_in_timing += scene.slides() - slides;
        side.frame.push_back(median(fr));
        side.traversal.push_back(median(tr));
        side.draw.push_back(median(dr));
        side.triangles.push_back(static_cast<double>(s.triangles));
        return scene.rgb();
      };
      const std::vector<std::uint8_t> image_off = time(false, k.off);
      const mrbsp::Frame off = [&] {
        mrbsp::Frame f;
        f.indices = scene.last_frame().indices;
        f.level = scene.last_frame().level;
        return f;
      }();
      const std::vector<std::uint8_t> image_on = time(true, k.on);
      const mrbsp::Frame& on = scene.last_frame();
      k.ratio.push_back(k.off.frame.back() / k.on.frame.back());
      k.identical.push_back(image_on == image_off ? 1.0 : 0.0);
      k.pass_ms.push_back(on.occlusion.pass_ms);
      k.ran.push_back(ran / c.repeats);
      k.tested.push_back(static_cast<double>(on.occlusion.tested_nodes));
      k.culled_nodes.push_back(static_cast<double>(on.occlusion.culled_nodes));

      // What the pass culls when it runs: the same view traversed again with the pass in every
      // traversal (occlusion_adaptive off), drawn and compared too.
      mrbsp::TraversalOptions forced_options = lod(mrbsp::LodMetric::kError, k.t);
      forced_options.occlusion = true;
      forced_options.occlusion_adaptive = false;
      scene.terrain().tree().traverse(scene.camera(), forced_options, forced);
      scene.renderer().set_frame(forced);
      scene.renderer().render();
      k.forced_identical.push_back(scene.renderer().rgb() == image_off ? 1.0 : 0.0);
      k.forced_triangles.push_back(static_cast<double>(forced.indices.size() / 3));
      // Hidden: the off frame's triangles that show in no pixel of its item buffer. Culled: the
      // off frame's triangles the forced pass leaves out.
      const auto on_set = triangle_set(forced);
      const auto off_set = triangle_set(off);
      double extra = 0;
      for (const TriangleKey& t : on_set) extra += off_set.count(t) ? 0 : 1;
      const std::vector<std::uint32_t> pixels = items.pixels_per_triangle(scene, off);
      double hidden = 0, hidden_culled = 0, visible_culled = 0, culled = 0, crack_px = 0, terrain_px = 0, cracks = 0, terrain_tris = 0;
      for (std::size_t t = 0; t < pixels.size(); ++t) {
        const bool kept = on_set.count({off.indices[3 * t], off.indices[3 * t + 1], off.indices[3 * t + 2]}) > 0;
        culled += kept ? 0 : 1;
        if (pixels[t] == 0) {
          ++hidden;
          hidden_culled += kept ? 0 : 1;
        } else if (!kept) {
          ++visible_culled;
        }
        if (off.level[t] == mrbsp::kMergedLevel) continue;
        ++terrain_tris;
        terrain_px += pixels[t];
        if (off.level[t] == mrbsp::kCrackLevel) {
          crack_px += pixels[t];
          ++cracks;
        }
      }
      k.culled_triangles.push_back(culled);
      k.extra_triangles.push_back(extra);
      k.hidden.push_back(hidden);
      k.hidden_share.push_back(share(hidden, static_cast<double>(pixels.size())));
      k.hidden_culled_share.push_back(share(hidden_culled, hidden));
      k.visible_culled.push_back(visible_culled);
      k.crack_pixel_share.push_back(share(crack_px, terrain_px));
      k.crack_triangle_share.push_back(share(cracks, terrain_tris));
    }
    const Config& k = configs[views[v].overview ? 2 : 0];
    char b[220];
    std::snprintf(b, sizeof b, "lowalt %s: view %zu/%zu (%s)  1 px off %.1f ms, on %.1f ms, hidden culled %.0f%%",
                  terrain.name.c_str(), v + 1, views.size(), views[v].overview ? "high" : "low", k.off.frame.back(),
                  k.on.frame.back(), 100.0 * k.hidden_culled_share.back());
    say(c, b);
  }

  json out;
  out["terrain"] = terrain.name;
  out["places"] = named ? "named" : "lowest points of the window";
  out["low_views"] = low_count;
  out["high_views"] = high_count;
  out["repeats"] = c.repeats;
  out["slides_while_timing"] = slides_in_timing;
  json list = json::array();
  for (const Config& k : configs) {
    json j;
    j["views"] = k.high ? "high" : "low";
    j["threshold_px"] = k.t;
    for (const auto& [name, side] : {std::pair{"off", &k.off}, std::pair{"on", &k.on}}) {
      j[name] = {{"frame_ms", to_json(summarize(side->frame))},
                 {"traversal_ms", to_json(summarize(side->traversal))},
                 {"draw_ms", to_json(summarize(side->draw))},
                 {"triangles", to_json(summarize(side->triangles))}};
    }
    j["off_over_on"] = to_json(summarize(k.ratio));
    j["off_over_on_of_medians"] = summarize(k.off.frame).median / summarize(k.on.frame).median;
    j["images_identical"] = std::accumulate(k.identical.begin(), k.identical.end(), 0.0) / static_cast<double>(k.identical.size());
    j["pass_ms"] = to_json(summarize(k.pass_ms));
    j["probe_pass_ms"] = to_json(summarize(k.probe_ms));
    j["pass_ran_share"] = std::accumulate(k.ran.begin(), k.ran.end(), 0.0) / static_cast<double>(k.ran.size());
    j["tested_nodes"] = to_json(summarize(k.tested));
    j["culled_nodes"] = to_json(summarize(k.culled_nodes));
    j["culled_triangles"] = to_json(summarize(k.culled_triangles));
    j["forced_pass"] = {{"triangles", to_json(summarize(k.forced_triangles))},
                        {"images_identical", std::accumulate(k.forced_identical.begin(), k.forced_identical.end(), 0.0) /
                                                 static_cast<double>(k.forced_identical.size())}};
    j["triangles_on_not_off"] = *std::max_element(k.extra_triangles.begin(), k.extra_triangles.end());
    j["hidden_triangles"] = to_json(summarize(k.hidden));
    j["hidden_share_of_drawn"] = to_json(summarize(k.hidden_share));
    j["hidden_culled_share"] = to_json(summarize(k.hidden_culled_share));
    j["visible_culled"] = *std::max_element(k.visible_culled.begin(), k.visible_culled.end());
    j["crack_pixel_share"] = to_json(summarize(k.crack_pixel_share));
    j["crack_triangle_share"] = to_json(summarize(k.crack_triangle_share));
    list.push_back(j);
  }
  out["occlusion"] = list;

  // The flight: per frame, the unculled draw (the reference image), then each coherence mode's
  // own traversal (its own Frame, so that it carries last frame's visibility) drawn by the
  // same renderer and compared with it.
  const std::vector<app::scene::CameraPose> flight = low_flight(place, c.flight_frames);
  say(c, "lowalt " + terrain.name + ": a " + std::to_string(flight.size()) + "-frame low flight");
  struct Mode {
    const char* name;
    mrbsp::Coherence coherence;
    mrbsp::Frame frame;
    std::vector<double> tested, full_tests, skipped, pass_ms, triangles;
    std::size_t identical = 0;
  };
  Mode modes[] = {{"every_node", mrbsp::Coherence::kOff, {}, {}, {}, {}, {}, {}, 0},
                  {"update", mrbsp::Coherence::kUpdate, {}, {}, {}, {}, {}, {}, 0},
                  {"conservative", mrbsp::Coherence::kConservative, {}, {}, {}, {}, {}, {}, 0}};
  std::vector<double> flight_off_ms;
  const mrbsp::TraversalOptions one = lod(mrbsp::LodMetric::kError, 1.0);
  for (std::size_t fno = 0; fno < flight.size(); ++fno) {
    const app::render::FrameStats s = scene.render(flight[fno], true, 45.0, one);
    flight_off_ms.push_back(frame_ms(s));
    const std::vector<std::uint8_t> reference = scene.rgb();
    for (Mode& m : modes) {
      mrbsp::TraversalOptions o = one;
      o.occlusion = true;
      o.coherence = m.coherence;
      o.p_skip = 0.5;
      o.occlusion_adaptive = false;  // every frame's pass, so that the modes compare
      scene.terrain().tree().traverse(scene.camera(), o, m.frame);
      scene.sync_vertices(scene.renderer());
      scene.renderer().set_frame(m.frame);
      scene.renderer().render();
      m.identical += scene.renderer().rgb() == reference ? 1 : 0;
      m.tested.push_back(static_cast<double>(m.frame.occlusion.tested_nodes + m.frame.occlusion.sampled_visible));
      m.full_tests.push_back(static_cast<double>(m.frame.occlusion.tested_nodes));
      m.skipped.push_back(static_cast<double>(m.frame.occlusion.skipped_tests));
      m.pass_ms.push_back(m.frame.occlusion.pass_ms);
      m.triangles.push_back(static_cast<double>(m.frame.indices.size() / 3));
    }
    if ((fno + 1) % 100 == 0 || fno + 1 == flight.size()) {
      say(c, "lowalt " + terrain.name + ": flight frame " + std::to_string(fno + 1) + "/" + std::to_string(flight.size()));
    }
  }
  const double every = std::accumulate(modes[0].tested.begin(), modes[0].tested.end(), 0.0);
  json fl;
  fl["frames"] = flight.size();
  fl["from"] = {place.flight_from.lat, place.flight_from.lon};
  fl["to"] = {place.flight_to.lat, place.flight_to.lon};
  fl["off_frame_ms"] = to_json(summarize(flight_off_ms));
  for (const Mode& m : modes) {
    const double tested = std::accumulate(m.tested.begin(), m.tested.end(), 0.0);  // full tests and samples
    fl[m.name] = {{"visibility_queries", to_json(summarize(m.tested))},
                  {"full_tests", to_json(summarize(m.full_tests))},
                  {"skipped_tests", to_json(summarize(m.skipped))},
                  {"tests_over_every_node", share(tested, every)},
                  {"pass_ms", to_json(summarize(m.pass_ms))},
                  {"triangles", to_json(summarize(m.triangles))},
                  {"images_identical", share(static_cast<double>(m.identical), static_cast<double>(flight.size()))}};
  }
  fl["p_skip"] = 0.5;
  out["flight"] = fl;
  return out;
}

}  // namespace terravol::bench
