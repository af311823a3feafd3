// Multiresolution BSP tree for terrain height fields.
//
// Implements Wiley, Campbell, Szygenda, Fussell, Hudson: "Multiresolution BSP Trees Applied to
// Terrain, Transparency, and General Objects", Graphics Interface 1997:
//   - section 4.1: nested LOD grids (each level doubles the samples per side); split planes on
//     grid lines of the coarsest level still available, alternating longitude and latitude to
//     keep regions square; where a region is one cell of that level, an alternative list of
//     two: the cell's two triangles (low) and the same region rebuilt from the next level (high);
//   - section 4.3: sliding. Nodes refer to lattice line indices, never to data, so moving the
//     window over the terrain only recomputes plane offsets, positions, boxes and errors
//     (refresh()); the node structure is built once;
//   - sections 5, 5.1 and figure 5: the draw order (far child, node polygons, near child) and
//     the LOD choice from the projected bounding box; a second metric, the screen-space error.
//
// Departures from the paper, and why:
//   - The traversal is an explicit stack over flat node arrays (no recursion, no pointers).
//   - The paper leaves cracks between neighbours at different levels unaddressed; there is no
//     depth buffer to hide them here, so they are filled with skirts: vertical quads in the
//     shared boundary plane, emitted only where the neighbour cell at the same level was not
//     drawn this frame (its region is drawn coarser or finer). A skirt lies in a split plane,
//     so it is ordered exactly: before the cell's triangles when the plane faces away from the
//     eye, after them otherwise. Skirts hang to a bottom below every level's polyline along
//     their lattice line within the level-0 cell edge (each such polyline interpolates samples
//     of that edge), so the two sides' skirts together cover the gap, whichever side is
//     higher. With the eye above the ground only the skirts facing the eye can show a crack
//     (a ray reaching a gap under the near cell's edge has crossed the near cell's surface),
//     so only those are drawn; below the ground only the others; near it, both.
//   - Inside a cell the two triangles are ordered by the vertical plane through the cell's
//     diagonal, which separates them.
#include "mrbsp/terrain_tree.h"

#include "mrbsp/tree_impl.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace terravol::mrbsp {

