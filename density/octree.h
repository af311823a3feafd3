// The colour-cube octree of a volume density (issue 15): Chamberlain, DeRose, Lischinski,
// Salesin and Snyder, "Fast Rendering of Complex Environments Using a Spatial Hierarchy"
// (Graphics Interface 1996; and their 1995 technical report). Every cell of an octree over the
// volume holds six RGBA faces, its appearance through an orthographic projection along each
// face's normal; a frame draws, front to back of the view frustum, each cell whose projected
// size is below epsilon pixels as its faces that face the eye, and opens the others
// (1995 report, section 3.1: Render(cell)). mrbsp::TerrainTree::traverse() orders the drawn
// cells exactly with the terrain and the merged surfaces (mrbsp/color_boxes.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "density/transfer.h"
#include "io/scene_frame.h"
#include "mrbsp/color_boxes.h"
#include "mrbsp/terrain_tree.h"
#include "volume/volume.h"

namespace terravol::density {

// The leaves: axis-aligned boxes of the scene frame, `boxes` per axis from `origin`, each
// `size` metres. For a geographic volume the lines x = c and y = c of the boxes are exactly the
// lattice's meridians and parallels (the scene frame makes them planes), so a leaf's column is
// a lattice cell's column; heights z = c are planes of the scene frame one lattice spacing
// apart, from the lowest point of the volume's lowest layer to the highest of its highest.
struct BoxGrid {
  std::array<int, 3> boxes{0, 0, 0};  // x (east), y (north), z (up)
  glm::dvec3 origin{0.0};             // the corner of leaf (0, 0, 0)
  glm::dvec3 size{1.0};               // of one leaf, metres
  std::size_t leaves() const {
    return static_cast<std::size_t>(boxes[0]) * static_cast<std::size_t>(boxes[1]) * static_cast<std::size_t>(boxes[2]);
  }
};

// How a cell's faces come from its children's (the two variants of the papers).
enum class Compositing : std::uint8_t {
  kOver,      // 1996, section 4: each pair of children along the face's normal composited front
              // over back (Porter and Duff), the four pairs averaged (premultiplied). Exact for
              // an emission-absorption medium seen along the axis: what is built by default.
  kCoverage,  // 1995 report, section 4.1: coverages added as if the two did not overlap
              // (min(1, a_front + a_back)), then averaged with coverage weights. Meant for opaque
              // surfaces; over a medium it makes coarse cells too opaque (docs/architecture.md).
};

struct BuildOptions {
  Compositing compositing = Compositing::kOver;
};

// Per-frame refinement (1995 report, section 3.1).
struct RefineOptions {
  double threshold_px = 1.0;  // epsilon: a cell is drawn as its faces when its largest side,
                              // at its distance from the eye (nearest point of its box), spans
                              // fewer pixels; else its children are visited
  bool leaves_only = false;   // open every cell down to the leaves (drawing every voxel cell)
  bool cull = true;           // leave out cells outside the view frustum
  // With a tolerance above 0, a cell whose faces stand for its whole subtree within it (its
  // error, ColorCubeOctree::cell_error) is also drawn as its faces while it spans fewer than
  // max_size_px pixels: the error-bounded level of hierarchical splatting (Laur and Hanrahan
  // 1991), which Chamberlain et al. 1996 (section 2) cite as their volume counterpart. 0 (the
  // default): the projected size alone decides, as in the papers. 32 px rather than 8 (docs/
  // architecture.md, "Densities"): the bench's default view draws 588k cells instead of 1.26 M,
  // within the same error targets.
  double error_tolerance = 0.0;  // premultiplied RGBA, 0..1 per channel
  double max_size_px = 32.0;
};

struct RefineStats {
  std::size_t visited = 0;  // cells tested
  std::size_t boxes = 0;    // drawn
  std::size_t culled = 0;   // outside the frustum
  std::size_t empty = 0;    // clear (every face transparent), left out with their subtrees
  std::vector<std::size_t> per_level;  // boxes drawn per level, 0 the leaves
  double ms = 0.0;
};

class ColorCubeOctree {
 public:
  // The density of `volume` in the scene frame `frame`: the volume's frame must be geographic
  // (heights above the datum, or above the ground given by `ground`, metres above the datum at
  // latitude and longitude in degrees). Every leaf's value at a box corner is the lattice's at
  // that point, interpolated linearly along the lattice's column (the corners lie on its
  // meridians and parallels); a corner below the lowest or above the highest layer is clear.
  // Builds the faces of every cell above the leaves (TBB, in parallel over subtrees; the
  // leaves' are computed when drawn). Keeps a copy of the values. Throws std::invalid_argument
  // (one line) for a volume with another frame, fewer than two points on an axis, or a
  // missing ground function for heights above the ground.
  ColorCubeOctree(const volume::Volume& volume, const io::SceneFrame& frame, const volume::GroundFunction& ground,
                  const DensitySpec& spec, const BuildOptions& options = {});

