// The coverage-mask tiler (tiler/renderer.h) against references written from its contract:
// per-sample brute force for coverage (tests/coverage/brute_force.h: each sample centre against
// each edge of the snapped projected polygon), per-sample compositing for translucency, and the
// sample accounting over real front-to-back traversals of random terrain.
#include "tiler/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "coverage/brute_force.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::tiler {
namespace {

using coverage::test::Bitmap;
using coverage::test::claimed_ref;

// Settings of a w x h renderer at aa (bands of band_rows, the texture shaded at texel_rate).
Settings sized(int w, int h, int aa = 8, int band_rows = 64, double texel_rate = 1.0) {
  Settings s;
  s.width = w;
  s.height = h;
  s.aa = aa;
  s.band_rows = band_rows;
  s.texel_rate = texel_rate;
  return s;
}

// A camera at the origin looking along +y, z up.
mrbsp::Camera front_camera(int w, int h, double fov = 50.0, double near_plane = 0.5) {
  mrbsp::Camera c;
  c.eye = glm::dvec3(0.0);
  c.forward = glm::dvec3(0, 1, 0);
  c.up = glm::dvec3(0, 0, 1);
  c.fov_y_deg = fov;
  c.width = w;
  c.height = h;
  c.near_plane = near_plane;
  return c;
}

// Window coordinates (pixels from the bottom-left) of a point for that camera, as GL maps it.
glm::dvec2 window_of(const mrbsp::Camera& c, const glm::dvec3& p) {
  const double focal = c.height * 0.5 / std::tan(c.fov_y_deg * 0.5 * M_PI / 180.0);
  return {c.width * 0.5 + focal * p.x / p.y, c.height * 0.5 + focal * p.z / p.y};
}

// Merged polygons only (no lattice): vertices and their colours.
struct Scene {
  std::vector<glm::vec3> positions;
  std::vector<glm::u8vec4> colors;
  std::vector<std::uint32_t> indices;
  SceneColors view() const {
    SceneColors s;
    s.positions = positions;
    s.lattice_side = 0;
    s.merged_base = 0;
    s.merged_colors = colors;
    return s;
  }
  void triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, glm::u8vec4 color) {
    for (const glm::dvec3& p : {a, b, c}) {
      indices.push_back(static_cast<std::uint32_t>(positions.size()));
      positions.emplace_back(p);
      colors.push_back(color);
    }
  }
};

Look black_sky() {
  Look l;
  l.sky_bottom = l.sky_top = glm::dvec3(0.0);
  return l;
}

// Per pixel, how many of its aa x aa samples the projected triangle covers (brute force on the
// sample lattice, pixel rows from the bottom).
std::vector<int> brute_counts(const mrbsp::Camera& cam, int aa, const std::vector<glm::dvec3>& tri) {
  std::vector<glm::dvec2> poly;
  for (const glm::dvec3& p : tri) poly.push_back(window_of(cam, p) * static_cast<double>(aa));
  const Bitmap bits = claimed_ref(poly, 0.0, cam.width * aa, cam.height * aa);
  std::vector<int> counts(static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height), 0);
  for (int y = 0; y < bits.h; ++y)
    for (int x = 0; x < bits.w; ++x)
      if (bits.at(x, y)) ++counts[static_cast<std::size_t>(y / aa) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(x / aa)];
  return counts;
}

std::uint8_t at(const std::vector<std::uint8_t>& rgb, int w, int h, int x, int y_from_bottom, int k) {
  return rgb[3 * (static_cast<std::size_t>(h - 1 - y_from_bottom) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) + static_cast<std::size_t>(k)];
}

TEST(TilerRenderer, RejectsBadSettings) {
  Settings s;
  s.aa = 3;
  EXPECT_THROW(Renderer{s}, std::invalid_argument);
  s.aa = 8;
  s.width = 2049;  // 2049 x 8 samples is beyond the pyramid's 16384
  EXPECT_THROW(Renderer{s}, std::invalid_argument);
  s.width = 100;
  s.texel_rate = -1;
  EXPECT_THROW(Renderer{s}, std::invalid_argument);
  s.texel_rate = 1;
  s.band_rows = 0;
  EXPECT_THROW(Renderer{s}, std::invalid_argument);
}

