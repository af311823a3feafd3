// Multiresolution BSP tree for terrain height fields.
//
// Implements Wiley, Campbell, Szygenda, Fussell, Hudson: "Multiresolution BSP Trees Applied to
// Terrain, Transparency, and General Objects", Graphics Interface 1997:
//   - section 4.1: nested LOD grids (each level doubles the samples per side); split planes on
//     grid lines of the coarsest level still available, alternating longitude and latitude to
//     keep regions square; where a region is one cell of that level, an alternative list of
//     two: the cell's two triangles (low) and the same region rebuilt from the next level (high);
//   - section 4.3: sliding. The topology depends only on the window's size, so moving the
//     window over the terrain only recomputes plane offsets, positions, z ranges and errors
//     (refresh()); nothing of the structure is rebuilt;
//   - sections 5, 5.1 and figure 5: the draw order (far child, node polygons, near child) and
//     the LOD choice from the projected bounding box; a second metric, the screen-space error.
//
// Departures from the paper, and why:
//   - No node is stored: a region is a cell (level, ci, cj) and its split planes are its
//     middle lattice lines (mrbsp/tree_impl.h), so the tree is a function of the window's
//     size. Per cell the tree keeps only its z range and error (CellZ); the traversal is an
//     explicit stack of implicit node names (no recursion, no pointers).
//   - The paper leaves cracks between neighbours at different levels unaddressed; there is no
//     depth buffer to hide them here. After the LOD choice, a balancing pass refines cells
//     until drawn neighbours differ by at most one level (like a restricted quadtree; it
//     depends on the camera only). Then the crack along the edge between a coarse cell and
//     its finer neighbour is exactly the vertical triangle (corner, middle sample of the
//     edge, corner): it lies in the shared boundary plane, is made of lattice samples and
//     lies within both cells' z ranges, so culling by their boxes stays right and it is
//     ordered like the plane: before the coarse cell's triangles when the plane faces away
//     from the eye, after them otherwise. A crack next to a culled cell lies in that cell's
//     box, outside the view, and needs no fill. (Earlier versions hung skirts 1 m below the
//     lowest sample of the level-0 edge: about half of all terrain fragments.)
//   - Inside a cell the two triangles are ordered by the vertical plane through the cell's
//     diagonal, which separates them.
//   - Merged polygons (merge.cpp) live in small BSPs at cells ("slots"); each region's culling
//     box holds them as well as its terrain.
#include "mrbsp/terrain_tree.h"

#include "mrbsp/tree_impl.h"

#include "coverage/pyramid.h"
#include "mrbsp/box_order.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace terravol::mrbsp {

void TerrainTree::Impl::refresh(const TerrainWindow& w) {
  if (w.cells != n) throw std::invalid_argument("TerrainTree: window has " + std::to_string(w.cells) + " cells, tree has " + std::to_string(n));
  const std::size_t side = static_cast<std::size_t>(n) + 1;
  if (w.xs.size() != side || w.ys.size() != side || w.z.size() != side * side) {
    throw std::invalid_argument("TerrainTree: window arrays do not match its cell count");
  }
  for (std::size_t i = 1; i < side; ++i) {
    if (!(w.xs[i] > w.xs[i - 1]) || !(w.ys[i] > w.ys[i - 1])) {
      throw std::invalid_argument("TerrainTree: plane offsets must increase strictly");
    }
  }
  // A window moved over the same terrain keeps what lies in both (section 4.3): the cell figures
  // here, the merged content below.
  const std::optional<std::pair<int, int>> shift = positions.empty() ? std::nullopt : shift_of(w);
  xs.assign(w.xs.begin(), w.xs.end());
  ys.assign(w.ys.begin(), w.ys.end());
  const auto zw = [&](int i, int j) { return w.z[static_cast<std::size_t>(j) * side + static_cast<std::size_t>(i)]; };

  if (!shift) positions.resize(merged_base());  // merged vertices come again; kept after a shift
  float lowest = std::numeric_limits<float>::max();
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      positions[vertex(i, j)] = glm::vec3(static_cast<float>(xs[i]), static_cast<float>(ys[j]), zw(i, j));
      lowest = std::min(lowest, zw(i, j));
    }
  wall_base = lowest - 100.0f;
  for (int wall = 0; wall < 4; ++wall) {
    for (int k = 0; k <= n; ++k) {
      const int i = wall == 0 ? 0 : wall == 1 ? n : k, j = wall == 2 ? 0 : wall == 3 ? n : k;
      positions[wall_vertex(wall, k)] = positions[vertex(i, j)];
      positions[wall_bottom(wall, k)] = glm::vec3(positions[vertex(i, j)].x, positions[vertex(i, j)].y, wall_base);
    }
  }

  // LOD cells above the finest: z range and error from their samples, independent of each
  // other (TBB over the cells of each level); after a shift, a cell in both windows keeps its
  // figures (copied from where it was).
  const std::vector<CellZ> before = shift ? cellz : std::vector<CellZ>{};
  for (int level = 0; level + 1 < levels; ++level) {
    const int s = cell_size(level), c = cells_at(level);
    CellZ* out = cellz.data() + cellz_offset[static_cast<std::size_t>(level + top)];
    const CellZ* was = shift ? before.data() + cellz_offset[static_cast<std::size_t>(level + top)] : nullptr;
    const int dci = shift ? shift->first / s : 0, dcj = shift ? shift->second / s : 0;
    tbb::parallel_for(tbb::blocked_range<int>(0, c * c, 64), [&](const tbb::blocked_range<int>& range) {
      for (int k = range.begin(); k != range.end(); ++k) {
        const int oi = k % c + dci, oj = k / c + dcj;  // where the cell was
        if (was && oi >= 0 && oj >= 0 && oi < c && oj < c) {
          out[static_cast<std::size_t>(k)] = was[static_cast<std::size_t>(oj * c + oi)];
          continue;
        }
        const int i0 = (k % c) * s, j0 = (k / c) * s;
        const float zsw = zw(i0, j0), zse = zw(i0 + s, j0), zne = zw(i0 + s, j0 + s), znw = zw(i0, j0 + s);
        float zmin = std::numeric_limits<float>::max(), zmax = -zmin, err = 0.0f;
        const float inv = 1.0f / static_cast<float>(s);
        for (int j = 0; j <= s; ++j) {
          const float v = static_cast<float>(j) * inv;
          for (int i = 0; i <= s; ++i) {
            const float h = zw(i0 + i, j0 + j);
            zmin = std::min(zmin, h);
            zmax = std::max(zmax, h);
            const float u = static_cast<float>(i) * inv;
            const float approx = u >= v ? zsw + u * (zse - zsw) + v * (zne - zse) : zsw + v * (znw - zsw) + u * (zne - znw);
            err = std::max(err, std::abs(h - approx));
          }
        }
        out[static_cast<std::size_t>(k)] = {zmin, zmax, err};
      }
    });
  }
  // Top levels: the union of their four children.
  for (int level = -1; level >= -top; --level) {
    const int c = cells_at(level);
    CellZ* out = cellz.data() + cellz_offset[static_cast<std::size_t>(level + top)];
    for (int cj = 0; cj < c; ++cj)
      for (int ci = 0; ci < c; ++ci) {
        CellZ u{std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(), 0.0f};
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a) {
            const CellZ ch = cell_z(level + 1, 2 * ci + a, 2 * cj + b);
            u.zmin = std::min(u.zmin, ch.zmin);
            u.zmax = std::max(u.zmax, ch.zmax);
          }
        out[static_cast<std::size_t>(cj * c + ci)] = u;
      }
  }
  // Section 4.3: other objects are merged again into the moved tree; what lies in both windows
  // stays.
  if (shift) {
    shift_merged(shift->first, shift->second);
  } else {
    redistribute_all();
  }
}

double TerrainTree::Impl::band_plane(int side, int band) const {
  const auto s0 = static_cast<std::size_t>(cell_size(0));
  const std::vector<double>& lines = side < 2 ? xs : ys;
  const double width = lines[s0] - lines[0];
  return side % 2 == 0 ? lines.front() - band * width : lines.back() + band * width;
}

std::optional<std::pair<int, int>> TerrainTree::Impl::shift_of(const TerrainWindow& w) const {
  // The moved window's first plane among this one's (or this one's among the moved one's).
  const auto offset = [&](const std::vector<double>& old, std::span<const double> moved) -> std::optional<int> {
    const auto in_old = std::lower_bound(old.begin(), old.end(), moved.front());
    if (in_old != old.end() && *in_old == moved.front()) return static_cast<int>(in_old - old.begin());
    const auto in_moved = std::lower_bound(moved.begin(), moved.end(), old.front());
    if (in_moved != moved.end() && *in_moved == old.front()) return -static_cast<int>(in_moved - moved.begin());
    return std::nullopt;
  };
  const std::optional<int> di = offset(xs, w.xs), dj = offset(ys, w.ys);
  if (!di || !dj) return std::nullopt;
  const int s0 = cell_size(0);
  if (*di % s0 != 0 || *dj % s0 != 0 || std::abs(*di) >= n || std::abs(*dj) >= n) return std::nullopt;
  // The same planes and heights wherever the two overlap.
  const std::size_t side = static_cast<std::size_t>(n) + 1;
  const int i0 = std::max(0, -*di), i1 = n - std::max(0, *di), j0 = std::max(0, -*dj), j1 = n - std::max(0, *dj);
  for (int i = i0; i <= i1; ++i)
    if (w.xs[static_cast<std::size_t>(i)] != xs[static_cast<std::size_t>(i + *di)]) return std::nullopt;
  for (int j = j0; j <= j1; ++j)
    if (w.ys[static_cast<std::size_t>(j)] != ys[static_cast<std::size_t>(j + *dj)]) return std::nullopt;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i)
      if (w.z[static_cast<std::size_t>(j) * side + static_cast<std::size_t>(i)] != z(i + *di, j + *dj)) return std::nullopt;
  return std::pair{*di, *dj};
}

