// terravol_coverage_bench: the cost of the coverage pyramid (coverage/pyramid.h, Greene 1996)
// at 1280x720, medians over repetitions. Not a test: it reports figures, it does not pass or
// fail.
//  - random triangles of 1, 10, 100 and 10^4 px: ns per cover() into a mostly vacant pyramid,
//    ns per hidden() against a vacant, a full and a half-covered pyramid;
//  - a terrain-like mesh (a height field of n x n cells, two triangles each, seen in perspective
//    from a low and a high eye): the occlusion pass of issue 12 (a quadtree of node boxes walked
//    front to back, each box tested with hidden() on its projected corners, the triangles of
//    visible leaves tiled with cover()), against tiling every triangle; ms per frame and pyramid
//    cells visited per pixel (Greene, section 9, reports about 1.1 for his antialiased tiler).
//
// Usage: terravol_coverage_bench [--repeat N] [--grid CELLS] [--margin PX] [--dilation PX]
//                                [--min-area PX2]
// --min-area leaves triangles of a smaller projected area untiled (in the terrain frames):
// coverage only ever under-claims then, so culling stays conservative, and the figures show
// what that trades.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

#include "coverage/pyramid.h"
#include "coverage/silhouette.h"

namespace {

using terravol::coverage::Pyramid;
// Thread CPU time: the machine is shared, and time spent descheduled is not the pyramid's.
struct Clock {
  using time_point = double;  // ns
  static double now() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e9 + static_cast<double>(t.tv_nsec);
  }
};
using Tri = std::array<glm::dvec2, 3>;
constexpr int kW = 1280, kH = 720;

double ns_since(Clock::time_point t) { return Clock::now() - t; }
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Random triangles of the given area (px^2), random shape (angles >= 20 degrees) and rotation,
// centred in the viewport.
std::vector<Tri> random_triangles(std::mt19937& rng, double area, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Tri> out;
  while (static_cast<int>(out.size()) < n) {
    const double a = 2 * std::numbers::pi * u(rng);
    Tri t;
    for (int i = 0; i < 3; ++i) {
      const double ang = a + 2 * std::numbers::pi * i / 3 + 0.6 * (u(rng) - 0.5);
      t[static_cast<std::size_t>(i)] = {std::cos(ang), std::sin(ang)};
    }
    const double cur = 0.5 * std::abs((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x));
    const double s = std::sqrt(area / cur);
    const double r = s * 1.2;
    const glm::dvec2 c(r + u(rng) * (kW - 2 * r), r + u(rng) * (kH - 2 * r));
    for (glm::dvec2& v : t) v = c + s * v;
    out.push_back(t);
  }
  return out;
}

struct Random {
  double cover_ns, hidden_vacant_ns, hidden_full_ns, hidden_half_ns, cells_per_cover;
};

Random bench_random(double area, int repeat, double margin, double dilation) {
  std::mt19937 rng(static_cast<unsigned>(area * 7 + 1));
  // Batches that keep the pyramid mostly vacant (a third of the viewport at most).
  const int batch = std::clamp(static_cast<int>(0.3 * kW * kH / area), 8, 20000);
  const std::vector<Tri> tris = random_triangles(rng, area, batch);
  Pyramid p(kW, kH);
  std::vector<double> cover, hv, hf, hh;
  double cells = 0;
  for (int r = 0; r < repeat; ++r) {
    p.clear();
    auto t = Clock::now();
    for (const Tri& tri : tris) p.cover(tri, margin);
    cover.push_back(ns_since(t) / batch);
    cells = static_cast<double>(p.stats().cells_visited) / batch;
    p.clear();
    int sink = 0;
    t = Clock::now();
    for (const Tri& tri : tris) sink += p.hidden(tri, dilation);
    hv.push_back(ns_since(t) / batch);
    p.cover(std::array{glm::dvec2(-10, -10), glm::dvec2(3000, -10), glm::dvec2(-10, 3000)}, 0.0);
    t = Clock::now();
    for (const Tri& tri : tris) sink += p.hidden(tri, dilation);
    hf.push_back(ns_since(t) / batch);
    // Half covered: the left half, with its edge a diagonal (a third of the triangles straddle
    // it and are visible, the rest answer on their own side).
    p.clear();
    p.cover(std::array{glm::dvec2(-10, -10), glm::dvec2(kW * 0.6, -10), glm::dvec2(kW * 0.4, kH + 10), glm::dvec2(-10, kH + 10)}, 0.0);
    t = Clock::now();
    for (const Tri& tri : tris) sink += p.hidden(tri, dilation);
    hh.push_back(ns_since(t) / batch);
    if (sink < 0) std::puts("");
  }
  return {median(cover), median(hv), median(hf), median(hh), cells};
}

