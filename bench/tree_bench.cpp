// terravol_tree_bench: build, slide and traversal of the MRBSP tree on a real mosaic, with
// medians over repetitions (Wiley et al. 1997, section 4.3 reports building at about 100x the
// cost of a slide). No rendering: this measures mrbsp/ and the mosaic read alone.
//
// Usage: terravol_tree_bench DEM... [--window CELLS] [--levels N] [--repeat N]
// Prints one JSON object: window read, build, slide and traversal times (median and spread).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "app/scene/terrain_scene.h"
#include "app/scene/timing.h"
#include "io/error.h"
#include "io/mosaic.h"
#include "io/void_fill.h"

namespace {

using terravol::app::scene::Clock;
using terravol::app::scene::ms_since;

struct Summary {
  double median, min, max;
};
Summary summarize(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v.front(), v.back()};
}

// The window's lattice in the tree's convention, in a fixed scene frame.
struct Lattice {
  std::vector<double> xs, ys;
  std::vector<float> z;
};
Lattice lattice_of(const terravol::io::Mosaic& m, const terravol::io::SceneFrame& f, int row0, int col0, int n) {
  terravol::io::Grid g = m.read_window(row0, col0, n + 1, n + 1);
  terravol::io::fill_voids(g);
  Lattice l;
  l.xs.resize(static_cast<std::size_t>(n) + 1);
  l.ys.resize(static_cast<std::size_t>(n) + 1);
  l.z.resize(static_cast<std::size_t>(n + 1) * static_cast<std::size_t>(n + 1));
  for (int i = 0; i <= n; ++i) l.xs[static_cast<std::size_t>(i)] = f.x_of_lon(g.georef.x0 + i * g.georef.dx);
  for (int j = 0; j <= n; ++j) l.ys[static_cast<std::size_t>(j)] = f.y_of_lat(g.georef.y0 - (n - j) * g.georef.dy);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      l.z[static_cast<std::size_t>(j) * static_cast<std::size_t>(n + 1) + static_cast<std::size_t>(i)] =
          g.heights[g.index(n - j, i)] - static_cast<float>(f.curvature_drop(l.xs[static_cast<std::size_t>(i)], l.ys[static_cast<std::size_t>(j)]));
  return l;
}

void print(const char* name, const Summary& s, bool last = false) {
  std::printf("  \"%s\": {\"median\": %.3f, \"min\": %.3f, \"max\": %.3f}%s\n", name, s.median, s.min, s.max, last ? "" : ",");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace terravol;
  std::vector<std::filesystem::path> dems;
  int n = 1024, levels = 0, repeat = 5;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if ((arg == "--window" || arg == "--levels" || arg == "--repeat") && a + 1 < argc) {
      const int v = std::atoi(argv[++a]);
      (arg == "--window" ? n : arg == "--levels" ? levels : repeat) = v;
    } else {
      dems.emplace_back(arg);
    }
  }
  if (dems.empty() || n < 2 || (n & (n - 1)) != 0 || repeat < 1) {
    std::fprintf(stderr, "usage: terravol_tree_bench DEM... [--window CELLS (power of two)] [--levels N] [--repeat N]\n");
    return 2;
  }
  try {
    const io::Mosaic mosaic = io::Mosaic::open(dems);
    if (levels == 0) levels = app::scene::default_levels(n);
    const int step = n / (1 << (levels - 1));  // fine cells per coarsest cell: the slide step
    if (mosaic.rows() < n + 1 + step || mosaic.cols() < n + 1 + step) {
      std::fprintf(stderr, "terravol_tree_bench: mosaic of %d x %d samples is too small for a %d-cell window plus a slide\n",
                   mosaic.rows(), mosaic.cols(), n);
      return 1;
    }
    const io::SceneFrame frame(mosaic.georef().y0 - 0.5 * n * mosaic.georef().dy,
                               mosaic.georef().x0 + 0.5 * n * mosaic.georef().dx);
    std::vector<double> read_ms, build_ms, slide_ms, traverse_ms;
    std::size_t triangles = 0;
    for (int r = 0; r < repeat; ++r) {
      auto t0 = Clock::now();
      const Lattice a = lattice_of(mosaic, frame, 0, 0, n);
      read_ms.push_back(ms_since(t0));
      t0 = Clock::now();
      mrbsp::TerrainTree tree({n, a.xs, a.ys, a.z}, levels);
      build_ms.push_back(ms_since(t0));
      // Slide by one coarsest cell east and south, as the viewer does near the window's edge.
      const Lattice b = lattice_of(mosaic, frame, step, step, n);
      t0 = Clock::now();
      tree.slide({n, b.xs, b.ys, b.z});
      slide_ms.push_back(ms_since(t0));
      // A low oblique view from the window's south-west quarter toward its centre.
      mrbsp::Camera c;
      c.eye = {b.xs[static_cast<std::size_t>(n / 4)], b.ys[static_cast<std::size_t>(n / 8)], 0.0};
      c.eye.z = b.z[static_cast<std::size_t>(n / 8) * static_cast<std::size_t>(n + 1) + static_cast<std::size_t>(n / 4)] + 1500.0;
      c.forward = glm::normalize(glm::dvec3(0.4, 1.0, -0.25));
      c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
      mrbsp::Frame f;
      tree.traverse(c, {}, f);  // warm
      t0 = Clock::now();
      tree.traverse(c, {}, f);
      traverse_ms.push_back(ms_since(t0));
      triangles = f.indices.size() / 3;
    }
    const Summary b = summarize(build_ms), s = summarize(slide_ms);
    std::printf("{\n  \"window_cells\": %d,\n  \"levels\": %d,\n  \"samples\": %lld,\n  \"repeat\": %d,\n", n, levels,
                static_cast<long long>(n + 1) * (n + 1), repeat);
    print("read_window_ms", summarize(read_ms));
    print("build_ms", b);
    print("slide_ms", s);
    print("traversal_ms", summarize(traverse_ms));
    std::printf("  \"triangles\": %zu,\n", triangles);
    std::printf("  \"build_msamples_per_s\": %.2f,\n", (n + 1.0) * (n + 1.0) / b.median / 1000.0);
    std::printf("  \"build_over_slide\": %.2f\n}\n", b.median / s.median);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol_tree_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
