// Merging other polygons into the MRBSP tree: Wiley et al. 1997, section 4.2 ("Merging Other
// Objects"). Insertion from the root is the ordinary BSP merge (Fuchs, Kedem, Naylor 1980):
// classify against the node's plane, split what spans, and at a node with LOD alternatives (a
// cell) put a copy into every alternative: the cell's low representation and its high subtree.
//
// Departures from the paper, and why (measured on the benchmark scenes, docs/architecture.md):
//   - A cell's terrain, in all its alternatives and with its crack fills, lies within the z
//     range [zmin, zmax] of its full-resolution samples. The plane z = zmax is therefore a
//     legal splitter of the cell's region: a piece above it stays at the cell, whole, in a
//     small BSP of its own ("above" slot), ordered against the whole terrain subtree by the
//     eye's side of that plane. Only pieces inside the height range go on into the children
//     and the low alternative. Copying every polygon into every alternative down to the finest
//     level, as the paper does, cut a triangle into about 45 pieces here.
//   - A piece below zmin is below the terrain at every LOD; an eye above the ground (which
//     render, view and fly require) sees it only through the terrain, so it is dropped. So is
//     the part of a piece below a drawn low triangle, in that triangle's column.
//   - Small BSPs are autopartitions whose splitter is chosen among a few sampled candidates
//     by fewest spans (and then balance), not in input order: input order undoes most of the
//     gain above.
//   - Each surface keeps its own pieces (SurfacePieces), so an edit re-distributes only that
//     surface and rebuilds only the small BSPs its old or new pieces touch.
//   - A split makes one vertex per edge and plane (EdgeCache): neighbouring pieces of one
//     surface share the vertices of their common edges, with no T-junction from the tree's
//     planes.
// Classification is in double precision, with a tolerance relative to the window's size.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/partitioner.h>

#include <glm/geometric.hpp>

#include "mrbsp/tree_impl.h"

namespace terravol::mrbsp {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct PlaneD {
  glm::dvec3 n;
  double d;  // front where dot(n, p) + d > 0
};

enum class Side { kBack, kFront, kCoplanar, kSpanning };

// The side of a polygon with vertices in front of the plane (`front`) and behind it (`back`).
Side side_of(bool front, bool back) {
  if (front && back) return Side::kSpanning;
  if (front) return Side::kFront;
  if (back) return Side::kBack;
  return Side::kCoplanar;
}

// The vertex made where an edge crosses a plane, once per (edge, plane): a flat open-addressing
// map from (lower vertex, higher vertex, plane id) to the vertex. Written by hand because the
// standard unordered_map costs a node allocation per entry and this is the merge's hottest map.
class EdgeCache {
 public:
  void clear() {
    std::fill(keys_.begin(), keys_.end(), Key{});
    size_ = 0;
  }
  // The vertex stored for the edge (a, b) and `plane`, or the result of make() stored now.
  template <class Make>
  std::uint32_t get(std::uint32_t a, std::uint32_t b, std::uint32_t plane, Make make) {
    if (a > b) std::swap(a, b);
    if (2 * (size_ + 1) > keys_.size()) grow();
    const Key key{a, b, plane, 1};
    std::size_t i = hash(key) & (keys_.size() - 1);
    while (keys_[i].used) {
      if (keys_[i].a == a && keys_[i].b == b && keys_[i].plane == plane) return values_[i];
      i = (i + 1) & (keys_.size() - 1);
    }
    const std::uint32_t v = make();
    keys_[i] = key;
    values_[i] = v;
    ++size_;
    return v;
  }

 private:
  struct Key {
    std::uint32_t a = 0, b = 0, plane = 0, used = 0;
  };
  static std::size_t hash(const Key& k) {
    std::uint64_t h = (static_cast<std::uint64_t>(k.a) << 32 | k.b) * 0x9E3779B97F4A7C15ull;
    h ^= (h >> 29) + static_cast<std::uint64_t>(k.plane) * 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
  void grow() {
    std::vector<Key> old_keys = std::move(keys_);
    std::vector<std::uint32_t> old_values = std::move(values_);
    keys_.assign(std::max<std::size_t>(64, 2 * old_keys.size()), Key{});
    values_.assign(keys_.size(), 0);
    size_ = 0;
    for (std::size_t k = 0; k < old_keys.size(); ++k) {
      if (!old_keys[k].used) continue;
      std::size_t i = hash(old_keys[k]) & (keys_.size() - 1);
      while (keys_[i].used) i = (i + 1) & (keys_.size() - 1);
      keys_[i] = old_keys[k];
      values_[i] = old_values[k];
      ++size_;
    }
  }
  std::vector<Key> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t size_ = 0;
};

int side_of(double s, double eps) { return s > eps ? 1 : (s < -eps ? -1 : 0); }

// Splits the convex polygon `in` (vertex ids) by a plane into `back` and `front` (appended);
// vertices within eps of the plane go to both. `dist(v)` is the signed distance of vertex v,
// `cut(a, b, t)` the vertex at a + t (b - a) for the edge (a, b).
template <class Dist, class Cut>
void split_polygon(std::span<const std::uint32_t> in, double eps, Dist dist, Cut cut, std::vector<std::uint32_t>& back,
                   std::vector<std::uint32_t>& front) {
  const std::size_t k = in.size();
  for (std::size_t i = 0; i < k; ++i) {
    const std::uint32_t a = in[i], b = in[(i + 1) % k];
    const double sa = dist(a), sb = dist(b);
    const int ca = side_of(sa, eps), cb = side_of(sb, eps);
    if (ca >= 0) front.push_back(a);
    if (ca <= 0) back.push_back(a);
    if (ca * cb < 0) {
      const std::uint32_t v = cut(a, b, sa / (sa - sb));
      front.push_back(v);
      back.push_back(v);
    }
  }
}

constexpr glm::vec2 kNoTcoord(-1.0f, -1.0f);

glm::u8vec4 mix_color(glm::u8vec4 a, glm::u8vec4 b, double t) {
  return glm::u8vec4(glm::round(glm::mix(glm::dvec4(a), glm::dvec4(b), t)));
}

// --- Distribution: one surface through the tree's planes --------------------------------------


class Distributor {
 public:
  Distributor(const TerrainTree::Impl& m, SurfacePieces& s) : m_(m), s_(s) {
    const double size = std::max(m.xs.back() - m.xs.front(), m.ys.back() - m.ys.front());
    eps_ = 1e-9 * std::max(size, 1.0);
  }

  // Every triangle anew.
  void run() {
    gathered_.clear();
    s_.refs.clear();
    s_.vertices.resize(s_.input_vertices);
    s_.colors.resize(s_.input_vertices);
    if (!s_.tcoords.empty()) s_.tcoords.resize(s_.input_vertices);
    s_.dropped = 0;
    for (std::size_t t = 0; t < s_.triangles.size() / 3; ++t) send(t);
    finish();
  }

  // After a slide (Impl::shift_merged): the pieces the surface has are those inside `kept`,
  // the lattice rectangle of the window that was already in the old one, and those of the
  // outside places that lie where places lay before (`kept_places`, their keys); the triangles reaching beyond
  // the rectangle are sent through the tree again, and what comes to a region inside it, or to
  // a kept band, is left out (its pieces are there already).
  // `renamed` holds the kept pieces (into the surface's refs).
  void run_outside(const TerrainTree::Impl::Region& kept, const std::unordered_set<SlotKey>& kept_places,
                   std::vector<SurfacePieces::Piece> renamed) {
    gathered_ = std::move(renamed);
    kept_ = kept;
    kept_places_ = kept_places;
    skip_kept_ = true;
    const glm::dvec2 lo(m_.xs[static_cast<std::size_t>(kept.i0)], m_.ys[static_cast<std::size_t>(kept.j0)]);
    const glm::dvec2 hi(m_.xs[static_cast<std::size_t>(kept.i1)], m_.ys[static_cast<std::size_t>(kept.j1)]);
    for (std::size_t t = 0; t < s_.triangles.size() / 3; ++t) {
      bool inside = true;
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3& v = s_.vertices[s_.triangles[3 * t + static_cast<std::size_t>(k)]];
        inside = inside && v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y;
      }
      if (!inside) send(t);
    }
    finish();
  }

 private:
  // Sends triangle t through the tree.
  void send(std::size_t t) {
    pool_.clear();
    pool_.insert(pool_.end(), {s_.triangles[3 * t], s_.triangles[3 * t + 1], s_.triangles[3 * t + 2]});
    if (!has_area(0, 3)) return;  // zero-area triangles draw nothing
    stack_.push_back({kChain, 0, 0, 0, 0, 0, 0, 3});
    while (!stack_.empty()) {
      const Work w = stack_.back();
      stack_.pop_back();
      step(w);
    }
  }

  // Keeps the pieces by slot (stable: in the order they came) and fits the storage.
  void finish() {
    s_.keep(gathered_);
    s_.vertices.shrink_to_fit();
    s_.colors.shrink_to_fit();
    s_.tcoords.shrink_to_fit();
  }

  // What to do with a polygon (pool_[first .. first + count)): kChain: the window's boundary
  // plane `stage` (0 west, 1 east, 2 south, 3 north; 4: inside, the root cell); kSquare: the
  // cell (level, ci, cj); kHalf: the x half `half` of that cell, to split at its middle y line.
  enum Kind : std::uint8_t { kChain, kSquare, kHalf };
  struct Work {
    Kind kind;
    std::uint8_t stage;
    std::int8_t level;
    std::uint8_t half;
    int ci, cj;
    std::uint32_t first, count;
  };
  static Work work(Kind kind, int level, int ci, int cj, int half, std::uint32_t first, std::uint32_t count) {
    return {kind, 0, static_cast<std::int8_t>(level), static_cast<std::uint8_t>(half), ci, cj, first, count};
  }

  std::span<const std::uint32_t> poly(std::uint32_t first, std::uint32_t count) const {
    return {pool_.data() + first, count};
  }

  bool has_area(std::uint32_t first, std::uint32_t count) const {
    glm::dvec3 n(0.0);
    const glm::dvec3 a = s_.vertices[pool_[first]];
    for (std::uint32_t k = 1; k + 1 < count; ++k) {
      n += glm::cross(s_.vertices[pool_[first + k]] - a, s_.vertices[pool_[first + k + 1]] - a);
    }
    return glm::length(n) > eps_ * eps_;
  }

  // Splits by the axis plane (axis 0: x, 1: y, 2: z) at `offset`, plane id `plane`; returns
  // the two parts as (first, count) in the pool, count 0 when empty.
  struct Parts {
    std::uint32_t back_first = 0, back_count = 0, front_first = 0, front_count = 0;
    bool coplanar = false;
  };
  Parts split_axis(std::uint32_t first, std::uint32_t count, int axis, double offset, std::uint32_t plane) {
    Parts parts;
    bool front = false, back = false;
    for (std::uint32_t k = 0; k < count; ++k) {
      const double s = s_.vertices[pool_[first + k]][axis] - offset;
      front |= s > eps_;
      back |= s < -eps_;
    }
    if (!front && !back) {
      parts.coplanar = true;  // lies in the plane: the back side takes it
      parts.back_first = first;
      parts.back_count = count;
      return parts;
    }
    if (!front) {
      parts.back_first = first;
      parts.back_count = count;
      return parts;
    }
    if (!back) {
      parts.front_first = first;
      parts.front_count = count;
      return parts;
    }
    back_.clear();
    front_.clear();
    split_polygon(
        std::span<const std::uint32_t>(pool_.data() + first, count), eps_,
        [&](std::uint32_t v) { return s_.vertices[v][axis] - offset; },
        [&](std::uint32_t a, std::uint32_t b, double) {
          return cache_.get(a, b, plane, [&] {
            // From the endpoint first in (x, y, z) order, whichever way the polygon runs: the
            // same edge gives the same bits in every Distributor (chunks of one surface are
            // distributed apart, distribute_all()), so their pieces meet without a crack.
            if (std::lexicographical_compare(&s_.vertices[b].x, &s_.vertices[b].x + 3, &s_.vertices[a].x, &s_.vertices[a].x + 3)) {
              std::swap(a, b);
            }
            const double da = s_.vertices[a][axis] - offset, db = s_.vertices[b][axis] - offset;
            const double t = da / (da - db);
            glm::dvec3 p = glm::mix(s_.vertices[a], s_.vertices[b], t);
            p[axis] = offset;  // exactly in the plane
            s_.vertices.push_back(p);
            s_.colors.push_back(mix_color(s_.colors[a], s_.colors[b], t));
            if (!s_.tcoords.empty()) s_.tcoords.push_back(glm::mix(s_.tcoords[a], s_.tcoords[b], static_cast<float>(t)));
            return static_cast<std::uint32_t>(s_.vertices.size() - 1);
          });
        },
        back_, front_);
    parts.back_first = static_cast<std::uint32_t>(pool_.size());
    parts.back_count = static_cast<std::uint32_t>(back_.size());
    pool_.insert(pool_.end(), back_.begin(), back_.end());
    parts.front_first = static_cast<std::uint32_t>(pool_.size());
    parts.front_count = static_cast<std::uint32_t>(front_.size());
    pool_.insert(pool_.end(), front_.begin(), front_.end());
    if (parts.back_count < 3) parts.back_count = 0;
    if (parts.front_count < 3) parts.front_count = 0;
    return parts;
  }