std::int32_t TerrainTree::Impl::build_region(int rx, int ry, int w, int h, int level) {
  const int s = cell_size(level);
  const auto index = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  if (w == s && h == s) {
    nodes[index].kind = kCell;
    nodes[index].level = static_cast<std::uint8_t>(level);
    nodes[index].cell = cell_id(level, rx / s, ry / s);
    if (level + 1 < levels) {
      const std::int32_t high = build_region(rx, ry, s, s, level + 1);
      nodes[index].child[0] = high;
    }
    return index;
  }
  // Split at the middle grid line of this level, the longer side first (x when square).
  const bool split_x = w >= h;
  const int line = split_x ? rx + w / 2 : ry + h / 2;
  nodes[index].kind = split_x ? kSplitX : kSplitY;
  nodes[index].line = line;
  const std::int32_t a = split_x ? build_region(rx, ry, w / 2, h, level) : build_region(rx, ry, w, h / 2, level);
  const std::int32_t b = split_x ? build_region(line, ry, w / 2, h, level) : build_region(rx, line, w, h / 2, level);
  nodes[index].child[0] = a;
  nodes[index].child[1] = b;
  return index;
}

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
  xs.assign(w.xs.begin(), w.xs.end());
  ys.assign(w.ys.begin(), w.ys.end());
  const auto z = [&](int i, int j) { return w.z[static_cast<std::size_t>(j) * side + static_cast<std::size_t>(i)]; };

  // Skirt bottoms. Every level's polyline along a lattice line, inside one level-0 edge
  // segment, interpolates samples of that segment; so a skirt under an edge on row j
  // reaches low enough at the lowest sample of row j within the level-0 segment(s) holding
  // the edge, minus 1 m. Two bottoms per sample: one for edges along its row (south and
  // north skirts), one for edges along its column (west and east skirts).
  const int s0 = cell_size(0);
  const std::size_t count = side * side;
  positions.resize(3 * count);
  std::vector<float> segment_min(static_cast<std::size_t>(level_cells[0]));
  for (int pass = 0; pass < 2; ++pass) {  // 0: along rows, 1: along columns
    for (int line = 0; line <= n; ++line) {
      const auto at = [&](int k) { return pass == 0 ? z(k, line) : z(line, k); };
      for (int seg = 0; seg < level_cells[0]; ++seg) {
        float mn = at(seg * s0);
        for (int k = seg * s0 + 1; k <= (seg + 1) * s0; ++k) mn = std::min(mn, at(k));
        segment_min[static_cast<std::size_t>(seg)] = mn;
      }
      for (int k = 0; k <= n; ++k) {
        float bottom = segment_min[static_cast<std::size_t>(std::min(k / s0, level_cells[0] - 1))];
        if (k % s0 == 0 && k > 0) bottom = std::min(bottom, segment_min[static_cast<std::size_t>(k / s0 - 1)]);
        const int i = pass == 0 ? k : line, j = pass == 0 ? line : k;
        const std::size_t v = vertex(i, j);
        positions[(1 + pass) * count + v] = glm::vec3(static_cast<float>(xs[i]), static_cast<float>(ys[j]), bottom - 1.0f);
      }
    }
  }
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) positions[vertex(i, j)] = glm::vec3(static_cast<float>(xs[i]), static_cast<float>(ys[j]), z(i, j));

  // Cells: box and error from their samples, independent of each other (TBB).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes.size(), 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      Node& node = nodes[k];
      if (node.kind != kCell) continue;
      const int level = node.level;
      const int s = cell_size(level);
      const std::uint32_t local = node.cell - level_offset[level];
      const int ci = static_cast<int>(local % static_cast<std::uint32_t>(level_cells[level]));
      const int cj = static_cast<int>(local / static_cast<std::uint32_t>(level_cells[level]));
      const int i0 = ci * s, j0 = cj * s;
      const float zsw = z(i0, j0), zse = z(i0 + s, j0), zne = z(i0 + s, j0 + s), znw = z(i0, j0 + s);
      float zmin = std::numeric_limits<float>::max(), zmax = -zmin, err = 0.0f;
      const float inv = 1.0f / static_cast<float>(s);
      for (int j = 0; j <= s; ++j) {
        const float v = static_cast<float>(j) * inv;
        for (int i = 0; i <= s; ++i) {
          const float h = z(i0 + i, j0 + j);
          zmin = std::min(zmin, h);
          zmax = std::max(zmax, h);
          const float u = static_cast<float>(i) * inv;
          const float approx = u >= v ? zsw + u * (zse - zsw) + v * (zne - zse) : zsw + v * (znw - zsw) + u * (zne - znw);
          err = std::max(err, std::abs(h - approx));
        }
      }
      node.error = err;
      node.lo = glm::vec3(static_cast<float>(xs[static_cast<std::size_t>(i0)]), static_cast<float>(ys[static_cast<std::size_t>(j0)]), zmin);
      node.hi = glm::vec3(static_cast<float>(xs[static_cast<std::size_t>(i0 + s)]), static_cast<float>(ys[static_cast<std::size_t>(j0 + s)]), zmax);
    }
  });
  // Split nodes: plane offsets and boxes from their children (pre-order: reverse index order).
  for (std::size_t k = nodes.size(); k-- > 0;) {
    Node& node = nodes[k];
    if (node.kind == kCell) continue;
    node.plane = static_cast<float>(node.kind == kSplitX ? xs[static_cast<std::size_t>(node.line)] : ys[static_cast<std::size_t>(node.line)]);
    const Node& a = nodes[static_cast<std::size_t>(node.child[0])];
    const Node& b = nodes[static_cast<std::size_t>(node.child[1])];
    node.lo = glm::min(a.lo, b.lo);
    node.hi = glm::max(a.hi, b.hi);
  }
  // The largest error of any alternative inside each level-0 cell (for the skirt choice).
  level0_error.assign(static_cast<std::size_t>(level_cells[0]) * static_cast<std::size_t>(level_cells[0]), 0.0f);
  for (const Node& node : nodes) {
    if (node.kind != kCell) continue;
    const int s = cell_size(node.level);
    const std::uint32_t local = node.cell - level_offset[node.level];
    const int ci = static_cast<int>(local % static_cast<std::uint32_t>(level_cells[node.level])) * s / s0;
    const int cj = static_cast<int>(local / static_cast<std::uint32_t>(level_cells[node.level])) * s / s0;
    float& e0 = level0_error[static_cast<std::size_t>(cj * level_cells[0] + ci)];
    e0 = std::max(e0, node.error);
  }
  merge();  // section 4.3: other objects are merged again into the moved tree
}