TerrainTree::TerrainTree(const TerrainWindow& window, int levels) : impl_(std::make_unique<Impl>()) {
  const int n = window.cells;
  if (n < 2 || (n & (n - 1)) != 0 || n > (1 << 15)) {
    throw std::invalid_argument("TerrainTree: cells per side must be a power of two in [2, 32768], is " + std::to_string(n));
  }
  const int k = std::countr_zero(static_cast<unsigned>(n));
  if (levels < 1 || levels > k + 1) {
    throw std::invalid_argument("TerrainTree: levels must be in [1, " + std::to_string(k + 1) + "], is " + std::to_string(levels));
  }
  Impl& m = *impl_;
  m.n = n;
  m.levels = levels;
  m.top = k - (levels - 1);  // level 0 has 2^top cells per side
  std::uint32_t offset = 0;
  for (int l = 0; l < levels; ++l) {
    m.level_offset.push_back(offset);
    offset += static_cast<std::uint32_t>(m.cells_at(l)) * static_cast<std::uint32_t>(m.cells_at(l));
  }
  m.total_cells = offset;
  for (int l = -m.top; l + 1 < levels; ++l) {
    m.cellz_offset.push_back(m.cellz.size());
    m.cellz.resize(m.cellz.size() + static_cast<std::size_t>(m.cells_at(l)) * static_cast<std::size_t>(m.cells_at(l)));
  }
  m.refresh(window);
}

Frame::Frame() = default;
Frame::~Frame() = default;
Frame::Frame(Frame&&) noexcept = default;
Frame& Frame::operator=(Frame&&) noexcept = default;