  void arrive(SlotKey slot, std::uint32_t first, std::uint32_t count) {
    gathered_.push_back({slot, static_cast<std::uint32_t>(s_.refs.size()), count});
    s_.refs.insert(s_.refs.end(), pool_.begin() + first, pool_.begin() + first + count);
  }

  // What lies beyond boundary plane `side`, cut into that side's bands (the band planes are
  // parallel to it; a piece in a band plane goes with the band nearer the window). A kept
  // band's pieces are there already (run_outside).
  void to_bands(int side, std::uint32_t first, std::uint32_t count) {
    const int axis = side < 2 ? 0 : 1;
    const bool low_side = side % 2 == 0;  // west and south lie below their planes
    for (int band = 0; band < kBands; ++band) {
      std::uint32_t near_first = first, near_count = count, far_count = 0, far_first = 0;
      if (band + 1 < kBands) {
        const Parts p = split_axis(first, count, axis, m_.band_plane(side, band + 1), band_plane_id(side, band));
        // split_axis gives a piece lying in the plane to the back: for west and south that is
        // beyond, so it is moved to the near side here.
        const bool in_plane = p.coplanar;
        near_first = low_side ? (in_plane ? p.back_first : p.front_first) : p.back_first;
        near_count = low_side ? (in_plane ? p.back_count : p.front_count) : p.back_count;
        far_first = low_side ? p.back_first : p.front_first;
        far_count = low_side ? (in_plane ? 0 : p.back_count) : p.front_count;
      }
      if (near_count >= 3) to_columns(side, band, near_first, near_count);
      if (far_count < 3) return;
      first = far_first;
      count = far_count;
    }
  }
  // A band's part cut into the places' columns (south and north) or rows (west and east;
  // Impl::column_axis, Impl::place_step); a kept place's pieces are there already
  // (run_outside).
  void to_columns(int side, int band, std::uint32_t first, std::uint32_t count) {
    const int columns = m_.place_columns(), step = m_.place_step(), axis = m_.column_axis(side);
    for (int column = 0; column < columns; ++column) {
      std::uint32_t in_first = first, in_count = count;
      bool rest = false;
      if (column + 1 < columns) {
        const int i = (column + 1) * step;
        const Parts p =
            split_axis(first, count, axis, m_.place_line(side, column + 1), axis == 0 ? x_plane(i) : y_plane(i));
        in_first = p.back_first;  // west (south) of the line (a piece in it goes there)
        in_count = p.back_count;
        first = p.front_first;
        count = p.front_count;
        rest = count >= 3;
      }
      if (in_count >= 3 && !(skip_kept_ && kept_places_.count(outside_key(side, band, column)))) {
        arrive(outside_key(side, band, column), in_first, in_count);
      }
      if (!rest) return;
    }
  }
  std::uint32_t band_plane_id(int side, int band) const {
    return static_cast<std::uint32_t>(2 * (m_.n + 1)) + m_.total_cells + static_cast<std::uint32_t>(side * kBands + band);
  }

  std::uint32_t x_plane(int i) const { return static_cast<std::uint32_t>(i); }
  std::uint32_t y_plane(int j) const { return static_cast<std::uint32_t>(m_.n + 1 + j); }

  void step(const Work& w) {
    if (w.kind == kChain) {
      if (w.stage == 4) {
        stack_.push_back(work(kSquare, -m_.top, 0, 0, 0, w.first, w.count));
        return;
      }
      // West and south keep the back side (beyond x < xs[0], y < ys[0]); east and north the front.
      const int axis = w.stage < 2 ? 0 : 1;
      const bool low_side = w.stage % 2 == 0;
      const std::vector<double>& lines = axis == 0 ? m_.xs : m_.ys;
      const double offset = low_side ? lines.front() : lines.back();
      const std::uint32_t plane = axis == 0 ? x_plane(low_side ? 0 : m_.n) : y_plane(low_side ? 0 : m_.n);
      Parts p = split_axis(w.first, w.count, axis, offset, plane);
      if (p.coplanar) {  // in the boundary plane: inside, with the window
        p.front_first = p.back_first;
        p.front_count = p.back_count;
        p.back_count = 0;
      }
      const std::uint32_t out_first = low_side ? p.back_first : p.front_first;
      const std::uint32_t out_count = low_side ? p.back_count : p.front_count;
      const std::uint32_t in_first = low_side ? p.front_first : p.back_first;
      const std::uint32_t in_count = low_side ? p.front_count : p.back_count;
      if (out_count >= 3) to_bands(w.stage, out_first, out_count);
      if (in_count >= 3) stack_.push_back({kChain, static_cast<std::uint8_t>(w.stage + 1), 0, 0, 0, 0, in_first, in_count});
      return;
    }
    const int level = w.level;
    const int s = m_.cell_size(level), half = s / 2;
    const int i0 = w.ci * s, j0 = w.cj * s;
    if (skip_kept_ && w.kind == kSquare && kept_.holds(i0, j0, s)) return;  // its pieces are kept
    if (w.kind == kHalf) {
      const int j = j0 + half;
      const Parts p = split_axis(w.first, w.count, 1, m_.ys[static_cast<std::size_t>(j)], y_plane(j));
      const int ci = 2 * w.ci + w.half;
      if (p.back_count >= 3) stack_.push_back(work(kSquare, level + 1, ci, 2 * w.cj, 0, p.back_first, p.back_count));
      if (p.front_count >= 3) stack_.push_back(work(kSquare, level + 1, ci, 2 * w.cj + 1, 0, p.front_first, p.front_count));
      return;
    }
    std::uint32_t first = w.first, count = w.count;
    if (level >= 0) {
      const CellZ cz = m_.cell_z(level, w.ci, w.cj);
      double lo = std::numeric_limits<double>::max(), hi = -lo;
      for (std::uint32_t k = 0; k < count; ++k) {
        const double z = s_.vertices[pool_[first + k]].z;
        lo = std::min(lo, z);
        hi = std::max(hi, z);
      }
      const std::uint32_t cell = m_.cell_id(level, w.ci, w.cj);
      const SlotKey above = static_cast<SlotKey>(cell) * 2 + static_cast<SlotKey>(SlotKind::kAbove);
      const SlotKey low = static_cast<SlotKey>(cell) * 2 + static_cast<SlotKey>(SlotKind::kLow);
      if (hi < static_cast<double>(cz.zmin) - eps_) {
        ++s_.dropped;  // below all of the cell's terrain
        return;
      }
      if (lo >= static_cast<double>(cz.zmax) - eps_) {
        arrive(above, first, count);
        return;
      }
      if (hi > static_cast<double>(cz.zmax) + eps_) {  // straddles the ceiling: cut there
        const Parts p = split_axis(first, count, 2, static_cast<double>(cz.zmax), 2 * static_cast<std::uint32_t>(m_.n + 1) + cell);
        if (p.front_count >= 3) arrive(above, p.front_first, p.front_count);
        if (p.back_count < 3) return;
        first = p.back_first;
        count = p.back_count;
      }
      arrive(low, first, count);  // a copy for the low alternative
      if (level == m_.levels - 1) return;
    }
    const int i = i0 + half;
    const Parts p = split_axis(first, count, 0, m_.xs[static_cast<std::size_t>(i)], x_plane(i));
    if (p.back_count >= 3) stack_.push_back(work(kHalf, level, w.ci, w.cj, 0, p.back_first, p.back_count));
    if (p.front_count >= 3) stack_.push_back(work(kHalf, level, w.ci, w.cj, 1, p.front_first, p.front_count));
  }

  const TerrainTree::Impl& m_;
  SurfacePieces& s_;
  std::vector<SurfacePieces::Piece> gathered_;  // kept by finish()
  double eps_ = 0.0;
  bool skip_kept_ = false;
  TerrainTree::Impl::Region kept_;
  std::unordered_set<SlotKey> kept_places_;
  std::vector<std::uint32_t> pool_, back_, front_;
  std::vector<Work> stack_;
  EdgeCache cache_;
};

// --- Small BSPs -------------------------------------------------------------------------------

// Builds a slot's small BSP from pieces that arrived there, or inserts more pieces into the one
// it has (ordinary BSP insertion, Fuchs, Kedem and Naylor 1980: down the existing planes,
// split where they span, a new autopartition where an empty side is reached).
class SlotBuilder {
 public:
  SlotBuilder(const TerrainTree::Impl& m, BspStore& out) : m_(m), out_(out) {
    const double size = std::max(m.xs.back() - m.xs.front(), m.ys.back() - m.ys.front());
    eps_ = 1e-9 * std::max(size, 1.0);
    origin_ = glm::dvec3(0.5 * (m.xs.front() + m.xs.back()), 0.5 * (m.ys.front() + m.ys.back()), 0.0);
  }

  // Adds a piece of `surface` (its vertex ids) to what is built or inserted.
  void add(const SurfacePieces& surface, std::uint32_t surface_id, std::span<const std::uint32_t> refs) {
    const std::uint32_t first = static_cast<std::uint32_t>(ids_.size());
    for (std::uint32_t v : refs) {
      const std::uint64_t key = static_cast<std::uint64_t>(surface_id) << 32 | v;
      ids_.push_back(local_vertex(key, surface.vertices[v], surface.colors[v],
                                  surface.tcoords.empty() ? kNoTcoord : surface.tcoords[v]));
    }
    Poly p{first, static_cast<std::uint32_t>(refs.size()), kMergedLevel, false, {}, surface_id};
    p.flat = plane_of(p, p.plane);
    sphere_of(p);
    polys_.push_back(p);
  }

  // An above or outside slot: an autopartition of the pieces, or their insertion. A fresh
  // one of at least kHalvedBuild pieces is built in two halves at once: the root's splitter is
  // chosen and the pieces partitioned here, then this builder builds the back side while a
  // second one, on another thread, builds the front side's pieces (copied, with their
  // vertices) into a store of its own, which is appended to this one. Each side's choices see
  // only that side's pieces, as in one builder; each side tries an axis-aligned splitter
  // first, as a root does (one builder tries it below a root only after an axis split), and
  // the root's split vertices are stored twice, at the same positions. The benchmark scene
  // over N44W072 stores 220,433 pieces so instead of 220,717; hydrogen.vtk 1.41x its input.
  // A slide of the benchmark's Utah volumes back west builds a level-0 cell's above slot of
  // 4,602 pieces, which took 29 ms alone on one core, while the slide's slot phase (37 ms of
  // CPU on two cores) waited for it.
  static constexpr std::size_t kHalvedBuild = 2048;
  void build_autopartition() {
    all_polys();
    const auto total = static_cast<std::uint32_t>(list_.size());
    PlaneD plane;
    bool on_axis = false;
    if (out_.root >= 0) {
      insert();
    } else if (total < kHalvedBuild || !choose(0, total, plane, true, on_axis)) {
      out_.root = build(0, total);
    } else {
      const std::int32_t root = new_node(plane);
      std::uint32_t nb = 0, nf = 0;
      partition(0, total, plane, root, nb, nf);
      BspStore front_store;
      SlotBuilder front(m_, front_store);
      for (std::uint32_t k = nb; k < nb + nf; ++k) front.adopt(*this, polys_[list_[k]]);
      list_.resize(nb);
      std::int32_t back = -1;
      tbb::parallel_invoke([&] { back = build(0, nb); }, [&] { front.build_autopartition(); });
      out_.nodes[static_cast<std::size_t>(root)].back = back;
      out_.root = root;
      finish();
      append(front_store, root);
      return;
    }
    finish();
  }