TerrainTree::TerrainTree(const TerrainWindow& window, int levels) : impl_(std::make_unique<Impl>()) {
  const int n = window.cells;
  if (n < 2 || (n & (n - 1)) != 0 || n > (1 << 15)) {
    throw std::invalid_argument("TerrainTree: cells per side must be a power of two in [2, 32768], is " + std::to_string(n));
  }
  int k = 0;
  while ((1 << k) < n) ++k;
  if (levels < 1 || levels > k + 1) {
    throw std::invalid_argument("TerrainTree: levels must be in [1, " + std::to_string(k + 1) + "], is " + std::to_string(levels));
  }
  Impl& m = *impl_;
  m.n = n;
  m.levels = levels;
  std::uint32_t offset = 0;
  for (int l = 0; l < levels; ++l) {
    m.level_offset.push_back(offset);
    m.level_cells.push_back(n / m.cell_size(l));
    offset += static_cast<std::uint32_t>(m.level_cells[l]) * static_cast<std::uint32_t>(m.level_cells[l]);
  }
  m.total_cells = offset;
  // Exactly the nodes build_region makes: a cell node per cell of every level; the c0 x c0
  // level-0 cells need c0^2 - 1 split nodes above them, and each cell with a finer level below
  // splits its high alternative into 2 x 2 cells with 3 more.
  const std::size_t c0 = static_cast<std::size_t>(m.level_cells[0]);
  const std::size_t finest = static_cast<std::size_t>(m.level_cells[levels - 1]) * static_cast<std::size_t>(m.level_cells[levels - 1]);
  const std::size_t node_count = offset + (c0 * c0 - 1) + 3 * (offset - finest);
  m.nodes.reserve(node_count);
  m.build_region(0, 0, n, n, 0);
  if (m.nodes.size() != node_count) {
    throw std::logic_error("TerrainTree: built " + std::to_string(m.nodes.size()) + " nodes, expected " + std::to_string(node_count));
  }
  m.refresh(window);
}

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

MemoryStats TerrainTree::memory() const {
  const Impl& m = *impl_;
  MemoryStats s;
  s.samples = m.lattice_count();
  s.nodes = held(m.nodes) + held(m.level_offset) + held(m.level_cells) + held(m.level0_error) + held(m.xs) + held(m.ys);
  // positions holds both: the terrain's blocks up to merged_base(), merged vertices after.
  const std::size_t terrain = std::min<std::size_t>(m.merged_base(), m.positions.capacity());
  s.vertices = terrain * sizeof(glm::vec3);
  s.merged = held(m.positions) - s.vertices + held(m.merge_input_positions) + held(m.merge_input_colors) +
             held(m.merge_input_triangles) + held(m.merged_colors) + held(m.polygons) + held(m.poly_vertices) +
             held(m.node_polys) + held(m.extras) + held(m.leaf_nodes) + held(m.leaf_polys);
  return s;
}

namespace {

struct Plane {
  glm::dvec3 n;
  double d;  // inside where dot(n, p) + d >= 0
};

// Marks a traversal stack entry that emits a node's polygons instead of visiting it.
constexpr std::int32_t kEmitBit = std::int32_t{1} << 30;

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

}  // namespace

