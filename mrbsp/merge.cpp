// Merging other polygons into the MRBSP tree: Wiley et al. 1997, section 4.2 ("Merging Other
// Objects"). Insertion from the root is the ordinary BSP merge (Fuchs, Kedem, Naylor 1980):
// classify against the node's plane, split what spans, keep what is coplanar at the node. At a
// node with LOD alternatives (a cell), a copy goes into every alternative: the cell's low
// representation and its high subtree. Inside a drawn cell the polygons and the cell's two
// terrain triangles are ordered by a small autopartition BSP whose root is the cell's
// diagonal plane (the plane the traversal already uses to order the two triangles).
// Classification is in double precision, with a tolerance relative to the window's size.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "mrbsp/tree_impl.h"

namespace terravol::mrbsp {

namespace {

enum class Side { kBack, kFront, kCoplanar, kSpanning };

struct PlaneD {
  glm::dvec3 n;
  double d;
};

// Polygon under construction: vertex indices and its tag.
struct Work {
  std::vector<std::uint32_t> verts;
  std::int8_t level = kMergedLevel;
};

class Merger {
 public:
  // expected_vertices: about how many merged vertices there will be (the merge before's
  // count), so that their double copies are allocated once.
  Merger(TerrainTree::Impl& m, std::size_t expected_vertices) : m_(m) {
    const double size = std::max(m.xs.back() - m.xs.front(), m.ys.back() - m.ys.front());
    eps_ = 1e-9 * std::max(size, 1.0);
    merged_.reserve(expected_vertices);
  }

  glm::dvec3 pos(std::uint32_t v) const {
    return v < m_.merged_base() ? glm::dvec3(m_.positions[v]) : merged_[v - m_.merged_base()];
  }

  std::uint32_t add_vertex(const glm::dvec3& p, const glm::u8vec4& c) {
    merged_.push_back(p);
    m_.merged_colors.push_back(c);
    return m_.merged_base() + static_cast<std::uint32_t>(merged_.size() - 1);
  }

  // Appends the merged vertices to the tree's positions, as floats (positions holds only the
  // terrain's blocks when the merge starts).
  void emit_positions() {
    m_.positions.reserve(m_.positions.size() + merged_.size());
    for (const glm::dvec3& p : merged_) m_.positions.emplace_back(p);
  }

  glm::u8vec4 color(std::uint32_t v) const {
    return v < m_.merged_base() ? glm::u8vec4(255) : m_.merged_colors[v - m_.merged_base()];
  }

  Side classify(const Work& w, const PlaneD& p) const {
    bool front = false, back = false;
    for (std::uint32_t v : w.verts) {
      const double s = glm::dot(p.n, pos(v)) + p.d;
      front |= s > eps_;
      back |= s < -eps_;
    }
    if (front && back) return Side::kSpanning;
    if (front) return Side::kFront;
    if (back) return Side::kBack;
    return Side::kCoplanar;
  }

  // Splits a spanning convex polygon; vertices within eps of the plane go to both sides.
  void split(const Work& w, const PlaneD& p, Work& back, Work& front) {
    back.verts.clear();
    front.verts.clear();
    back.level = front.level = w.level;
    const std::size_t k = w.verts.size();
    for (std::size_t i = 0; i < k; ++i) {
      const std::uint32_t a = w.verts[i], b = w.verts[(i + 1) % k];
      const glm::dvec3 pa = pos(a), pb = pos(b);
      const double sa = glm::dot(p.n, pa) + p.d, sb = glm::dot(p.n, pb) + p.d;
      const int ca = sa > eps_ ? 1 : (sa < -eps_ ? -1 : 0), cb = sb > eps_ ? 1 : (sb < -eps_ ? -1 : 0);
      if (ca >= 0) front.verts.push_back(a);
      if (ca <= 0) back.verts.push_back(a);
      if (ca * cb < 0) {
        const double t = sa / (sa - sb);
        const glm::dvec4 c = glm::mix(glm::dvec4(color(a)), glm::dvec4(color(b)), t);
        const std::uint32_t v = add_vertex(glm::mix(pa, pb, t), glm::u8vec4(glm::round(c)));
        front.verts.push_back(v);
        back.verts.push_back(v);
      }
    }
  }

  // Newell's normal; false for a degenerate (zero-area) polygon.
  bool plane_of(const Work& w, PlaneD& out) const {
    glm::dvec3 n(0.0), c(0.0);
    const std::size_t k = w.verts.size();
    for (std::size_t i = 0; i < k; ++i) {
      const glm::dvec3 a = pos(w.verts[i]), b = pos(w.verts[(i + 1) % k]);
      n += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
      c += a;
    }
    const double len = glm::length(n);
    if (!(len > eps_ * eps_)) return false;  // twice the area, against a tolerance-sized square
    out.n = n / len;
    out.d = -glm::dot(out.n, c / static_cast<double>(k));
    return true;
  }

  std::uint32_t store(const Work& w) {
    Polygon p;
    p.first = static_cast<std::uint32_t>(m_.poly_vertices.size());
    p.count = static_cast<std::uint32_t>(w.verts.size());
    p.level = w.level;
    m_.poly_vertices.insert(m_.poly_vertices.end(), w.verts.begin(), w.verts.end());
    m_.polygons.push_back(p);
    return static_cast<std::uint32_t>(m_.polygons.size() - 1);
  }