  // A low slot of cell (level, ci, cj): the diagonal plane; on each side the terrain triangle's
  // plane with the triangle in it, the pieces above it in an autopartition, those below dropped
  // (kDropSide). Into an existing one, an insertion.
  void build_low(int level, int ci, int cj) {
    all_polys();
    if (out_.root >= 0) {
      insert();
      finish();
      return;
    }
    const int s = m_.cell_size(level);
    const std::uint32_t sw = m_.vertex(ci * s, cj * s), se = m_.vertex(ci * s + s, cj * s);
    const std::uint32_t ne = m_.vertex(ci * s + s, cj * s + s), nw = m_.vertex(ci * s, cj * s + s);
    const glm::dvec3 a(m_.positions[sw]), c(m_.positions[ne]);
    PlaneD diag;
    diag.n = glm::normalize(glm::dvec3(-(c.y - a.y), c.x - a.x, 0.0));  // negative on the south-east side
    diag.d = -glm::dot(diag.n, a);
    const std::uint32_t total = static_cast<std::uint32_t>(list_.size());
    const std::int32_t root = new_node(diag);
    std::uint32_t nb = 0, nf = 0;
    partition(0, total, diag, root, nb, nf);
    const std::uint32_t triangles[2][3] = {{sw, se, ne}, {sw, ne, nw}};
    std::int32_t sides[2];
    std::uint32_t begin[2] = {0, nb}, end[2] = {nb, nb + nf};
    // The front range lies after the back one: partition it first, so that the back's stays.
    for (int side = 1; side >= 0; --side) {  // 0: back (south-east), 1: front (north-west)
      const std::uint32_t* t = triangles[side];
      const glm::dvec3 p0(m_.positions[t[0]]), p1(m_.positions[t[1]]), p2(m_.positions[t[2]]);
      PlaneD plane;
      plane.n = glm::normalize(glm::cross(p1 - p0, p2 - p0));  // counter-clockwise from above: up
      plane.d = -glm::dot(plane.n, p0);
      const std::int32_t node = new_node(plane);
      out_.nodes[static_cast<std::size_t>(node)].back = kDropSide;
      const std::uint32_t terrain = static_cast<std::uint32_t>(polys_.size());
      polys_.push_back({static_cast<std::uint32_t>(ids_.size()), 3, static_cast<std::int8_t>(level), true, plane, kTerrainSurface});
      for (int k = 0; k < 3; ++k) ids_.push_back(kTerrainRef | t[k]);
      sphere_of(polys_.back());
      coplanar_.push_back({node, terrain});
      std::uint32_t below = 0, above = 0;
      partition(begin[side], end[side], plane, node, below, above);
      dropped_ += below;  // under the drawn triangle: hidden from every eye above the ground
      const std::int32_t upper = build(begin[side] + below, begin[side] + below + above);
      out_.nodes[static_cast<std::size_t>(node)].front = upper;
      sides[side] = node;
    }
    out_.nodes[static_cast<std::size_t>(root)].back = sides[0];
    out_.nodes[static_cast<std::size_t>(root)].front = sides[1];
    out_.root = root;
    finish();
  }

  std::size_t dropped() const { return dropped_; }

 private:
  // A polygon while building; its plane computed once (split parts inherit it).
  struct Poly {
    std::uint32_t first, count;
    std::int8_t level;
    bool flat = false;  // has a plane (not degenerate)
    PlaneD plane{};
    std::uint32_t surface = 0;
    // A sphere holding the polygon, for the splitter choice's quick side test, and its x and
    // y extent, for axis_split() (set by sphere_of).
    glm::dvec3 centre{0.0};
    double radius = -1.0;
    glm::dvec2 lo{0.0}, hi{0.0};
  };

  // The centre of the polygon's vertex bounds and the distance to its farthest vertex.
  void sphere_of(Poly& p) const {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (std::uint32_t k = 0; k < p.count; ++k) {
      const glm::dvec3 v = pos(ids_[p.first + k]);
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    p.centre = 0.5 * (lo + hi);
    p.lo = glm::dvec2(lo);
    p.hi = glm::dvec2(hi);
    double r2 = 0.0;
    for (std::uint32_t k = 0; k < p.count; ++k) {
      const glm::dvec3 d = pos(ids_[p.first + k]) - p.centre;
      r2 = std::max(r2, glm::dot(d, d));
    }
    p.radius = std::sqrt(r2);
  }

  // The local vertex of `key` (a surface's vertex, or an adopted one), made the first time.
  std::uint32_t local_vertex(std::uint64_t key, const glm::dvec3& position, glm::u8vec4 color,
                             glm::vec2 tcoord) {
    const auto [it, fresh] = local_.try_emplace(key, static_cast<std::uint32_t>(pos_.size()));
    if (fresh) {
      pos_.push_back(position);
      col_.push_back(color);
      tc_.push_back(tcoord);
    }
    return it->second;
  }

  // Takes a polygon of another builder (of an above or outside slot: no lattice vertices), its
  // vertices copied once each.
  void adopt(const SlotBuilder& from, const Poly& p) {
    constexpr std::uint64_t kAdopted = std::uint64_t{0xFFFFFFFEu} << 32;
    const std::uint32_t first = static_cast<std::uint32_t>(ids_.size());
    for (std::uint32_t k = 0; k < p.count; ++k) {
      const std::uint32_t v = from.ids_[p.first + k];
      ids_.push_back(local_vertex(kAdopted | v, from.pos_[v], from.col_[v], from.tc_[v]));
    }
    Poly q = p;
    q.first = first;
    polys_.push_back(q);
  }

  // Appends a finished store built from adopted polygons (staged vertices, no lattice ones) as
  // the front side of node `at`: its nodes, polygons, references and vertices after this
  // store's (children still follow their parents).
  void append(BspStore& side, std::int32_t at) {
    if (side.root < 0) return;
    const auto node0 = static_cast<std::int32_t>(out_.nodes.size());
    const auto poly0 = static_cast<std::uint32_t>(out_.polys.size());
    const auto ref0 = static_cast<std::uint32_t>(out_.refs.size());
    if (!out_.staged) out_.staged = std::make_unique<StagedVertices>();
    StagedVertices& staged = *out_.staged;
    const auto vertex0 = static_cast<std::uint32_t>(staged.positions.size());
    for (BspNode bn : side.nodes) {
      if (bn.back >= 0) bn.back += node0;
      if (bn.front >= 0) bn.front += node0;
      bn.first += poly0;
      out_.nodes.push_back(bn);
    }
    for (Polygon q : side.polys) {
      q.first += ref0;
      out_.polys.push_back(q);
    }
    for (const std::uint32_t r : side.refs) out_.refs.push_back(vertex0 + r);
    if (side.staged) {
      const StagedVertices& more = *side.staged;
      staged.positions.insert(staged.positions.end(), more.positions.begin(), more.positions.end());
      staged.colors.insert(staged.colors.end(), more.colors.begin(), more.colors.end());
      staged.tcoords.insert(staged.tcoords.end(), more.tcoords.begin(), more.tcoords.end());
    }
    out_.nodes[static_cast<std::size_t>(at)].front = side.root + node0;
    out_.pieces += side.pieces;
    out_.dropped += side.dropped;
    out_.top = std::max(out_.top, side.top);
  }

  void all_polys() {
    list_.clear();
    for (std::uint32_t p = 0; p < polys_.size(); ++p) list_.push_back(p);
  }

  glm::dvec3 pos(std::uint32_t v) const {
    return (v & kTerrainRef) ? glm::dvec3(m_.positions[v & ~kTerrainRef]) : pos_[v];
  }
  glm::u8vec4 color(std::uint32_t v) const { return (v & kTerrainRef) ? glm::u8vec4(255) : col_[v]; }
  glm::vec2 tcoord(std::uint32_t v) const { return (v & kTerrainRef) ? kNoTcoord : tc_[v]; }

  std::int32_t new_node(const PlaneD& p) {
    BspNode node;
    node.n = glm::vec3(p.n);
    node.d = static_cast<float>(p.d);
    out_.nodes.push_back(node);
    return static_cast<std::int32_t>(out_.nodes.size() - 1);
  }

  Side classify(const Poly& p, const PlaneD& pl) const {
    bool front = false, back = false;
    for (std::uint32_t k = 0; k < p.count; ++k) {
      const double s = glm::dot(pl.n, pos(ids_[p.first + k])) + pl.d;
      front |= s > eps_;
      back |= s < -eps_;
    }
    return side_of(front, back);
  }

  // Newell's normal; false for a degenerate (zero-area) polygon.
  bool plane_of(const Poly& p, PlaneD& out) const {
    glm::dvec3 n(0.0), c(0.0);
    for (std::uint32_t i = 0; i < p.count; ++i) {
      const glm::dvec3 a = pos(ids_[p.first + i]), b = pos(ids_[p.first + (i + 1) % p.count]);
      n += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
      c += a;
    }
    const double len = glm::length(n);
    if (!(len > eps_ * eps_)) return false;
    out.n = n / len;
    out.d = -glm::dot(out.n, c / static_cast<double>(p.count));
    return true;
  }

  // Sorts list_[begin, end) by `plane` into back then front ranges in place (spanning pieces
  // split, both parts kept; coplanar ones recorded at `node`); nb and nf are their sizes.
  void partition(std::uint32_t begin, std::uint32_t end, const PlaneD& plane, std::int32_t node, std::uint32_t& nb,
                 std::uint32_t& nf) {
    back_list_.clear();
    front_list_.clear();
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::uint32_t p = list_[k];
      switch (classify(polys_[p], plane)) {
        case Side::kCoplanar:
          coplanar_.push_back({node, p});
          break;
        case Side::kBack:
          back_list_.push_back(p);
          break;
        case Side::kFront:
          front_list_.push_back(p);
          break;
        case Side::kSpanning: {
          split_a_.clear();
          split_b_.clear();
          const Poly src = polys_[p];
          // Copy the ids: split_polygon reads them while ids_ may grow.
          tmp_.assign(ids_.begin() + src.first, ids_.begin() + src.first + src.count);
          split_polygon(
              tmp_, eps_, [&](std::uint32_t v) { return glm::dot(plane.n, pos(v)) + plane.d; },
              [&](std::uint32_t a, std::uint32_t b, double t) {
                return cache_.get(a, b, static_cast<std::uint32_t>(node), [&] {
                  pos_.push_back(glm::mix(pos(a), pos(b), t));
                  col_.push_back(mix_color(color(a), color(b), t));
                  tc_.push_back(glm::mix(tcoord(a), tcoord(b), static_cast<float>(t)));
                  return static_cast<std::uint32_t>(pos_.size() - 1);
                });
              },
              split_a_, split_b_);
          for (auto* part : {&split_a_, &split_b_}) {
            if (part->size() < 3) continue;
            (part == &split_a_ ? back_list_ : front_list_).push_back(static_cast<std::uint32_t>(polys_.size()));
            polys_.push_back({static_cast<std::uint32_t>(ids_.size()), static_cast<std::uint32_t>(part->size()), src.level,
                              src.flat, src.plane, src.surface});
            ids_.insert(ids_.end(), part->begin(), part->end());
            sphere_of(polys_.back());
          }
          break;
        }
      }
    }
    nb = static_cast<std::uint32_t>(back_list_.size());
    nf = static_cast<std::uint32_t>(front_list_.size());
    // The parts may outnumber the range (splits): list_ grows; what followed `end` is finished.
    list_.resize(begin + nb + nf);
    std::copy(back_list_.begin(), back_list_.end(), list_.begin() + begin);
    std::copy(front_list_.begin(), front_list_.end(), list_.begin() + begin + nb);
  }

  // The splitter for list_[begin, end): among up to kCandidates polygons spread through the
  // range, the plane spanning the fewest of up to kSamples polygons spread through it, then the
  // most balanced. False when every polygon there is degenerate.
  // Measured on hydrogen.vtk's isosurface (12,000 triangles in one slot) and the benchmark
  // scene: how many polygons a candidate is scored on matters far more than how many
  // candidates there are (16 candidates over 40 samples store 1.63x the input, over 400
  // samples 1.44x, over 1,000 1.37x; 64 candidates over all of them 1.32x). So the samples are
  // many, and each is cheap: its bounding sphere decides its side unless the plane passes
  // through the sphere, and a candidate stops being counted once its spans alone score worse
  // than the best so far. The candidates are screened on 32 of the samples first, and the
  // best few (kFinalists, 3 then) scored on all of them. 16 candidates over 512 samples so:
  // hydrogen 1.47x, the benchmark scene 2.03x, the merge 1.3-1.4x the time of 6 candidates
  // over 40 unscreened (1.73x and 2.18x); 12 over 256: 1.51x and 2.06x, 1.15x the time.
  // Besides the polygons' own planes, vertical planes through the edges of nearly horizontal
  // polygons are candidates: a surface over the ground such as an agl slice is a height field
  // on the volume's lattice, and the vertical planes through its edges order it as the
  // terrain's own planes order the terrain, cutting none of it (as an autopartition of its
  // own tilted planes does). On the benchmark scene (16 candidates over 512 samples) the slice
  // then stores 1.25x its input (1.77x without), everything 2.01x (2.37x); hydrogen.vtk's
  // closed surface 1.43x (1.37x: for a blob these planes win locally and cost more below; for
  // steeper polygons they are not tried).
  // Set-up per call dominated (an autopartition makes about one node per polygon, most with a
  // handful of polygons): sets of at most kFew go to choose_among_few(), and the samples'
  // vertices are packed as floats for score(). The slots' building on the benchmark scene over
  // N44W072 went from 492 to 372 ms of CPU, with 228,673 pieces stored instead of 229,369 (hydrogen.vtk: 1.49x its input).

