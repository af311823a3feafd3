// Private to mrbsp/: the flat storage of TerrainTree, shared by terrain_tree.cpp (build,
// refresh, traversal) and merge.cpp (merging other polygons, section 4.2).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/terrain_tree.h"

namespace terravol::mrbsp {

enum : std::uint8_t { kSplitX = 0, kSplitY = 1, kCell = 2 };

// One node of the flat tree (pre-order: children always follow their parent).
struct Node {
  glm::vec3 lo{0.0f}, hi{0.0f};      // bounding box of the region's samples (scene frame)
  float error = 0.0f;                // cell: largest |low-alternative height - full-res sample| (m)
  float plane = 0.0f;                // split: offset of the plane x = plane or y = plane
  std::int32_t child[2] = {-1, -1};  // split: [0] west/south side, [1] east/north side;
                                     // cell: child[0] = high alternative, or -1 at the finest level
  std::uint32_t cell = 0;            // cell: global cell id (Impl::cell_id)
  std::int32_t line = 0;             // split: lattice line index of the plane
  std::int32_t extra = -1;           // index into Impl::extras when merged polygons touch the node
  std::uint8_t kind = kSplitX;
  std::uint8_t level = 0;
};

// A convex planar polygon: `count` vertex indices (into positions()) from poly_vertices[first].
struct Polygon {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  std::int8_t level = kMergedLevel;  // the terrain level for a cell's own triangles
};

// A node of a leaf's small BSP (section 4.2, "in a terrain leaf"): the plane n.p + d = 0,
// the polygons lying in it, and the two sides. Children are -1 when empty.
struct LeafNode {
  glm::dvec3 n{0.0};
  double d = 0.0;
  std::int32_t back = -1, front = -1;
  std::uint32_t first = 0, count = 0;  // into Impl::leaf_polys
};

// Merged content of one tree node: coplanar polygons of a split node, or the leaf BSP of a
// cell's low alternative.
struct Extra {
  std::uint32_t first = 0, count = 0;  // split node: polygon ids in Impl::node_polys
  std::int32_t leaf_root = -1;         // cell node: root of its leaf BSP in Impl::leaf_nodes
};

struct TerrainTree::Impl {
  int n = 0;       // cells per side
  int levels = 0;  // L
  std::vector<Node> nodes;
  std::vector<double> xs, ys;
  std::vector<glm::vec3> positions;  // lattice, row bottoms, column bottoms, merged vertices
  std::vector<std::uint32_t> level_offset;  // first global cell id of each level
  std::vector<int> level_cells;             // cells per side at each level
  std::uint32_t total_cells = 0;
  std::vector<float> level0_error;  // per level-0 cell: the largest error of any cell inside it

  // Merged polygons (merge.cpp). The inputs are kept so that slide() can merge them again.
  // Every merge leaves each container at the size it needs (no growth slack), so memory
  // follows the current merge, not the largest so far.
  // The merged vertices are kept once, as floats in `positions`: their double copies, which
  // classification needs, live only while a merge runs.
  std::vector<glm::dvec3> merge_input_positions;
  std::vector<glm::u8vec4> merge_input_colors;
  std::vector<std::uint32_t> merge_input_triangles;
  std::vector<glm::u8vec4> merged_colors;
  std::vector<Polygon> polygons;
  std::vector<std::uint32_t> poly_vertices;
  std::vector<std::uint32_t> node_polys;
  std::vector<Extra> extras;
  std::vector<LeafNode> leaf_nodes;
  std::vector<std::uint32_t> leaf_polys;
  MergeStats merge_stats;

  int cell_size(int level) const { return 1 << (levels - 1 - level); }
  std::uint32_t cell_id(int level, int ci, int cj) const {
    return level_offset[level] + static_cast<std::uint32_t>(cj * level_cells[level] + ci);
  }
  std::uint32_t vertex(int i, int j) const { return static_cast<std::uint32_t>(j * (n + 1) + i); }
  std::uint32_t lattice_count() const { return static_cast<std::uint32_t>((n + 1) * (n + 1)); }
  std::uint32_t merged_base() const { return 3 * lattice_count(); }

  std::int32_t build_region(int rx, int ry, int w, int h, int level);
  void refresh(const TerrainWindow& window);
  void merge();  // (re)merges merge_input_* into the current tree
};

}  // namespace terravol::mrbsp
