// Textured slices: the exact sheet of slice() simplified by a restricted quadtree (B. Von Herzen
// and A. H. Barr, "Accurate triangulations of deformed, intersecting surfaces", SIGGRAPH 1987;
// R. Pajarola, "Large scale terrain visualization using the restricted quadtree
// triangulation", IEEE Visualization 1998, section 3), the colours carried by a texture.
//
// Why a restricted quadtree: the sheet is a grid of samples (a height field over the lattice
// columns for alt/agl, a sheet over longitude or latitude and height for lat/lon), so a
// hierarchy over that grid simplifies it in time linear in the samples, uses only grid samples
// as vertices (exact there), and needs no search or priority queue. Greedy row/column merging
// is as cheap but only merges along one direction at a time, so a sheet curved in both (the
// Earth's curvature on an alt sheet, terrain under an agl one) keeps long thin strips; edge
// collapse (vtkQuadricDecimation) adapts better but costs seconds and moves vertices off the
// lattice lines, which the texture's coordinates need.
//
// The hierarchy: node (x, y) of level l covers cells [x 2^l, (x + 1) 2^l) along u and v; level
// 0 are the sheet's cells. A node of level >= 1 is drawn as a fan of four triangles about its
// centre sample, each split at its edge's midpoint where the neighbour across that edge is
// finer (restriction keeps neighbours within one level, so that one midpoint is all a fan
// needs to meet them without T-junctions); a cell of level 0 as two triangles along its
// shorter diagonal, as slice() draws it.
//
// The error bound E(node), in scene metres, holds for every sample s in the node and every
// choice of split edges: |P(s) - F(s)| <= E, P the exact sheet, F the node's fan, both at the
// sheet coordinates of s. Level 1: the fan's vertices are all the node's samples but its four
// edge midpoints, so E = the largest |P(m) - (P(a) + P(b)) / 2| over its edges (a, b) with
// midpoints m. Level >= 2: each child's (unsplit) fan triangles lie inside one of the node's
// fan triangles whatever its splits, so F_child - F is linear on each and largest at the
// children's fan vertices; the only ones F does not interpolate are the edge midpoints and the
// children's centres (on the node's diagonals, where F is the mean of the diagonal's ends), so
// E = max E(children) + the largest such deviation. The bound is conservative (the triangle
// inequality adds the levels' deviations) and monotone (a node's E is at least its
// children's), so selecting top-down by E <= tolerance needs no saturation pass. It costs O(1)
// per node: the whole pyramid is linear in the samples.
//
// Departures from Pajarola: nodes are cells of a grid of any size and shape (the pyramid is
// cut at the grid's edges: a node reaching past them, or holding a cell slice() drops, has E =
// infinity and is always split, so the simplified sheet covers exactly slice()'s cells), and
// restriction is enforced per edge on the split flags (a split node of level l splits the
// parents of its edge neighbours), from the finest level up, instead of through a dependency
// graph of vertices.
#include "volume/textured_slice.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "volume/slice_sheet.h"

namespace terravol::volume {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

class Quadtree {
 public:
  explicit Quadtree(const detail::SliceSheet& sheet) : sheet_(sheet) {
    const int w0 = sheet.nu - 1, h0 = sheet.nv - 1;
    if (w0 < 1 || h0 < 1) return;
    // Level 0: the cells.
    levels_.push_back(Level{w0, h0, {}, {}, {}});
    Level& cells = levels_.back();
    cells.error.resize(static_cast<std::size_t>(w0) * static_cast<std::size_t>(h0));
    cells.any.resize(cells.error.size());
    for (int v = 0; v < h0; ++v)
      for (int u = 0; u < w0; ++u) {
        const bool ok = sheet.cell_usable(u, v);
        cells.error[cells.at(u, v)] = ok ? 0.0f : kInf;
        cells.any[cells.at(u, v)] = ok ? 1 : 0;
      }
    // Coarser levels until one node covers the grid.
    while (levels_.back().w > 1 || levels_.back().h > 1) {
      const int l = static_cast<int>(levels_.size());
      const Level& fine = levels_.back();
      Level level{(fine.w + 1) / 2, (fine.h + 1) / 2, {}, {}, {}};
      level.error.assign(static_cast<std::size_t>(level.w) * static_cast<std::size_t>(level.h), kInf);
      level.any.assign(level.error.size(), 0);
      const int size = 1 << l;
      for (int y = 0; y < level.h; ++y)
        for (int x = 0; x < level.w; ++x) {
          float worst = 0.0f;
          std::uint8_t any = 0;
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
              const int cx = 2 * x + dx, cy = 2 * y + dy;
              if (cx >= fine.w || cy >= fine.h) {
                worst = kInf;  // the node reaches past the grid
                continue;
              }
              worst = std::max(worst, fine.error[fine.at(cx, cy)]);
              any |= fine.any[fine.at(cx, cy)];
            }
          const std::size_t id = level.at(x, y);
          level.any[id] = any;
          if (worst == kInf || (x + 1) * size > w0 || (y + 1) * size > h0) continue;
          level.error[id] = worst + static_cast<float>(deviation(x * size, y * size, size));
        }
      levels_.push_back(std::move(level));
    }
  }