TerrainTree::TerrainTree(const TerrainTree& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
TerrainTree::~TerrainTree() = default;
TerrainTree::TerrainTree(TerrainTree&&) noexcept = default;
TerrainTree& TerrainTree::operator=(TerrainTree&&) noexcept = default;

int TerrainTree::cells() const { return impl_->n; }
int TerrainTree::levels() const { return impl_->levels; }
const std::vector<glm::vec3>& TerrainTree::positions() const { return impl_->positions; }
void TerrainTree::slide(const TerrainWindow& window) { impl_->refresh(window); }

namespace {

template <class T>
std::size_t held(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace

std::size_t BspStore::bytes() const {
  std::size_t n = held(nodes) + held(boxes) + held(polys) + held(refs);
  if (staged) n += sizeof(StagedVertices) + held(staged->positions) + held(staged->colors) + held(staged->tcoords);
  return n;
}

void BspStore::bound_nodes(const std::vector<glm::vec3>& where) {
  const auto at = [&](std::uint32_t r) -> const glm::vec3& {
    const std::uint32_t v = refs[r];
    if (r < staged_refs) return where[v];
    return (v & kTerrainRef) ? where[v & ~kTerrainRef] : staged->positions[v];
  };
  // The store's bounds first: the grid the nodes' boxes are rounded to.
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (std::uint32_t r = 0; r < refs.size(); ++r) {
    lo = glm::min(lo, glm::dvec3(at(r)));
    hi = glm::max(hi, glm::dvec3(at(r)));
  }
  // In single precision, the base rounded down and the step up (twice, for the base's
  // rounding), so that 65535 steps from the base reach past the highest vertex.
  for (int a = 0; a < 3; ++a) {
    float b = static_cast<float>(lo[a]);
    if (b > lo[a]) b = std::nextafter(b, -std::numeric_limits<float>::infinity());
    float step = static_cast<float>(std::max((hi[a] - b) / 65535.0, 1e-9));
    step = std::nextafter(std::nextafter(step, std::numeric_limits<float>::infinity()), std::numeric_limits<float>::infinity());
    box_base[a] = b;
    box_step[a] = step;
  }
  const glm::dvec3 base(box_base), step(box_step);
  const auto down = [&](const glm::vec3& p) {
    const glm::dvec3 q = glm::floor((glm::dvec3(p) - base) / step);
    return glm::clamp(q, glm::dvec3(0.0), glm::dvec3(65535.0));
  };
  const auto up = [&](const glm::vec3& p) {
    const glm::dvec3 q = glm::ceil((glm::dvec3(p) - base) / step);
    return glm::clamp(q, glm::dvec3(0.0), glm::dvec3(65535.0));
  };
  boxes.assign(nodes.size(), NodeBox{});
  boxes.shrink_to_fit();
  for (std::size_t k = nodes.size(); k-- > 0;) {
    const BspNode& bn = nodes[k];
    glm::dvec3 qlo(65536.0), qhi(-1.0);
    for (std::uint32_t q = bn.first; q < bn.first + bn.count; ++q) {
      const Polygon& p = polys[q];
      for (std::uint32_t r = p.first; r < p.first + p.count; ++r) {
        qlo = glm::min(qlo, down(at(r)));
        qhi = glm::max(qhi, up(at(r)));
      }
    }
    for (const std::int32_t child : {bn.back, bn.front}) {
      if (child < 0) continue;  // none, or kDropSide
      const NodeBox& c = boxes[static_cast<std::size_t>(child)];
      if (c.lo[0] > c.hi[0]) continue;  // empty
      qlo = glm::min(qlo, glm::dvec3(c.lo[0], c.lo[1], c.lo[2]));
      qhi = glm::max(qhi, glm::dvec3(c.hi[0], c.hi[1], c.hi[2]));
    }
    if (qlo.x > qhi.x) continue;  // empty: stays lo > hi
    NodeBox& b = boxes[k];
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = static_cast<std::uint16_t>(qlo[a]);
      b.hi[a] = static_cast<std::uint16_t>(qhi[a]);
    }
  }
}

std::size_t SurfacePieces::bytes() const {
  return held(triangles) + held(vertices) + held(colors) + held(tcoords) + held(runs) + held(counts) + held(refs);
}

void SurfacePieces::keep(std::vector<Piece>& gathered) {
  // A slide gathers the pieces it keeps in order (renamed runs), then the few it sends through
  // the moved window: only what follows the sorted start is sorted, then merged in. Both steps
  // are stable, so the order is a stable sort's of the whole. Sorting all of it took 1-5 ms per
  // surface of the bench's Utah slide.
  const auto by_slot = [](const Piece& a, const Piece& b) { return a.slot < b.slot; };
  const auto sorted_end = std::is_sorted_until(gathered.begin(), gathered.end(), by_slot);
  std::stable_sort(sorted_end, gathered.end(), by_slot);
  std::inplace_merge(gathered.begin(), sorted_end, gathered.end(), by_slot);
  std::size_t kept_refs = 0;  // refs may hold more (a slide's dropped pieces)
  for (const Piece& p : gathered) kept_refs += p.count;
  std::vector<std::uint32_t> sorted;
  sorted.reserve(kept_refs);
  runs.clear();
  std::vector<std::uint16_t>().swap(counts);
  counts.reserve(gathered.size());
  for (const Piece& p : gathered) {
    if (p.count > 0xFFFFu) throw std::length_error("SurfacePieces::keep: a piece of " + std::to_string(p.count) + " vertices");
    if (runs.empty() || runs.back().slot != p.slot) {
      runs.push_back({p.slot, static_cast<std::uint32_t>(counts.size()), static_cast<std::uint32_t>(sorted.size())});
    }
    counts.push_back(static_cast<std::uint16_t>(p.count));
    sorted.insert(sorted.end(), refs.begin() + p.first, refs.begin() + p.first + p.count);
  }
  refs = std::move(sorted);
  runs.shrink_to_fit();
}

MemoryStats TerrainTree::memory() const {
  const Impl& m = *impl_;
  MemoryStats s;
  s.samples = m.lattice_count();
  s.nodes = held(m.level_offset) + held(m.xs) + held(m.ys) + held(m.cellz) + held(m.cellz_offset);
  // positions holds both: the terrain's blocks up to merged_base(), merged vertices after.
  const std::size_t terrain = std::min<std::size_t>(m.merged_base(), m.positions.capacity());
  s.vertices = terrain * sizeof(glm::vec3);
  s.merged = held(m.positions) - s.vertices + held(m.merged_colors) + held(m.surfaces) + held(m.slots) +
             held(m.content_index.bits) + held(m.content_index.rank) + held(m.content) + held(m.top_content);
  for (const auto& [id, surface] : m.surfaces) s.merged += surface.bytes();
  for (const Slot& slot : m.slots) s.merged += slot.store ? sizeof(BspStore) + slot.store->bytes() : 0;
  for (const auto& level : m.top_content) s.merged += held(level);
  return s;
}

namespace {

struct Plane {
  glm::dvec3 n;
  double d;  // inside where dot(n, p) + d >= 0
};

// The view volume's side and near planes, pointing inwards.
std::array<Plane, 5> frustum_planes(const Camera& c) {
  const glm::dvec3 f = glm::normalize(c.forward);
  const glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  const glm::dvec3 u = glm::cross(r, f);
  const double ty = std::tan(glm::radians(c.fov_y_deg) * 0.5);
  const double tx = ty * static_cast<double>(c.width) / c.height;
  const auto through_eye = [&](glm::dvec3 n) {
    n = glm::normalize(n);
    return Plane{n, -glm::dot(n, c.eye)};
  };
  return {through_eye(glm::cross(u, f + r * tx)),   // right: normal points left-inwards
          through_eye(glm::cross(f - r * tx, u)),   // left
          through_eye(glm::cross(f + u * ty, r)),   // top
          through_eye(glm::cross(r, f - u * ty)),   // bottom
          Plane{f, -glm::dot(f, c.eye) - c.near_plane}};
}

bool box_outside(const std::array<Plane, 5>& planes, const glm::vec3& lo, const glm::vec3& hi) {
  for (const Plane& p : planes) {
    const glm::dvec3 v(p.n.x >= 0 ? hi.x : lo.x, p.n.y >= 0 ? hi.y : lo.y, p.n.z >= 0 ? hi.z : lo.z);
    if (glm::dot(p.n, v) + p.d < 0) return true;
  }
  return false;
}

// The frustum test with a mask of the planes still to test (bit k: plane k): -1 when the box
// lies outside one of them, else the mask less the planes it lies wholly inside, which its
// sub-boxes need not test again.
int box_planes(const std::array<Plane, 5>& planes, const glm::vec3& lo, const glm::vec3& hi, int mask) {
  for (int k = 0; k < 5; ++k) {
    if (!(mask & (1 << k))) continue;
    const Plane& p = planes[static_cast<std::size_t>(k)];
    const glm::dvec3 far(p.n.x >= 0 ? hi.x : lo.x, p.n.y >= 0 ? hi.y : lo.y, p.n.z >= 0 ? hi.z : lo.z);
    if (glm::dot(p.n, far) + p.d < 0) return -1;
    const glm::dvec3 near(p.n.x >= 0 ? lo.x : hi.x, p.n.y >= 0 ? lo.y : hi.y, p.n.z >= 0 ? lo.z : hi.z);
    if (glm::dot(p.n, near) + p.d >= 0) mask &= ~(1 << k);
  }
  return mask;
}

double box_distance(const glm::dvec3& e, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::dvec3 q = glm::clamp(e, glm::dvec3(lo), glm::dvec3(hi));
  return glm::length(q - e);
}

// Projected screen area (pixels) of a box's 2D bounding rectangle, clipped to the viewport;
// infinite when a corner lies behind the near plane.
double box_area_px(const Camera& c, const glm::dvec3& f, const glm::dvec3& r, const glm::dvec3& u, double focal_px,
                   const glm::vec3& lo, const glm::vec3& hi) {
  double x0 = std::numeric_limits<double>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 p((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec3 d = p - c.eye;
    const double depth = glm::dot(d, f);
    if (depth <= c.near_plane) return std::numeric_limits<double>::infinity();
    const double sx = focal_px * glm::dot(d, r) / depth, sy = focal_px * glm::dot(d, u) / depth;
    x0 = std::min(x0, sx);
    x1 = std::max(x1, sx);
    y0 = std::min(y0, sy);
    y1 = std::max(y1, sy);
  }
  const double hw = c.width * 0.5, hh = c.height * 0.5;
  x0 = std::clamp(x0, -hw, hw);
  x1 = std::clamp(x1, -hw, hw);
  y0 = std::clamp(y0, -hh, hh);
  y1 = std::clamp(y1, -hh, hh);
  return (x1 - x0) * (y1 - y0);
}

// Traversal stack items: an implicit node name or a slot to emit, packed into 64 bits.
// Bits 0-2 kind, 3-8 level + top, 9-29 ci, 30-50 cj, 51 half (which x half); slots, and the
// places of subtrees walked apart (pass 4), bits 3+.
enum : std::uint64_t { kSquare = 0, kHalf = 1, kEmitSlot = 2, kLeaf = 3, kEmitBoxes = 4, kSubtreePlace = 5 };
constexpr std::uint64_t pack(std::uint64_t kind, int level_index, int ci, int cj, int half = 0) {
  return kind | (static_cast<std::uint64_t>(level_index) << 3) | (static_cast<std::uint64_t>(ci) << 9) |
         (static_cast<std::uint64_t>(cj) << 30) | (static_cast<std::uint64_t>(half) << 51);
}
constexpr std::uint64_t pack_slot(std::int32_t slot) { return kEmitSlot | (static_cast<std::uint64_t>(slot) << 3); }
// A bucket of colour boxes (mrbsp/box_order.h), emitted like a slot.
constexpr std::uint64_t pack_boxes(std::int32_t bucket) { return kEmitBoxes | (static_cast<std::uint64_t>(bucket) << 3); }
constexpr std::uint64_t kind_of(std::uint64_t item) { return item & 7u; }
constexpr int level_index_of(std::uint64_t item) { return static_cast<int>((item >> 3) & 63u); }
constexpr int ci_of(std::uint64_t item) { return static_cast<int>((item >> 9) & 0x1FFFFFu); }
constexpr int cj_of(std::uint64_t item) { return static_cast<int>((item >> 30) & 0x1FFFFFu); }
constexpr int half_of(std::uint64_t item) { return static_cast<int>((item >> 51) & 1u); }
constexpr std::int32_t slot_of(std::uint64_t item) { return static_cast<std::int32_t>(item >> 3); }

}  // namespace

void TerrainTree::traverse(const Camera& camera, const TraversalOptions& options, Frame& frame,
                           std::span<const ColorBox> boxes) const {
  Impl& lazy = *impl_;  // builds the low alternatives it draws for the first time
  const Impl& m = lazy;
  frame.indices.clear();
  frame.level.clear();
  frame.transient_positions.clear();
  frame.transient_colors.clear();
  frame.boxes = {};
  if (frame.box_scratch_) frame.box_scratch_->active = false;
  // Set once the boxes are distributed (after the occlusion pass): the walk of pass 4 then
  // puts their buckets in its order.
  BoxScratch* box_order = nullptr;
  const std::size_t previous_nodes = frame.nodes_visited;
  frame.nodes_visited = 0;
  frame.leaves = 0;
  frame.crack_triangles = 0;
  frame.balanced_cells = 0;
  frame.occlusion = {};
  frame.lod_histogram.assign(static_cast<std::size_t>(m.levels), 0);
  // Per cell: the traversal's stamp << 3 | kDrawn or kRefined; anything else: not visited.
  if (frame.stamp_.size() != m.total_cells) {
    frame.stamp_.assign(m.total_cells, 0);
    frame.current_stamp_ = 0;
  }
  if (++frame.current_stamp_ >= (1u << 29)) {  // wrapped: clear once every 2^29 frames
    std::fill(frame.stamp_.begin(), frame.stamp_.end(), 0);
    frame.current_stamp_ = 1;
  }
  constexpr std::uint32_t kDrawn = 1, kRefined = 2, kChecked = 4;  // kChecked: pass 2's, below
  constexpr std::uint32_t kWasHidden = 1, kWasOpened = 2, kWasVisible = 3;  // Frame::visibility_
  const std::uint32_t stamp = frame.current_stamp_ << 3;
  auto& marks = frame.stamp_;
  const auto state = [&](std::uint32_t cell) { return (marks[cell] & ~7u) == stamp ? marks[cell] & 3u : 0u; };

  const glm::dvec3 f = glm::normalize(camera.forward);
  const glm::dvec3 r = glm::normalize(glm::cross(f, camera.up));
  const glm::dvec3 u = glm::cross(r, f);
  const double focal_px = camera.height * 0.5 / std::tan(glm::radians(camera.fov_y_deg) * 0.5);
  const auto planes = frustum_planes(camera);
  const glm::dvec3 e = camera.eye;
  const bool back_to_front = !options.front_to_back;

  // The highest merged content in a cell's subtree (-inf when none).
  const auto content_top = [&](int level, int ci, int cj) {
    if (level < 0) return m.top_content.empty() ? -std::numeric_limits<float>::infinity()
                                                : m.top_content[static_cast<std::size_t>(level + m.top)][static_cast<std::size_t>(cj * m.cells_at(level) + ci)];
    if (m.content_index.empty()) return -std::numeric_limits<float>::infinity();
    const std::int32_t c = m.content_index.find(m.cell_id(level, ci, cj));
    return c < 0 ? -std::numeric_limits<float>::infinity() : m.content[static_cast<std::size_t>(c)].top;
  };
  const auto content_of = [&](int level, int ci, int cj) -> const CellContent* {
    if (level < 0 || m.content_index.empty()) return nullptr;
    const std::int32_t c = m.content_index.find(m.cell_id(level, ci, cj));
    return c < 0 ? nullptr : &m.content[static_cast<std::size_t>(c)];
  };
  // The window's sides the eye lies beyond (west, east, south, north): their walls are drawn.
  const bool beyond[4] = {e.x < m.xs.front(), e.x > m.xs.back(), e.y < m.ys.front(), e.y > m.ys.back()};
  // The cell's terrain box, and whether the box holding its content too (merged pieces up to
  // top, walls down to bottom) is in view.
  struct Box {
    glm::vec3 lo, hi;
    float top, bottom;
    glm::vec3 content_lo() const { return glm::vec3(lo.x, lo.y, bottom); }
    glm::vec3 content_hi() const { return glm::vec3(hi.x, hi.y, top); }
  };
  const auto box_of = [&](int level, int ci, int cj, const CellZ& cz) __attribute__((always_inline)) {
    const int s = m.cell_size(level), i0 = ci * s, j0 = cj * s;
    const bool wall = (beyond[0] && i0 == 0) || (beyond[1] && i0 + s == m.n) || (beyond[2] && j0 == 0) || (beyond[3] && j0 + s == m.n);
    return Box{glm::vec3(static_cast<float>(m.xs[static_cast<std::size_t>(i0)]), static_cast<float>(m.ys[static_cast<std::size_t>(j0)]), cz.zmin),
               glm::vec3(static_cast<float>(m.xs[static_cast<std::size_t>(i0 + s)]), static_cast<float>(m.ys[static_cast<std::size_t>(j0 + s)]), cz.zmax),
               std::max(cz.zmax, content_top(level, ci, cj)), wall ? m.wall_base : cz.zmin};
  };
  const auto in_view = [&](const Box& b) { return !options.cull || !box_outside(planes, b.content_lo(), b.content_hi()); };

  // Pass 1, the LOD choice (sections 5 and 5.1): every cell in view, refined while the metric
  // asks; the drawn cells listed by level. A cell's decision depends on the camera and the
  // cell alone, so subtrees are decided apart: below LOD level 1 in parallel, when the last
  // traversal into this Frame visited TraversalOptions::parallel_min_nodes cells or more.
  // The marks (what pass 2 and the walk read) are the serial ones; only the order of the
  // by_level lists differs, and pass 2's refinements do not depend on it (each one refines a
  // drawn cell toward a neighbour, whichever comes first).
  auto& by_level = frame.by_level_;
  by_level.resize(static_cast<std::size_t>(m.levels));
  for (auto& l : by_level) l.clear();
  // Decides the cell of `item`: listed in `lists` when drawn, its children pushed onto `st`
  // when refined. Items carry the frustum planes their box still has to be tested against
  // (bits 52-56).
  const auto decide = [&](std::uint64_t item, std::vector<std::uint64_t>& st, std::vector<std::vector<std::uint64_t>>& lists) {
    const int level = level_index_of(item) - m.top, ci = ci_of(item), cj = cj_of(item);
    if (level == m.levels - 1 && (item >> 52 & 31) == 0) {
      // A finest cell inside every frustum plane its parent straddled is drawn whatever its
      // box: its heights (four samples of the lattice, a cache miss or two) are not read.
      marks[m.cell_id(level, ci, cj)] = stamp | kDrawn;
      lists[static_cast<std::size_t>(level)].push_back(static_cast<std::uint64_t>(ci) << 32 | static_cast<std::uint32_t>(cj));
      return;
    }
    const CellZ cz = m.cell_z(level, ci, cj);
    const Box box = box_of(level, ci, cj, cz);
    const int planes_left = options.cull ? box_planes(planes, box.content_lo(), box.content_hi(), static_cast<int>(item >> 52) & 31) : 0;
    if (planes_left < 0) return;
    bool refine = level < m.levels - 1;
    if (level >= 0 && refine && !options.full_res) {
      if (options.metric == LodMetric::kError) {
        const double dist = std::max(box_distance(e, box.lo, box.hi), camera.near_plane);
        refine = cz.error * focal_px / dist > options.threshold_px;
      } else {
        refine = box_area_px(camera, f, r, u, focal_px, box.lo, box.hi) > options.threshold_px;
      }
    }
    if (level >= 0) marks[m.cell_id(level, ci, cj)] = stamp | (refine ? kRefined : kDrawn);
    if (!refine) {
      lists[static_cast<std::size_t>(level)].push_back(static_cast<std::uint64_t>(ci) << 32 | static_cast<std::uint32_t>(cj));
      return;
    }
    // The children's heights and marks, asked for now: they are decided after the deepest
    // child's subtree, and on a cold cache (a frame's draw comes between traversals) each is
    // a miss otherwise. Two rows of each.
    const int child = level + 1;
    for (int row = 0; row < 2; ++row) {
      const int cj2 = 2 * cj + row;
      if (child >= 0) __builtin_prefetch(&marks[m.cell_id(child, 2 * ci, cj2)], 1);
      if (child < m.levels - 1) {
        __builtin_prefetch(&m.cellz[m.cellz_offset[static_cast<std::size_t>(child + m.top)] +
                                    static_cast<std::size_t>(cj2 * m.cells_at(child) + 2 * ci)]);
      } else if (planes_left != 0) {
        __builtin_prefetch(&m.positions[m.vertex(2 * ci, cj2)]);
        if (row == 1) __builtin_prefetch(&m.positions[m.vertex(2 * ci, cj2 + 1)]);
      }
    }
    for (int k = 0; k < 4; ++k) {
      st.push_back(pack(kSquare, level_index_of(item) + 1, 2 * ci + (k & 1), 2 * cj + (k >> 1)) |
                   static_cast<std::uint64_t>(planes_left) << 52);
    }
  };
  auto& stack = frame.stack_;
  stack.clear();
  stack.push_back(pack(kSquare, 0, 0, 0) | std::uint64_t{31} << 52);
  // The level index whose items become subtrees of their own (none: -1).
  const int split = m.levels > 1 && previous_nodes >= options.parallel_min_nodes ? m.top + 1 : -1;
  auto& roots = frame.subtree_roots_;
  roots.clear();
  while (!stack.empty()) {
    const std::uint64_t item = stack.back();
    stack.pop_back();
    if (level_index_of(item) == split) {
      roots.push_back(item);
      continue;
    }
    ++frame.nodes_visited;
    decide(item, stack, by_level);
  }
  if (!roots.empty()) {
    if (frame.subtrees_.size() < roots.size()) frame.subtrees_.resize(roots.size());
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, roots.size(), 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t k = range.begin(); k != range.end(); ++k) {
            Frame::Subtree& sub = frame.subtrees_[k];
            sub.by_level.resize(static_cast<std::size_t>(m.levels));
            for (auto& l : sub.by_level) l.clear();
            sub.nodes = 0;
            sub.stack.assign(1, roots[k]);
            while (!sub.stack.empty()) {
              const std::uint64_t item = sub.stack.back();
              sub.stack.pop_back();
              ++sub.nodes;
              decide(item, sub.stack, sub.by_level);
            }
          }
        },
        tbb::simple_partitioner());
    for (std::size_t k = 0; k < roots.size(); ++k) {
      const Frame::Subtree& sub = frame.subtrees_[k];
      frame.nodes_visited += sub.nodes;
      for (std::size_t l = 0; l < by_level.size(); ++l) by_level[l].insert(by_level[l].end(), sub.by_level[l].begin(), sub.by_level[l].end());
    }
  }

  // Pass 2, balance: neighbours drawn at most one level apart, so that every crack is one
  // triangle of lattice samples (below). A drawn cell at level k needs every edge neighbour of
  // its parent (level k - 1) refined or drawn; where one lies in a cell drawn at level k - 2 or
  // coarser, that cell is refined (down to level k - 2) instead. Refining only creates drawn
  // cells at coarser levels than k, so one sweep from the finest level up settles it. Depends
  // on the camera only, never on what is visible beyond the frustum test.
  if (options.crack_fills) {
    const auto draw_child = [&](int level, int ci, int cj) {
      const CellZ cz = m.cell_z(level, ci, cj);
      if (!in_view(box_of(level, ci, cj, cz))) return;
      marks[m.cell_id(level, ci, cj)] = stamp | kDrawn;
      by_level[static_cast<std::size_t>(level)].push_back(static_cast<std::uint64_t>(ci) << 32 | static_cast<std::uint32_t>(cj));
    };
    for (int k = m.levels - 1; k >= 2; --k) {
      auto& list = by_level[static_cast<std::size_t>(k)];
      for (std::size_t q = 0; q < list.size(); ++q) {
        const int ci = static_cast<int>(list[q] >> 32), cj = static_cast<int>(list[q] & 0xFFFFFFFFu);
        // A finest cell is never refined: only coarser ones need their state read again.
        if (k < m.levels - 1 && state(m.cell_id(k, ci, cj)) != kDrawn) continue;
        const int pi = ci / 2, pj = cj / 2, pc = m.cells_at(k - 1);
        // Siblings ask the same of their parent's neighbours: once is enough (kChecked, a bit
        // beside the parent's state; a later refinement of the parent may clear it, which only
        // asks again). On the bench terrain views at 1 px this pass took 0.37-0.53 ms without
        // it, 0.24 ms with it.
        std::uint32_t& parent = marks[m.cell_id(k - 1, pi, pj)];  // refined in this traversal
        if ((parent & ~3u) == (stamp | kChecked)) continue;
        parent |= kChecked;
        const int nbr[4][2] = {{pi - 1, pj}, {pi + 1, pj}, {pi, pj - 1}, {pi, pj + 1}};
        for (const auto& nb : nbr) {
          if (nb[0] < 0 || nb[1] < 0 || nb[0] >= pc || nb[1] >= pc) continue;
          // The drawn cell covering the neighbour at k - 2 or coarser, if any.
          int level = k - 2, x = nb[0] / 2, y = nb[1] / 2;
          while (level >= 0 && state(m.cell_id(level, x, y)) == 0) {
            --level;
            x /= 2;
            y /= 2;
          }
          if (level < 0 || state(m.cell_id(level, x, y)) != kDrawn) continue;
          // Refine it and its descendants over the neighbour down to level k - 2.
          for (; level <= k - 2; ++level) {
            marks[m.cell_id(level, x, y)] = stamp | kRefined;
            ++frame.balanced_cells;
            const int shift = k - 2 - level;  // from level + 1 to the neighbour's level k - 1
            const int tx = nb[0] >> shift, ty = nb[1] >> shift;
            for (int c = 0; c < 4; ++c) {
              const int cx = 2 * x + (c & 1), cy = 2 * y + (c >> 1);
              if (level + 1 <= k - 2 && cx == tx && cy == ty) continue;  // refined in the next round
              draw_child(level + 1, cx, cy);
            }
            x = tx;
            y = ty;
            if (level + 1 > k - 2) break;
          }
        }
      }
    }
  }

  // One item of the walk below: what it puts out, and what it pushes onto `items` (the
  // walk's stack, or one subtree's) to come out after it.
  const auto walk_item = [&](bool b2f, std::uint64_t item, std::vector<std::uint64_t>& items, auto&& enter, auto&& out) {
    const auto push_pair = [&](std::uint64_t far_item, std::uint64_t near_item) {
      items.push_back(b2f ? near_item : far_item);
      items.push_back(b2f ? far_item : near_item);
    };
    const std::uint64_t kind = kind_of(item);
    if (kind == kEmitSlot || kind == kLeaf || kind == kEmitBoxes) {
      out(item);
      return;
    }
    const int level_index = level_index_of(item), level = level_index - m.top;
    const int ci = ci_of(item), cj = cj_of(item);
    const int s = m.cell_size(level), half = s / 2;
    const int i0 = ci * s, j0 = cj * s;
    if (kind == kHalf) {  // the y split of one x half of a square
      const int a = half_of(item);
      if (level >= 0 && !enter(level, ci, cj, a)) return;  // hidden
      const std::uint64_t south = pack(kSquare, level_index + 1, 2 * ci + a, 2 * cj);
      const std::uint64_t north = pack(kSquare, level_index + 1, 2 * ci + a, 2 * cj + 1);
      if (e.y >= m.ys[static_cast<std::size_t>(j0 + half)]) push_pair(south, north); else push_pair(north, south);
      return;
    }
    // A square: a top cell (always split, if in view) or an LOD cell as decided.
    bool refine = true;
    // A cell left out keeps the colour boxes of its whole column, drawn in its place.
    const auto left_out = [&] {
      const std::int32_t b = box_order ? box_order->whole(level_index, ci, cj) : -1;
      if (b >= 0) out(pack_boxes(b));
    };
    if (level >= 0) {
      const std::uint32_t st = state(m.cell_id(level, ci, cj));
      if (st == 0 || !enter(level, ci, cj, -1)) {  // out of view, or hidden
        left_out();
        return;
      }
      refine = st == kRefined;
    } else if (!in_view(box_of(level, ci, cj, m.cell_z(level, ci, cj)))) {
      left_out();
      return;
    }
    const CellContent* content = content_of(level, ci, cj);
    // What comes out, in back-to-front order: the pieces above the cell's terrain (when the
    // eye is below the plane z = zmax they are far), the terrain part, the pieces above
    // (when the eye is above that plane they are near). Pushed in reverse. Colour boxes above
    // the cell go into its above slot when it has one, else they come out in its place, at
    // their separation height (mrbsp/box_order.h).
    std::uint64_t above = 0;
    double above_z = 0.0;
    if (content && content->above >= 0) {
      above = pack_slot(content->above);
      above_z = static_cast<double>(m.cell_z(level, ci, cj).zmax);
    } else if (const std::int32_t b = box_order ? box_order->above(level_index, ci, cj) : -1; b >= 0) {
      above = pack_boxes(b);
      above_z = static_cast<double>(separation_height(m, level, ci, cj));
    }
    const bool above_near = above != 0 && e.z >= above_z;
    const bool above_first = above != 0 && above_near != b2f;
    const bool above_last = above != 0 && !above_first;
    if (above_last) items.push_back(above);
    if (refine) {
      if (level + 1 >= 0) {  // the children's marks, read when they come off the stack
        __builtin_prefetch(&marks[m.cell_id(level + 1, 2 * ci, 2 * cj)]);
        __builtin_prefetch(&marks[m.cell_id(level + 1, 2 * ci, 2 * cj + 1)]);
      }
      const std::uint64_t west = pack(kHalf, level_index, ci, cj, 0), east = pack(kHalf, level_index, ci, cj, 1);
      if (e.x >= m.xs[static_cast<std::size_t>(i0 + half)]) push_pair(west, east); else push_pair(east, west);
    } else {
      items.push_back(pack(kLeaf, level_index, ci, cj));
    }
    if (above_first) items.push_back(above);
  };
  // The decided tree in order (the far side of every split first for back_to_front, the near
  // one otherwise): `enter(level, ci, cj, half)` for each LOD cell reached (half -1) and each
  // of its x halves (half 0 west, 1 east) when it is refined (false leaves it out),
  // `out(item)` for each drawn cell (kLeaf) and slot (kEmitSlot) in order. Items on the stack
  // are pushed in reverse of the order they are to come out in. A square at level index
  // `split_at` (none: -1) is handed to `at_split` in its place instead, for its subtree to be
  // walked apart (walk_item from it alone gives that subtree's part of the order).
  const auto walk = [&](bool b2f, auto&& enter, auto&& out, int split_at, auto&& at_split) {
    stack.clear();
    // The window, inside the chain of its four boundary planes: beyond each lie the kOutside
    // slots of one side (west x < xs[0], east x > xs[n], south y < ys[0], north y > ys[n]), in
    // bands parallel to the plane. Built from the innermost out: the window, then each
    // boundary plane's bands on the far or near side of what is inside it. A side's bands are
    // slabs between parallel planes: back to front, those farther from the eye along the axis
    // first (slabs on opposite sides of the eye cannot overlap on screen), the one holding the
    // eye last.
    auto& order = frame.outside_order_;
    order.clear();
    order.push_back(pack(kSquare, 0, 0, 0));
    auto& places = frame.outside_places_;
    for (int side = 3; side >= 0; --side) {
      const std::vector<std::int32_t>& slots = m.outside[static_cast<std::size_t>(side)];
      // Colour boxes beyond the side in places without a slot (BoxScratch::outside_places).
      const std::vector<BoxScratch::OutsideBoxes>* boxed = box_order ? &box_order->outside_places(side) : nullptr;
      if (slots.empty() && (boxed == nullptr || boxed->empty())) continue;
      // Each place is a box: its band's slab across the side's axis, its column's (row's) along
      // the other; sorted by the band's distance from the eye, then the column's. (The first and
      // last rows of west and east reach beyond the window's south and north planes; the
      // distance to the row's bounds within the window orders them the same among parallel
      // slabs.)
      const double eye_at = side < 2 ? e.x : e.y, eye_across = side < 2 ? e.y : e.x;
      places.clear();
      const auto place = [&](int band, int column, std::uint64_t item) {
        const double a = m.band_plane(side, band);
        const double b = band + 1 < kBands ? m.band_plane(side, band + 1) : (side % 2 == 0 ? -INFINITY : INFINITY);
        const double x0 = m.place_line(side, column);
        const double x1 = m.place_line(side, column + 1);
        const double column_distance =
            eye_across < x0 ? x0 - eye_across : eye_across > x1 ? eye_across - x1 : 0.0;
        const double lo = std::min(a, b), hi = std::max(a, b);
        const double band_distance = eye_at < lo ? lo - eye_at : eye_at > hi ? eye_at - hi : 0.0;
        places.push_back({band_distance, column_distance, item});
      };
      for (const std::int32_t slot : slots) {
        const OutsidePlace p = outside_place(m.slots[static_cast<std::size_t>(slot)].key);
        place(p.band, p.column, pack_slot(slot));
      }
      if (boxed != nullptr) {
        for (const BoxScratch::OutsideBoxes& b : *boxed) place(b.band, b.column, pack_boxes(b.bucket));
      }
      std::sort(places.begin(), places.end(), [&](const Frame::OutsideOrder& p, const Frame::OutsideOrder& q) {
        if (p.band_distance != q.band_distance) return b2f ? p.band_distance > q.band_distance : p.band_distance < q.band_distance;
        return b2f ? p.column_distance > q.column_distance : p.column_distance < q.column_distance;
      });
      for (const Frame::OutsideOrder& p : places) order.push_back(p.item);
      // After everything inside, or before it.
      if (beyond[side] != b2f) std::rotate(order.begin(), order.end() - static_cast<std::ptrdiff_t>(places.size()), order.end());
    }
    for (std::size_t k = order.size(); k-- > 0;) stack.push_back(order[k]);
    while (!stack.empty()) {
      const std::uint64_t item = stack.back();
      stack.pop_back();
      if (kind_of(item) == kSquare && level_index_of(item) == split_at) {
        at_split(item);
        continue;
      }
      walk_item(b2f, item, stack, enter, out);
    }
  };
  // A drawn cell's crack fills: where the same-level neighbour is refined, balance put it one
  // level finer, so the gap between this cell's edge and the neighbour's is exactly the
  // triangle (corner, the edge's middle sample, corner), in the shared boundary plane.
  struct Edge {
    bool needed;
    bool faces_away;  // the boundary plane lies beyond the cell's content from the eye
    std::uint32_t a, mid, b;
  };
  const auto edges_of = [&](int level, int ci, int cj, std::array<Edge, 4>& edges) {
    const int s = m.cell_size(level), cells = m.cells_at(level), h = s / 2;
    const int i0 = ci * s, j0 = cj * s, i1 = i0 + s, j1 = j0 + s;
    const bool fills = options.crack_fills && s > 1;
    edges = {{
        {fills && ci > 0 && state(m.cell_id(level, ci - 1, cj)) == kRefined, e.x >= m.xs[static_cast<std::size_t>(i0)],
         m.vertex(i0, j1), m.vertex(i0, j0 + h), m.vertex(i0, j0)},
        {fills && ci + 1 < cells && state(m.cell_id(level, ci + 1, cj)) == kRefined, e.x <= m.xs[static_cast<std::size_t>(i1)],
         m.vertex(i1, j0), m.vertex(i1, j0 + h), m.vertex(i1, j1)},
        {fills && cj > 0 && state(m.cell_id(level, ci, cj - 1)) == kRefined, e.y >= m.ys[static_cast<std::size_t>(j0)],
         m.vertex(i0, j0), m.vertex(i0 + h, j0), m.vertex(i1, j0)},
        {fills && cj + 1 < cells && state(m.cell_id(level, ci, cj + 1)) == kRefined, e.y <= m.ys[static_cast<std::size_t>(j1)],
         m.vertex(i1, j1), m.vertex(i0 + h, j1), m.vertex(i0, j1)},
    }};
  };

  // Pass 3, occlusion (Greene 1996, sections 3-5): front to back over the decided tree, each
  // LOD cell's box (its content's) tested against the coverage of the opaque terrain tiled
  // so far (section 5.2, test-only tiling of the box's silhouette), and each drawn cell's
  // terrain triangles and crack fills tiled (section 3.1). Merged polygons are translucent and
  // never tiled; walls are not tiled either (less coverage is always conservative). Everything tiled before a cell lies on the near side of some plane that
  // separates it from the cell, so a cell whose box is covered is hidden by nearer opaque
  // terrain, which the back-to-front draw puts over it: leaving it out changes no pixel.
  // Window coordinates are computed in double precision as GL maps them (glViewport(0, 0,
  // width, height)); llvmpipe transforms float positions with float matrices, so a pixel is
  // claimed only when its centre is inside a triangle by more than that error (the margin),
  // and a box is hidden only when its silhouette dilated by it is covered.
  // When the pass does not pay (it culled fewer drawn cells than it kept: it tiles every kept
  // cell, and on llvmpipe tiling a triangle costs about what drawing a hidden one does), the
  // next kOcclusionBackoff traversals with this Frame leave it out (options.occlusion_adaptive),
  // and the one after that tries it again. Leaving it out culls nothing: the same image.
  constexpr int kOcclusionBackoff = 8;
  bool occlusion = options.occlusion;
  if (occlusion && options.occlusion_adaptive && frame.occlusion_backoff_ > 0) {
    --frame.occlusion_backoff_;
    occlusion = false;
    frame.occlusion.left_out = true;
  }
  if (occlusion) {
    frame.occlusion.ran = true;
    const auto t0 = std::chrono::steady_clock::now();
    if (!frame.pyramid_ || frame.pyramid_->width() != camera.width || frame.pyramid_->height() != camera.height) {
      frame.pyramid_ = std::make_unique<coverage::Pyramid>(camera.width, camera.height);
    } else {
      frame.pyramid_->clear();
    }
    coverage::Pyramid& pyramid = *frame.pyramid_;
    if (frame.visibility_.size() != m.total_cells) frame.visibility_.assign(m.total_cells, 0);
    const double hw = 0.5 * camera.width, hh = 0.5 * camera.height;
    const double eye_norm = glm::length(e);
    // Window coordinates of p; false (and nothing) when p is not beyond the near plane.
    const auto project = [&](const glm::dvec3& p, glm::dvec2& w, double& depth) {
      const glm::dvec3 d = p - e;
      depth = glm::dot(d, f);
      if (!(depth > camera.near_plane)) return false;
      w = glm::dvec2(hw + focal_px * glm::dot(d, r) / depth, hh + focal_px * glm::dot(d, u) / depth);
      return true;
    };
    // The float pipeline's error at depth `depth` for points as far as `extent` from the
    // origin, in pixels: float32's relative precision (2^-24), times a few roundings, times
    // the magnitudes it multiplies, projected; plus the 1/256 px snapping.
    const auto error_px = [&](double extent, double depth) {
      return 0.004 + 8.0 * 5.96e-8 * (extent + eye_norm) * focal_px / depth;
    };
    // A vertex projected once for the triangles of a cell that share it.
    struct Projected {
      glm::dvec2 w;
      double depth, extent;
      bool ok;
    };
    const auto project_vertex = [&](std::uint32_t v) {
      const glm::dvec3 p(m.positions[v]);
      Projected q{};
      q.ok = project(p, q.w, q.depth);
      q.extent = glm::length(p);
      return q;
    };
    const auto tile = [&](const Projected& a, const Projected& b, const Projected& c) {
      if (!a.ok || !b.ok || !c.ok) return;
      const glm::dvec2 w[3] = {a.w, b.w, c.w};
      ++frame.occlusion.tiled_triangles;
      pyramid.cover(w, error_px(std::max({a.extent, b.extent, c.extent}), std::min({a.depth, b.depth, c.depth})));
    };
    // A cell's two terrain triangles, (sw, se, ne) and (sw, ne, nw): when both project with
    // the same orientation, se and nw lie on opposite sides of their shared diagonal, so
    // together they are the quadrilateral (sw, se, ne, nw), tiled in one call (the pyramid
    // claims no more than the quadrilateral's inside even when it is not convex). The
    // quadrilateral also claims the centres near the diagonal, which the triangles tiled
    // apart would leave to neither: they share its two transformed vertices, and GL's
    // rasterization is watertight, so every centre on or near it is filled by one of them.
    const auto tile_cell = [&](const Projected& sw, const Projected& se, const Projected& ne, const Projected& nw) {
      const auto area2 = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
        return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      };
      // Twice the signed areas, px^2; nearly flat triangles (whose orientation the float
      // pipeline may see otherwise) are tiled apart.
      constexpr double kMinArea2 = 1e-3;
      const bool ok = sw.ok && se.ok && ne.ok && nw.ok;
      const double s0 = ok ? area2(sw.w, se.w, ne.w) : 0.0, s1 = ok ? area2(sw.w, ne.w, nw.w) : 0.0;
      if (!((s0 > kMinArea2 && s1 > kMinArea2) || (s0 < -kMinArea2 && s1 < -kMinArea2))) {
        tile(sw, se, ne);
        tile(sw, ne, nw);
        return;
      }
      const glm::dvec2 w[4] = {sw.w, se.w, ne.w, nw.w};
      frame.occlusion.tiled_triangles += 2;
      pyramid.cover(w, error_px(std::max({sw.extent, se.extent, ne.extent, nw.extent}),
                                std::min({sw.depth, se.depth, ne.depth, nw.depth})));
    };
    glm::dvec2 corners[8];
    walk(
        false,
        [&](int level, int ci, int cj, int half) {
          const std::uint32_t cell = m.cell_id(level, ci, cj);
          // A square's x halves are not tested: their two squares each are, and a half's box
          // (the union of theirs) is hidden only when both are, so testing it saved less than
          // its test cost (two more z ranges and eight more projections per refined square).
          if (half >= 0) return true;
          const bool leaf = state(cell) == kDrawn;
          // Bittner and Havran 2001: what this node was last frame decides whether to test it.
          // Hierarchy updating: a square opened last frame (tested visible, not a leaf) and not
          // a leaf now goes straight to its children, unless all four of those were hidden (the
          // pull-up: it is then a termination node again and tested). Conservative updating:
          // a leaf visible last frame is assumed visible again with probability p_skip
          // (decided by a hash of the cell and the frame, so runs repeat). Either way nothing
          // that would be drawn is left out: the LOD choice and the image do not change.
          std::uint32_t* memo = &frame.visibility_[cell];
          const auto was = [&](std::uint32_t v) { return v >> 2 == frame.current_stamp_ - 1 ? v & 3u : 0u; };
          const auto remember = [&](std::uint32_t v) { *memo = frame.current_stamp_ << 2 | v; };
          const auto children_hidden = [&] {
            for (int k = 0; k < 4; ++k)
              if (was(frame.visibility_[m.cell_id(level + 1, 2 * ci + (k & 1), 2 * cj + (k >> 1))]) != kWasHidden)
                return false;
            return true;
          };
          const std::uint32_t last = was(*memo);
          if (options.coherence != Coherence::kOff && last == kWasOpened && !leaf && !children_hidden()) {
            ++frame.occlusion.skipped_tests;
            remember(kWasOpened);
            return true;
          }
          if (options.coherence == Coherence::kConservative && last == kWasVisible && leaf) {
            std::uint64_t h = (static_cast<std::uint64_t>(cell) << 32 | frame.current_stamp_) * 0x9E3779B97F4A7C15ull;
            h ^= h >> 31;
            if (static_cast<double>(h >> 11) * 0x1.0p-53 < options.p_skip) {
              ++frame.occlusion.skipped_tests;
              remember(kWasVisible);
              return true;
            }
          }
          remember(leaf ? kWasVisible : kWasOpened);
          const Box b = box_of(level, ci, cj, m.cell_z(level, ci, cj));
          // A sample before the test: the projection of any point of the box lies inside its
          // silhouette, so when the pixel under the box's centre, or under its top's centre, is
          // still vacant the box is visible (nearly always: the pixel's centre may lie just
          // outside the silhouette, and then a cull is missed, never made wrongly). Most boxes
          // the walk meets are visible; this answers them for two projections and two bit
          // lookups instead of eight projections and a test-only tiling.
          {
            const glm::dvec3 mid(0.5 * (static_cast<double>(b.lo.x) + b.hi.x), 0.5 * (static_cast<double>(b.lo.y) + b.hi.y),
                                 0.5 * (static_cast<double>(b.bottom) + b.top));
            glm::dvec2 w;
            double depth = 0.0;
            for (const double z : {mid.z, static_cast<double>(b.top)}) {
              if (!project(glm::dvec3(mid.x, mid.y, z), w, depth)) return true;  // reaches the eye's plane: visible
              const double px = std::floor(w.x), py = std::floor(w.y);
              if (px >= 0 && py >= 0 && px < camera.width && py < camera.height &&
                  !pyramid.covered(static_cast<int>(px), static_cast<int>(py))) {
                ++frame.occlusion.sampled_visible;
                return true;
              }
            }
          }
          double near_depth = std::numeric_limits<double>::max();
          for (int k = 0; k < 8; ++k) {
            const glm::dvec3 p((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.top : b.bottom);
            double depth = 0.0;
            if (!project(p, corners[k], depth)) return true;  // reaches the eye's plane: visible
            near_depth = std::min(near_depth, depth);
          }
          // No corner is farther from the origin than the corner of the largest magnitudes.
          const double extent = glm::length(glm::max(glm::abs(glm::dvec3(b.content_lo())), glm::abs(glm::dvec3(b.content_hi()))));
          ++frame.occlusion.tested_nodes;
          const double dilation = error_px(extent, near_depth);
          if (dilation > coverage::kMaxMargin || !pyramid.hidden(corners, dilation)) return true;
          remember(kWasHidden);
          ++frame.occlusion.culled_nodes;
          return false;
        },
        [&](std::uint64_t item) {
          if (kind_of(item) != kLeaf) return;
          const int level = level_index_of(item) - m.top, ci = ci_of(item), cj = cj_of(item);
          const int s = m.cell_size(level), i0 = ci * s, j0 = cj * s;
          const Projected sw = project_vertex(m.vertex(i0, j0)), se = project_vertex(m.vertex(i0 + s, j0)),
                          ne = project_vertex(m.vertex(i0 + s, j0 + s)), nw = project_vertex(m.vertex(i0, j0 + s));
          tile_cell(sw, se, ne, nw);
          std::array<Edge, 4> edges;
          edges_of(level, ci, cj, edges);
          // Each fill's ends are two of the cell's corners, in the order edges_of gives them.
          const Projected* ends[4][2] = {{&nw, &sw}, {&se, &ne}, {&sw, &se}, {&ne, &nw}};
          for (std::size_t k = 0; k < 4; ++k)
            if (edges[k].needed) tile(*ends[k][0], project_vertex(edges[k].mid), *ends[k][1]);
        },
        -1, [](std::uint64_t) {});
    frame.occlusion.pass_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }

  // The colour boxes, sent through the decided tree (mrbsp/color_boxes.cpp): from here the walk
  // puts their buckets in its order.
  if (!boxes.empty()) {
    if (!frame.box_scratch_) frame.box_scratch_ = std::make_unique<BoxScratch>();
    Decided decided;
    decided.marks = &marks;
    decided.stamp = stamp;
    if (occlusion) {
      decided.visibility = &frame.visibility_;
      decided.hidden = frame.current_stamp_ << 2 | kWasHidden;
    }
    decided.top_in_view.resize(static_cast<std::size_t>(m.top));
    for (int li = 0; li < m.top; ++li) {
      const int level = li - m.top, cells = m.cells_at(level);
      auto& flags = decided.top_in_view[static_cast<std::size_t>(li)];
      flags.resize(static_cast<std::size_t>(cells * cells));
      for (int cj = 0; cj < cells; ++cj)
        for (int ci = 0; ci < cells; ++ci)
          flags[static_cast<std::size_t>(cj * cells + ci)] = in_view(box_of(level, ci, cj, m.cell_z(level, ci, cj))) ? 1 : 0;
    }
    frame.box_scratch_->distribute(lazy, camera, decided, boxes);
    box_order = frame.box_scratch_.get();
  }

  // Pass 4, the order of the draw: the decided tree, less what occlusion found hidden. When
  // the LOD choice ran in parallel subtrees, and no colour boxes share their scratch, so does
  // the walk: each subtree below LOD level 1 into its own part of the order, joined in order.
  // The low slots drawn for the first time are built after the walk, in parallel, their
  // vertices flushed in the draw's order (each is built once, before pass 5 emits it, and its
  // vertices get the indices they got when slots were built one by one on the way).
  auto& leaves = frame.leaves_;
  leaves.clear();
  // What one part of the walk enters: its drawn cells counted per level and in all, the
  // unbuilt low slots among them listed.
  const auto enter_into = [&](std::vector<std::size_t>& histogram, std::size_t& drawn, std::vector<std::int32_t>& unbuilt) {
    return [&, h = &histogram, d = &drawn, u = &unbuilt](int level, int ci, int cj, int half) {
      const std::uint32_t cell = m.cell_id(level, ci, cj);
      if (occlusion && half < 0 && frame.visibility_[cell] == (frame.current_stamp_ << 2 | kWasHidden)) return false;
      if (half < 0 && state(cell) == kDrawn) {
        const CellContent* content = content_of(level, ci, cj);
        if (content && content->low >= 0 && !m.slots[static_cast<std::size_t>(content->low)].built) u->push_back(content->low);
        ++(*h)[static_cast<std::size_t>(level)];
        ++*d;
      }
      return true;
    };
  };
  auto& walk_roots = frame.subtree_roots_;  // pass 1 is done with its own
  walk_roots.clear();
  auto& unbuilt = frame.unbuilt_;  // the serial part's, with -1 - k in subtree k's place
  unbuilt.clear();
  walk(back_to_front, enter_into(frame.lod_histogram, frame.leaves, unbuilt), [&](std::uint64_t item) { leaves.push_back(item); },
       box_order == nullptr ? split : -1, [&](std::uint64_t root) {
         leaves.push_back(kSubtreePlace | static_cast<std::uint64_t>(walk_roots.size()) << 3);
         unbuilt.push_back(-1 - static_cast<std::int32_t>(walk_roots.size()));
         walk_roots.push_back(root);
       });
  if (!walk_roots.empty()) {
    if (frame.subtrees_.size() < walk_roots.size()) frame.subtrees_.resize(walk_roots.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, walk_roots.size(), 4), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t k = range.begin(); k != range.end(); ++k) {
        Frame::Subtree& sub = frame.subtrees_[k];
        sub.leaves.clear();
        sub.unbuilt.clear();
        sub.histogram.assign(static_cast<std::size_t>(m.levels), 0);
        sub.nodes = 0;  // here: its drawn cells
        const auto enter = enter_into(sub.histogram, sub.nodes, sub.unbuilt);
        const auto out = [&](std::uint64_t item) { sub.leaves.push_back(item); };
        sub.stack.assign(1, walk_roots[k]);
        while (!sub.stack.empty()) {
          const std::uint64_t item = sub.stack.back();
          sub.stack.pop_back();
          walk_item(back_to_front, item, sub.stack, enter, out);
        }
      }
    });
    auto& joined = frame.joined_leaves_;
    joined.clear();
    for (const std::uint64_t item : leaves) {
      if (kind_of(item) != kSubtreePlace) {
        joined.push_back(item);
        continue;
      }
      const Frame::Subtree& sub = frame.subtrees_[static_cast<std::size_t>(item >> 3)];
      joined.insert(joined.end(), sub.leaves.begin(), sub.leaves.end());
      frame.leaves += sub.nodes;
      for (std::size_t l = 0; l < sub.histogram.size(); ++l) frame.lod_histogram[l] += sub.histogram[l];
    }
    leaves.swap(joined);
  }
  // Rarely any (a region drawn at a level for the first time): the vector allocates only then.
  std::vector<std::int32_t> in_order;
  for (const std::int32_t slot : unbuilt) {
    if (slot >= 0) {
      in_order.push_back(slot);
      continue;
    }
    const auto& part = frame.subtrees_[static_cast<std::size_t>(-1 - slot)].unbuilt;
    in_order.insert(in_order.end(), part.begin(), part.end());
  }
  lazy.build_pending(in_order);
  if (occlusion) {
    std::size_t drawn = 0;  // the drawn cells of the LOD choice, culled or not
    for (int level = 0; level < m.levels; ++level)
      for (const std::uint64_t c : by_level[static_cast<std::size_t>(level)])
        drawn += state(m.cell_id(level, static_cast<int>(c >> 32), static_cast<int>(c & 0xFFFFFFFFu))) == kDrawn ? 1 : 0;
    frame.occlusion.culled_leaves = drawn - frame.leaves;
    frame.occlusion_backoff_ = frame.occlusion.culled_leaves < frame.leaves ? kOcclusionBackoff : 0;
  }

  // Pass 5: expand each drawn cell into its crack fills and triangles, and each slot into its
  // polygons, in order.
  // Triangles are written through a cursor into buffers opened to the expected count (grown
  // by doubling when a view needs more) and cut to size at the end: no per-triangle
  // bookkeeping of std::vector, and no allocation once the Frame is warm. Opening them to
  // their capacity instead cleared all of it in every frame (std::vector::resize fills), so
  // one full-resolution frame made every later one slower: the bench's terrain views, which
  // share a Frame with full-resolution ones, spent about 1 ms of a 1.8 ms pass so.
  // A sink is where one chunk of the order writes (the whole order when it runs serially).
  struct Sink {
    std::vector<std::uint32_t>& indices;
    std::vector<std::int8_t>& level;
    std::vector<std::uint64_t>& stack;  // the small BSPs' walk
    std::size_t triangles = 0, cracks = 0;
    void open(std::size_t expected) {
      const std::size_t want = expected + expected / 4 + 1024;  // crack fills and walls are not estimated
      if (level.size() < want) {
        level.resize(want);
        indices.resize(3 * want);
      }
    }
    void emit(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::int8_t lvl) {
      if (triangles == level.size()) {
        level.resize(2 * triangles);
        indices.resize(6 * triangles);
      }
      std::uint32_t* out = indices.data() + 3 * triangles;
      out[0] = a;
      out[1] = b;
      out[2] = c;
      level[triangles++] = lvl;
    }
  };
  // A slot's small BSP: the far side of each plane first. With culling, a subtree whose box
  // lies outside the view frustum is left out (GL would clip all of it away), each box tested
  // only against the planes its parent's box straddles.
  // Every slot emitted is built: above and outside slots when merged, low ones by pass 4.
  // Colour boxes put in a slot's BSP come out at the empty sides of its nodes; such a slot is
  // drawn without leaving out subtrees by their boxes (which hold its own polygons only).
  frame.transient_base = static_cast<std::uint32_t>(m.positions.size());
  const auto emit_boxes = [&](Sink& out, std::int32_t bucket) {
    box_order->emit_bucket(bucket, e, back_to_front, frame);
    for (const BoxScratch::Tri& t : box_order->tris) out.emit(t.a, t.b, t.c, t.level);
  };
  auto emit_store = [&](Sink& out, const BspStore& store, std::int32_t slot) {
    auto& st = out.stack;
    st.clear();
    const bool boxed = box_order && box_order->in_slot(slot);
    // Items: node index, bit 31 set to emit the node's own polygons, bits 32-36 the planes left;
    // or with bit 40 a bucket of boxes.
    constexpr std::uint64_t kEmitBit = std::uint64_t{1} << 31, kBoxBit = std::uint64_t{1} << 40;
    const auto push_node = [&](std::int32_t node, int mask) {
      if (node < 0) return;
      if (options.cull && mask != 0) {
        const NodeBox& box = store.boxes[static_cast<std::size_t>(node)];
        if (box.lo[0] > box.hi[0]) return;  // holds nothing
        // Outward in double, then to floats rounded outward again: the box still holds the subtree.
        const glm::dvec3 lo = glm::dvec3(store.box_base) + glm::dvec3(box.lo[0], box.lo[1], box.lo[2]) * glm::dvec3(store.box_step);
        const glm::dvec3 hi = glm::dvec3(store.box_base) + glm::dvec3(box.hi[0], box.hi[1], box.hi[2]) * glm::dvec3(store.box_step);
        const glm::vec3 flo(std::nextafter(static_cast<float>(lo.x), -INFINITY), std::nextafter(static_cast<float>(lo.y), -INFINITY),
                            std::nextafter(static_cast<float>(lo.z), -INFINITY));
        const glm::vec3 fhi(std::nextafter(static_cast<float>(hi.x), INFINITY), std::nextafter(static_cast<float>(hi.y), INFINITY),
                            std::nextafter(static_cast<float>(hi.z), INFINITY));
        mask = box_planes(planes, flo, fhi, mask);
        if (mask < 0) return;
      }
      st.push_back(static_cast<std::uint64_t>(node) | static_cast<std::uint64_t>(mask) << 32);
    };
    if (boxed && store.root < 0) {
      if (const std::int32_t b = box_order->bsp(slot, BoxScratch::kRootless, 0); b >= 0) emit_boxes(out, b);
    }
    push_node(store.root, boxed ? 0 : 31);
    while (!st.empty()) {
      const std::uint64_t item = st.back();
      st.pop_back();
      if (item & kBoxBit) {
        emit_boxes(out, static_cast<std::int32_t>(item & (kEmitBit - 1)));
        continue;
      }
      const auto node = static_cast<std::size_t>(item & (kEmitBit - 1));
      const BspNode& bn = store.nodes[node];
      if (item & kEmitBit) {
        for (std::uint32_t k = 0; k < bn.count; ++k) {
          const Polygon& p = store.polys[bn.first + k];
          const std::uint32_t a = store.refs[p.first];
          for (std::uint32_t q = 1; q + 1 < p.count; ++q) out.emit(a, store.refs[p.first + q], store.refs[p.first + q + 1], p.level);
        }
        continue;
      }
      const int mask = static_cast<int>(item >> 32);
      const bool eye_front = glm::dot(glm::dvec3(bn.n), e) + static_cast<double>(bn.d) >= 0.0;
      // The side drawn first (1: front): the far one for back to front.
      const int first_side = eye_front != back_to_front ? 1 : 0;
      // An empty side (-1) may hold boxes.
      const auto push_side = [&](int side) {
        const std::int32_t child = side ? bn.front : bn.back;
        if (boxed && child == -1) {
          if (const std::int32_t b = box_order->bsp(slot, static_cast<std::int32_t>(node), side); b >= 0) {
            st.push_back(kBoxBit | static_cast<std::uint64_t>(b));
          }
          return;
        }
        push_node(child, mask);
      };
      push_side(1 - first_side);
      st.push_back(kEmitBit | item);
      push_side(first_side);
    }
  };
  // A drawn cell's walls: on each window side the eye lies beyond and the cell touches, the
  // quad from the cell's edge (copies of its two boundary samples) down to wall_base, in the
  // boundary plane and the cell's box. Like a crack fill facing the eye, after the cell's
  // triangles.
  const auto emit_walls = [&](Sink& out, int level, int ci, int cj) {
    const int s = m.cell_size(level);
    for (int side = 0; side < 4; ++side) {
      if (!beyond[side]) continue;
      const int i0 = ci * s, j0 = cj * s;
      const bool touches = side == 0 ? i0 == 0 : side == 1 ? i0 + s == m.n : side == 2 ? j0 == 0 : j0 + s == m.n;
      if (!touches) continue;
      const int k0 = side < 2 ? j0 : i0, k1 = k0 + s;  // the edge's samples along the side
      const std::uint32_t a = m.wall_vertex(side, k0), b = m.wall_vertex(side, k1);
      out.emit(a, b, m.wall_bottom(side, k1), kWallLevel);
      out.emit(a, m.wall_bottom(side, k1), m.wall_bottom(side, k0), kWallLevel);
    }
  };
  const auto emit_item = [&](Sink& out, std::uint64_t item) {
    if (kind_of(item) == kEmitSlot) {
      emit_store(out, *m.slots[static_cast<std::size_t>(slot_of(item))].store, slot_of(item));
      return;
    }
    if (kind_of(item) == kEmitBoxes) {
      emit_boxes(out, slot_of(item));
      return;
    }
    const int level = level_index_of(item) - m.top;
    const int ci = ci_of(item), cj = cj_of(item);
    const int s = m.cell_size(level);
    const int i0 = ci * s, j0 = cj * s, i1 = i0 + s, j1 = j0 + s;
    const std::uint32_t sw = m.vertex(i0, j0), se = m.vertex(i1, j0), ne = m.vertex(i1, j1), nw = m.vertex(i0, j1);

    // Crack fills, ordered like their boundary plane: before the cell's triangles when it
    // faces away from the eye, after them otherwise.
    std::array<Edge, 4> edges;
    edges_of(level, ci, cj, edges);
    const auto emit_fills = [&](bool away) {
      for (const Edge& edge : edges) {
        if (edge.needed && edge.faces_away == away) {
          out.emit(edge.a, edge.mid, edge.b, kCrackLevel);
          ++out.cracks;
        }
      }
      if (!away) emit_walls(out, level, ci, cj);  // they face the eye
    };
    emit_fills(back_to_front);

    const CellContent* content = content_of(level, ci, cj);
    if (content && content->low >= 0) {
      emit_store(out, *m.slots[static_cast<std::size_t>(content->low)].store, content->low);
    } else {
      // The diagonal sw-ne separates (sw, se, ne) on its south-east side from (sw, ne, nw).
      const double side = (m.xs[static_cast<std::size_t>(i1)] - m.xs[static_cast<std::size_t>(i0)]) * (e.y - m.ys[static_cast<std::size_t>(j0)]) -
                          (m.ys[static_cast<std::size_t>(j1)] - m.ys[static_cast<std::size_t>(j0)]) * (e.x - m.xs[static_cast<std::size_t>(i0)]);
      const bool eye_south_east = side < 0;
      const auto lvl = static_cast<std::int8_t>(level);
      if (box_order && box_order->leaf(level_index_of(item), ci, cj)) {  // with colour boxes above the triangles
        box_order->emit_leaf(m, level_index_of(item), ci, cj, e, eye_south_east, back_to_front, frame);
        for (const BoxScratch::Tri& t : box_order->tris) out.emit(t.a, t.b, t.c, t.level);
      } else if (eye_south_east == back_to_front) {  // draw the north-west triangle first
        out.emit(sw, ne, nw, lvl);
        out.emit(sw, se, ne, lvl);
      } else {
        out.emit(sw, se, ne, lvl);
        out.emit(sw, ne, nw, lvl);
      }
    }
    emit_fills(!back_to_front);
  };

  // Chunks: the order cut where the estimated triangles (a slot's pieces, a cell's two or its
  // low slot's pieces) reach equal shares. The colour boxes' buckets and leaves write into
  // shared scratch (BoxScratch::tris, the frame's own vertices), so a frame with boxes runs
  // serially. On the benchmark's N44W072 view with volumes (180k merged triangles) this pass
  // took 12.6 of the traversal's 14.2 ms serially.
  // The store an item draws from, if any (a slot, or a cell's low alternative).
  const auto store_of = [&](std::uint64_t item) -> const BspStore* {
    if (kind_of(item) == kEmitSlot)
      return m.slots[static_cast<std::size_t>(slot_of(item))].store.get();
    if (kind_of(item) == kEmitBoxes) return nullptr;
    const CellContent* content = content_of(level_index_of(item) - m.top, ci_of(item), cj_of(item));
    return content && content->low >= 0
               ? m.slots[static_cast<std::size_t>(content->low)].store.get()
               : nullptr;
  };
  const auto estimate_of = [&](std::uint64_t item) -> std::size_t {
    if (kind_of(item) == kEmitBoxes) return 0;
    const BspStore* store = store_of(item);
    return store ? store->pieces : 2;
  };
  // Without merged content every item is a cell of two triangles (and its crack fills): the
  // estimate and the cuts need no walk over the items.
  const bool cells_only = m.slots.empty() && !box_order;
  std::size_t estimate = 0;
  if (cells_only) {
    estimate = 2 * leaves.size();
  } else if (!box_order) {
    for (const std::uint64_t item : leaves) estimate += estimate_of(item);
  }
  const std::size_t chunks = box_order || estimate < options.parallel_min_triangles
                                 ? 1
                                 : std::min<std::size_t>(leaves.size(), 2 * static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()));
  // Chunk c writes leaves [cut[c], cut[c + 1]); chunk 0 into the frame's own buffers, the
  // others into their scratch, joined after it in order. One chunk is the serial pass.
  auto& cut = frame.chunk_cuts_;
  cut.assign(chunks + 1, leaves.size());
  cut[0] = 0;
  std::size_t so_far = 0, next = 1;
  if (cells_only) {
    for (std::size_t c = 1; c < chunks; ++c) cut[c] = leaves.size() * c / chunks;
    next = chunks;
  }
  for (std::size_t k = 0; k < leaves.size() && next < chunks; ++k) {
    so_far += estimate_of(leaves[k]);
    while (next < chunks && so_far * chunks >= estimate * next) cut[next++] = k + 1;
  }
  if (frame.chunks_.size() < chunks) frame.chunks_.resize(chunks);
  const auto run_chunk = [&](std::size_t c) {
    Frame::EmitChunk& chunk = frame.chunks_[c];
    Sink out{c == 0 ? frame.indices : chunk.indices, c == 0 ? frame.level : chunk.level, chunk.stack};
    out.open(estimate / chunks);
    // Each store's arrays lie apart on the heap, and the walk of a small one waited mostly on
    // their first lines: the store two items ahead and the arrays of the next one are fetched
    // meanwhile. The benchmark's N44W072 view with volumes (10,417 items, 177k merged pieces;
    // a still `fly`, three alternating runs): traversal 8.7-9.5 ms against 10.3-11.0; with each
    // item's store looked up once, 7.2-7.7 ms (three runs, the machine quieter then).
    const std::size_t end = cut[c + 1];
    const BspStore* coming = cut[c] + 1 < end ? store_of(leaves[cut[c] + 1]) : nullptr;
    for (std::size_t k = cut[c]; k < end; ++k) {
      const BspStore* after = k + 2 < end ? store_of(leaves[k + 2]) : nullptr;
      if (after != nullptr) __builtin_prefetch(after);
      if (coming != nullptr) {
        __builtin_prefetch(coming->nodes.data());
        __builtin_prefetch(coming->polys.data());
        __builtin_prefetch(coming->refs.data());
      }
      emit_item(out, leaves[k]);
      coming = after;
    }
    chunk.triangles = out.triangles;
    chunk.crack_triangles = out.cracks;
  };
  if (chunks == 1) {
    run_chunk(0);
  } else {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t c = range.begin(); c != range.end(); ++c) run_chunk(c);
        },
        tbb::simple_partitioner());
  }
  std::size_t total = 0;
  frame.crack_triangles = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    total += frame.chunks_[c].triangles;
    frame.crack_triangles += frame.chunks_[c].crack_triangles;
  }
  std::size_t at = frame.chunks_[0].triangles;
  frame.indices.resize(3 * total);  // keeps the first chunk's triangles in place
  frame.level.resize(total);
  for (std::size_t c = 1; c < chunks; ++c) {
    const Frame::EmitChunk& chunk = frame.chunks_[c];
    std::copy_n(chunk.indices.begin(), 3 * chunk.triangles, frame.indices.begin() + static_cast<std::ptrdiff_t>(3 * at));
    std::copy_n(chunk.level.begin(), chunk.triangles, frame.level.begin() + static_cast<std::ptrdiff_t>(at));
    at += chunk.triangles;
  }
  if (box_order) frame.boxes = box_order->stats;
}

}  // namespace terravol::mrbsp
