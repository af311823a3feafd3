// The Multiresolution BSP terrain tree (Wiley et al. 1997, sections 4, 4.1, 4.3, 5, 5.1):
// nested LOD grids of a square terrain window, split planes on meridians and parallels (the
// scene frame's planes x = c and y = c), one LOD choice per alternative list per frame, and
// an exact back-to-front (or front-to-back) triangle order with no depth buffer.
// No VTK and no file I/O here: heights in, index lists out.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/color_boxes.h"

namespace terravol::coverage {
class Pyramid;
}

namespace terravol::mrbsp {

struct BoxScratch;  // mrbsp/box_order.h

// The terrain window, in the scene frame (metres). Samples form an (n+1) x (n+1) lattice,
// n = 2^k cells per side: column i lies on the plane x = xs[i], row j on y = ys[j] (row 0
// south, column 0 west), height z[j * (n + 1) + i]. xs and ys must increase strictly.
struct TerrainWindow {
  int cells = 0;                 // n, a power of two, >= 2
  std::span<const double> xs;    // n + 1 plane offsets, west to east
  std::span<const double> ys;    // n + 1 plane offsets, south to north
  std::span<const float> z;      // (n + 1)^2 heights, row-major from the south-west
};

enum class LodMetric : std::uint8_t {
  kArea,   // the paper's: projected screen area (pixels) of the region's bounding box
  kError,  // screen-space error (pixels): the low alternative's largest vertical error against
           // the full-resolution samples it replaces, projected at the box's nearest distance
};

// A pinhole camera in the scene frame.
struct Camera {
  glm::dvec3 eye{0.0};
  glm::dvec3 forward{0.0, 1.0, 0.0};  // unit view direction
  glm::dvec3 up{0.0, 0.0, 1.0};       // unit, orthogonal to forward
  double fov_y_deg = 45.0;            // vertical field of view, (0, 180)
  int width = 1280, height = 720;     // viewport, pixels
  double near_plane = 1.0;            // metres, > 0
};

// The default threshold of each metric: 2 px of screen-space error (Cesium's terrain default;
// over a 24-view flythrough of N44W072 it draws a median 25x fewer triangles than full
// resolution with PSNR >= 35 dB, tests/app/flythrough_quality_test.cpp), and 500 square
// pixels of projected box area (about as many triangles on the same views).
constexpr float default_threshold(LodMetric metric) { return metric == LodMetric::kError ? 2.0f : 500.0f; }

enum class Coherence : std::uint8_t { kOff, kUpdate, kConservative };

struct TraversalOptions {
  LodMetric metric = LodMetric::kError;
  float threshold_px = default_threshold(LodMetric::kError);  // refine while the metric exceeds this
  bool full_res = false;        // every region at the finest level (the quality reference)
  bool front_to_back = false;   // reverse order (nearest first)
  bool cull = true;             // view-frustum culling of regions
  // Coverage-mask occlusion culling (Greene 1996, sections 3-5): a front-to-back pass over the
  // LOD choice tiles the opaque terrain into a coverage pyramid and tests each region's box
  // against it; regions found hidden are left out. Conservative: the image is the one drawn
  // without it (a pixel is claimed only when its centre lies inside a tiled triangle by more
  // than the projection's float error).
  bool occlusion = false;
  // Coherence of the occlusion tests over frames drawn with the same Frame (Bittner and Havran
  // 2001): kUpdate tests only the last frame's termination nodes (hidden cells and visible
  // leaves; hierarchy updating with pull-up); kConservative also assumes a leaf visible last
  // frame visible again with probability p_skip. Never changes the LOD choice or the image.
  Coherence coherence = Coherence::kOff;
  double p_skip = 0.5;
  // With occlusion: when a pass culls fewer drawn cells than it keeps, leave it out of the next
  // 8 traversals with the same Frame, then try it again (the pass costs about as much per kept
  // triangle as drawing a hidden one saves, so below that it cannot pay). Never changes the
  // image. Off: the pass runs in every traversal.
  bool occlusion_adaptive = true;
  bool crack_fills = true;      // balance neighbours within one level and fill the cracks between
                                // them (off for wireframe views, where fills only clutter)
  // The last pass (the drawn cells and small BSPs written out as triangles) runs in parallel
  // chunks of the draw order, joined in that order, when the frame is estimated to draw at
  // least this many triangles and has no colour boxes; the triangles are the same either way.
  std::size_t parallel_min_triangles = 8192;
  // The LOD choice decides the subtrees below LOD level 1 in parallel when the previous
  // traversal into the same Frame visited at least this many cells (a Frame's first is
  // serial); the choice is the same either way.
  std::size_t parallel_min_nodes = 4096;
};

// Frame::level values other than terrain levels (0 coarsest, levels-1 finest).
inline constexpr std::int8_t kCrackLevel = -1;   // a crack fill
inline constexpr std::int8_t kMergedLevel = -2;  // a merged polygon (isosurface, slice, ...)
inline constexpr std::int8_t kWallLevel = -3;    // a wall closing a window side the eye is beyond

// What merging did (section 4.2), for the whole tree after the last change.
struct MergeStats {
  std::size_t surfaces = 0;
  std::size_t input_triangles = 0;
  std::size_t stored_polygons = 0;  // merged pieces kept in the tree, all LOD copies counted
  std::size_t dropped_pieces = 0;   // pieces found below the terrain (never visible) and dropped
  std::size_t slots = 0;            // small BSPs
  std::size_t pending_slots = 0;    // of those, low alternatives not built yet (built when first drawn)
  std::size_t pending_pieces = 0;   // pieces waiting in them (before their BSPs split them)
  std::size_t lazy_built_slots = 0; // low alternatives built by traversals since the last change
  double lazy_build_ms = 0.0;       // what building those cost
  std::size_t merged_vertices = 0;  // vertices of the stored pieces (positions() after merged_base())
  std::size_t rebuilt_slots = 0;    // of the last change: small BSPs made again
  std::size_t inserted_slots = 0;   // of those: new pieces inserted into the BSP kept, not built anew
  std::size_t worn_slots = 0;       // after it: small BSPs that insertions cut past 1.15x a build (tidy())
  double distribute_ms = 0.0;       // of the last change: sending its surfaces through the tree
  double build_ms = 0.0;            // of the last change: the small BSPs and the vertices
  double merge_ms = 0.0;            // of the last change: all of it
};

// A surface to merge: three indices per triangle into `vertices` (scene frame, metres), with
// per-vertex RGBA `colors` (translucent or opaque) and, optionally, per-vertex texture
// coordinates (empty, or one per vertex), interpolated like the colours where pieces are split.
struct SurfaceInput {
  std::span<const glm::dvec3> vertices;
  std::span<const glm::u8vec4> colors;
  std::span<const std::uint32_t> triangles;
  std::span<const glm::vec2> tcoords = {};
};

// Bytes a TerrainTree holds, by part: the capacities of its containers times their element
// sizes (what the allocator gave them, not what is in use), for benchmarks and memory checks.
// Allocator overhead and the Impl object itself are not counted.
struct MemoryStats {
  std::size_t nodes = 0;     // tree nodes and per-level tables (cell ids, errors), plane offsets
  std::size_t vertices = 0;  // positions of lattice samples (not merged ones)
  std::size_t merged = 0;    // everything merge() keeps: inputs, merged vertices and colours,
                             // polygons, coplanar lists, leaf BSPs
  std::size_t samples = 0;   // lattice samples, (n+1)^2: a count, not bytes
  std::size_t total() const { return nodes + vertices + merged; }
};

// What the occlusion pass did (TraversalOptions::occlusion).
struct OcclusionStats {
  std::size_t tested_nodes = 0;   // region boxes tested against the pyramid
  std::size_t skipped_tests = 0;  // tests coherence left out
  std::size_t culled_nodes = 0;   // of those, found hidden
  std::size_t sampled_visible = 0;  // boxes found visible before the test, by a vacant pixel
                                    // under their centre (not counted in tested_nodes)
  std::size_t culled_leaves = 0;  // drawn cells of the LOD choice left out with them
  bool ran = false;               // the pass ran in this traversal
  bool left_out = false;          // occlusion was asked for, and occlusion_adaptive left it out
  std::size_t tiled_triangles = 0;
  double pass_ms = 0.0;
};

// What one traversal produced. Triangles are index triples into TerrainTree::positions(),
// in draw order. level[t] is the LOD level of triangle t, kCrackLevel, kMergedLevel,
// kWallLevel or kBoxLevel. The faces of colour boxes (traverse() with boxes) use vertices of
// their own: index transient_base + k is transient_positions[k], coloured transient_colors[k]
// (transient_base is positions().size() when the traversal ended).
struct Frame {
  std::vector<std::uint32_t> indices;  // 3 per triangle
  std::vector<std::int8_t> level;      // 1 per triangle
  std::size_t nodes_visited = 0;
  std::size_t leaves = 0;
  std::size_t crack_triangles = 0;  // crack fills drawn
  std::size_t balanced_cells = 0;   // cells refined only to keep neighbours within one level
  std::vector<std::size_t> lod_histogram;  // leaves drawn per level
  OcclusionStats occlusion;
  std::vector<glm::vec3> transient_positions;
  std::vector<glm::u8vec4> transient_colors;
  std::uint32_t transient_base = 0;
  BoxStats boxes;