  // The side of sample k of the plane n.p + d = 0 (relative to origin_), in single precision
  // with a tolerance of the rounding of the sample's coordinates (about four units in the last
  // place of its distance from origin_, at least eps_): only for scoring (partition()
  // classifies exactly). A tolerance fixed for the whole window (4 cm for a 100 km window) let
  // the scoring take nearly coplanar small polygons for coplanar: hydrogen.vtk's isosurface,
  // 64 m across above the bundled DEM, stored 2.06x its input; with 16 units 1.59x, with 4
  // 1.49x (1.47x with the exact classification).
  Side classify_sample(std::uint32_t k, const glm::vec3& n, float d) const {
    const std::uint32_t end = k + 1 < sample_first_.size() ? sample_first_[k + 1] : static_cast<std::uint32_t>(sample_vertices_.size());
    const float tolerance = sample_tolerance_[k];
    bool front = false, back = false;
    for (std::uint32_t v = sample_first_[k]; v < end; ++v) {
      const glm::vec3& p = sample_vertices_[v];
      const float s = n.x * p.x + n.y * p.y + n.z * p.z + d;
      front |= s > tolerance;
      back |= s < -tolerance;
    }
    return side_of(front, back);
  }

  // A span costs as much as this much imbalance. 16 rather than 8 (2026-12-07, side by side):
  // 0.9% fewer pieces on the benchmark scene over N44W072 (221,979 against 223,988) and 0.8-3.2%
  // fewer of hydrogen.vtk's isosurface over five cameras, merges as fast within the noise; 20
  // gave about the same, 4 stored 9% more of hydrogen.vtk's.
  static constexpr double kW = 16.0;

  // The score of a splitter (kW per span plus the imbalance) over every stride-th of the
  // samples choose() packed; infinity once it cannot be below `cutoff`.
  double score(const PlaneD& plane, std::uint32_t samples, std::uint32_t stride, double cutoff) const {
    const glm::vec3 n(plane.n);
    const auto d = static_cast<float>(plane.d + glm::dot(plane.n, origin_));
    // Sides by sphere first (a loop without branches, which lists the samples whose sphere the
    // plane passes through), then those listed, by their vertices.
    int front = 0, back = 0;
    std::uint32_t* straddlers = straddlers_.data();
    std::uint32_t straddling = 0;
    for (std::uint32_t k = 0; k < samples; k += stride) {
      const glm::vec4& sp = sample_spheres_[k];
      const float dist = n.x * sp.x + n.y * sp.y + n.z * sp.z + d;
      const bool f = dist > sp.w, b = dist < -sp.w;
      front += f;
      back += b;
      straddlers[straddling] = k;  // kept only when neither side
      straddling += !(f || b);
    }
    // The polygons the plane passes through the spheres of can lessen the imbalance by at
    // most their number: a candidate that cannot win even so is not looked at further.
    if (std::abs(front - back) - static_cast<int>(straddling) >= cutoff) return std::numeric_limits<double>::infinity();
    int spans = 0;
    for (std::uint32_t s = 0; s < straddling; ++s) {
      switch (classify_sample(straddlers[s], n, d)) {
        case Side::kSpanning:
          if (kW * ++spans >= cutoff) return std::numeric_limits<double>::infinity();
          break;
        case Side::kFront: ++front; break;
        case Side::kBack: ++back; break;
        case Side::kCoplanar: break;
      }
    }
    return kW * spans + std::abs(front - back);
  }

  // choose() for at most kFew polygons, which most calls are (an autopartition ends in a node
  // per polygon): each polygon's own plane scored exactly on the others, with no sampling.
  // The sampled scoring's set-up cost several times the work here.
  static constexpr std::uint32_t kFew = 4;
  bool choose_among_few(std::uint32_t begin, std::uint32_t end, PlaneD& best) const {
    double best_score = std::numeric_limits<double>::max();
    for (std::uint32_t c = begin; c < end; ++c) {
      const Poly& candidate = polys_[list_[c]];
      if (!candidate.flat) continue;
      int spans = 0, front = 0, back = 0;
      for (std::uint32_t k = begin; k < end; ++k) {
        if (k == c) continue;
        switch (classify(polys_[list_[k]], candidate.plane)) {
          case Side::kSpanning: ++spans; break;
          case Side::kFront: ++front; break;
          case Side::kBack: ++back; break;
          case Side::kCoplanar: break;
        }
      }
      const double score = kW * spans + std::abs(front - back);
      if (score < best_score) {
        best_score = score;
        best = candidate.plane;
        if (spans == 0 && std::abs(front - back) <= 1) break;
      }
    }
    return best_score < std::numeric_limits<double>::max();
  }

  // The most balanced plane x = c or y = c that spans none of list_[begin, end) and leaves at
  // least a quarter of them on each side, if there is one: found exactly by sweeping the
  // polygons' extents along each axis (sorted by their low end, a plane can go where every
  // extent before lies at or below it and every one after at or above it).
  // Such a plane is as good a splitter as there is (it cuts nothing), and it costs a sort
  // instead of the sampled scoring. It exists wherever the polygons lie in columns apart:
  // above all a slice of a geographic volume, whose lattice lines lie in the planes x = c and
  // y = c of the scene frame (as the terrain's do), so that its cells separate along them down
  // to single cells; and the separate parts of an isosurface. Planes z = c as well were tried
  // (benchmark scenes, side by side): 56 fewer pieces of 224,000, and merges no faster.
  bool axis_split(std::uint32_t begin, std::uint32_t end, PlaneD& best) {
    const std::uint32_t size = end - begin;
    std::uint32_t best_small = (size + 3) / 4;  // the smaller side must hold at least this many
    bool found = false;
    for (int a = 0; a < 2; ++a) {
      extents_.clear();
      for (std::uint32_t k = begin; k < end; ++k) {
        const Poly& p = polys_[list_[k]];
        extents_.push_back({p.lo[a], p.hi[a]});
      }
      std::sort(extents_.begin(), extents_.end());
      double top = -std::numeric_limits<double>::infinity();
      for (std::uint32_t k = 0; k + 1 < size; ++k) {
        top = std::max(top, extents_[k].second);
        // Planes at `top` between the first k + 1 extents and the rest: none spans.
        if (extents_[k + 1].first < top - eps_) continue;
        const std::uint32_t small = std::min(k + 1, size - k - 1);
        if (small < best_small || (found && small == best_small)) continue;
        best_small = small;
        best.n = glm::dvec3(a == 0 ? 1.0 : 0.0, a == 1 ? 1.0 : 0.0, 0.0);
        best.d = -top;
        found = true;
      }
    }
    return found;
  }

  // `axis`: try axis_split() first (build() stops trying below a range that had none).
  bool choose(std::uint32_t begin, std::uint32_t end, PlaneD& best, bool axis, bool& split_on_axis) {
    constexpr std::uint32_t kCandidates = 16, kSamples = 512;
    constexpr double kFlat = 0.8;  // |n.z| of a polygon whose edge's vertical plane is a candidate
    const std::uint32_t size = end - begin;
    split_on_axis = false;
    if (axis && size >= 2 && axis_split(begin, end, best)) {
      split_on_axis = true;
      return true;
    }
    if (size <= kFew) return choose_among_few(begin, end, best);
    const std::uint32_t candidates = std::min(size, kCandidates), samples = std::min(size, kSamples);
    // The samples' spheres, packed (floats suffice: they only guide the choice; the partition
    // classifies exactly).
    sample_spheres_.clear();
    sample_polys_.clear();
    sample_first_.clear();
    sample_tolerance_.clear();
    sample_vertices_.clear();
    straddlers_.resize(std::max<std::size_t>(straddlers_.size(), samples));
    for (std::uint32_t k = 0; k < samples; ++k) {
      const std::uint32_t q = list_[begin + static_cast<std::uint32_t>(static_cast<std::uint64_t>(k) * size / samples)];
      const Poly& p = polys_[q];
      sample_spheres_.push_back(glm::vec4(glm::vec3(p.centre - origin_), static_cast<float>(p.radius + eps_)));
      sample_polys_.push_back(q);
      sample_first_.push_back(static_cast<std::uint32_t>(sample_vertices_.size()));
      const double reach = glm::length(p.centre - origin_) + p.radius;
      sample_tolerance_.push_back(static_cast<float>(std::max(eps_, 2.5e-7 * reach)));
      for (std::uint32_t v = 0; v < p.count; ++v) sample_vertices_.push_back(glm::vec3(pos(ids_[p.first + v]) - origin_));
    }
    // Candidates 0 .. candidates-1: the polygons' own planes; then, for every second of those
    // polygons that lies within about 37 degrees of horizontal, the vertical plane through its
    // longest edge.
    candidate_planes_.clear();
    for (std::uint32_t c = 0; c < candidates + candidates / 2; ++c) {
      const bool vertical = c >= candidates;
      const std::uint32_t which = vertical ? 2 * (c - candidates) + 1 : c;
      const Poly& candidate = polys_[list_[begin + static_cast<std::uint32_t>(static_cast<std::uint64_t>(which) * size / candidates)]];
      if (!candidate.flat) continue;
      if (!vertical) {
        candidate_planes_.push_back({candidate.plane, false});
        continue;
      }
      if (std::abs(candidate.plane.n.z) < kFlat) continue;
      PlaneD vplane;
      double best_len = 0;
      for (std::uint32_t k = 0; k < candidate.count; ++k) {
        const glm::dvec3 a = pos(ids_[candidate.first + k]), b = pos(ids_[candidate.first + (k + 1) % candidate.count]);
        const glm::dvec2 e(b.x - a.x, b.y - a.y);
        const double len = glm::length(e);
        if (len > best_len) {
          best_len = len;
          vplane.n = glm::dvec3(-e.y / len, e.x / len, 0.0);
          vplane.d = -glm::dot(vplane.n, a);
        }
      }
      if (best_len > 1e-6) candidate_planes_.push_back({vplane, true});
    }
    // Each candidate is scored first on every stride-th sample, and only the few best then on
    // all of them: about a third of the work. Six finalists rather than three (2026-12-07):
    // hydrogen.vtk's isosurface above the bundled DEM (enu:45.5,6.5,1900) stores 1.40-1.46x its
    // input over five cameras instead of 1.46-1.53x (4: 1.45-1.49x; 10: 1.39-1.45x; every
    // candidate on every sample: 1.40-1.47x, the greedy choice being no better for it); the
    // benchmark scene over N44W072 220,717 pieces instead of 221,979, with merges and edits
    // as fast within the noise (two alternating translucency runs each). Screening on 64
    // samples with three finalists gave 1.41-1.48x.
    constexpr std::uint32_t kScreen = 32, kFinalists = 6;
    const std::uint32_t stride = samples > 2 * kScreen ? samples / kScreen : 1;
    if (stride > 1 && candidate_planes_.size() > kFinalists) {
      std::vector<std::pair<double, std::size_t>>& ranked = ranked_;
      ranked.clear();
      for (std::size_t c = 0; c < candidate_planes_.size(); ++c) {
        ranked.push_back({score(candidate_planes_[c].plane, samples, stride, std::numeric_limits<double>::max()), c});
      }
      std::partial_sort(ranked.begin(), ranked.begin() + kFinalists, ranked.end());
      std::vector<Candidate> finalists;
      for (std::uint32_t k = 0; k < kFinalists; ++k) finalists.push_back(candidate_planes_[ranked[k].second]);
      candidate_planes_ = std::move(finalists);
    }
    double best_score = std::numeric_limits<double>::max();
    bool found = false;
    for (const Candidate& candidate : candidate_planes_) {
      const double s = score(candidate.plane, samples, 1, best_score);
      if (!(s < best_score)) continue;
      if (candidate.vertical) {
        // A plane through no polygon removes none: it must leave polygons on both sides, found
        // exactly, so that each side is smaller than the range.
        bool has_front = false, has_back = false;
        for (std::uint32_t k = 0; k < samples && !(has_front && has_back); ++k) {
          const Side side = classify(polys_[sample_polys_[k]], candidate.plane);
          has_front |= side == Side::kFront;
          has_back |= side == Side::kBack;
        }
        if (!has_front || !has_back) continue;
      }
      best_score = s;
      best = candidate.plane;
      found = true;
    }
    if (found) return true;
    for (std::uint32_t k = begin; k < end; ++k) {
      if (polys_[list_[k]].flat) {
        best = polys_[list_[k]].plane;
        return true;
      }
    }
    return false;
  }

