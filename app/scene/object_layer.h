// The models placed on the terrain as drawn (issue 16; Wiley et al. 1997, sections 6 and 7.2):
// each model read once (objects/model.h) with its levels of detail (objects/lod.h) shared by all
// of its instances, each instance placed in the scene frame (objects/placement.h) and merged
// into the terrain's tree (section 4.2) as its own surface, in the level its projected size
// asks for this frame, so that it is drawn in the tree's exact back-to-front order against the
// terrain, the volumes and the other instances, opaque or translucent.
//
// Where this departs from the paper (section 6): the paper builds one MRBSP per object whose
// nodes hold every LOD as stored alternatives, chosen during the traversal, and isolates the
// object from the rest of the scene by the planes of its bounding volume. Here the tree
// (mrbsp/) merges plain surfaces only and chooses alternatives for the terrain alone, so the
// level is chosen here, per instance and per frame, before the traversal (the same metric and
// threshold as the terrain's, mrbsp::TraversalOptions), and an instance whose level changed is
// merged again in its new level (TerrainTree::set_surfaces re-merges only the small BSPs its
// old and new pieces touch). The cost moves from storage (every level in the tree) to the
// frames where a level changes; the order stays exact, since whatever is merged is ordered by
// the tree's planes and its small BSPs' autopartitions. The bounding-box planes are not
// inserted: the tree's own splitters order an instance against everything else.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "app/scene/scene_file.h"
#include "app/scene/terrain_scene.h"
#include "io/scene_frame.h"
#include "mrbsp/terrain_tree.h"
#include "objects/lod.h"
#include "objects/shading.h"
#include "volume/geometry.h"

namespace terravol::app::scene {

// Surface ids of the tree: VolumeLayer's are volume << 16 | kind << 14 | index with kinds 0-2;
// objects take kind 3: instance i has (i >> 14) << 16 | 3 << 14 | (i & 0x3fff).
std::uint32_t object_surface_id(std::size_t instance);

// An instance whose box's projected diagonal is below this many pixels is drawn as its model's
// colour cube (objects::color_cube; Chamberlain et al. 1995).
inline constexpr double kColorCubePixels = 1.0;

// The largest instance placed: its box's diagonal times its scale, metres (a model in
// millimetres given scale 1000 by mistake would otherwise cover the window).
inline constexpr double kMaxObjectMetres = 50'000.0;

struct ObjectFigures {
  std::size_t models = 0, instances = 0;
  std::size_t full_triangles = 0;   // every instance at level 0
  std::size_t chosen_triangles = 0; // every instance in its level of the last update
  std::size_t lod_triangles = 0;    // the levels of every model (colour cubes included), stored once per model
  std::size_t remerged = 0;         // of the last update(): instances merged again
  std::size_t cubes = 0;            // of the last update(): instances drawn as colour cubes
  double read_ms = 0, lod_ms = 0;   // reading the models, making their levels
  double place_ms = 0, merge_ms = 0;  // of the last update(): placing new levels, merging
};

class ObjectLayer {
 public:
  static constexpr int kHidden = -2;
  using GroundFunction = std::function<double(double lat, double lon)>;  // metres above the datum

  ObjectLayer();
  // Reads every distinct model file once, makes its levels (`lod`) and its colour cube, and
  // works out where each instance stands (`ground` for heights above ground). Nothing is
  // merged until update(). Throws io::FormatError("FILE: ...") for a model that cannot be read
  // and std::invalid_argument("FILE: ...") for a pose out of range or an instance more than
  // kMaxObjectMetres across.
  // Every level of every instance is lit by `sun` (objects::sunlit) once placed; the colour
  // cube drawn below a pixel is not.
  ObjectLayer(const std::vector<ObjectSpec>& specs, const GroundFunction& ground, const io::SceneFrame& frame,
              const objects::LodOptions& lod = {}, const objects::Sunlight& sun = {});
  ~ObjectLayer();
  ObjectLayer(ObjectLayer&&) noexcept;
  ObjectLayer& operator=(ObjectLayer&&) noexcept;

  std::size_t size() const { return instances_.size(); }

  // Chooses each instance's level for `camera` and merges those whose choice changed (into a
  // tree it has not merged into before: every instance). The level: with options.full_res or
  // a fixed level, that one; else, with the kError metric, the coarsest level whose
  // screen-space error (objects::Lod::error, the largest Hausdorff distance of it and every finer level, times
  // the scale, over the distance from the eye to the instance's box, in pixels of the camera's
  // height) is at most options.threshold_px; with kArea, the coarsest whose projected box area
  // (square pixels) per two triangles is at most the threshold (the terrain's cells: two
  // triangles each). Below kColorCubePixels of projected diagonal, the colour cube (not with
  // full_res or a fixed level). Returns whether anything was merged.
  bool update(TerrainScene& scene, const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options);
  // Every instance at `level` (clamped to its model's last level) from now on; -1: chosen per
  // frame again.
  void set_fixed_level(int level) { fixed_level_ = level; }
  // Hidden objects are taken out of the tree at the next update() (each instance's surface
  // emptied) and merged in again, in the levels chosen then, once shown.
  void set_visible(bool visible) { visible_ = visible; }
  bool visible() const { return visible_; }

  // The level each instance is merged in (-1 before the first update, kHidden while hidden;
  // levels().size() for the colour cube).
  int level_of(std::size_t instance) const;
  std::size_t model_of(std::size_t instance) const;
  const std::vector<objects::Lod>& levels(std::size_t model) const;
  // The instance's vertices in the scene frame at `level` (cached once made).
  const volume::Mesh& placed(std::size_t instance, int level);
  // Every instance in its merged level, in the scene frame (pick, the plain-VTK baseline).
  volume::Mesh visible_mesh() const;
  const ObjectFigures& figures() const { return figures_; }

 private:
  struct Model;
  struct Instance;
  int choose(const Instance& in, const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options) const;
  std::vector<std::unique_ptr<Model>> models_;
  std::vector<std::unique_ptr<Instance>> instances_;
  std::unique_ptr<io::SceneFrame> frame_;
  ObjectFigures figures_;
  const void* merged_tree_ = nullptr;
  int fixed_level_ = -1;
  bool visible_ = true;
  objects::Sunlight sun_;
};

}  // namespace terravol::app::scene