  // Chooses the leaves for `tolerance` (metres): split flags, then restriction.
  void select(double tolerance) {
    const int top = static_cast<int>(levels_.size()) - 1;
    for (int l = 1; l <= top; ++l) {
      Level& level = levels_[static_cast<std::size_t>(l)];
      level.split.resize(level.error.size());
      for (std::size_t i = 0; i < level.error.size(); ++i) {
        level.split[i] = level.any[i] && !(static_cast<double>(level.error[i]) <= tolerance);
      }
    }
    // A split node's children meet the node's edge neighbours, which must then be at most one
    // level coarser than the children: split their parents (and, to keep the tree, the node's).
    for (int l = 1; l < top; ++l) {
      const Level& level = levels_[static_cast<std::size_t>(l)];
      Level& up = levels_[static_cast<std::size_t>(l) + 1];
      for (int y = 0; y < level.h; ++y)
        for (int x = 0; x < level.w; ++x) {
          if (!level.split[level.at(x, y)]) continue;
          up.split[up.at(x / 2, y / 2)] = 1;
          if (x > 0) up.split[up.at((x - 1) / 2, y / 2)] = 1;
          if (x + 1 < level.w) up.split[up.at((x + 1) / 2, y / 2)] = 1;
          if (y > 0) up.split[up.at(x / 2, (y - 1) / 2)] = 1;
          if (y + 1 < level.h) up.split[up.at(x / 2, (y + 1) / 2)] = 1;
        }
    }
  }

  // Visits the leaves chosen by select(): leaf(level, x, y, split_edges) with split_edges bit e
  // set where edge e (0 bottom, 1 right, 2 top, 3 left) has its midpoint; level 0 leaves are
  // drawable cells.
  template <class Leaf>
  void leaves(Leaf leaf) const {
    const int top = static_cast<int>(levels_.size()) - 1;
    for (int l = top; l >= 0; --l) {
      const Level& level = levels_[static_cast<std::size_t>(l)];
      const Level* parent = l < top ? &levels_[static_cast<std::size_t>(l) + 1] : nullptr;
      for (int y = 0; y < level.h; ++y)
        for (int x = 0; x < level.w; ++x) {
          const std::size_t id = level.at(x, y);
          if (parent != nullptr && !parent->split[parent->at(x / 2, y / 2)]) continue;  // not present
          if (!level.any[id]) continue;
          if (l == 0) {
            leaf(0, x, y, 0);
            continue;
          }
          if (level.split[id]) continue;
          auto split = [&](int nx, int ny) {
            return nx >= 0 && ny >= 0 && nx < level.w && ny < level.h && level.split[level.at(nx, ny)];
          };
          const int edges = (split(x, y - 1) ? 1 : 0) | (split(x + 1, y) ? 2 : 0) | (split(x, y + 1) ? 4 : 0) |
                            (split(x - 1, y) ? 8 : 0);
          leaf(l, x, y, edges);
        }
    }
  }

  std::size_t triangle_count() const {
    std::size_t n = 0;
    leaves([&](int l, int, int, int edges) { n += l == 0 ? 2 : 4 + static_cast<std::size_t>(std::popcount(static_cast<unsigned>(edges))); });
    return n;
  }

  // The finite error bounds of levels >= 1, sorted and unique (the tolerances at which the
  // selection changes).
  std::vector<float> breakpoints() const {
    std::vector<float> e;
    for (std::size_t l = 1; l < levels_.size(); ++l)
      for (float x : levels_[l].error)
        if (x != kInf) e.push_back(x);
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    return e;
  }

 private:
  struct Level {
    int w, h;                         // nodes along u and v
    std::vector<float> error;         // E, metres; infinity when the node cannot be one leaf
    std::vector<std::uint8_t> any;    // holds a drawable cell
    std::vector<std::uint8_t> split;  // select()'s choice
    std::size_t at(int x, int y) const { return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x); }
  };

  const glm::dvec3& p(int u, int v) const { return sheet_.position[sheet_.index(u, v)]; }

  // The largest deviation from the fan of node (u0, v0) of `size` cells of the samples the fan
  // does not interpolate and its children's fans do (see the top of the file).
  double deviation(int u0, int v0, int size) const {
    const int h = size / 2, u1 = u0 + size, v1 = v0 + size, uc = u0 + h, vc = v0 + h;
    auto off = [&](int u, int v, int ua, int va, int ub, int vb) {
      return glm::length(p(u, v) - 0.5 * (p(ua, va) + p(ub, vb)));
    };
    double d = std::max({off(uc, v0, u0, v0, u1, v0), off(u1, vc, u1, v0, u1, v1), off(uc, v1, u0, v1, u1, v1),
                         off(u0, vc, u0, v0, u0, v1)});
    if (size >= 4) {
      const int q = h / 2;
      d = std::max({d, off(u0 + q, v0 + q, u0, v0, uc, vc), off(u1 - q, v0 + q, u1, v0, uc, vc),
                    off(u1 - q, v1 - q, u1, v1, uc, vc), off(u0 + q, v1 - q, u0, v1, uc, vc)});
    }
    return d;
  }

  const detail::SliceSheet& sheet_;
  std::vector<Level> levels_;
};

}  // namespace

