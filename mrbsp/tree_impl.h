// Private to mrbsp/: the storage of TerrainTree, shared by terrain_tree.cpp (refresh,
// traversal) and merge.cpp (merging other polygons, section 4.2).
//
// The topology is implicit (nothing of it is stored): a square region is a *cell* (level,
// ci, cj) of side cell_size(level) samples. Levels 0 .. L-1 are the LOD levels (0 coarsest,
// L-1 the full resolution); levels -1 .. -m are coarser *top* levels above level 0 that only
// organise the window (level -m is one cell, the whole window) and carry no LOD choice. Every
// cell above the finest splits first at its middle x line into two halves, then each half at
// its middle y line, into its four children (level + 1, 2 ci + a, 2 cj + b): the split
// planes x = xs[i] and y = ys[j] lie on lattice lines of the coarser level, as section 4.1
// asks. At a cell of level >= 0 the LOD choice is between its low alternative (its two
// triangles) and its children (the high alternative).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/terrain_tree.h"

namespace terravol::mrbsp {

// Terrain figures of one cell: the range of its full-resolution samples (every alternative
// and every crack fill of the region lies within it) and the largest vertical error of its low
// alternative against them (0 at the finest level, unused at top levels).
struct CellZ {
  float zmin = 0.0f, zmax = 0.0f, error = 0.0f;
};

// A convex planar polygon of a small BSP: `count` vertex indices (into TerrainTree::
// positions()) from BspStore::refs[first], and the surface it comes from.
struct Polygon {
  std::uint32_t first = 0;
  std::uint16_t count = 0;
  std::int8_t level = kMergedLevel;  // the terrain level for a cell's own triangles
  std::uint32_t surface = 0;         // the surface id; kTerrainSurface for a terrain triangle
};
inline constexpr std::uint32_t kTerrainSurface = 0xFFFFFFFFu;
// While a store is being built, a reference with kTerrainRef set is a lattice vertex (the rest
// of the bits) and one without indexes the store's staged vertices.
inline constexpr std::uint32_t kTerrainRef = 0x80000000u;

// A node of a small BSP (section 4.2, "in a terrain leaf" and above the terrain): the plane
// n.p + d = 0, the polygons lying in it, and the two sides (-1 when empty; kDropSide for the
// space below a low alternative's terrain triangle, where pieces are dropped). The plane is
// kept in single precision (the pieces were split against it in double): it only tells the
// eye's side, wrong at most for an eye within millimetres of it, where either order draws the
// same. 32 bytes: what a traversal reads at every node it passes; the node's box is in
// BspStore::boxes.
struct BspNode {
  glm::vec3 n{0.0f};
  float d = 0.0f;
  std::int32_t back = -1, front = -1;
  std::uint32_t first = 0, count = 0;  // into the store's polys
};
static_assert(sizeof(BspNode) == 32);

// A box bounding every polygon of a node's subtree (its own and both sides', as drawn:
// positions() floats), so that a traversal leaves out subtrees outside the view frustum: in
// steps of BspStore::box_step from BspStore::box_base, rounded outward (lo down, hi up), so
// that it holds the subtree; empty (lo > hi) when the subtree holds nothing. 12 bytes.
struct NodeBox {
  std::uint16_t lo[3] = {1, 1, 1}, hi[3] = {0, 0, 0};
};
inline constexpr std::int32_t kDropSide = -2;

// A std::unique_ptr whose copy copies what it points to, so that the structures holding one
// copy deeply with their implicit copy (a store's staged vertices; the stores themselves are
// shared by copies of the tree, Slot::own_store).
template <class T>
struct DeepPtr : std::unique_ptr<T> {
  DeepPtr() = default;
  DeepPtr(std::unique_ptr<T>&& p) noexcept : std::unique_ptr<T>(std::move(p)) {}  // implicit: p = make_unique
  DeepPtr(const DeepPtr& o) : std::unique_ptr<T>(o ? std::make_unique<T>(*o) : nullptr) {}
  DeepPtr(DeepPtr&&) noexcept = default;
  DeepPtr& operator=(const DeepPtr& o) { return *this = DeepPtr(o); }
  DeepPtr& operator=(DeepPtr&&) noexcept = default;
  ~DeepPtr() = default;
};

// Vertices made while a small BSP is built, before Impl::flush() moves them into the tree's
// merged vertices.
struct StagedVertices {
  std::vector<glm::vec3> positions;
  std::vector<glm::u8vec4> colors;
  std::vector<glm::vec2> tcoords;
};

// The small BSP of one slot: nodes, polygons and references (indices into positions()). New
// vertices are staged (`staged`), with the references made since `staged_refs` pointing into
// them, until Impl::flush() moves them into the tree's merged vertices, makes those references
// global and lets `staged` go. Kept small: there is one per built slot (17,763 in the
// benchmark scene).
struct BspStore {
  std::vector<BspNode> nodes;
  std::vector<NodeBox> boxes;  // one per node (bound_nodes()), kept apart: read only near the frustum's sides
  glm::vec3 box_base{0.0f}, box_step{1.0f};  // the boxes' grid: the store's bounds in at most 65535 steps
  std::vector<Polygon> polys;
  std::vector<std::uint32_t> refs;
  DeepPtr<StagedVertices> staged;  // null when nothing is staged
  std::uint32_t staged_refs = 0;
  std::int32_t root = -1;
  std::uint32_t pieces = 0;   // merged polygons (terrain triangles not counted)
  std::uint32_t dropped = 0;  // pieces found below the low triangles and dropped
  float top = -1e30f;         // highest merged vertex ever put in (an upper bound after removals)
  // The pieces that arrived (before it cut them), now and when it was last built anew, and its
  // pieces then. Insertions cut more than a build, which chooses its planes for the pieces:
  // worn() when its pieces per arrived piece grew past `factor` times what the build made.
  std::uint32_t arrivals = 0, fresh_arrivals = 0, fresh_pieces = 0;
  bool worn(double factor) const {
    return static_cast<double>(pieces) * fresh_arrivals > factor * static_cast<double>(fresh_pieces) * arrivals;
  }
  std::size_t bytes() const;
  std::size_t staged_count() const { return staged ? staged->positions.size() : 0; }
  // Sets every node's subtree box (boxes, box_base, box_step) from its polygons' vertices: references
  // into `where` (the tree's positions()), and those made since staged_refs as staged (before
  // Impl::flush(); so boxes can be set while slots are built in parallel). Children follow
  // their parents in `nodes` (build and insertion append them), so one pass from the last node
  // up settles every box.
  void bound_nodes(const std::vector<glm::vec3>& positions);
};

// Where merged polygons are kept. Per cell of level >= 0: kAbove holds the pieces of the
// cell's region above its ceiling zmax (ordered against the whole terrain of the region by the
// plane z = zmax: the eye's side of it is near), kLow the cell's low alternative: its two
// terrain triangles and the pieces above them. Around the window, kOutside slots hold what
// lies beyond its four boundary planes (west, east, south, north, in this order: a piece
// beyond two belongs to the first), in bands one level-0 cell wide parallel to the plane: band
// b of the west side lies between the planes x = xs[0] - (b + 1) w and x = xs[0] - b w (w the
// level-0 cell's width), the last band (kBands - 1) everything beyond; each band is cut further
// into rows a quarter of a level-0 cell wide (Impl::place_step; west and east: its "columns"
// lie along y, the first and last reaching beyond the south and north planes) or such columns
// (south and north, which lie between the west and east planes). A slide by whole level-0
// cells keeps most of them (Impl::shift_merged), and they are built apart (in parallel, and
// none as large as a band: the band a slide fills with the column that left the window held
// 10,000 pieces of the benchmark's Utah volumes and took 25-34 ms to build alone; a level-0
// row of it still 4,679 pieces and 30-38 ms).
enum class SlotKind : std::uint8_t { kAbove = 0, kLow = 1, kOutside = 2 };
inline constexpr int kBands = 16;
inline constexpr int kMaxColumns = 32768;  // place columns of a window (at most its cells), at most

// A slot's key: the cell's global id (Impl::cell_id) times 2 plus the kind, or for kOutside
// outside_key(side, band, column) (side 0 west, 1 east, 2 south, 3 north; column 0 for west and
// east). Cells number at most 1.5e9 (a 32768-cell window), so keys fit 32 bits below
// kOutsideKey0.
using SlotKey = std::uint32_t;
inline constexpr SlotKey kOutsideKey0 = 0xFFFFFFFFu - 4u * kBands * kMaxColumns;
inline constexpr SlotKey outside_key(int side, int band, int column) {
  return kOutsideKey0 + static_cast<SlotKey>((side * kBands + band) * kMaxColumns + column);
}
struct OutsidePlace {
  int side, band, column;
};
inline constexpr OutsidePlace outside_place(SlotKey key) {
  const auto k = static_cast<int>(key - kOutsideKey0);
  return {k / kMaxColumns / kBands, k / kMaxColumns % kBands, k % kMaxColumns};
}

// Which cells hold merged content, and where its record is: a bit per cell and the count of
// set bits before each 64-bit word (rank), so a record is found in O(1) with 1.5 bits per cell.
struct ContentIndex {
  std::vector<std::uint64_t> bits;
  std::vector<std::uint32_t> rank;
  void build(std::size_t cells, const std::vector<std::uint32_t>& sorted_cells);
  bool empty() const { return bits.empty(); }
  std::int32_t find(std::uint32_t cell) const {
    const std::uint64_t word = bits[cell >> 6], bit = std::uint64_t{1} << (cell & 63u);
    if (!(word & bit)) return -1;
    return static_cast<std::int32_t>(rank[cell >> 6] + static_cast<std::uint32_t>(__builtin_popcountll(word & (bit - 1))));
  }
};

// What a cell's subtree holds of merged content, for cells that hold any (sparse).
struct CellContent {
  std::int32_t above = -1, low = -1;  // slot indices (into Impl::slots), -1 when none
  float top = 0.0f;                   // highest merged vertex in the subtree
};

// One surface's polygons after distribution through the tree's planes (merge.cpp): pieces
// arrived at slots, kept by slot and in the order they were made within a slot. Vertices are
// the input's followed by those made by splitting (double precision, for classification).
struct SurfacePieces {
  std::size_t input_triangles = 0;
  std::size_t input_vertices = 0;           // the first vertices are the input's
  std::vector<std::uint32_t> triangles;      // the input triangles (kept for slide())
  std::vector<glm::dvec3> vertices;
  std::vector<glm::u8vec4> colors;
  std::vector<glm::vec2> tcoords;  // empty, or one per vertex
  // A piece while pieces are gathered (Distributor): its `count` references from refs[first].
  struct Piece {
    SlotKey slot;
    std::uint32_t first;
    std::uint32_t count;
  };
  // The pieces kept, 2 bytes each rather than a Piece's 12 (most of them wait in low slots
  // never built): run k is the pieces [runs[k].piece0, runs[k + 1].piece0) of slot
  // runs[k].slot (runs sorted by slot), their references one after the other in `refs` from
  // runs[k].ref0, counts[p] of them for piece p.
  struct Run {
    SlotKey slot;
    std::uint32_t piece0, ref0;
  };
  std::vector<Run> runs;
  std::vector<std::uint16_t> counts;
  std::vector<std::uint32_t> refs;
  std::size_t dropped = 0;  // pieces found below the terrain and dropped
  std::size_t bytes() const;
  std::size_t piece_count() const { return counts.size(); }
  // Calls f(std::span<const std::uint32_t>) with the references of each piece of run k.
  template <class F>
  void for_each_in_run(std::size_t k, F&& f) const {
    const std::uint32_t end = k + 1 < runs.size() ? runs[k + 1].piece0 : static_cast<std::uint32_t>(counts.size());
    const std::uint32_t* r = refs.data() + runs[k].ref0;
    for (std::uint32_t p = runs[k].piece0; p < end; r += counts[p], ++p) f(std::span<const std::uint32_t>(r, counts[p]));
  }
  // The same for the pieces that arrived at slot `key` (none when none did).
  template <class F>
  void for_each_arrival(SlotKey key, F&& f) const {
    const auto at = std::lower_bound(runs.begin(), runs.end(), key, [](const Run& a, SlotKey b) { return a.slot < b; });
    if (at != runs.end() && at->slot == key) for_each_in_run(static_cast<std::size_t>(at - runs.begin()), f);
  }
  // Keeps `gathered` (pieces into refs, in any order): sorted by slot (stable), refs reordered
  // to match; references no piece of `gathered` points to are dropped. Throws std::length_error
  // for a piece of more than 65535 vertices.
  void keep(std::vector<Piece>& gathered);
};

// A slot and its small BSP. Above and outside slots are built when merged; low slots only
// when a traversal first draws their cell low (most low alternatives of the coarse levels are
// never drawn from inside the window), so until then `built` is false and `top` and `pending`
// come from the pieces that arrived there.
struct Slot {
  SlotKey key = 0;
  bool built = false;
  std::size_t pending = 0;  // pieces arrived, while not built
  float top = 0.0f;         // highest vertex of the pieces arrived; once built, the store's top
  // Held apart (about 200 bytes of empty containers): most slots are low alternatives that are
  // never built. Not null when built. A copy of the tree shares its slots' stores instead of
  // copying them (`terravol view` copies the scene to slide it on a worker thread while frames
  // wait for the copy); a store is changed only through own_store().
  std::shared_ptr<const BspStore> store;
  // The store's, or 0 when there is none.
  std::size_t refs() const { return store ? store->refs.size() : 0; }
  // The store to change, of a slot that has one: first copied when another tree shares it (copy
  // on write).
  // Two trees sharing a store may call it at once from their own threads: each then changes
  // only its own copy, and a store is changed in place only once no other tree holds it.
  BspStore& own_store() {
    if (store.use_count() > 1) store = std::make_shared<BspStore>(*store);
    // The other tree's last reads of the store happened before it let go of it.
    std::atomic_thread_fence(std::memory_order_acquire);
    return const_cast<BspStore&>(*store);  // made non-const (make_shared<BspStore>)
  }
};

struct TerrainTree::Impl {
  int n = 0;       // cells per side
  int levels = 0;  // L
  int top = 0;     // m: top levels -1 .. -m
  std::vector<double> xs, ys;
  // The lattice, the walls' vertices (wall_vertex()), then the merged vertices.
  std::vector<glm::vec3> positions;
  float wall_base = 0.0f;  // the walls' bottom: 100 m below the window's lowest sample
  // Per level index l + top (l = -m .. L-2): its cells' figures, row-major from the south-west.
  std::vector<CellZ> cellz;               // every level above the finest, coarsest first
  std::vector<std::size_t> cellz_offset;  // per level index l + top: where its cells start
  std::vector<std::uint32_t> level_offset;  // first global cell id of each LOD level (>= 0)
  std::uint32_t total_cells = 0;            // cells of all LOD levels