TEST(TilerRenderer, RejectsIndicesBeyondThePositionsAndAMismatchedCamera) {
  Renderer r(sized(40, 30));
  Scene sc;
  sc.triangle({-1, 5, -1}, {1, 5, -1}, {0, 5, 1}, {255, 255, 255, 255});
  std::vector<std::uint32_t> bad{0, 1, 3};
  EXPECT_THROW(r.render(sc.view(), black_sky(), front_camera(40, 30), 100.0, bad), std::invalid_argument);
  EXPECT_THROW(r.render(sc.view(), black_sky(), front_camera(41, 30), 100.0, sc.indices), std::invalid_argument);
  EXPECT_NO_THROW(r.render(sc.view(), black_sky(), front_camera(40, 30), 100.0, sc.indices));
}

// Exact coverage of small cases: each random white triangle on black, at every aa and with
// bands a few rows high (triangles cross them), gives every pixel 255 times the share of its
// samples the brute force finds inside the snapped projection.
TEST(TilerRenderer, SingleTrianglesCoverExactlyTheBruteForceSamples) {
  std::mt19937 rng(1996);
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(3.0, 12.0);
  for (int aa : {1, 2, 4, 8}) {
    for (int trial = 0; trial < 12; ++trial) {
      const int w = 37 + trial, h = 29;
      Renderer r(sized(w, h, aa, 1 + trial % 7));
      const mrbsp::Camera cam = front_camera(w, h);
      std::vector<glm::dvec3> tri;
      for (int i = 0; i < 3; ++i) {
        const double d = depth(rng);
        tri.emplace_back(u(rng) * d * 0.5, d, u(rng) * d * 0.4);
      }
      Scene sc;
      sc.triangle(tri[0], tri[1], tri[2], {255, 255, 255, 255});
      // The brute force takes the float positions the renderer sees.
      std::vector<glm::dvec3> seen;
      for (const glm::vec3& p : sc.positions) seen.emplace_back(p);
      r.render(sc.view(), black_sky(), cam, 100.0, sc.indices);
      const std::vector<int> want = brute_counts(cam, aa, seen);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const int n = want[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
          // Within 1 level of the brute force's share (the colour is interpolated in float):
          // one sample is worth 255 / 64 = 4 levels or more.
          ASSERT_NEAR(at(r.rgb(), w, h, x, y, 0), 255.0 * n / (aa * aa), 1.0) << "aa " << aa << " trial " << trial << " pixel " << x << ", " << y;
        }
      }
    }
  }
}

// A terrain window of n x n cells with random heights, its tree, and colours for it.
struct Terrain {
  int n;
  std::vector<double> xs, ys;
  std::vector<float> z;
  std::vector<std::uint8_t> texture;  // RGBA
  std::unique_ptr<mrbsp::TerrainTree> tree;
  Terrain(int cells, std::mt19937& rng) : n(cells) {
    std::uniform_real_distribution<float> hgt(0.0f, 400.0f);
    std::uniform_int_distribution<int> c(0, 255);
    for (int i = 0; i <= n; ++i) {
      xs.push_back(100.0 * i);
      ys.push_back(100.0 * i);
    }
    for (int k = 0; k < (n + 1) * (n + 1); ++k) {
      z.push_back(hgt(rng));
      for (int k2 = 0; k2 < 3; ++k2) texture.push_back(static_cast<std::uint8_t>(c(rng)));
      texture.push_back(255);
    }
    tree = std::make_unique<mrbsp::TerrainTree>(mrbsp::TerrainWindow{n, xs, ys, z}, 4);
  }
  SceneColors colors() const {
    SceneColors s;
    s.positions = tree->positions();
    s.lattice_side = n + 1;
    s.texture = texture;
    s.merged_base = tree->merged_base();
    s.merged_colors = tree->merged_colors();
    return s;
  }
};

mrbsp::Camera random_camera(std::mt19937& rng, int w, int h, double size) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  mrbsp::Camera c;
  // Above the window or beyond its sides (walls), looking at a point of it.
  c.eye = glm::dvec3((u(rng) * 1.6 - 0.3) * size, (u(rng) * 1.6 - 0.3) * size, 500.0 + u(rng) * 1500.0);
  const glm::dvec3 target(u(rng) * size, u(rng) * size, 200.0);
  c.forward = glm::normalize(target - c.eye);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  c.fov_y_deg = 30.0 + u(rng) * 40.0;
  c.width = w;
  c.height = h;
  c.near_plane = 1.0;
  return c;
}