  // An autopartition of list_[begin, end), with an explicit stack (a BSP of parallel layers is
  // as deep as it has polygons). Returns its root, -1 when empty.
  std::int32_t build(std::uint32_t begin, std::uint32_t end) {
    struct Task {
      std::int32_t parent;  // -1: the root
      bool front;
      std::uint32_t begin, end;
      bool axis;  // try axis_split(): the root, and below an axis split
    };
    std::int32_t root = -1;
    std::vector<Task> tasks{{-1, false, begin, end, true}};
    const std::uint32_t keep = end;  // list_ beyond the range may be reused; restore its size
    while (!tasks.empty()) {
      const Task t = tasks.back();
      tasks.pop_back();
      if (t.begin == t.end) continue;
      list_.resize(t.end);  // what lay beyond belonged to finished tasks
      PlaneD plane;
      bool on_axis = false;
      if (!choose(t.begin, t.end, plane, t.axis, on_axis)) continue;  // only degenerate polygons: nothing to draw
      const std::int32_t node = new_node(plane);
      if (t.parent < 0) {
        root = node;
      } else if (t.front) {
        out_.nodes[static_cast<std::size_t>(t.parent)].front = node;
      } else {
        out_.nodes[static_cast<std::size_t>(t.parent)].back = node;
      }
      std::uint32_t nb = 0, nf = 0;
      partition(t.begin, t.end, plane, node, nb, nf);
      tasks.push_back({node, false, t.begin, t.begin + nb, on_axis});
      tasks.push_back({node, true, t.begin + nb, t.begin + nb + nf, on_axis});
    }
    list_.resize(keep);
    return root;
  }

  // Inserts list_ into the existing BSP: each task carries its own list, since new subtrees
  // (build) use list_ as their stack.
  void insert() {
    struct Task {
      std::int32_t node;
      std::vector<std::uint32_t> list;
    };
    std::vector<Task> tasks;
    tasks.push_back({out_.root, list_});
    while (!tasks.empty()) {
      Task t = std::move(tasks.back());
      tasks.pop_back();
      const BspNode bn = out_.nodes[static_cast<std::size_t>(t.node)];
      const PlaneD plane{glm::dvec3(bn.n), static_cast<double>(bn.d)};
      list_ = std::move(t.list);
      std::uint32_t nb = 0, nf = 0;
      partition(0, static_cast<std::uint32_t>(list_.size()), plane, t.node, nb, nf);
      std::vector<std::uint32_t> sides[2] = {std::vector<std::uint32_t>(list_.begin(), list_.begin() + nb),
                                             std::vector<std::uint32_t>(list_.begin() + nb, list_.begin() + nb + nf)};
      for (int side = 0; side < 2; ++side) {
        if (sides[side].empty()) continue;
        const std::int32_t child = side == 0 ? bn.back : bn.front;
        if (child == kDropSide) {
          dropped_ += sides[side].size();
        } else if (child >= 0) {
          tasks.push_back({child, std::move(sides[side])});
        } else {
          list_ = std::move(sides[side]);
          const std::int32_t sub = build(0, static_cast<std::uint32_t>(list_.size()));
          BspNode& parent = out_.nodes[static_cast<std::size_t>(t.node)];
          (side == 0 ? parent.back : parent.front) = sub;
        }
      }
    }
  }

  // Lays out every node's polygons again: its old ones, then those added now (with new
  // references: kTerrainRef | lattice vertex, or an index into the staged vertices, of which
  // only those used are kept, as floats).
  void finish() {
    std::stable_sort(coplanar_.begin(), coplanar_.end(),
                     [](const std::pair<std::int32_t, std::uint32_t>& a, const std::pair<std::int32_t, std::uint32_t>& b) {
                       return a.first < b.first;
                     });
    std::vector<Polygon> old = std::move(out_.polys);
    out_.polys.clear();
    out_.polys.reserve(old.size() + coplanar_.size());
    out_.staged_refs = static_cast<std::uint32_t>(out_.refs.size());
    std::vector<std::uint32_t> remap(pos_.size(), std::numeric_limits<std::uint32_t>::max());
    std::size_t c = 0;
    for (std::size_t node = 0; node < out_.nodes.size(); ++node) {
      BspNode& bn = out_.nodes[node];
      const std::uint32_t first = static_cast<std::uint32_t>(out_.polys.size());
      out_.polys.insert(out_.polys.end(), old.begin() + bn.first, old.begin() + bn.first + bn.count);
      for (; c < coplanar_.size() && coplanar_[c].first == static_cast<std::int32_t>(node); ++c) {
        const Poly& p = polys_[coplanar_[c].second];
        Polygon q;
        q.first = static_cast<std::uint32_t>(out_.refs.size());
        q.count = static_cast<std::uint16_t>(p.count);
        q.level = p.level;
        q.surface = p.surface;
        for (std::uint32_t k = 0; k < p.count; ++k) {
          std::uint32_t v = ids_[p.first + k];
          if (!(v & kTerrainRef)) {
            if (remap[v] == std::numeric_limits<std::uint32_t>::max()) {
              if (!out_.staged) out_.staged = std::make_unique<StagedVertices>();
              StagedVertices& staged = *out_.staged;
              remap[v] = static_cast<std::uint32_t>(staged.positions.size());
              staged.positions.emplace_back(pos_[v]);
              staged.colors.push_back(col_[v]);
              if (m_.has_tcoords) staged.tcoords.push_back(tc_[v]);
              out_.top = std::max(out_.top, static_cast<float>(pos_[v].z));
            }
            v = remap[v];
          }
          out_.refs.push_back(v);
        }
        out_.polys.push_back(q);
        if (p.level == kMergedLevel) ++out_.pieces;
      }
      bn.first = first;
      bn.count = static_cast<std::uint32_t>(out_.polys.size()) - first;
    }
    out_.dropped += dropped_;
    out_.nodes.shrink_to_fit();
    out_.polys.shrink_to_fit();
    out_.refs.shrink_to_fit();
  }

  const TerrainTree::Impl& m_;
  BspStore& out_;
  double eps_ = 0.0;
  std::unordered_map<std::uint64_t, std::uint32_t> local_;  // (surface, vertex) -> local vertex
  std::vector<glm::dvec3> pos_;
  std::vector<glm::u8vec4> col_;
  std::vector<glm::vec2> tc_;
  std::vector<Poly> polys_;
  std::vector<std::uint32_t> ids_, list_, back_list_, front_list_, split_a_, split_b_, tmp_;
  std::vector<std::pair<std::int32_t, std::uint32_t>> coplanar_;  // (node, polygon)
  EdgeCache cache_;
  std::size_t dropped_ = 0;
  glm::dvec3 origin_{0.0};  // the window's centre: the samples' spheres are relative to it
  struct Candidate {
    PlaneD plane;
    bool vertical;  // through no polygon (choose())
  };
  std::vector<Candidate> candidate_planes_;
  std::vector<std::pair<double, double>> extents_;  // axis_split(): (low, high) along one axis
  std::vector<std::pair<double, std::size_t>> ranked_;
  std::vector<glm::vec4> sample_spheres_;  // choose(): centre, radius plus the tolerance
  std::vector<std::uint32_t> sample_polys_;
  // choose(): the samples' vertices relative to origin_, packed (sample k's from
  // sample_first_[k] to sample_first_[k + 1], or to the end for the last).
  std::vector<std::uint32_t> sample_first_;
  std::vector<float> sample_tolerance_;  // classify_sample()'s, per sample
  std::vector<glm::vec3> sample_vertices_;
  mutable std::vector<std::uint32_t> straddlers_;  // score(): the samples the plane passes through the spheres of
};

// The cell (level, ci, cj) of a global cell id.
struct CellName {
  int level, ci, cj;
};
CellName cell_name(const TerrainTree::Impl& m, std::uint32_t id) {
  int level = 0;
  while (level + 1 < m.levels && m.level_offset[static_cast<std::size_t>(level + 1)] <= id) ++level;
  const auto local = id - m.level_offset[static_cast<std::size_t>(level)];
  const auto c = static_cast<std::uint32_t>(m.cells_at(level));
  return {level, static_cast<int>(local % c), static_cast<int>(local / c)};
}

bool is_low(SlotKey key) { return key < kOutsideKey0 && key % 2 == static_cast<SlotKey>(SlotKind::kLow); }

// Builds a slot's small BSP from what `builder` was given, or inserts it into the BSP the
// store already has: a low slot's against its cell's two triangles, any other's as an
// autopartition.
void build_slot(const TerrainTree::Impl& m, SlotKey key, SlotBuilder& builder) {
  if (is_low(key)) {
    const CellName c = cell_name(m, key / 2);
    builder.build_low(c.level, c.ci, c.cj);
  } else {
    builder.build_autopartition();
  }
}

// Builds a slot's small BSP afresh from the pieces every surface sent there, and notes what
// the build made of them (BspStore::fresh_pieces).
void build_anew(const TerrainTree::Impl& m, Slot& slot) {
  auto store = std::make_shared<BspStore>();
  slot.store = store;
  SlotBuilder builder(m, *store);
  std::uint32_t arrivals = 0;
  for (const auto& [id, s] : m.surfaces) {
    s.for_each_arrival(slot.key, [&](std::span<const std::uint32_t> piece) {
      builder.add(s, id, piece);
      ++arrivals;
    });
  }
  build_slot(m, slot.key, builder);
  store->fresh_pieces = store->pieces;
  store->arrivals = store->fresh_arrivals = arrivals;
}

template <class T>
void release(std::vector<T>& v) {
  std::vector<T>().swap(v);
}

// Unlinks the nodes a removal left vacant: no polygon of their own, no dropped side, and
// nothing on one of their sides. Such a plane separates nothing, but it would go on cutting
// whatever is inserted later (after a slice moved, the planes of its old pieces cut the new
// ones). The node is replaced by its other side (or by nothing); unlinked nodes stay in
// `nodes`, unreached, until the slot is built anew. Children still follow their parents.
void prune_vacant(BspStore& st) {
  std::vector<std::uint32_t> held(st.nodes.size(), 0);  // polygons in each node's subtree
  for (std::size_t k = st.nodes.size(); k-- > 0;) {
    const BspNode& bn = st.nodes[k];
    held[k] = bn.count;
    for (const std::int32_t child : {bn.back, bn.front})
      if (child >= 0) held[k] += held[static_cast<std::size_t>(child)];
  }
  const auto empty = [&](std::int32_t c) { return c == -1 || (c >= 0 && held[static_cast<std::size_t>(c)] == 0); };
  const auto resolve = [&](std::int32_t c) {
    while (c >= 0) {
      const BspNode& bn = st.nodes[static_cast<std::size_t>(c)];
      if (bn.count != 0 || bn.back == kDropSide || bn.front == kDropSide) return c;
      if (empty(bn.back) && empty(bn.front)) return std::int32_t{-1};
      if (!empty(bn.back) && !empty(bn.front)) return c;
      c = empty(bn.back) ? bn.front : bn.back;
    }
    return c;
  };
  st.root = resolve(st.root);
  for (BspNode& bn : st.nodes) {
    bn.back = resolve(bn.back);
    bn.front = resolve(bn.front);
  }
}

// Removes the polygons of the surfaces in `ids` (sorted) from a store and prunes the nodes
// left vacant; returns the references dropped with them. Its top becomes that of what stays.
std::size_t remove_surfaces(BspStore& st, const std::vector<std::uint32_t>& ids, const std::vector<glm::vec3>& positions) {
  std::vector<Polygon> polys;
  std::vector<std::uint32_t> refs;
  polys.reserve(st.polys.size());
  refs.reserve(st.refs.size());
  st.pieces = 0;
  st.top = -1e30f;
  for (BspNode& bn : st.nodes) {
    const std::uint32_t first = static_cast<std::uint32_t>(polys.size());
    for (std::uint32_t k = bn.first; k < bn.first + bn.count; ++k) {
      Polygon p = st.polys[k];
      if (p.surface != kTerrainSurface && std::binary_search(ids.begin(), ids.end(), p.surface)) continue;
      const std::uint32_t from = p.first;
      p.first = static_cast<std::uint32_t>(refs.size());
      refs.insert(refs.end(), st.refs.begin() + from, st.refs.begin() + from + p.count);
      if (p.surface != kTerrainSurface) {
        ++st.pieces;
        for (std::uint32_t r = p.first; r < p.first + p.count; ++r) st.top = std::max(st.top, positions[refs[r]].z);
      }
      polys.push_back(p);
    }
    bn.first = first;
    bn.count = static_cast<std::uint32_t>(polys.size()) - first;
  }
  prune_vacant(st);
  const std::size_t removed = st.refs.size() - refs.size();
  refs.shrink_to_fit();
  polys.shrink_to_fit();
  st.refs = std::move(refs);
  st.polys = std::move(polys);
  st.staged_refs = static_cast<std::uint32_t>(st.refs.size());
  return removed;
}

}  // namespace

void TerrainTree::Impl::distribute(SurfacePieces& s) const { Distributor(*this, s).run(); }