  // Merged content. Surfaces by id; slots sorted by key; cell content by global cell id (top
  // levels by level and index in top_content).
  std::vector<std::pair<std::uint32_t, SurfacePieces>> surfaces;  // sorted by id
  std::vector<Slot> slots;                                           // sorted by key
  ContentIndex content_index;        // cells with content -> their record in `content`
  std::vector<CellContent> content;  // in cell id order
  std::vector<std::vector<float>> top_content;  // per top level: highest content per cell (or -inf)
  // The kOutside slots (indices into slots) of each side.
  std::array<std::vector<std::int32_t>, 4> outside;
  std::vector<glm::u8vec4> merged_colors;
  std::vector<glm::vec2> merged_tcoords;  // one per merged vertex while has_tcoords, else empty
  bool has_tcoords = false;               // some surface has texture coordinates
  std::size_t dead_refs = 0;  // references removed since the merged vertices were last compacted
  std::uint64_t merged_version = 0;  // changes whenever merged vertices are renumbered
  MergeStats merge_stats;

  int cells_at(int level) const { return n >> (levels - 1 - level); }  // per side, any level >= -top
  int cell_size(int level) const { return 1 << (levels - 1 - level); }
  std::uint32_t cell_id(int level, int ci, int cj) const {
    return level_offset[static_cast<std::size_t>(level)] + static_cast<std::uint32_t>(cj * cells_at(level) + ci);
  }
  std::uint32_t vertex(int i, int j) const { return static_cast<std::uint32_t>(j * (n + 1) + i); }
  std::uint32_t lattice_count() const { return static_cast<std::uint32_t>((n + 1) * (n + 1)); }
  // Walls close the window's sides toward an eye beyond them (traverse()): in the boundary
  // plane of side s (0 west, 1 east, 2 south, 3 north), a copy of each boundary sample k
  // (k = j on the west and east sides, i on the south and north, 0 .. n), then the same
  // samples lowered to wall_base.
  std::uint32_t wall_vertex(int side, int k) const { return lattice_count() + static_cast<std::uint32_t>(2 * side * (n + 1) + k); }
  std::uint32_t wall_bottom(int side, int k) const { return wall_vertex(side, n + 1 + k); }
  std::uint32_t merged_base() const { return lattice_count() + static_cast<std::uint32_t>(8 * (n + 1)); }
  float z(int i, int j) const { return positions[vertex(i, j)].z; }
  // The figures of a cell at any level >= -top; the finest level's from its four samples.
  // Inline: the traversal's LOD choice asks it of every cell it visits.
  CellZ cell_z(int level, int ci, int cj) const {
    if (level == levels - 1) {
      const float a = z(ci, cj), b = z(ci + 1, cj), c = z(ci, cj + 1), d = z(ci + 1, cj + 1);
      return {std::min(std::min(a, b), std::min(c, d)), std::max(std::max(a, b), std::max(c, d)), 0.0f};
    }
    return cellz[cellz_offset[static_cast<std::size_t>(level + top)] + static_cast<std::size_t>(cj * cells_at(level) + ci)];
  }

