// Private to mrbsp/: per-frame colour boxes (mrbsp/color_boxes.h) sent through the decided
// tree of one traversal and kept, until the traversal emits them, in buckets at the places of
// the tree's order where they belong (mrbsp/color_boxes.cpp). terrain_tree.cpp asks for the
// buckets while it walks the decided tree and emits them there.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/color_boxes.h"
#include "mrbsp/tree_impl.h"

namespace terravol::mrbsp {

// What the traversal decided for this frame, as the distribution reads it (the same tests as
// its walk: terrain_tree.cpp builds this from its marks).
struct Decided {
  const std::vector<std::uint32_t>* marks = nullptr;  // Frame::stamp_
  std::uint32_t stamp = 0;                             // this traversal's, shifted left by 3
  const std::vector<std::uint32_t>* visibility = nullptr;  // Frame::visibility_, when occlusion ran
  std::uint32_t hidden = 0;                                // the value of a hidden cell there
  // Per top level index (0 for the window, ..., top - 1) and cell (row-major): whether the walk
  // enters the cell (its content box is in view).
  std::vector<std::vector<std::uint8_t>> top_in_view;
  // 0: not in the decided tree (out of view), 1: drawn, 2: refined.
  std::uint32_t state(std::uint32_t cell) const {
    const std::uint32_t v = (*marks)[cell];
    return (v & ~7u) == stamp ? v & 3u : 0u;
  }
  bool is_hidden(std::uint32_t cell) const { return visibility != nullptr && (*visibility)[cell] == hidden; }
};

// The plane z = c that separates what lies above a cell from its subtree: at an LOD cell its
// terrain's zmax (merged pieces reaching below it were cut there and went on down); at a top
// cell, which keeps no pieces of its own, the higher of its terrain and of its subtree's
// merged content.
float separation_height(const TerrainTree::Impl& m, int level, int ci, int cj);

// One traversal's boxes, distributed. Items of a bucket keep the order the boxes were given in.
struct BoxScratch {
  struct OutsideBoxes {  // a place beyond a window side without an outside slot, and its bucket
    int band, column;
    std::int32_t bucket;
  };
  struct Part {  // a box, or the piece of one inside a region of the tree
    glm::vec3 lo, hi;
    std::uint32_t box;    // index into the boxes given
    std::uint8_t faces;   // bit f: face f is the box's own (not a cut by a plane of the tree)
    std::int32_t next;    // in its bucket
  };
  struct Poly {  // a face, or the piece of one, cut by the planes of a small BSP or a cell's triangles
    std::uint32_t first, count;  // into verts
    glm::u8vec4 rgba;
    std::int32_t next;
  };
  struct Bucket {
    std::int32_t head = -1, tail = -1;
    bool polys = false;  // holds Polys, else Parts
  };
  struct Tri {  // an emitted triangle: indices into the tree's positions, then the frame's transient vertices
    std::uint32_t a, b, c;
    std::int8_t level;
  };

  std::span<const ColorBox> boxes;
  std::vector<Part> parts;
  std::vector<Poly> polys;
  std::vector<glm::dvec3> verts;
  std::vector<Bucket> buckets;
  std::unordered_map<std::uint64_t, std::int32_t> index;  // bucket key -> bucket
  std::vector<std::uint8_t> slot_boxed;                   // per slot: some bucket lies in its BSP
  std::vector<Tri> tris;                                  // what the last emit_* call emitted
  // Scratch of the distribution.
  std::vector<std::pair<Part, std::uint64_t>> work;
  std::vector<std::int32_t> order;
  struct Poly3 {  // a convex polygon being cut, in place
    static constexpr int kMax = 16;
    std::array<glm::dvec3, kMax> v;
    int n = 0;
  };
  struct Item {  // a box (poly -1) or one of its faces (a polygon of poly_pool_) on its way down a small BSP
    std::int32_t node, poly;
    int face;
  };
  std::vector<Item> bsp_stack_;
  std::vector<Poly3> poly_pool_;
  std::array<std::vector<OutsideBoxes>, 4> outside_places_;
  std::unordered_map<std::uint32_t, std::int32_t> outside_slot_;  // outside slot key -> slot
  glm::dvec3 eye_{0.0};
  BoxStats stats;
  bool active = false;

  // Sends every box through the decided tree (the window's boundary planes, the cells' split
  // planes, the separation heights, then the drawn cells' triangles or small BSPs), filling the
  // buckets. Builds the low alternatives of drawn cells that receive faces (as the walk would).
  void distribute(TerrainTree::Impl& m, const Camera& camera, const Decided& d, std::span<const ColorBox> given);

  // Buckets the walk asks for (-1: none). `level_index` is level + top, as the walk packs it.
  std::int32_t whole(int level_index, int ci, int cj) const;  // a cell not entered: all of its column
  std::int32_t above(int level_index, int ci, int cj) const;  // above its separation height (no slot there)
  // Beyond a window side, in the places (band, column: mrbsp/tree_impl.h, "kOutside") that have
  // no outside slot: one bucket each, for the walk to draw where such a slot would be. (Boxes
  // in a place with a slot go into its small BSP.)
  const std::vector<OutsideBoxes>& outside_places(int side) const { return outside_places_[static_cast<std::size_t>(side)]; }
  bool leaf(int level_index, int ci, int cj) const;           // in a drawn cell without a low slot
  bool in_slot(std::int32_t slot) const {
    return slot >= 0 && static_cast<std::size_t>(slot) < slot_boxed.size() && slot_boxed[static_cast<std::size_t>(slot)];
  }
  std::int32_t bsp(std::int32_t slot, std::int32_t node, int side) const;  // at an empty side of a BSP node
  static constexpr std::int32_t kRootless = 0x7FFFFFFF;  // bsp(slot, kRootless, 0): a store without nodes

  // Emission into `tris` (cleared first): a bucket's faces, facing the eye, as triangles of new
  // vertices appended to frame.transient_positions and transient_colors (indices from
  // frame.transient_base); in the bucket's order, or reversed for front to back.
  void emit_bucket(std::int32_t bucket, const glm::dvec3& eye, bool back_to_front, Frame& frame);
  // A drawn cell without a low slot: its two terrain triangles (sw, se, ne) and (sw, ne, nw),
  // the south-east one first when eye_south_east == back_to_front is false (as the walk orders
  // them), each with the faces above it in its half of the cell, on the side of its plane the
  // eye decides.
  void emit_leaf(const TerrainTree::Impl& m, int level_index, int ci, int cj, const glm::dvec3& eye, bool eye_south_east,
                 bool back_to_front, Frame& frame);

 private:
  std::int32_t bucket(std::uint64_t key, bool holds_polys);
  void add_part(std::uint64_t key, const Part& p);
  void add_poly(std::uint64_t key, const glm::dvec3* v, std::size_t n, glm::u8vec4 rgba);
  std::int32_t find(std::uint64_t key) const;
  // The part's faces (its own, cut to the part) as polygons into slot's small BSP.
  void insert_into_slot(const TerrainTree::Impl& m, std::int32_t slot, const Part& p, double tol);
  void emit_part(const Part& p, const glm::dvec3& eye, Frame& frame);
  void emit_poly(const Poly& p, Frame& frame);
  // A part beyond window side `side` cut into that side's bands and (south, north) level-0
  // columns as the merge cuts pieces (merge.cpp, to_bands): into the place's slot, else its bucket.
  void to_outside(const TerrainTree::Impl& m, int side, const Part& p, double tol);
};

}  // namespace terravol::mrbsp