void TerrainTree::Impl::distribute_all(const std::vector<SurfacePieces*>& list) const {
  // A surface of more than kChunk triangles is sent in chunks of about kChunk, each through its
  // own Distributor on a copy of the surface's input vertices, and the chunks' pieces joined
  // (theirs by slot, in chunk order: the order one Distributor would give) with their new
  // vertices renumbered after one another. An edge two chunks split gets a vertex in each, at
  // the same position (split_axis cuts from the same endpoint). One edit's slice or isosurface
  // is then distributed on every core instead of one.
  constexpr std::size_t kChunk = 8192;
  struct Task {
    std::size_t surface;
    std::size_t first, last;  // triangles
    SurfacePieces part;       // unused when the surface is one chunk
  };
  std::vector<Task> tasks;
  std::vector<std::size_t> first_task(list.size() + 1, 0);
  for (std::size_t k = 0; k < list.size(); ++k) {
    first_task[k] = tasks.size();
    const std::size_t triangles = list[k]->triangles.size() / 3;
    const std::size_t chunks = std::max<std::size_t>(1, (triangles + kChunk / 2) / kChunk);
    for (std::size_t c = 0; c < chunks; ++c) tasks.push_back({k, triangles * c / chunks, triangles * (c + 1) / chunks, {}});
  }
  first_task[list.size()] = tasks.size();
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, tasks.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          Task& task = tasks[t];
          SurfacePieces& s = *list[task.surface];
          if (first_task[task.surface + 1] - first_task[task.surface] == 1) {
            distribute(s);
            continue;
          }
          SurfacePieces& part = task.part;
          part.input_vertices = s.input_vertices;
          part.input_triangles = task.last - task.first;
          part.triangles.assign(s.triangles.begin() + static_cast<std::ptrdiff_t>(3 * task.first),
                                s.triangles.begin() + static_cast<std::ptrdiff_t>(3 * task.last));
          part.vertices.assign(s.vertices.begin(), s.vertices.begin() + static_cast<std::ptrdiff_t>(s.input_vertices));
          part.colors.assign(s.colors.begin(), s.colors.begin() + static_cast<std::ptrdiff_t>(s.input_vertices));
          if (!s.tcoords.empty()) {
            part.tcoords.assign(s.tcoords.begin(), s.tcoords.begin() + static_cast<std::ptrdiff_t>(s.input_vertices));
          }
          distribute(part);
        }
      },
      tbb::simple_partitioner());
  tbb::parallel_for(std::size_t{0}, list.size(), [&](std::size_t k) {
    const std::size_t t0 = first_task[k], t1 = first_task[k + 1];
    if (t1 - t0 == 1) return;
    SurfacePieces& s = *list[k];
    const std::size_t input = s.input_vertices;
    s.vertices.resize(input);
    s.colors.resize(input);
    if (!s.tcoords.empty()) s.tcoords.resize(input);
    s.dropped = 0;
    std::vector<std::uint32_t> offset(t1 - t0);  // what a chunk's new vertex ids gain
    for (std::size_t t = t0; t < t1; ++t) {
      const SurfacePieces& part = tasks[t].part;
      offset[t - t0] = static_cast<std::uint32_t>(s.vertices.size() - input);
      s.vertices.insert(s.vertices.end(), part.vertices.begin() + static_cast<std::ptrdiff_t>(input), part.vertices.end());
      s.colors.insert(s.colors.end(), part.colors.begin() + static_cast<std::ptrdiff_t>(input), part.colors.end());
      if (!s.tcoords.empty()) s.tcoords.insert(s.tcoords.end(), part.tcoords.begin() + static_cast<std::ptrdiff_t>(input), part.tcoords.end());
      s.dropped += part.dropped;
    }
    // The chunks' runs joined by slot (a k-way merge of sorted run lists).
    s.runs.clear();
    s.counts.clear();
    s.refs.clear();
    std::vector<std::size_t> at(t1 - t0, 0);
    for (;;) {
      SlotKey slot = std::numeric_limits<SlotKey>::max();
      bool any = false;
      for (std::size_t c = 0; c < at.size(); ++c) {
        const SurfacePieces& part = tasks[t0 + c].part;
        if (at[c] < part.runs.size()) {
          slot = std::min(slot, part.runs[at[c]].slot);
          any = true;
        }
      }
      if (!any) break;
      s.runs.push_back({slot, static_cast<std::uint32_t>(s.counts.size()), static_cast<std::uint32_t>(s.refs.size())});
      for (std::size_t c = 0; c < at.size(); ++c) {
        const SurfacePieces& part = tasks[t0 + c].part;
        if (at[c] >= part.runs.size() || part.runs[at[c]].slot != slot) continue;
        const std::size_t r = at[c]++;
        const std::uint32_t p0 = part.runs[r].piece0;
        const std::uint32_t p1 = r + 1 < part.runs.size() ? part.runs[r + 1].piece0 : static_cast<std::uint32_t>(part.counts.size());
        const std::uint32_t ref0 = part.runs[r].ref0;
        const std::uint32_t ref1 = r + 1 < part.runs.size() ? part.runs[r + 1].ref0 : static_cast<std::uint32_t>(part.refs.size());
        s.counts.insert(s.counts.end(), part.counts.begin() + p0, part.counts.begin() + p1);
        for (std::uint32_t q = ref0; q < ref1; ++q) {
          const std::uint32_t v = part.refs[q];
          s.refs.push_back(v < input ? v : v + offset[c]);
        }
      }
    }
    s.runs.shrink_to_fit();
    s.counts.shrink_to_fit();
    s.refs.shrink_to_fit();
    s.vertices.shrink_to_fit();
    s.colors.shrink_to_fit();
    s.tcoords.shrink_to_fit();
  });
}

void ContentIndex::build(std::size_t cells, const std::vector<std::uint32_t>& sorted_cells) {
  bits.assign((cells + 63) / 64, 0);
  for (std::uint32_t c : sorted_cells) bits[c >> 6] |= std::uint64_t{1} << (c & 63u);
  rank.resize(bits.size());
  std::uint32_t count = 0;
  for (std::size_t w = 0; w < bits.size(); ++w) {
    rank[w] = count;
    count += static_cast<std::uint32_t>(__builtin_popcountll(bits[w]));
  }
}

void TerrainTree::Impl::flush(BspStore& st) {
  const auto base = static_cast<std::uint32_t>(positions.size());
  if (st.staged) {
    const StagedVertices& staged = *st.staged;
    if (positions.capacity() < positions.size() + staged.positions.size()) {
      // Grown by a quarter, not doubled: lazily built slots arrive one by one.
      const std::size_t want =
          std::max(positions.size() + staged.positions.size(), positions.size() + (positions.size() - merged_base()) / 4);
      positions.reserve(want);
      merged_colors.reserve(want - merged_base());
      if (has_tcoords) merged_tcoords.reserve(want - merged_base());
    }
    positions.insert(positions.end(), staged.positions.begin(), staged.positions.end());
    merged_colors.insert(merged_colors.end(), staged.colors.begin(), staged.colors.end());
    merged_tcoords.insert(merged_tcoords.end(), staged.tcoords.begin(), staged.tcoords.end());
  }
  for (std::size_t r = st.staged_refs; r < st.refs.size(); ++r) {
    const std::uint32_t v = st.refs[r];
    st.refs[r] = (v & kTerrainRef) ? (v & ~kTerrainRef) : base + v;
  }
  st.staged_refs = static_cast<std::uint32_t>(st.refs.size());
  st.staged.reset();
}

void TerrainTree::Impl::compact() {
  const std::uint32_t base = merged_base();
  std::vector<std::uint32_t> remap(positions.size() - base, std::numeric_limits<std::uint32_t>::max());
  std::vector<glm::vec3> kept_positions(positions.begin(), positions.begin() + base);
  std::vector<glm::u8vec4> kept_colors;
  std::vector<glm::vec2> kept_tcoords;
  for (Slot& slot : slots) {
    if (!slot.store) continue;
    for (std::uint32_t& v : slot.own_store().refs) {
      if (v < base) continue;
      std::uint32_t& r = remap[v - base];
      if (r == std::numeric_limits<std::uint32_t>::max()) {
        r = static_cast<std::uint32_t>(kept_positions.size());
        kept_positions.push_back(positions[v]);
        kept_colors.push_back(merged_colors[v - base]);
        if (has_tcoords) kept_tcoords.push_back(merged_tcoords[v - base]);
      }
      v = r;
    }
  }
  kept_positions.shrink_to_fit();
  kept_colors.shrink_to_fit();
  positions = std::move(kept_positions);
  merged_colors = std::move(kept_colors);
  merged_tcoords = std::move(kept_tcoords);
  dead_refs = 0;
  ++merged_version;
}

void TerrainTree::Impl::make_content() {
  content_index = {};
  release(content);
  release(top_content);
  for (auto& side : outside) side.clear();
  // The cells with content and their ancestors, marked in a bitmap (a cell's ancestors are
  // marked before it is: the walk up stops at the first marked one), then listed in id order.
  // The slots are sorted by key, so a cell's two (above and low) come one after the other:
  // each cell is looked at once. Measured on the benchmark's Utah scene (92,000 slots), this
  // and the slots' own tops (Slot::top, no store read) took make_content from 5.9-8.2 ms to
  // 4.1-6.4 ms per edit or slide (2026-12-07, the translucency suite's edits and slides).
  std::vector<std::uint64_t> marked((total_cells + 63) / 64, 0);
  constexpr std::uint32_t kNoCell = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t previous = kNoCell;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    const SlotKey key = slots[k].key;
    if (key >= kOutsideKey0) {
      outside[static_cast<std::size_t>(outside_place(key).side)].push_back(static_cast<std::int32_t>(k));
      continue;
    }
    if (key / 2 == previous) continue;
    previous = key / 2;
    CellName c = cell_name(*this, key / 2);
    for (; c.level >= 0; --c.level, c.ci /= 2, c.cj /= 2) {
      const std::uint32_t id = cell_id(c.level, c.ci, c.cj);
      std::uint64_t& word = marked[id >> 6];
      const std::uint64_t bit = std::uint64_t{1} << (id & 63u);
      if (word & bit) break;
      word |= bit;
    }
  }
  std::vector<std::uint32_t> cells;
  for (std::size_t w = 0; w < marked.size(); ++w) {
    for (std::uint64_t b = marked[w]; b != 0; b &= b - 1) {
      cells.push_back(static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(__builtin_ctzll(b))));
    }
  }
  if (cells.empty()) return;
  content_index.build(total_cells, cells);
  content.assign(cells.size(), {-1, -1, -std::numeric_limits<float>::infinity()});
  std::int32_t record = -1;
  previous = kNoCell;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    const SlotKey key = slots[k].key;
    if (key >= kOutsideKey0) continue;
    if (key / 2 != previous) record = content_index.find(key / 2);
    previous = key / 2;
    CellContent& c = content[static_cast<std::size_t>(record)];
    (key % 2 == static_cast<SlotKey>(SlotKind::kAbove) ? c.above : c.low) = static_cast<std::int32_t>(k);
    c.top = std::max(c.top, slots[k].top);
  }
  // Tops up the tree, finest first (cell ids grow with the level): every ancestor holds the
  // highest content of its subtree; the top levels in top_content.
  top_content.resize(static_cast<std::size_t>(top));
  for (int l = -top; l < 0; ++l) {
    top_content[static_cast<std::size_t>(l + top)].assign(static_cast<std::size_t>(cells_at(l)) * static_cast<std::size_t>(cells_at(l)),
                                                         -std::numeric_limits<float>::infinity());
  }
  for (std::size_t k = cells.size(); k-- > 0;) {
    const CellName c = cell_name(*this, cells[k]);
    const float t = content[k].top;
    if (c.level > 0) {
      CellContent& parent = content[static_cast<std::size_t>(content_index.find(cell_id(c.level - 1, c.ci / 2, c.cj / 2)))];
      parent.top = std::max(parent.top, t);
    } else if (top > 0) {
      float& p = top_content[static_cast<std::size_t>(top - 1)][static_cast<std::size_t>((c.cj / 2) * cells_at(-1) + c.ci / 2)];
      p = std::max(p, t);
    }
  }
  for (int l = -1; l > -top; --l) {
    const int c = cells_at(l);
    for (int cj = 0; cj < c; ++cj)
      for (int ci = 0; ci < c; ++ci) {
        const float t = top_content[static_cast<std::size_t>(l + top)][static_cast<std::size_t>(cj * c + ci)];
        float& p = top_content[static_cast<std::size_t>(l - 1 + top)][static_cast<std::size_t>((cj / 2) * cells_at(l - 1) + ci / 2)];
        p = std::max(p, t);
      }
  }
}

// A slot whose pieces per arrived piece grew past kWorn times what its last build made of them
// is worn (MergeStats::worn_slots; TerrainTree::tidy builds it anew).
constexpr double kWorn = 1.15;