  Frame();
  ~Frame();
  Frame(Frame&&) noexcept;
  Frame& operator=(Frame&&) noexcept;

  // Scratch space of the traversal, kept so that a reused Frame does not allocate.
  std::vector<std::uint64_t> stack_;
  std::vector<std::uint64_t> leaves_;
  std::vector<std::uint64_t> outside_order_;  // the window and the outside bands, in draw order
  struct OutsideOrder {
    double band_distance, column_distance;
    std::uint64_t item;  // the walk's: an outside slot, or a bucket of colour boxes
  };
  std::vector<OutsideOrder> outside_places_;
  // The last pass's chunks of the draw order: each one's small-BSP stack and counts, and for
  // every chunk after the first (which writes into indices and level) its triangles.
  struct EmitChunk {
    std::vector<std::uint32_t> indices;
    std::vector<std::int8_t> level;
    std::vector<std::uint64_t> stack;
    std::size_t triangles = 0, crack_triangles = 0;
  };
  std::vector<EmitChunk> chunks_;
  std::vector<std::size_t> chunk_cuts_;  // chunk c: leaves_[chunk_cuts_[c], chunk_cuts_[c + 1])
  std::vector<std::vector<std::uint64_t>> by_level_;  // drawn cells per level (ci << 32 | cj)
  // The subtrees the LOD choice decides, and the walk of the draw order walks, in parallel:
  // their roots, and each one's stack, drawn cells per level and cells visited (the walk's:
  // cells drawn), and the walk's part of the order, drawn cells counted per level and low
  // slots to build.
  std::vector<std::uint64_t> subtree_roots_;
  struct Subtree {
    std::vector<std::uint64_t> stack;
    std::vector<std::vector<std::uint64_t>> by_level;
    std::size_t nodes = 0;
    std::vector<std::uint64_t> leaves;
    std::vector<std::size_t> histogram;
    std::vector<std::int32_t> unbuilt;
  };
  std::vector<Subtree> subtrees_;
  std::vector<std::int32_t> unbuilt_;        // the walk's low slots to build (-1 - k: subtree k's)
  std::vector<std::uint64_t> joined_leaves_;  // the walk's order with the subtrees' parts in place
  std::unique_ptr<coverage::Pyramid> pyramid_;        // the occlusion pass's
  std::vector<std::uint32_t> visibility_;  // per cell: stamp << 2 | what occlusion found
  std::vector<std::uint32_t> stamp_;  // per cell: the traversal that last drew it
  std::uint32_t current_stamp_ = 0;
  int occlusion_backoff_ = 0;  // traversals still to leave the occlusion pass out of
  std::unique_ptr<BoxScratch> box_scratch_;  // the colour boxes' buckets (mrbsp/color_boxes.cpp)
};

class TerrainTree {
 public:
  // Builds the tree of a window with `levels` LOD levels (1 <= levels <= k + 1 for
  // n = 2^k; level levels-1 is the full-resolution grid, each coarser level halves the
  // samples per side). Throws std::invalid_argument for a bad window or level count.
  TerrainTree(const TerrainWindow& window, int levels);
  // An independent copy: what the copy does afterwards (slide, merge, traverse) leaves `other`
  // as it is, and each may then be used on its own thread (terravol view slides a copy on a
  // worker thread while frames go on). The small BSPs of merged surfaces are shared until one
  // of the two changes them (copy on write), so the copy is cheap. It must not run while
  // another thread changes `other`.
  TerrainTree(const TerrainTree& other);
  ~TerrainTree();
  TerrainTree(TerrainTree&&) noexcept;
  TerrainTree& operator=(TerrainTree&&) noexcept;