// No sample shaded twice in opaque scenes: over real front-to-back traversals of random terrain
// (terrain, crack fills, walls, and opaque merged polygons through the terrain), every pixel's
// aa^2 samples are each shaded once, by a triangle or by the sky, and the counters add up.
TEST(TilerRenderer, OpaqueTraversalsShadeEverySampleExactlyOnce) {
  std::mt19937 rng(14);
  Terrain t(32, rng);
  // Opaque merged triangles crossing the terrain (pieces above it are kept, below dropped).
  std::vector<glm::dvec3> verts;
  std::vector<glm::u8vec4> cols;
  std::vector<std::uint32_t> tris;
  std::uniform_real_distribution<double> u(0.0, 3200.0), zz(0.0, 700.0);
  for (int k = 0; k < 20; ++k) {
    for (int i = 0; i < 3; ++i) {
      tris.push_back(static_cast<std::uint32_t>(verts.size()));
      verts.emplace_back(u(rng), u(rng), zz(rng));
      cols.emplace_back(200, 40, 40, 255);
    }
  }
  t.tree->merge(verts, cols, tris);
  for (int aa : {8, 4, 1}) {
    const Settings s = sized(160, 90, aa, 7, aa == 4 ? 0.0 : 1.0);
    Renderer r(s);
    for (int view = 0; view < 6; ++view) {
      const mrbsp::Camera cam = random_camera(rng, s.width, s.height, 3200.0);
      mrbsp::TraversalOptions o;
      o.front_to_back = true;
      mrbsp::Frame f;
      t.tree->traverse(cam, o, f);
      ASSERT_GT(f.indices.size(), 0u);
      const Stats st = r.render(t.colors(), black_sky(), cam, 20000.0, f.indices);
      EXPECT_EQ(st.translucent, 0u);
      const auto total = static_cast<std::uint64_t>(s.width) * static_cast<std::uint64_t>(s.height) * static_cast<std::uint64_t>(aa * aa);
      EXPECT_EQ(st.samples_covered + st.samples_background, total) << "aa " << aa << " view " << view;
      EXPECT_GT(st.samples_covered, total / 10);
      for (std::size_t p = 0; p < r.sample_counts().size(); ++p) {
        ASSERT_EQ(r.sample_counts()[p], aa * aa) << "aa " << aa << " view " << view << " pixel " << p;
      }
    }
  }
}

// Translucent layers in front of an opaque one, given nearest first, composite as the "under"
// operator says: C = sum_k c_k a_k prod_{j<k} (1 - a_j) + (prod (1 - a_k)) c_opaque.
TEST(TilerRenderer, TranslucentLayersCompositeUnderInTheGivenOrder) {
  Renderer r(sized(24, 16));
  Scene sc;
  const auto quad = [&](double d, glm::u8vec4 c) {
    sc.triangle({-50, d, -50}, {50, d, -50}, {50, d, 50}, c);
    sc.triangle({-50, d, -50}, {50, d, 50}, {-50, d, 50}, c);
  };
  const std::vector<glm::u8vec4> layers{{250, 20, 20, 90}, {20, 240, 30, 128}, {40, 60, 250, 200}};
  for (std::size_t k = 0; k < layers.size(); ++k) quad(2.0 + static_cast<double>(k), layers[k]);
  quad(10.0, {100, 100, 100, 255});
  Look look = black_sky();
  const Stats st = r.render(sc.view(), look, front_camera(24, 16), 100.0, sc.indices);
  EXPECT_EQ(st.translucent, 6u);
  double t = 1.0;
  glm::dvec3 want(0.0);
  for (const glm::u8vec4& c : layers) {
    const double a = c.a / 255.0;
    want += t * a * glm::dvec3(c.r, c.g, c.b);
    t *= 1.0 - a;
  }
  want += t * glm::dvec3(100.0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 24; ++x)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(at(r.rgb(), 24, 16, x, y, k), want[k], 0.51) << x << ", " << y;
}