  // A rectangle of the lattice, samples [i0, i1] x [j0, j1] (window indices).
  struct Region {
    int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
    // Whether it holds the square of side s samples from (i, j).
    bool holds(int i, int j, int s) const { return i >= i0 && j >= j0 && i + s <= i1 && j + s <= j1; }
  };

  // A new window (section 4.3). When it is this one moved by whole level-0 cells over the same
  // terrain (the same plane offsets and heights where the two overlap: shift_of), what lies in
  // both is kept: the overlap's cell figures, and its merged slots and pieces (shift_merged);
  // the rest is computed anew.
  void refresh(const TerrainWindow& window);
  // (di, dj) when `window` is this one moved by di columns and dj rows (multiples of the
  // level-0 cell size, less than the window) over the same terrain; nothing otherwise.
  std::optional<std::pair<int, int>> shift_of(const TerrainWindow& window) const;
  // The plane offset where outside band `band` of `side` ends toward the window (band 0: the
  // boundary plane itself) and its width (a level-0 cell's), along x for west and east, y for
  // south and north.
  double band_plane(int side, int band) const;
  // How the outside places of `side` are cut across its bands: along y into rows (west and
  // east) or along x into columns (south and north), each place_step() samples wide: a quarter
  // of a level-0 cell (at least one sample), place_columns() of them. The axis, and the plane
  // offset where column c begins (c = place_columns(): where the last ends).
  // A quarter rather than a whole level-0 cell (2026-12-07): the place a slide fills with the
  // column that left the window held 4,679 pieces of the benchmark's Utah volumes and took
  // 30-38 ms to build, alone on one core, of slot builds of 38-45 ms in all on two.
  static constexpr int kPlacesPerCell = 4;
  int column_axis(int side) const { return side < 2 ? 1 : 0; }
  int place_step() const { return std::max(1, cell_size(0) / kPlacesPerCell); }
  int place_columns() const { return n / place_step(); }
  double place_line(int side, int c) const {
    const auto at = static_cast<std::size_t>(c) * static_cast<std::size_t>(place_step());
    return (side < 2 ? ys : xs)[at];
  }
  // After refresh() moved the lattice by (di, dj): slots and pieces of cells in both windows
  // renamed (and the lattice vertices of their terrain triangles), the others dropped, and the
  // triangles reaching beyond the overlap merged into the rest of the window.
  void shift_merged(int di, int dj);
  // Merging (merge.cpp). distribute() sends one surface's triangles through the tree;
  // rebuild() makes the slots whose keys are in `dirty` again from every surface's pieces,
  // then the cell content and the merged vertices.
  void distribute(SurfacePieces& s) const;
  // distribute() of every surface listed, in parallel, large ones in chunks.
  void distribute_all(const std::vector<SurfacePieces*>& list) const;
  // After the surfaces with ids `changed` were replaced (their pieces distributed anew) and
  // `touched` holds every slot key their old or new pieces reach: removes their old polygons
  // from those slots and inserts the new ones (a slot left empty or worn out, far more planes
  // than polygons, is built anew from every surface's pieces), then flushes the vertices and
  // remakes the cell content.
  // With `rebuild`, `changed` is empty and every slot in `touched` is built anew (tidy()).
  void update(const std::vector<std::uint32_t>& changed, std::vector<SlotKey> touched, bool rebuild = false);
  void redistribute_all();  // after refresh(): every surface again, every slot anew
  // Builds slots[k] (a low slot first drawn) and flushes its vertices.
  void build_pending(std::size_t k);
  // Builds those slots (low slots first drawn, none built yet, no repeats) in parallel, then
  // flushes their vertices in the order given: the indices one by one in that order gives.
  void build_pending(std::span<const std::int32_t> ks);
  // Moves a store's staged vertices into positions and merged_colors.
  void flush(BspStore& store);
  void make_content();
  void compact();  // drops merged vertices no reference uses
};

}  // namespace terravol::mrbsp