TexturedMesh textured_slice(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec,
                            const GroundFunction& ground, const SheetOptions& options) {
  if (!(options.tolerance_m >= 0.0) || !std::isfinite(options.tolerance_m)) {
    throw std::invalid_argument("slice " + std::string(slice_kind_name(spec.kind)) + ": the sheet tolerance " +
                                std::to_string(options.tolerance_m) + " m must be finite and >= 0");
  }
  const detail::SliceSheet sheet = detail::slice_sheet(volume, mapper, spec, ground);
  TexturedMesh out;
  out.width = sheet.nu;
  out.height = sheet.nv;
  out.texels = sheet.color;

  Quadtree tree(sheet);
  out.tolerance_m = options.tolerance_m;
  tree.select(out.tolerance_m);
  if (options.max_triangles > 0 && tree.triangle_count() > options.max_triangles) {
    // The smallest breakpoint above the tolerance that meets the cap (the count falls as the
    // tolerance grows: a merged node has at most 8 triangles where its children had at least 8,
    // and its neighbours lose midpoints), else the largest.
    const std::vector<float> e = tree.breakpoints();
    auto lo = std::upper_bound(e.begin(), e.end(), static_cast<float>(options.tolerance_m));
    auto hi = e.end();
    while (lo < hi) {
      const auto mid = lo + (hi - lo) / 2;
      tree.select(*mid);
      if (tree.triangle_count() <= options.max_triangles) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    if (lo != e.end()) {
      out.tolerance_m = *lo;
    } else if (!e.empty()) {
      out.tolerance_m = std::max(options.tolerance_m, static_cast<double>(e.back()));  // every merge there is
    }
    tree.select(out.tolerance_m);
  }

  // Emit: one vertex per sample used, with its texel centre as texture coordinates.
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> index(sheet.position.size(), kUnused);
  Mesh& mesh = out.mesh;
  auto vertex = [&](int u, int v) {
    const std::size_t id = sheet.index(u, v);
    if (index[id] == kUnused) {
      index[id] = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(sheet.position[id]);
      mesh.colors.push_back(sheet.color[id]);
      out.tcoords.emplace_back((static_cast<float>(u) + 0.5f) / static_cast<float>(sheet.nu),
                               (static_cast<float>(v) + 0.5f) / static_cast<float>(sheet.nv));
    }
    return index[id];
  };
  auto triangle = [&](int ua, int va, int ub, int vb, int uc, int vc) {
    const glm::dvec3 &a = sheet.position[sheet.index(ua, va)], &b = sheet.position[sheet.index(ub, vb)],
                     &c = sheet.position[sheet.index(uc, vc)];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return;
    mesh.triangles.insert(mesh.triangles.end(), {vertex(ua, va), vertex(ub, vb), vertex(uc, vc)});
  };
  tree.leaves([&](int l, int x, int y, int edges) {
    if (l == 0) {  // as slice() draws a cell: along the shorter diagonal, counter-clockwise in (u, v)
      const glm::dvec3 &a = sheet.position[sheet.index(x, y)], &b = sheet.position[sheet.index(x + 1, y)],
                       &c = sheet.position[sheet.index(x + 1, y + 1)], &d = sheet.position[sheet.index(x, y + 1)];
      const glm::dvec3 ac = c - a, bd = d - b;
      if (glm::dot(ac, ac) <= glm::dot(bd, bd)) {
        triangle(x, y, x + 1, y, x + 1, y + 1);
        triangle(x, y, x + 1, y + 1, x, y + 1);
      } else {
        triangle(x, y, x + 1, y, x, y + 1);
        triangle(x + 1, y, x + 1, y + 1, x, y + 1);
      }
      return;
    }
    const int s = 1 << l, h = s / 2, u0 = x * s, v0 = y * s, uc = u0 + h, vc = v0 + h;
    // The corners counter-clockwise from (u0, v0); edge e runs from corner e to corner e + 1.
    const int cu[5] = {u0, u0 + s, u0 + s, u0, u0}, cv[5] = {v0, v0, v0 + s, v0 + s, v0};
    for (int e = 0; e < 4; ++e) {
      if (edges & (1 << e)) {
        const int mu = (cu[e] + cu[e + 1]) / 2, mv = (cv[e] + cv[e + 1]) / 2;
        triangle(uc, vc, cu[e], cv[e], mu, mv);
        triangle(uc, vc, mu, mv, cu[e + 1], cv[e + 1]);
      } else {
        triangle(uc, vc, cu[e], cv[e], cu[e + 1], cv[e + 1]);
      }
    }
  });
  return out;
}

}  // namespace terravol::volume