  int cells() const;
  int levels() const;

  // Vertex positions: the lattice samples (index v = j * (n + 1) + i), then from merged_base()
  // the merged vertices. The lattice changes only in slide(); merges, traversals (which build
  // low alternatives' pieces when first drawn) and slide() change the merged vertices.
  const std::vector<glm::vec3>& positions() const;

  // Emits the triangles of the view into `frame` (cleared first; its capacity is reused, so
  // a frame reused across calls does not allocate once warm). Order: for back-to-front,
  // every triangle is drawn after every triangle it can be hidden by (BSP order: the far
  // side of each split plane first; inside a cell, the triangle beyond the cell's diagonal
  // plane first; crack fills on boundary planes facing away from the eye before the cell,
  // facing it after). The LOD choice (options.metric and threshold) is then balanced so that
  // drawn neighbours differ by at most one level, and each crack between a cell and its
  // finer neighbour is filled exactly by the vertical triangle (corner, the edge's middle
  // sample, corner) in their shared boundary plane: lattice samples only, within both cells'
  // z ranges.
  // Culling (options.cull) tests each region's box holding everything drawn in it: its
  // terrain and the merged pieces kept in its subtree. The LOD choice uses the terrain's own
  // box and error, so merging never changes which terrain is drawn. A cell drawn low for the
  // first time since the last merge gets its merged pieces built then (positions() and
  // merged_colors() grow by its vertices; merge_stats() counts it): traverse() changes the
  // tree's merged storage, so it must not run on two threads at once.
  // Colour boxes (mrbsp/color_boxes.h), given in an order in which no box comes before a box
  // it can hide (an octree's back-to-front order for this eye; front_to_back reverses it as
  // it reverses everything), are drawn as their faces that face the eye, in the same exact
  // order: each piece of a box is ordered against the terrain and the merged pieces by the
  // tree's planes (the window's sides, the cells' split planes, the plane z = zmax of each
  // cell entered, its triangles or the small BSP of a drawn cell), and faces below the terrain
  // are dropped (mrbsp/color_boxes.cpp gives the argument). The tree is not changed (but for
  // the low alternatives' pieces built on first use, as above). Frame::boxes says what it cost.
  void traverse(const Camera& camera, const TraversalOptions& options, Frame& frame,
                std::span<const ColorBox> boxes = {}) const;