  // Inserts one polygon from the root.
  void insert(Work w) {
    stack_.push_back({0, std::move(w)});
    Work back, front;
    while (!stack_.empty()) {
      auto [index, poly] = std::move(stack_.back());
      stack_.pop_back();
      const Node& node = m_.nodes[static_cast<std::size_t>(index)];
      if (node.kind == kCell) {
        cell_polys_[index].push_back(poly);
        if (node.child[0] >= 0) stack_.push_back({node.child[0], std::move(poly)});
        continue;
      }
      PlaneD p{node.kind == kSplitX ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0),
               -(node.kind == kSplitX ? m_.xs[static_cast<std::size_t>(node.line)] : m_.ys[static_cast<std::size_t>(node.line)])};
      switch (classify(poly, p)) {
        case Side::kCoplanar:
          coplanar_[index].push_back(store(poly));
          break;
        case Side::kBack:
          stack_.push_back({node.child[0], std::move(poly)});
          break;
        case Side::kFront:
          stack_.push_back({node.child[1], std::move(poly)});
          break;
        case Side::kSpanning:
          split(poly, p, back, front);
          stack_.push_back({node.child[0], back});
          stack_.push_back({node.child[1], front});
          break;
      }
    }
  }

  // Builds a leaf BSP over `polys`, with `forced` as the root plane when given.
  std::int32_t build_leaf(std::vector<Work> polys, const PlaneD* forced) {
    if (polys.empty()) return -1;
    PlaneD p;
    std::size_t start = 0;
    if (forced) {
      p = *forced;
    } else {
      while (start < polys.size() && !plane_of(polys[start], p)) ++start;
      if (start == polys.size()) return -1;  // only degenerate polygons left: nothing to draw
    }
    std::vector<Work> back, front;
    std::vector<std::uint32_t> here;
    Work b, f;
    for (std::size_t i = start; i < polys.size(); ++i) {
      switch (classify(polys[i], p)) {
        case Side::kCoplanar:
          here.push_back(store(polys[i]));
          break;
        case Side::kBack:
          back.push_back(std::move(polys[i]));
          break;
        case Side::kFront:
          front.push_back(std::move(polys[i]));
          break;
        case Side::kSpanning:
          split(polys[i], p, b, f);
          back.push_back(b);
          front.push_back(f);
          break;
      }
    }
    const auto index = static_cast<std::int32_t>(m_.leaf_nodes.size());
    m_.leaf_nodes.emplace_back();
    m_.leaf_nodes[static_cast<std::size_t>(index)].n = p.n;
    m_.leaf_nodes[static_cast<std::size_t>(index)].d = p.d;
    m_.leaf_nodes[static_cast<std::size_t>(index)].first = static_cast<std::uint32_t>(m_.leaf_polys.size());
    m_.leaf_nodes[static_cast<std::size_t>(index)].count = static_cast<std::uint32_t>(here.size());
    m_.leaf_polys.insert(m_.leaf_polys.end(), here.begin(), here.end());
    const std::int32_t bi = build_leaf(std::move(back), nullptr);
    const std::int32_t fi = build_leaf(std::move(front), nullptr);
    m_.leaf_nodes[static_cast<std::size_t>(index)].back = bi;
    m_.leaf_nodes[static_cast<std::size_t>(index)].front = fi;
    return index;
  }

  void finish() {
    for (auto& [index, ids] : coplanar_) {
      Extra e;
      e.first = static_cast<std::uint32_t>(m_.node_polys.size());
      e.count = static_cast<std::uint32_t>(ids.size());
      m_.node_polys.insert(m_.node_polys.end(), ids.begin(), ids.end());
      m_.nodes[static_cast<std::size_t>(index)].extra = static_cast<std::int32_t>(m_.extras.size());
      m_.extras.push_back(e);
    }
    for (auto& [index, polys] : cell_polys_) {
      const Node& node = m_.nodes[static_cast<std::size_t>(index)];
      const int s = m_.cell_size(node.level);
      const std::uint32_t local = node.cell - m_.level_offset[node.level];
      const int ci = static_cast<int>(local % static_cast<std::uint32_t>(m_.level_cells[node.level]));
      const int cj = static_cast<int>(local / static_cast<std::uint32_t>(m_.level_cells[node.level]));
      const std::uint32_t sw = m_.vertex(ci * s, cj * s), se = m_.vertex(ci * s + s, cj * s);
      const std::uint32_t ne = m_.vertex(ci * s + s, cj * s + s), nw = m_.vertex(ci * s, cj * s + s);
      // The cell's terrain triangles first, so that their planes split the merged polygons.
      std::vector<Work> items;
      items.push_back({{sw, se, ne}, static_cast<std::int8_t>(node.level)});
      items.push_back({{sw, ne, nw}, static_cast<std::int8_t>(node.level)});
      for (auto& w : polys) items.push_back(std::move(w));
      // The vertical plane through the diagonal, negative on the south-east side.
      const glm::dvec3 a = pos(sw), c = pos(ne);
      PlaneD diag;
      diag.n = glm::normalize(glm::dvec3(-(c.y - a.y), c.x - a.x, 0.0));
      diag.d = -glm::dot(diag.n, a);
      Extra e;
      e.leaf_root = build_leaf(std::move(items), &diag);
      m_.nodes[static_cast<std::size_t>(index)].extra = static_cast<std::int32_t>(m_.extras.size());
      m_.extras.push_back(e);
    }
  }