// A height field of n x n cells, 2 triangles each: ridges across the view.
struct Terrain {
  int n;
  double cell = 30.0;  // m
  std::vector<double> z;
  double at(int i, int j) const { return z[static_cast<std::size_t>(j) * static_cast<std::size_t>(n + 1) + static_cast<std::size_t>(i)]; }
  glm::dvec3 p(int i, int j) const { return {i * cell, j * cell, at(i, j)}; }
};

Terrain make_terrain(int n) {
  Terrain t{n, 30.0, {}};
  const double size = n * t.cell;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = i * t.cell / size, y = j * t.cell / size;
      t.z.push_back(300 * std::sin(6.0 * y + 2 * std::sin(3 * x)) * std::sin(1.5 + 4 * x) + 120 * std::sin(23 * x + 17 * y) +
                    40 * std::sin(61 * x - 47 * y));
    }
  }
  return t;
}

struct View {
  glm::dmat4 clip;
  glm::dvec3 eye;
  const char* name;
};

// A quadtree over the cells, with each view's projections and front-to-back orders computed
// beforehand, so that a frame times the pyramid and the walk alone.
struct Node {
  int i0, j0, size;                  // cells
  double zmin, zmax;
  std::array<int, 4> kids{-1, -1, -1, -1};
};

struct Frame {
  double ms = 0;
  std::size_t tiled = 0, tested = 0, culled = 0, culled_triangles = 0;
  double cells_per_pixel = 0, hidden_cells_per_pixel = 0, covered_fraction = 0;
};

class TerrainBench {
 public:
  TerrainBench(const Terrain& t, int leaf) : t_(t), leaf_(leaf) { build(0, 0, t.n); }

  std::size_t triangles() const { return 2 * static_cast<std::size_t>(t_.n) * static_cast<std::size_t>(t_.n); }