void TerrainTree::Impl::update(const std::vector<std::uint32_t>& changed_in, std::vector<SlotKey> touched, bool rebuild) {
  const auto t0 = Clock::now();
  std::vector<std::uint32_t> changed = changed_in;
  std::sort(changed.begin(), changed.end());
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());

  // Each touched slot, in parallel: its old store less the changed surfaces' polygons (and the
  // planes they leave vacant, prune_vacant), with their new pieces inserted; built anew from
  // every surface's pieces when it was empty or would be worn out (far more planes than
  // polygons), or with `rebuild`; a low slot never drawn stays unbuilt. Insertion sends the new
  // pieces down planes chosen for other polygons, which cut them more than planes chosen for
  // them, and what it cut stays cut (BspStore::worn, tidy()). On the benchmark scene over
  // N44W072 (6 isosurfaces, a slice; its first view draws 198k triangles), twelve slice moves
  // left frames of 213-228k triangles and twelve isovalue changes 230-241k, and without the
  // pruning 243-279k after two of each; building anew every slot whose changed pieces were
  // over a tenth of what stays kept them at 196-210k, but took a slice move's merge from
  // 99-146 to 171-232 ms (side by side): tidy() spends that when the viewer is idle instead.
  // Where a slice move's merge goes (2026-12-07, 40 moves of that slice, counted per move):
  // about 277 slots take insertions (22.5k new pieces, 65 ms of CPU), 149 slots the removal
  // left empty are built from the new pieces alone (15.9k), 71 are built anew as worn by the
  // rule below (22.8k pieces of every surface) and 32 are new: 114 ms of CPU for the builds,
  // on two cores. Inserting into the worn ones too (tidy() rebuilding them later) saved
  // nothing: merges of 110-137 ms against 110-123 ms, side by side.
  std::vector<Slot> fresh(touched.size());
  std::vector<std::size_t> removed(touched.size(), 0);
  std::vector<std::uint8_t> inserted(touched.size(), 0);
  // Largest first (old polygons and arrivals), one slot at a time: a few slots of the coarsest
  // cells hold most pieces, and TBB's default chunks put neighbouring keys (those slots) on one
  // thread. On the benchmark scene over N44W072 the initial merge's slot phase went from
  // 420-460 ms to about 300 ms on two cores.
  std::vector<std::pair<std::size_t, std::size_t>> order(touched.size());
  tbb::parallel_for(std::size_t{0}, touched.size(), [&](std::size_t k) {
    std::size_t count = 0;
    for (const auto& [id, s] : surfaces) s.for_each_arrival(touched[k], [&](std::span<const std::uint32_t>) { ++count; });
    const auto old = std::lower_bound(slots.begin(), slots.end(), touched[k], [](const Slot& a, SlotKey b) { return a.key < b; });
    if (old != slots.end() && old->key == touched[k] && old->store) count += old->store->polys.size();
    order[k] = {count, k};
  });
  std::sort(order.begin(), order.end(), std::greater<>());
  const auto update_slot = [&](std::size_t k) {
    const SlotKey key = touched[k];
    Slot& slot = fresh[k];
    const auto old = std::lower_bound(slots.begin(), slots.end(), key, [](const Slot& a, SlotKey b) { return a.key < b; });
    if (old != slots.end() && old->key == key) slot = std::move(*old);
    slot.key = key;
    slot.pending = 0;
    slot.top = -1e30f;
    std::size_t arriving = 0;  // pieces of the changed surfaces
    for (const auto& [id, s] : surfaces) {
      const bool changed_here = std::binary_search(changed.begin(), changed.end(), id);
      s.for_each_arrival(key, [&](std::span<const std::uint32_t> piece) {
        ++slot.pending;
        arriving += changed_here;
        for (std::uint32_t r : piece) slot.top = std::max(slot.top, static_cast<float>(s.vertices[r].z));
      });
    }
    if (slot.pending == 0) {  // nothing left here
      removed[k] = slot.refs();
      slot = Slot{};
      slot.key = key;
      return;
    }
    if (is_low(key) && !slot.built) return;  // built when first drawn
    // The changed surfaces' new pieces inserted into the BSP kept.
    const auto insert_changed = [&] {
      SlotBuilder builder(*this, slot.own_store());
      for (const auto& [id, s] : surfaces) {
        if (!std::binary_search(changed.begin(), changed.end(), id)) continue;
        s.for_each_arrival(key, [&](std::span<const std::uint32_t> piece) { builder.add(s, id, piece); });
      }
      build_slot(*this, key, builder);
    };
    bool anew = !slot.built || rebuild;
    if (slot.built) {
      if (!rebuild) removed[k] = remove_surfaces(slot.own_store(), changed, positions);
      anew = anew || slot.store->pieces == 0 || slot.store->nodes.size() > 4 * slot.store->pieces + 64;
      if (anew) removed[k] += slot.store->refs.size();
    }
    if (!anew) {
      if (arriving > 0) insert_changed();
      inserted[k] = arriving > 0;
      slot.own_store().arrivals = slot.pending;
    }
    if (anew) build_anew(*this, slot);
    slot.built = true;
    slot.pending = 0;
    slot.top = slot.store->top;
    slot.own_store().bound_nodes(positions);  // read only here: flushes come after
  };
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, order.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) update_slot(order[k].second);
      },
      tbb::simple_partitioner());
  // Merge into the sorted slots: untouched ones kept, touched ones replaced (or gone when empty).
  std::vector<Slot> merged;
  merged.reserve(slots.size() + fresh.size());
  std::size_t a = 0, b = 0;
  while (a < slots.size() || b < fresh.size()) {
    if (b == fresh.size() || (a < slots.size() && slots[a].key < fresh[b].key)) {
      merged.push_back(std::move(slots[a++]));
    } else {
      if (a < slots.size() && slots[a].key == fresh[b].key) ++a;
      if (fresh[b].pending > 0 || fresh[b].built) merged.push_back(std::move(fresh[b]));
      ++b;
    }
  }
  slots = std::move(merged);
  slots.shrink_to_fit();
  if (surfaces.empty()) release(surfaces);
  merge_stats.rebuilt_slots += touched.size();
  merge_stats.inserted_slots += static_cast<std::size_t>(std::count(inserted.begin(), inserted.end(), 1));
  for (std::size_t r : removed) dead_refs += r;
  // One pass over the slots for every figure and for the stores to flush: the stores lie apart
  // on the heap, and each pass over them all (the benchmark's Utah scene holds 83,000) cost a
  // few milliseconds of cache misses, five of them a fifth of a slide's merge.
  merge_stats.surfaces = surfaces.size();
  merge_stats.input_triangles = 0;
  merge_stats.dropped_pieces = 0;
  for (const auto& [id, s] : surfaces) {
    merge_stats.input_triangles += s.input_triangles;
    merge_stats.dropped_pieces += s.dropped;
  }
  merge_stats.worn_slots = 0;
  merge_stats.stored_polygons = 0;
  merge_stats.pending_slots = 0;
  merge_stats.pending_pieces = 0;
  std::size_t staged = 0, live = 0;
  std::vector<BspStore*> to_flush;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (k + 8 < slots.size() && slots[k + 8].store) __builtin_prefetch(slots[k + 8].store.get());
    Slot& slot = slots[k];
    merge_stats.pending_slots += slot.built ? 0 : 1;
    merge_stats.pending_pieces += slot.pending;
    const BspStore* store = slot.store.get();
    if (store == nullptr) continue;
    merge_stats.worn_slots += store->worn(kWorn);
    merge_stats.stored_polygons += store->pieces;
    merge_stats.dropped_pieces += store->dropped;
    staged += store->staged_count();
    live += store->refs.size();
    if (store->staged || store->staged_refs < store->refs.size()) {
      to_flush.push_back(&slot.own_store());
    }
  }
  // Room for the staged vertices and, when the vertices must move anyway, a sixteenth of the
  // merged ones more (not doubled: the memory stays near what the merge needs). Reserved
  // exactly, every slide and edit moved all of them (1.5 M positions, 18 MB, on the benchmark's
  // Utah scene): 3-12 ms of a slide's merge, none after the first with the sixteenth.
  const std::size_t slack =
      positions.capacity() < positions.size() + staged ? (positions.size() - merged_base()) / 16 : 0;
  positions.reserve(positions.size() + staged + slack);
  merged_colors.reserve(merged_colors.size() + staged + slack);
  if (has_tcoords) merged_tcoords.reserve(merged_tcoords.size() + staged + slack);
  for (BspStore* store : to_flush) flush(*store);  // in the slots' order
  if (dead_refs > live) compact();
  make_content();
  merge_stats.slots = slots.size();
  merge_stats.merged_vertices = merged_colors.size();
  merge_stats.build_ms += ms_since(t0);
}

void TerrainTree::Impl::build_pending(std::size_t k) {
  const auto slot = static_cast<std::int32_t>(k);
  build_pending(std::span<const std::int32_t>(&slot, 1));
}

void TerrainTree::Impl::build_pending(std::span<const std::int32_t> ks) {
  if (ks.empty()) return;
  const auto t0 = Clock::now();
  // Each slot's builder reads the surfaces and the lattice and writes its own store, its
  // vertices staged; the flushes, which append to positions, come after all of them.
  tbb::parallel_for(std::size_t{0}, ks.size(), [&](std::size_t q) {
    Slot& slot = slots[static_cast<std::size_t>(ks[q])];
    build_anew(*this, slot);
    slot.built = true;
    slot.pending = 0;
    slot.top = slot.store->top;
    slot.own_store().bound_nodes(positions);  // read only here: flushes come after
  });
  for (const std::int32_t k : ks) {
    Slot& slot = slots[static_cast<std::size_t>(k)];
    flush(slot.own_store());
    merge_stats.stored_polygons += slot.store->pieces;
    merge_stats.dropped_pieces += slot.store->dropped;
    --merge_stats.pending_slots;
    ++merge_stats.lazy_built_slots;
  }
  merge_stats.merged_vertices = merged_colors.size();
  merge_stats.lazy_build_ms += ms_since(t0);
}

namespace {

void check_surface(const SurfaceInput& s) {
  if (s.colors.size() != s.vertices.size()) {
    throw std::invalid_argument("TerrainTree::merge: " + std::to_string(s.colors.size()) + " colours for " +
                                std::to_string(s.vertices.size()) + " vertices");
  }
  if (!s.tcoords.empty() && s.tcoords.size() != s.vertices.size()) {
    throw std::invalid_argument("TerrainTree::merge: " + std::to_string(s.tcoords.size()) + " texture coordinates for " +
                                std::to_string(s.vertices.size()) + " vertices");
  }
  if (s.triangles.size() % 3 != 0) throw std::invalid_argument("TerrainTree::merge: triangle indices not a multiple of 3");
  for (std::uint32_t i : s.triangles) {
    if (i >= s.vertices.size()) throw std::invalid_argument("TerrainTree::merge: index " + std::to_string(i) + " out of range");
  }
}

// Zeroes the figures of the last change (MergeStats) before a new one.
void start_change(MergeStats& s) {
  s.rebuilt_slots = 0;
  s.inserted_slots = 0;
  s.distribute_ms = 0.0;
  s.build_ms = 0.0;
  s.lazy_built_slots = 0;
  s.lazy_build_ms = 0.0;
}

void keys_of(const SurfacePieces& s, std::vector<SlotKey>& out) {
  for (const SurfacePieces::Run& run : s.runs) out.push_back(run.slot);
}

}  // namespace

void TerrainTree::Impl::redistribute_all() {
  const auto t0 = Clock::now();
  start_change(merge_stats);
  std::vector<SurfacePieces*> list;
  for (auto& [id, s] : surfaces) list.push_back(&s);
  distribute_all(list);
  merge_stats.distribute_ms = ms_since(t0);
  std::vector<SlotKey> touched;
  std::vector<std::uint32_t> ids;
  for (const auto& [id, s] : surfaces) {
    keys_of(s, touched);
    ids.push_back(id);
  }
  release(slots);
  positions.resize(merged_base());
  positions.shrink_to_fit();
  release(merged_colors);
  release(merged_tcoords);
  dead_refs = 0;
  ++merged_version;
  update(ids, touched);
  merge_stats.merge_ms = ms_since(t0);
}