void TerrainTree::traverse(const Camera& camera, const TraversalOptions& options, Frame& frame) const {
  const Impl& m = *impl_;
  frame.indices.clear();
  frame.level.clear();
  frame.nodes_visited = 0;
  frame.leaves = 0;
  frame.skirt_triangles = 0;
  frame.lod_histogram.assign(static_cast<std::size_t>(m.levels), 0);
  if (frame.stamp_.size() != m.total_cells) {
    frame.stamp_.assign(m.total_cells, 0);
    frame.current_stamp_ = 0;
  }
  if (++frame.current_stamp_ == 0) {  // wrapped: clear once every 2^32 frames
    std::fill(frame.stamp_.begin(), frame.stamp_.end(), 0);
    frame.current_stamp_ = 1;
  }
  const std::uint32_t stamp = frame.current_stamp_;

  const glm::dvec3 f = glm::normalize(camera.forward);
  const glm::dvec3 r = glm::normalize(glm::cross(f, camera.up));
  const glm::dvec3 u = glm::cross(r, f);
  const double focal_px = camera.height * 0.5 / std::tan(glm::radians(camera.fov_y_deg) * 0.5);
  const auto planes = frustum_planes(camera);
  const glm::dvec3 e = camera.eye;
  const bool back_to_front = !options.front_to_back;

  // Pass 1: walk the tree, choose LODs, collect the drawn cells in order.
  auto& stack = frame.stack_;
  auto& leaves = frame.leaves_;
  stack.clear();
  leaves.clear();
  stack.push_back(0);
  while (!stack.empty()) {
    const std::int32_t top = stack.back();
    stack.pop_back();
    if (top & kEmitBit) {  // a split node's coplanar polygons, between its far and near sides
      leaves.push_back(top);
      continue;
    }
    const Node& node = m.nodes[static_cast<std::size_t>(top)];
    ++frame.nodes_visited;
    if (options.cull && box_outside(planes, node.lo, node.hi)) continue;
    if (node.kind == kCell) {
      bool refine = node.child[0] >= 0;
      if (refine && !options.full_res) {
        if (options.metric == LodMetric::kError) {
          const double dist = std::max(box_distance(e, node.lo, node.hi), camera.near_plane);
          refine = node.error * focal_px / dist > options.threshold_px;
        } else {
          refine = box_area_px(camera, f, r, u, focal_px, node.lo, node.hi) > options.threshold_px;
        }
      }
      if (refine) {
        stack.push_back(node.child[0]);
      } else {
        leaves.push_back(static_cast<std::int32_t>(&node - m.nodes.data()));
        frame.stamp_[node.cell] = stamp;
        ++frame.lod_histogram[node.level];
      }
      continue;
    }
    // The eye's side of the plane: its own side is near. Push the near child first so that
    // the far child is popped (drawn) first; the reverse for front-to-back.
    const double eye_coord = node.kind == kSplitX ? e.x : e.y;
    const bool eye_high = eye_coord >= node.plane;
    const std::int32_t near_child = node.child[eye_high ? 1 : 0], far_child = node.child[eye_high ? 0 : 1];
    const std::int32_t first = back_to_front ? far_child : near_child, second = back_to_front ? near_child : far_child;
    stack.push_back(second);
    if (node.extra >= 0) stack.push_back(kEmitBit | static_cast<std::int32_t>(&node - m.nodes.data()));  // its coplanar polygons
    stack.push_back(first);
  }
  frame.leaves = static_cast<std::size_t>(std::count_if(leaves.begin(), leaves.end(), [](std::int32_t v) { return !(v & kEmitBit); }));

  // Which skirts can show a crack. With the eye above the ground, a ray reaching a gap under
  // the near cell's edge has crossed that cell's surface first, so only the skirts of cells
  // beyond a boundary plane (the plane facing the eye) can show; below the ground, only the
  // others. Near the ground (within the largest error of the level-0 cell under the eye),
  // both kinds are drawn.
  bool draw_facing = options.skirts, draw_away = options.skirts;
  if (options.skirts) {
    const auto clamp_index = [](const std::vector<double>& v, double x) {
      const auto it = std::upper_bound(v.begin(), v.end(), x);
      return static_cast<int>(std::clamp<std::ptrdiff_t>(it - v.begin() - 1, 0, static_cast<std::ptrdiff_t>(v.size()) - 2));
    };
    const int i = clamp_index(m.xs, e.x), j = clamp_index(m.ys, e.y);
    const float ground = std::max({m.positions[m.vertex(i, j)].z, m.positions[m.vertex(i + 1, j)].z,
                                   m.positions[m.vertex(i, j + 1)].z, m.positions[m.vertex(i + 1, j + 1)].z});
    const float low = std::min({m.positions[m.vertex(i, j)].z, m.positions[m.vertex(i + 1, j)].z,
                                m.positions[m.vertex(i, j + 1)].z, m.positions[m.vertex(i + 1, j + 1)].z});
    const int s0 = m.cell_size(0);
    const float margin = m.level0_error[static_cast<std::size_t>((j / s0) * m.level_cells[0] + i / s0)];
    if (e.z > ground + margin) draw_away = false;
    if (e.z < low - margin) draw_facing = false;
  }

  // Pass 2: expand each drawn cell into its skirts and triangles, in order.
  const auto count = static_cast<std::uint32_t>((m.n + 1) * (m.n + 1));
  // Triangles are written through a cursor into buffers opened to their full capacity (grown
  // by doubling when a view needs more) and cut to size at the end: no per-triangle
  // bookkeeping of std::vector, and no allocation once the Frame is warm.
  std::size_t triangles = 0;
  frame.indices.resize(std::max<std::size_t>(frame.indices.capacity(), 3 * 1024));
  frame.level.resize(frame.indices.size() / 3);
  auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::int8_t level) {
    if (triangles == frame.level.size()) {
      frame.level.resize(2 * triangles);
      frame.indices.resize(6 * triangles);
    }
    std::uint32_t* out = frame.indices.data() + 3 * triangles;
    out[0] = a;
    out[1] = b;
    out[2] = c;
    frame.level[triangles++] = level;
  };
  // A quad under the edge a-b; `bottom` is the offset of the bottoms for its direction.
  auto emit_skirt = [&](std::uint32_t a, std::uint32_t b, std::uint32_t bottom) {
    emit(a, bottom + a, bottom + b, kSkirtLevel);
    emit(a, bottom + b, b, kSkirtLevel);
    frame.skirt_triangles += 2;
  };
  auto emit_polygon = [&](const Polygon& p) {  // a convex planar polygon as a fan
    for (std::uint32_t k = 1; k + 1 < p.count; ++k) {
      emit(m.poly_vertices[p.first], m.poly_vertices[p.first + k], m.poly_vertices[p.first + k + 1], p.level);
    }
  };
  // A leaf's small BSP: the far side of each plane first.
  auto emit_leaf_bsp = [&](std::int32_t root) {
    auto& st = frame.leaf_stack_;
    st.clear();
    st.push_back(root);
    while (!st.empty()) {
      const std::int32_t top = st.back();
      st.pop_back();
      if (top & kEmitBit) {
        const LeafNode& ln = m.leaf_nodes[static_cast<std::size_t>(top & ~kEmitBit)];
        for (std::uint32_t k = 0; k < ln.count; ++k) emit_polygon(m.polygons[m.leaf_polys[ln.first + k]]);
        continue;
      }
      const LeafNode& ln = m.leaf_nodes[static_cast<std::size_t>(top)];
      const bool eye_front = glm::dot(ln.n, e) + ln.d >= 0.0;
      const std::int32_t far_side = eye_front ? ln.back : ln.front, near_side = eye_front ? ln.front : ln.back;
      const std::int32_t first = back_to_front ? far_side : near_side, second = back_to_front ? near_side : far_side;
      if (second >= 0) st.push_back(second);
      st.push_back(kEmitBit | top);
      if (first >= 0) st.push_back(first);
    }
  };
  for (const std::int32_t item : leaves) {
    if (item & kEmitBit) {
      const Extra& x = m.extras[static_cast<std::size_t>(m.nodes[static_cast<std::size_t>(item & ~kEmitBit)].extra)];
      for (std::uint32_t k = 0; k < x.count; ++k) emit_polygon(m.polygons[m.node_polys[x.first + k]]);
      continue;
    }
    const Node& node = m.nodes[static_cast<std::size_t>(item)];
    const std::uint32_t cell = node.cell;
    const int level = node.level;
    const int s = m.cell_size(level), cells = m.level_cells[level];
    const std::uint32_t local = cell - m.level_offset[level];
    const int ci = static_cast<int>(local % cells), cj = static_cast<int>(local / cells);
    const int i0 = ci * s, j0 = cj * s, i1 = i0 + s, j1 = j0 + s;
    const std::uint32_t sw = m.vertex(i0, j0), se = m.vertex(i1, j0), ne = m.vertex(i1, j1), nw = m.vertex(i0, j1);

    // Skirts: only where the same-level neighbour was not drawn this frame.
    struct Edge {
      bool needed;
      bool faces_away;  // the boundary plane lies beyond the cell's content from the eye
      std::uint32_t a, b, bottom;
    };
    const Edge edges[4] = {
        {ci > 0 && frame.stamp_[m.cell_id(level, ci - 1, cj)] != stamp, e.x >= m.xs[i0], nw, sw, 2 * count},          // west
        {ci + 1 < cells && frame.stamp_[m.cell_id(level, ci + 1, cj)] != stamp, e.x <= m.xs[i1], se, ne, 2 * count},  // east
        {cj > 0 && frame.stamp_[m.cell_id(level, ci, cj - 1)] != stamp, e.y >= m.ys[j0], sw, se, count},          // south
        {cj + 1 < cells && frame.stamp_[m.cell_id(level, ci, cj + 1)] != stamp, e.y <= m.ys[j1], ne, nw, count},  // north
    };
    const bool first_pass_far = back_to_front;
    for (const Edge& edge : edges)
      if (edge.needed && edge.faces_away == first_pass_far && (edge.faces_away ? draw_away : draw_facing))
        emit_skirt(edge.a, edge.b, edge.bottom);

    if (node.extra >= 0 && m.extras[static_cast<std::size_t>(node.extra)].leaf_root >= 0) {
      emit_leaf_bsp(m.extras[static_cast<std::size_t>(node.extra)].leaf_root);
      for (const Edge& edge : edges)
        if (edge.needed && edge.faces_away != first_pass_far && (edge.faces_away ? draw_away : draw_facing))
          emit_skirt(edge.a, edge.b, edge.bottom);
      continue;
    }
    // The diagonal sw-ne separates (sw, se, ne) on its south-east side from (sw, ne, nw).
    const double side = (m.xs[i1] - m.xs[i0]) * (e.y - m.ys[j0]) - (m.ys[j1] - m.ys[j0]) * (e.x - m.xs[i0]);
    const bool eye_south_east = side < 0;
    const auto lvl = static_cast<std::int8_t>(level);
    if (eye_south_east == back_to_front) {  // draw the north-west triangle first
      emit(sw, ne, nw, lvl);
      emit(sw, se, ne, lvl);
    } else {
      emit(sw, se, ne, lvl);
      emit(sw, ne, nw, lvl);
    }
    for (const Edge& edge : edges)
      if (edge.needed && edge.faces_away != first_pass_far && (edge.faces_away ? draw_away : draw_facing))
        emit_skirt(edge.a, edge.b, edge.bottom);
  }
  frame.indices.resize(3 * triangles);
  frame.level.resize(triangles);
}

}  // namespace terravol::mrbsp