  // Projects every triangle and node box, and orders children and leaf cells nearest first.
  // Triangles with a vertex behind the near plane, and node boxes reaching it, are skipped (the
  // bench does not clip) and counted.
  void prepare(const View& v, double min_area) {
    tris_.clear();
    ok_.clear();
    for (int j = 0; j < t_.n; ++j) {
      for (int i = 0; i < t_.n; ++i) {
        const glm::dvec3 a = t_.p(i, j), b = t_.p(i + 1, j), c = t_.p(i + 1, j + 1), d = t_.p(i, j + 1);
        for (const auto& tri : {std::array{a, b, c}, std::array{a, c, d}}) {
          std::array<glm::dvec4, 3> clip;
          for (int q = 0; q < 3; ++q) clip[static_cast<std::size_t>(q)] = v.clip * glm::dvec4(tri[static_cast<std::size_t>(q)], 1.0);
          Tri w{};
          bool in_front = true;
          for (const glm::dvec4& h : clip) in_front = in_front && h.w >= 1.0;
          ok_.push_back(in_front && terravol::coverage::project_to_window(clip, kW, kH, w));
          tris_.push_back(w);
        }
      }
    }
    plan_.assign(nodes_.size(), {});
    for (std::size_t k = 0; k < nodes_.size(); ++k) {
      Node& n = nodes_[k];
      Plan& pl = plan_[k];
      std::array<glm::dvec4, 8> clip;
      for (int q = 0; q < 8; ++q) {
        const glm::dvec3 c((n.i0 + (q & 1 ? n.size : 0)) * t_.cell, (n.j0 + (q & 2 ? n.size : 0)) * t_.cell, q & 4 ? n.zmax : n.zmin);
        clip[static_cast<std::size_t>(q)] = v.clip * glm::dvec4(c, 1.0);
      }
      pl.projected = terravol::coverage::project_to_window(clip, kW, kH, pl.corners);
      const auto dist = [&](const Node& q) {
        const glm::dvec2 c((q.i0 + 0.5 * q.size) * t_.cell, (q.j0 + 0.5 * q.size) * t_.cell);
        return glm::length(c - glm::dvec2(v.eye));
      };
      if (n.kids[0] >= 0) {
        pl.order = n.kids;
        std::sort(pl.order.begin(), pl.order.end(), [&](int x, int y) { return dist(nodes_[static_cast<std::size_t>(x)]) < dist(nodes_[static_cast<std::size_t>(y)]); });
      } else {
        std::vector<std::pair<double, int>> cells;
        for (int j = n.j0; j < n.j0 + n.size; ++j)
          for (int i = n.i0; i < n.i0 + n.size; ++i) {
            const glm::dvec3 c((i + 0.5) * t_.cell, (j + 0.5) * t_.cell, 0.5 * (t_.at(i, j) + t_.at(i + 1, j + 1)));
            cells.push_back({glm::length(c - v.eye), j * t_.n + i});
          }
        std::sort(cells.begin(), cells.end());
        // The leaf's triangles in draw order, stored together as a caller projecting them just
        // before tiling would have them (in cache).
        for (const auto& c : cells) {
          for (int q = 2 * c.second; q <= 2 * c.second + 1; ++q) {
            const Tri& w = tris_[static_cast<std::size_t>(q)];
            const double area = 0.5 * std::abs((w[1].x - w[0].x) * (w[2].y - w[0].y) - (w[1].y - w[0].y) * (w[2].x - w[0].x));
            if (ok_[static_cast<std::size_t>(q)] && area >= min_area) pl.tris.push_back(w);
          }
        }
      }
    }
  }

  std::size_t skipped() const { return static_cast<std::size_t>(std::count(ok_.begin(), ok_.end(), false)); }

  double median_triangle_area() const {
    std::vector<double> a;
    for (std::size_t k = 0; k < tris_.size(); ++k) {
      if (!ok_[k]) continue;
      const Tri& w = tris_[k];
      const glm::dvec2 c = (w[0] + w[1] + w[2]) / 3.0;
      if (c.x >= 0 && c.y >= 0 && c.x < kW && c.y < kH)
        a.push_back(0.5 * std::abs((w[1].x - w[0].x) * (w[2].y - w[0].y) - (w[1].y - w[0].y) * (w[2].x - w[0].x)));
    }
    return a.empty() ? 0 : median(a);
  }

  // Tiles every triangle front to back, or, with cull, tests node boxes first (Greene 1996,
  // section 5.2).
  Frame frame(Pyramid& p, bool cull, double margin, double dilation) {
    p.clear();
    Frame f;
    const auto t0 = Clock::now();
    walk(p, 0, cull, margin, dilation, f);
    f.ms = ns_since(t0) * 1e-6;
    f.cells_per_pixel = static_cast<double>(p.stats().cells_visited) / (kW * kH);
    f.hidden_cells_per_pixel = static_cast<double>(p.stats().hidden_cells_visited) / (kW * kH);
    f.covered_fraction = static_cast<double>(p.covered_count()) / (kW * kH);
    return f;
  }