 private:
  TerrainTree::Impl& m_;
  double eps_ = 0.0;
  std::vector<glm::dvec3> merged_;  // the merged vertices in double precision, for classifying
  std::vector<std::pair<std::int32_t, Work>> stack_;
  std::unordered_map<std::int32_t, std::vector<std::uint32_t>> coplanar_;
  std::unordered_map<std::int32_t, std::vector<Work>> cell_polys_;
};

}  // namespace

namespace {

// Frees a container's storage (clear() keeps it).
template <class T>
void release(std::vector<T>& v) {
  std::vector<T>().swap(v);
}

// Sizes a container's storage to what it holds (push_back leaves up to twice that).
template <class T>
void fit(std::vector<T>& v) {
  if (v.capacity() > v.size()) std::vector<T>(v.begin(), v.end()).swap(v);
}

}  // namespace

void TerrainTree::Impl::merge() {
  const auto t0 = std::chrono::steady_clock::now();
  // Forget what was merged before. The containers keep their storage while this merge fills
  // them again (a slide, section 4.3, merges into the moved window: reusing it spares the
  // page faults and regrowth of some 300 MB, about half a second), and are fitted to what
  // they hold at the end. Only cleared, they would keep the capacity of the largest merge so
  // far plus push_back's slack: measured in terravol fly over examples/utah-flight.json, the
  // positions held room for 12.6 M vertices for 6.6 M, and the merged vertices' double copies
  // (kept then) grew to 201 MB at the second slide and stayed there.
  const std::size_t previous_vertices = merge_stats.merged_vertices;
  positions.resize(merged_base());
  merged_colors.clear();
  polygons.clear();
  poly_vertices.clear();
  node_polys.clear();
  extras.clear();
  leaf_nodes.clear();
  leaf_polys.clear();
  for (Node& node : nodes) node.extra = -1;
  merge_stats = {};
  if (!merge_input_triangles.empty()) {
    Merger merger(*this, std::max(previous_vertices, merge_input_positions.size()));
    for (std::size_t v = 0; v < merge_input_positions.size(); ++v) {
      merger.add_vertex(merge_input_positions[v], merge_input_colors[v]);
    }
    const std::uint32_t base = merged_base();
    for (std::size_t t = 0; t + 2 < merge_input_triangles.size(); t += 3) {
      Work w;
      w.verts = {base + merge_input_triangles[t], base + merge_input_triangles[t + 1], base + merge_input_triangles[t + 2]};
      PlaneD unused;
      if (!merger.plane_of(w, unused)) continue;  // zero-area triangles draw nothing
      merger.insert(std::move(w));
    }
    merger.finish();
    merger.emit_positions();
  }  // the merge's scratch (double vertices, polygons per node) is freed here, before fitting
  fit(positions);
  fit(merged_colors);
  fit(polygons);
  fit(poly_vertices);
  fit(node_polys);
  fit(extras);
  fit(leaf_nodes);
  fit(leaf_polys);
  merge_stats.input_triangles = merge_input_triangles.size() / 3;
  merge_stats.stored_polygons = polygons.size();
  merge_stats.merged_vertices = merged_colors.size();
  merge_stats.merge_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

MergeStats TerrainTree::merge(std::span<const glm::dvec3> vertices, std::span<const glm::u8vec4> colors,
                              std::span<const std::uint32_t> triangles) {
  if (colors.size() != vertices.size()) {
    throw std::invalid_argument("TerrainTree::merge: " + std::to_string(colors.size()) + " colours for " +
                                std::to_string(vertices.size()) + " vertices");
  }
  if (triangles.size() % 3 != 0) throw std::invalid_argument("TerrainTree::merge: triangle indices not a multiple of 3");
  for (std::uint32_t i : triangles) {
    if (i >= vertices.size()) throw std::invalid_argument("TerrainTree::merge: index " + std::to_string(i) + " out of range");
  }
  // Exactly sized copies (assign() would keep a larger earlier capacity).
  release(impl_->merge_input_positions);
  release(impl_->merge_input_colors);
  release(impl_->merge_input_triangles);
  impl_->merge_input_positions.assign(vertices.begin(), vertices.end());
  impl_->merge_input_colors.assign(colors.begin(), colors.end());
  impl_->merge_input_triangles.assign(triangles.begin(), triangles.end());
  impl_->merge();
  return impl_->merge_stats;
}

const std::vector<glm::u8vec4>& TerrainTree::merged_colors() const { return impl_->merged_colors; }
std::uint32_t TerrainTree::merged_base() const { return impl_->merged_base(); }

}  // namespace terravol::mrbsp