  // Sliding (section 4.3): replace the heights and plane offsets for a window moved over the
  // terrain by whole coarse cells. When the plane offsets and heights of the samples the two
  // windows share are the same (to the bit), what lies on them is kept: their cells' figures
  // and merged pieces (renamed to their new cells); only what enters is computed and merged.
  // Any other window is computed and merged anew. Same preconditions as the constructor, and
  // window.cells must equal cells().
  void slide(const TerrainWindow& window);

  // Merging other polygons (section 4.2). Each surface (an isosurface, a slice, ...) is kept
  // under its id; set_surface() replaces what that id held (an empty surface removes it) and
  // re-merges only the small BSPs its old and new pieces touch, so an edit costs about what
  // that surface costs. Each triangle is sent from the root through the window's boundary
  // planes (what lies outside the window is kept in small BSPs beyond them, in bands one
  // level-0 cell wide) and the cells' split planes, classified in double precision with a tolerance of 1e-9 times the window
  // size; at a cell of an LOD level, a piece entirely above the cell's terrain (above zmax)
  // stays there whole, in a small BSP ordered against all of the cell's terrain by the plane
  // z = zmax; a piece entirely below the cell's terrain (below zmin) is dropped, since no eye
  // above the ground can see it; what lies between is copied into the cell's low alternative
  // (ordered against its two triangles by the cell's diagonal plane and their planes, parts
  // below the triangles dropped) and sent on into its children. Pieces that straddle zmax are
  // cut there. Small BSPs are autopartitions whose splitters are chosen among sampled
  // candidates by fewest spans. A split makes one vertex per edge and plane. Merged vertices
  // follow the terrain's in positions(); their colours are merged_colors(). slide() merges
  // every surface again into the moved window. Throws std::invalid_argument for an index out
  // of range or sizes that disagree (and then changes nothing).
  MergeStats set_surface(std::uint32_t id, const SurfaceInput& surface);
  // Several at once (one re-merge): surfaces[k] replaces id ids[k].
  MergeStats set_surfaces(std::span<const std::uint32_t> ids, std::span<const SurfaceInput> surfaces);
  // Insertion is fast, but the planes it sends new pieces down were chosen for other polygons,
  // and what it cuts stays cut: after a slice move the benchmark's view drew 227k triangles
  // where small BSPs built for what they then held draw 202k. tidy() builds anew every small
  // BSP whose pieces per arrived piece grew past 1.15 times what its last build made
  // (MergeStats::worn_slots), for a caller with time to spare (the viewer when idle). Returns
  // what it cost; the image does not change.
  MergeStats tidy();
  // Replaces every surface by one (id 0).
  MergeStats merge(std::span<const glm::dvec3> vertices, std::span<const glm::u8vec4> colors,
                   std::span<const std::uint32_t> triangles);
  const MergeStats& merge_stats() const;
  // RGBA of merged vertex k, which is positions()[merged_base() + k].
  const std::vector<glm::u8vec4>& merged_colors() const;
  // Texture coordinates of merged vertex k when some surface has them (then one per merged
  // vertex, (-1, -1) for vertices of surfaces without), else empty.
  const std::vector<glm::vec2>& merged_tcoords() const;
  std::uint32_t merged_base() const;
  // Changes whenever merged vertices already in positions() are renumbered or replaced (a
  // merge of everything, a slide, a compaction after edits). While it stays the same, merges
  // and traversals only append vertices, so a renderer holding positions() need only take the
  // new tail.
  std::uint64_t merged_version() const;

  // The bytes held now, by part (MemoryStats). nodes and vertices depend only on cells() and
  // levels(): about 170 bytes per lattice sample for 3 or more levels (2.3 nodes of 56 bytes
  // and three 12-byte positions per sample), so about 4x when the window's side doubles, and
  // unchanged by slide(). merged is 0 before any merge() and after merging nothing; merge()
  // and slide() leave its containers at the size the current merge needs (the merged vertices'
  // within a sixteenth more), so it follows the current merge, not the largest one so far.
  MemoryStats memory() const;

  struct Impl;  // defined in mrbsp/tree_impl.h, private to mrbsp/

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace terravol::mrbsp