// Translucent triangles whose edges cross pixels: per sample, the layers in front of it
// composite under each other and over the opaque background; the pixel is the mean of its
// samples. The reference composites each sample from the brute-force coverage of each layer.
TEST(TilerRenderer, TranslucentEdgesCompositeSampleBySample) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> c(0, 255), alpha(40, 220);
  for (int aa : {8, 2}) {
    for (int trial = 0; trial < 6; ++trial) {
      const int w = 31, h = 23;
      Renderer r(sized(w, h, aa, 5));
      const mrbsp::Camera cam = front_camera(w, h);
      Scene sc;
      std::vector<std::vector<glm::dvec3>> tris;
      for (int k = 0; k < 5; ++k) {
        const double d = 3.0 + k;  // nearest first
        std::vector<glm::dvec3> t3;
        for (int i = 0; i < 3; ++i) t3.emplace_back(u(rng) * d * 0.5, d, u(rng) * d * 0.4);
        const bool opaque = k == 4;
        sc.triangle(t3[0], t3[1], t3[2], {c(rng), c(rng), c(rng), opaque ? 255 : alpha(rng)});
        tris.emplace_back();
        for (std::size_t i = sc.positions.size() - 3; i < sc.positions.size(); ++i) tris.back().emplace_back(sc.positions[i]);
      }
      Look look;
      look.sky_bottom = look.sky_top = glm::dvec3(30, 60, 90);
      r.render(sc.view(), look, cam, 100.0, sc.indices);
      // Reference: per sample, front to back.
      std::vector<Bitmap> cover;
      for (const auto& t3 : tris) {
        std::vector<glm::dvec2> poly;
        for (const glm::dvec3& p : t3) poly.push_back(window_of(cam, p) * static_cast<double>(aa));
        cover.push_back(claimed_ref(poly, 0.0, w * aa, h * aa));
      }
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          glm::dvec3 sum(0.0);
          for (int sy = 0; sy < aa; ++sy) {
            for (int sx = 0; sx < aa; ++sx) {
              double t = 1.0;
              glm::dvec3 col(0.0);
              bool done = false;
              for (std::size_t k = 0; k < tris.size() && !done; ++k) {
                if (!cover[k].at(x * aa + sx, y * aa + sy)) continue;
                const glm::u8vec4 vc = sc.colors[3 * k];
                const double a = vc.a / 255.0;
                col += t * a * glm::dvec3(vc.r, vc.g, vc.b);
                t *= 1.0 - a;
                done = vc.a == 255;
              }
              if (!done) col += t * glm::dvec3(30, 60, 90);
              sum += col;
            }
          }
          sum /= static_cast<double>(aa * aa);
          for (int k = 0; k < 3; ++k) {
            ASSERT_NEAR(at(r.rgb(), w, h, x, y, k), sum[k], 0.51) << "aa " << aa << " trial " << trial << " pixel " << x << ", " << y;
          }
        }
      }
    }
  }
}

// The sky is VTK's linear gradient: at a pixel, bottom + (top - bottom) times the height of its
// centre over the image's.
TEST(TilerRenderer, EmptyViewIsTheLinearSkyGradient) {
  Renderer r(sized(8, 50, 4));
  Look look;
  look.sky_bottom = glm::dvec3(200, 10, 0);
  look.sky_top = glm::dvec3(0, 110, 250);
  Scene sc;
  const Stats st = r.render(sc.view(), look, front_camera(8, 50), 100.0, sc.indices);
  EXPECT_EQ(st.samples_background, 8u * 50u * 16u);
  for (int y = 0; y < 50; ++y) {
    const double f = (y + 0.5) / 50.0;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(at(r.rgb(), 8, 50, 3, y, k), look.sky_bottom[k] + (look.sky_top[k] - look.sky_bottom[k]) * f, 0.51) << y;
    }
  }
}