 private:
  struct Plan {
    bool projected = false;
    std::array<glm::dvec2, 8> corners;
    std::array<int, 4> order{};
    std::vector<Tri> tris;
  };

  int build(int i0, int j0, int size) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.push_back({i0, j0, size, 1e300, -1e300});
    for (int j = j0; j <= j0 + size; ++j)
      for (int i = i0; i <= i0 + size; ++i) {
        nodes_[static_cast<std::size_t>(id)].zmin = std::min(nodes_[static_cast<std::size_t>(id)].zmin, t_.at(i, j));
        nodes_[static_cast<std::size_t>(id)].zmax = std::max(nodes_[static_cast<std::size_t>(id)].zmax, t_.at(i, j));
      }
    if (size > leaf_) {
      const int h = size / 2;
      const std::array<int, 4> kids{build(i0, j0, h), build(i0 + h, j0, h), build(i0, j0 + h, h), build(i0 + h, j0 + h, h)};
      nodes_[static_cast<std::size_t>(id)].kids = kids;
    }
    return id;
  }

  void walk(Pyramid& p, int id, bool cull, double margin, double dilation, Frame& f) {
    const Plan& pl = plan_[static_cast<std::size_t>(id)];
    const Node& n = nodes_[static_cast<std::size_t>(id)];
    if (cull && id != 0 && pl.projected) {
      ++f.tested;
      if (p.hidden(pl.corners, dilation)) {
        ++f.culled;
        f.culled_triangles += 2 * static_cast<std::size_t>(n.size) * static_cast<std::size_t>(n.size);
        return;
      }
    }
    if (n.kids[0] < 0) {
      for (const Tri& t : pl.tris) p.cover(t, margin);
      f.tiled += pl.tris.size();
      return;
    }
    for (int k : pl.order) walk(p, k, cull, margin, dilation, f);
  }

  const Terrain& t_;
  int leaf_;
  std::vector<Node> nodes_;
  std::vector<Plan> plan_;
  std::vector<Tri> tris_;
  std::vector<bool> ok_;
};

}  // namespace