  // A new transfer function: every cell's faces again (the lattice's resampling is kept).
  void set_transfer(const DensitySpec& spec);
  const DensitySpec& spec() const { return spec_; }
  const BoxGrid& grid() const { return grid_; }
  int levels() const { return static_cast<int>(dims_.size()); }  // leaves are level 0
  std::array<int, 3> cells_at(int level) const { return dims_[static_cast<std::size_t>(level)]; }
  double build_ms() const { return build_ms_; }        // of the last set of faces
  double resample_ms() const { return resample_ms_; }  // the columns (constructor only)
  std::size_t bytes() const;                           // what the octree holds

  // The boxes to draw from `camera` (scene frame), in a back-to-front order (each cell's
  // children far side first on every axis: an order in which no box comes before one it can
  // hide), appended to `out`; colours straight. Each face's opacity is its optical depth
  // scaled by A_a / P, the box's face area over its area projected along the direction from
  // the eye to its centre (so that its optical mass is kept off the axes; octree.cpp), then
  // rounded to 1/255 up or down at random (a hash of the cell and face, so frames repeat)
  // with the odds that keep its mean.
  void refine(const mrbsp::Camera& camera, const RefineOptions& options, std::vector<mrbsp::ColorBox>& out,
              RefineStats& stats) const;

  // For tests: the resampled value at box corner (i, j, k), 0 <= i <= boxes[0] etc. (NaN where
  // clear); a cell's box; and a cell's faces, premultiplied RGBA in [0, 1] (face f: axis f / 2,
  // seen from the low side for f even, the high side for f odd), computed now for leaves and
  // decoded from storage (8 bits) above them.
  float corner_value(int i, int j, int k) const;
  void cell_box(int level, int i, int j, int k, glm::dvec3& lo, glm::dvec3& hi) const;
  std::array<glm::vec4, 6> cell_faces(int level, int i, int j, int k) const;
  // A cell's error, premultiplied RGBA (0..1, to 1/255 above): how far its faces may be from
  // what its subtree shows there. Per face, the largest difference of a channel between the
  // face and one of the columns of children it averages, plus the largest error of its
  // children (0 for a leaf).
  double cell_error(int level, int i, int j, int k) const;

  using Faces = std::array<glm::vec4, 6>;  // premultiplied, float
  // What a cell above the leaves keeps per face: straight sRGB and sqrt(alpha), 8 bits each
  // (the square root keeps faint faces: alpha 0.001 is stored as 8/255).
  using Packed = std::array<glm::u8vec4, 6>;

 private:
  Faces leaf_faces(int i, int j, int k) const;
  Faces build_cell(int level, int i, int j, int k);
  float children_error(int level, int i, int j, int k) const;  // the largest of its children's
  // Stores a cell's faces (packed) and its error: `deviation` plus its children's.
  void keep(int level, int i, int j, int k, const Faces& f, float deviation);
  bool maybe_filled(int level, int i, int j, int k) const;
  // The coarsest level with at least 64 cells (at least 1): the build and the refinement
  // work on its subtrees in parallel.
  int parallel_level() const;
  std::size_t cell_index(int level, int i, int j, int k) const;
  void build_all();

  DensitySpec spec_;
  BuildOptions options_;
  BoxGrid grid_;
  std::vector<std::array<int, 3>> dims_;  // cells per axis at each level
  // The lattice's columns: dims0 x dims1 values per layer (x fastest), nz layers.
  std::array<int, 3> lattice_{0, 0, 0};
  std::vector<float> values_;
  // Per box corner column (i, j): the lattice layer under box height 0 (base) and the weight
  // of the one above it; and the corner heights k with data (k_lo..k_hi; k_lo > k_hi: none).
  std::vector<std::int32_t> base_;
  std::vector<float> weight_;
  // Per level, per column block: the box heights a cell there may hold data in.
  std::vector<std::vector<std::array<std::int32_t, 2>>> filled_;
  std::optional<TransferTable> table_;
  // Per box corner (x fastest, then y, then z): its transfer table entry, -1 clear; made with
  // each transfer function (each corner is shared by eight leaves).
  std::vector<std::int16_t> entries_;
  std::vector<std::vector<Packed>> packed_;  // per level >= 1
  // Per level >= 1, per cell: its error in 1/255 units, rounded up (255: 255 or more).
  std::vector<std::vector<std::uint8_t>> errors_;
  double build_ms_ = 0.0, resample_ms_ = 0.0;
};

}  // namespace terravol::density