// Textured triangles take the texture bilinearly between texel centres (a vertex's texel centre
// is its lattice sample), and haze mixes toward its colour by the interpolated per-vertex
// amount; shading every sample and shading a magnified fragment once agree.
TEST(TilerRenderer, TextureIsBilinearBetweenTexelCentresAndHazeMixesIn) {
  // A 2 x 2 lattice standing upright 10 m in front of the camera, filling the view.
  std::vector<glm::vec3> pos{{-40, 10, -40}, {40, 10, -40}, {-40, 10, 40}, {40, 10, 40}};
  const std::vector<std::array<int, 3>> tex{{200, 0, 0}, {0, 200, 0}, {0, 0, 200}, {200, 200, 200}};
  std::vector<std::uint8_t> rgba;
  for (const auto& c : tex) rgba.insert(rgba.end(), {static_cast<std::uint8_t>(c[0]), static_cast<std::uint8_t>(c[1]), static_cast<std::uint8_t>(c[2]), 255});
  std::vector<std::uint32_t> idx{0, 1, 3, 0, 3, 2};
  SceneColors sc;
  sc.positions = pos;
  sc.lattice_side = 2;
  sc.texture = rgba;
  sc.merged_base = 4;
  for (double rate : {1.0, 0.0}) {
    Renderer r(sized(64, 64, 4, 64, rate));
    const mrbsp::Camera cam = front_camera(64, 64, 90.0);  // the view spans x, z in [-10, 10] at y = 10
    Look look = black_sky();
    r.render(sc, look, cam, 100.0, idx);
    // Pixel (x, y) centre maps to texel coordinates ((X + 40) / 80, (Z + 40) / 80) with
    // X = (x + 0.5 - 32) / 32 * 10 and likewise Z.
    for (int y = 0; y < 64; y += 7) {
      for (int x = 0; x < 64; x += 5) {
        const double X = (x + 0.5 - 32) / 32 * 10, Z = (y + 0.5 - 32) / 32 * 10;
        const double fu = (X + 40) / 80, fv = (Z + 40) / 80;
        for (int k = 0; k < 3; ++k) {
          const double b = tex[0][k] + (tex[1][k] - tex[0][k]) * fu, t = tex[2][k] + (tex[3][k] - tex[2][k]) * fu;
          ASSERT_NEAR(at(r.rgb(), 64, 64, x, y, k), b + (t - b) * fv, 0.51) << x << ", " << y << " rate " << rate;
        }
      }
    }
    // Haze: every vertex at depth 10 m, distance 10 m: 0.85 (1 - 1/e) of the way to the haze.
    look.haze_distance = 10.0;
    look.haze_color = glm::dvec3(255, 255, 255);
    r.render(sc, look, cam, 100.0, idx);
    const double h = 0.85 * (1.0 - std::exp(-1.0));
    const double centre = (200.0 + 0.0 + 0.0 + 200.0) / 4;  // red at the middle of the lattice
    EXPECT_NEAR(at(r.rgb(), 64, 64, 31, 31, 0), centre + (255 - centre) * h, 2.0);
  }
}

// A triangle reaching behind the eye is clipped at the near plane: it covers what lies beyond
// the plane and nothing else, as a ray cast finds (up to samples next to its edges).
TEST(TilerRenderer, TriangleThroughTheNearPlaneIsClippedThere) {
  const int w = 64, h = 48, aa = 4;
  Renderer r(sized(w, h, aa));
  const mrbsp::Camera cam = front_camera(w, h, 60.0, 2.0);
  Scene sc;
  sc.triangle({-3, -5, -1}, {4, 20, -2}, {-2, 15, 3}, {255, 255, 255, 255});
  const Stats st = r.render(sc.view(), black_sky(), cam, 100.0, sc.indices);
  EXPECT_EQ(st.clipped, 1u);
  const glm::dvec3 a(sc.positions[0]), b(sc.positions[1]), c(sc.positions[2]);
  const double focal = h * 0.5 / std::tan(30.0 * M_PI / 180.0);
  std::uint64_t want = 0;
  for (int y = 0; y < h * aa; ++y) {
    for (int x = 0; x < w * aa; ++x) {
      const glm::dvec3 d(((x + 0.5) / aa - w * 0.5) / focal, 1.0, ((y + 0.5) / aa - h * 0.5) / focal);
      // Ray-plane, then inside the triangle, then beyond the near plane (depth along y).
      const glm::dvec3 nrm = glm::cross(b - a, c - a);
      const double t = glm::dot(nrm, a) / glm::dot(nrm, d);
      const glm::dvec3 p = t * d;
      const bool in = glm::dot(glm::cross(b - a, p - a), nrm) >= 0 && glm::dot(glm::cross(c - b, p - b), nrm) >= 0 &&
                      glm::dot(glm::cross(a - c, p - c), nrm) >= 0;
      if (in && t >= 2.0) ++want;
    }
  }
  ASSERT_GT(want, 1000u);
  EXPECT_NEAR(static_cast<double>(st.samples_covered), static_cast<double>(want), want * 0.01);
}

}  // namespace
}  // namespace terravol::tiler