int main(int argc, char** argv) {
  int repeat = 7, grid = 256;
  double margin = 1.0 / 16.0, dilation = 1.0 / 16.0, min_area = 0.0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (a + 1 >= argc) {
      std::fprintf(stderr, "terravol_coverage_bench: %s needs a value\n", arg.c_str());
      return 2;
    }
    const char* val = argv[++a];
    char* end = nullptr;
    const double x = std::strtod(val, &end);
    if (*end != '\0' || !std::isfinite(x)) {
      std::fprintf(stderr, "terravol_coverage_bench: %s: '%s' is not a number\n", arg.c_str(), val);
      return 2;
    }
    if (arg == "--repeat" && x >= 1) {
      repeat = static_cast<int>(x);
    } else if (arg == "--grid" && x >= 8 && x <= 4096 && (static_cast<int>(x) & (static_cast<int>(x) - 1)) == 0) {
      grid = static_cast<int>(x);
    } else if (arg == "--margin" && x >= 0 && x <= 16) {
      margin = x;
    } else if (arg == "--dilation" && x >= 0 && x <= 16) {
      dilation = x;
    } else if (arg == "--min-area" && x >= 0) {
      min_area = x;
    } else {
      std::fprintf(stderr,
                   "usage: terravol_coverage_bench [--repeat N>=1] [--grid CELLS (power of two, 8..4096)] [--margin PX 0..16] "
                   "[--dilation PX 0..16] [--min-area PX2 >= 0]\n");
      return 2;
    }
  }
  std::printf("{\n  \"viewport\": [%d, %d], \"repeat\": %d, \"margin_px\": %g, \"dilation_px\": %g, \"min_area_px\": %g,\n", kW, kH,
              repeat, margin, dilation, min_area);
  {
    Pyramid p(kW, kH);
    std::vector<double> c;
    for (int r = 0; r < 20 * repeat; ++r) {
      p.cover(std::array{glm::dvec2(-10, -10), glm::dvec2(3000, -10), glm::dvec2(-10, 3000)}, 0.0);
      const auto t = Clock::now();
      p.clear();
      c.push_back(ns_since(t));
    }
    std::printf("  \"clear_us\": %.2f,\n", median(c) * 1e-3);
  }
  std::printf("  \"random_triangles\": [\n");
  const double areas[] = {1, 10, 100, 1e4};
  for (std::size_t i = 0; i < 4; ++i) {
    const Random r = bench_random(areas[i], repeat, margin, dilation);
    std::printf(
        "    {\"area_px\": %g, \"cover_ns\": %.1f, \"cells_per_cover\": %.2f, \"hidden_ns_vacant\": %.1f, \"hidden_ns_full\": %.1f, "
        "\"hidden_ns_half\": %.1f}%s\n",
        areas[i], r.cover_ns, r.cells_per_cover, r.hidden_vacant_ns, r.hidden_full_ns, r.hidden_half_ns, i + 1 < 4 ? "," : "");
  }
  std::printf("  ],\n  \"terrain\": [\n");
  const Terrain terrain = make_terrain(grid);
  const double size = grid * terrain.cell;
  const glm::dmat4 proj = glm::perspective(glm::radians(45.0), static_cast<double>(kW) / kH, 1.0, 1e6);
  const glm::dvec3 low_eye(0.5 * size, -0.02 * size, terrain.at(grid / 2, 0) + 350.0);
  const glm::dvec3 high_eye(0.5 * size, -0.4 * size, 0.5 * size);
  const View views[] = {
      {proj * glm::lookAt(low_eye, glm::dvec3(0.5 * size, 0.6 * size, 0.0), glm::dvec3(0, 0, 1)), low_eye, "low"},
      {proj * glm::lookAt(high_eye, glm::dvec3(0.5 * size, 0.5 * size, 0.0), glm::dvec3(0, 0, 1)), high_eye, "high"},
  };
  TerrainBench tb(terrain, 8);
  Pyramid p(kW, kH);
  for (std::size_t vi = 0; vi < 2; ++vi) {
    const View& v = views[vi];
    tb.prepare(v, min_area);
    std::vector<double> all_ms, cull_ms;
    Frame all, cull;
    for (int r = 0; r < repeat; ++r) {
      all = tb.frame(p, false, margin, dilation);
      all_ms.push_back(all.ms);
      cull = tb.frame(p, true, margin, dilation);
      cull_ms.push_back(cull.ms);
    }
    std::printf(
        "    {\"view\": \"%s\", \"triangles\": %zu, \"skipped_at_near_plane\": %zu, \"median_triangle_px\": %.2f, "
        "\"covered_fraction\": %.3f,\n"
        "     \"tile_all\": {\"ms\": %.3f, \"tiled\": %zu, \"ns_per_cover\": %.1f, \"cells_per_pixel\": %.3f},\n"
        "     \"occlusion_pass\": {\"ms\": %.3f, \"tiled\": %zu, \"nodes_tested\": %zu, \"nodes_culled\": %zu, "
        "\"triangles_culled\": %zu, \"cells_per_pixel\": %.3f, \"hidden_cells_per_pixel\": %.3f}}%s\n",
        v.name, tb.triangles(), tb.skipped(), tb.median_triangle_area(), all.covered_fraction, median(all_ms), all.tiled,
        median(all_ms) * 1e6 / static_cast<double>(std::max<std::size_t>(all.tiled, 1)), all.cells_per_pixel, median(cull_ms),
        cull.tiled, cull.tested, cull.culled, cull.culled_triangles, cull.cells_per_pixel, cull.hidden_cells_per_pixel,
        vi + 1 < 2 ? "," : "");
  }
  std::printf("  ]\n}\n");
  return 0;
}