void TerrainTree::Impl::shift_merged(int di, int dj) {
  const auto t0 = Clock::now();
  start_change(merge_stats);
  // The overlap in the moved window's indices; a cell there was (ci + di / s, cj + dj / s).
  const Region kept{std::max(0, -di), std::max(0, -dj), n - std::max(0, di), n - std::max(0, dj)};
  // An outside place lies where one lay before when both lie between the same planes: west and
  // east bands move by di / s0 bands and their rows by dj / row rows (row: place_step());
  // south and north bands by dj / s0 bands and their columns by di / row columns. The last bands
  // (everything beyond) stay only where their plane did not move, and so do the first and last
  // rows (which reach beyond the south and north planes) where the window did not move north or
  // south. (The columns of south and north lie between the west and east planes.)
  const int s0 = cell_size(0), columns = place_columns(), row = place_step();
  const auto moved_place = [&](SlotKey key) -> std::optional<SlotKey> {
    const OutsidePlace p = outside_place(key);
    // A band beyond a plane that moved toward it is nearer now, and farther when it moved away.
    const int shift = p.side == 0 ? di / s0 : p.side == 1 ? -di / s0 : p.side == 2 ? dj / s0 : -dj / s0;
    const int across = (p.side < 2 ? dj : di) / row;  // the rows' or columns' move
    const int band = p.band == kBands - 1 ? p.band : p.band + shift, column = p.column - across;
    if (p.band == kBands - 1 ? shift != 0 : band < 0 || band >= kBands - 1) return std::nullopt;
    if (p.side < 2) {
      // The first and last rows reach beyond the south and north planes: kept only in place,
      // and no other row becomes one of them.
      const bool open_end = p.column == 0 || p.column == columns - 1;
      if (open_end ? across != 0 : column <= 0 || column >= columns - 1) return std::nullopt;
    } else if (column < 0 || column >= columns) {
      return std::nullopt;
    }
    return outside_key(p.side, band, column);
  };
  std::unordered_set<SlotKey> kept_places;
  const auto renamed = [&](SlotKey key) -> std::optional<SlotKey> {
    if (key >= kOutsideKey0) return moved_place(key);  // beyond the old window: kept where it is, else merged again
    const CellName c = cell_name(*this, key / 2);
    const int s = cell_size(c.level), ci = c.ci - di / s, cj = c.cj - dj / s;
    if (!kept.holds(ci * s, cj * s, s)) return std::nullopt;
    return static_cast<SlotKey>(cell_id(c.level, ci, cj)) * 2 + key % 2;
  };

  // Slots of cells in both windows, renamed, with their terrain triangles' lattice vertices.
  // Each slot apart (in parallel: the references of every kept store are read and written),
  // then the kept ones gathered in order.
  std::vector<std::optional<SlotKey>> keys(slots.size());
  const tbb::blocked_range<std::size_t> all(0, slots.size(), 512);
  tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      keys[k] = renamed(slots[k].key);
      // Only a low slot's two terrain triangles refer to samples: the rest of the references
      // are merged vertices, which do not move. Every reference of every store was looked at
      // until 2026-12-07: about 7 ms of the bench's Utah slide.
      if (!keys[k] || !slots[k].store || !is_low(slots[k].key)) continue;
      // Sample (i, j) becomes (i - di, j - dj): its index moves by a constant (a kept slot's
      // samples all lie in the overlap). Dividing each reference into (i, j) instead cost the
      // bench's Utah slide (92,000 slots) 4-5 ms more: 96.5 and 79.4 ms against 91.6 and
      // 75.3 ms, alternating runs.
      const auto moved_by = static_cast<std::uint32_t>(dj * (n + 1) + di);  // modulo 2^32: negative too
      BspStore& store = slots[k].own_store();
      for (const Polygon& p : store.polys) {
        if (p.surface != kTerrainSurface) continue;
        for (std::uint32_t r = p.first; r < p.first + p.count; ++r) store.refs[r] -= moved_by;
      }
    }
  });
  std::vector<Slot> moved;
  moved.reserve(slots.size());
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (!keys[k]) {
      dead_refs += slots[k].refs();
      continue;
    }
    slots[k].key = *keys[k];
    if (*keys[k] >= kOutsideKey0) kept_places.insert(*keys[k]);
    moved.push_back(std::move(slots[k]));
  }
  // Renaming keeps the order of a level's cells, and levels keep theirs, so only the outside
  // places at the end can come out of order: sorted there, and merged in.
  const auto by_key = [](const Slot& a, const Slot& b) { return a.key < b.key; };
  const auto sorted_end = std::is_sorted_until(moved.begin(), moved.end(), by_key);
  std::sort(sorted_end, moved.end(), by_key);
  std::inplace_merge(moved.begin(), sorted_end, moved.end(), by_key);
  slots = std::move(moved);

  // Each surface: its pieces in both windows renamed, the rest dropped, and what reaches beyond
  // the overlap sent through the moved window (Distributor::run_outside); then its vertices
  // less those no piece uses any more. The kept pieces point into the surface's references as
  // they are (the new ones are appended after them): keep() copies them once, in order.
  tbb::parallel_for(std::size_t{0}, surfaces.size(), [&](std::size_t k) {
    SurfacePieces& s = surfaces[k].second;
    std::vector<SurfacePieces::Piece> pieces;
    for (std::size_t r = 0; r < s.runs.size(); ++r) {
      const std::optional<SlotKey> key = renamed(s.runs[r].slot);
      if (!key) continue;
      s.for_each_in_run(r, [&](std::span<const std::uint32_t> piece) {
        const auto first = static_cast<std::uint32_t>(piece.data() - s.refs.data());
        pieces.push_back({*key, first, static_cast<std::uint32_t>(piece.size())});
      });
    }
    Distributor(*this, s).run_outside(kept, kept_places, std::move(pieces));
    std::vector<std::uint32_t> remap(s.vertices.size(), 0);
    for (std::uint32_t r : s.refs) remap[r] = 1;
    std::uint32_t used = 0;
    for (std::uint32_t v = 0; v < s.vertices.size(); ++v) {
      if (v >= s.input_vertices && !remap[v]) continue;  // the input's are kept (slides send them again)
      s.vertices[used] = s.vertices[v];  // used <= v: moves only downward, in order
      s.colors[used] = s.colors[v];
      if (!s.tcoords.empty()) s.tcoords[used] = s.tcoords[v];
      remap[v] = used++;
    }
    for (std::uint32_t& r : s.refs) r = remap[r];
    s.vertices.resize(used);
    s.colors.resize(used);
    if (!s.tcoords.empty()) s.tcoords.resize(used);
    s.vertices.shrink_to_fit();
    s.colors.shrink_to_fit();
    s.tcoords.shrink_to_fit();
  });
  merge_stats.distribute_ms = ms_since(t0);

  // The slots the new pieces reach (none of them kept): built by update() as edits are. A
  // surface's runs and the slots are both sorted by key, so each run's slot is searched from
  // the last one's onward, galloping: a binary search of all the slots for every run took 6 ms
  // of the bench's Utah slide (seven surfaces, 92,000 slots).
  std::vector<SlotKey> touched;
  std::vector<std::uint32_t> ids;
  const auto below = [](const Slot& a, SlotKey b) { return a.key < b; };
  for (const auto& [id, s] : surfaces) {
    ids.push_back(id);
    auto at = slots.begin();
    for (const SurfacePieces::Run& run : s.runs) {
      std::size_t step = 1;
      auto bound = at;
      while (bound != slots.end() && bound->key < run.slot) {
        at = bound;
        const auto left = static_cast<std::size_t>(slots.end() - bound);
        bound = left > step ? bound + static_cast<std::ptrdiff_t>(step) : slots.end();
        step *= 2;
      }
      at = std::lower_bound(at, bound, run.slot, below);
      if (at == slots.end() || at->key != run.slot) touched.push_back(run.slot);
    }
  }
  ++merged_version;  // the lattice vertices moved
  update(ids, std::move(touched));
  merge_stats.merge_ms = ms_since(t0);
}

MergeStats TerrainTree::set_surfaces(std::span<const std::uint32_t> ids, std::span<const SurfaceInput> inputs) {
  if (ids.size() != inputs.size()) throw std::invalid_argument("TerrainTree::set_surfaces: ids and surfaces differ in number");
  for (const SurfaceInput& s : inputs) check_surface(s);
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  start_change(m.merge_stats);
  // Replacing every surface there is, or the first with texture coordinates coming or the last
  // going: start from nothing (no old polygons to remove).
  // The given ids sorted, so that each stored surface is looked up in O(log k): with thousands
  // of object instances a linear search per surface would be quadratic.
  std::vector<std::uint32_t> sorted_ids(ids.begin(), ids.end());
  std::sort(sorted_ids.begin(), sorted_ids.end());
  const auto given = [&](std::uint32_t id) { return std::binary_search(sorted_ids.begin(), sorted_ids.end(), id); };
  bool everything = true, tcoords = false;
  for (const auto& [id, s] : m.surfaces) {
    const bool replaced = given(id);
    everything = everything && replaced;
    tcoords = tcoords || (!replaced && !s.tcoords.empty());
  }
  for (const SurfaceInput& in : inputs) tcoords = tcoords || (!in.tcoords.empty() && !in.triangles.empty());
  const bool flip = tcoords != m.has_tcoords;  // then every surface is merged again
  m.has_tcoords = tcoords;
  everything = everything || flip;
  if (everything) {
    release(m.slots);
    m.positions.resize(m.merged_base());
    m.positions.shrink_to_fit();
    release(m.merged_colors);
    release(m.merged_tcoords);
    m.dead_refs = 0;
    ++m.merged_version;
  }
  std::vector<SlotKey> touched;
  const auto find = [&](std::uint32_t id) {
    return std::lower_bound(m.surfaces.begin(), m.surfaces.end(), id,
                            [](const std::pair<std::uint32_t, SurfacePieces>& a, std::uint32_t i) { return a.first < i; });
  };
  for (std::size_t k = 0; k < ids.size(); ++k) {
    auto it = find(ids[k]);
    if (it != m.surfaces.end() && it->first == ids[k]) {
      if (!everything) keys_of(it->second, touched);
      m.surfaces.erase(it);
    }
    const SurfaceInput& in = inputs[k];
    if (in.triangles.empty()) continue;
    SurfacePieces s;
    s.input_triangles = in.triangles.size() / 3;
    s.input_vertices = in.vertices.size();
    s.triangles.assign(in.triangles.begin(), in.triangles.end());
    s.vertices.assign(in.vertices.begin(), in.vertices.end());
    s.colors.assign(in.colors.begin(), in.colors.end());
    s.tcoords.assign(in.tcoords.begin(), in.tcoords.end());
    m.surfaces.insert(find(ids[k]), {ids[k], std::move(s)});
  }
  std::vector<std::size_t> changed;  // indices into m.surfaces to distribute
  std::vector<std::uint32_t> changed_ids(ids.begin(), ids.end());
  for (std::size_t k = 0; k < m.surfaces.size(); ++k) {
    if (flip || given(m.surfaces[k].first)) changed.push_back(k);
    if (flip) changed_ids.push_back(m.surfaces[k].first);
  }
  std::vector<SurfacePieces*> list;
  for (std::size_t k : changed) list.push_back(&m.surfaces[k].second);
  m.distribute_all(list);
  m.merge_stats.distribute_ms = ms_since(t0);
  for (std::size_t k : changed) keys_of(m.surfaces[k].second, touched);
  m.update(changed_ids, std::move(touched));
  m.merge_stats.merge_ms = ms_since(t0);
  return m.merge_stats;
}

MergeStats TerrainTree::tidy() {
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  start_change(m.merge_stats);
  std::vector<SlotKey> worn;
  for (const Slot& slot : m.slots)
    if (slot.store && slot.store->worn(kWorn)) worn.push_back(slot.key);
  if (!worn.empty()) m.update({}, std::move(worn), true);
  m.merge_stats.merge_ms = ms_since(t0);
  return m.merge_stats;
}

MergeStats TerrainTree::set_surface(std::uint32_t id, const SurfaceInput& surface) {
  return set_surfaces(std::span<const std::uint32_t>(&id, 1), std::span<const SurfaceInput>(&surface, 1));
}

MergeStats TerrainTree::merge(std::span<const glm::dvec3> vertices, std::span<const glm::u8vec4> colors,
                              std::span<const std::uint32_t> triangles) {
  const SurfaceInput input{vertices, colors, triangles};
  check_surface(input);
  std::vector<std::uint32_t> ids;
  std::vector<SurfaceInput> inputs;
  for (const auto& [id, s] : impl_->surfaces) {
    if (id == 0) continue;
    ids.push_back(id);
    inputs.push_back({});
  }
  ids.push_back(0);
  inputs.push_back(input);
  return set_surfaces(ids, inputs);
}

const MergeStats& TerrainTree::merge_stats() const { return impl_->merge_stats; }
const std::vector<glm::u8vec4>& TerrainTree::merged_colors() const { return impl_->merged_colors; }
const std::vector<glm::vec2>& TerrainTree::merged_tcoords() const { return impl_->merged_tcoords; }
std::uint32_t TerrainTree::merged_base() const { return impl_->merged_base(); }
std::uint64_t TerrainTree::merged_version() const { return impl_->merged_version; }

}  // namespace terravol::mrbsp
