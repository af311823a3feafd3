// The RF volumes of a scene as drawn: each volume read once and placed in the scene frame, the
// geometry of its isosurfaces and slices (volume/geometry.h), and the merge of all visible
// geometry into the terrain's tree (Wiley et al. 1997, section 4.2). Interactive changes
// re-extract only the geometry that changed; the merge itself is always of everything visible,
// since TerrainTree::merge replaces what was merged before.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "app/scene/scene_file.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "io/mosaic.h"
#include "io/scene_frame.h"
#include "volume/geometry.h"

namespace terravol::app::scene {

// What merging the volumes cost: the geometry (extraction) and the tree's merge.
struct MergeFigures {
  std::size_t input_triangles = 0;  // isosurfaces and slices as extracted
  std::size_t tree_triangles = 0;   // after splitting by the tree's planes, all LOD copies
  double geometry_ms = 0, merge_ms = 0;
};

// The colour legend of the volumes (the renderer draws it in the lower right): continuous,
// colours sampled evenly over [lo, hi]; or discrete (isosurfaces), one swatch per entry of
// `labels`, colors[k] for labels[k]. Empty colours: no legend.
struct Legend {
  std::string title;
  double lo = 0.0, hi = 1.0;
  std::vector<Rgb> colors;
  std::vector<std::string> labels;  // empty: continuous
};

class VolumeLayer {
 public:
  VolumeLayer();
  // Reads every volume (volume::read_volume, with the spec's field and frame), reads the ground
  // under each from the mosaic (for heights above ground and terrain-following slices) and
  // extracts the geometry of its styles in `frame`. Throws io::FormatError for bad files and
  // std::invalid_argument("FILE: ...") for a volume without a frame or a slice outside it.
  // Each isosurface and slice is decimated to at most `max_triangles` (volume::decimate; 0:
  // never), so that merging stays in seconds.
  VolumeLayer(const std::vector<VolumeSpec>& specs, const io::Mosaic& mosaic, const io::SceneFrame& frame,
              std::size_t max_triangles = kDefaultSurfaceTriangles);
  ~VolumeLayer();
  VolumeLayer(VolumeLayer&&) noexcept;
  VolumeLayer& operator=(VolumeLayer&&) noexcept;

  std::size_t size() const { return volumes_.size(); }
  const VolumeSpec& spec(std::size_t volume) const;  // throws std::invalid_argument when out of range

  // The geometry of every visible volume (isosurfaces, then slices, volume by volume), in the
  // scene frame with per-vertex RGBA: what merge_into() merges.
  volume::Mesh visible_mesh() const;
  // Merges the geometry of every visible volume into the scene's tree.
  void merge_into(TerrainScene& scene);
  const MergeFigures& figures() const { return figures_; }

  // Interactive changes: re-extract the one piece of geometry (call merge_into() after).
  // Throw std::invalid_argument for indices out of range and slices outside the volume.
  void set_visible(std::size_t volume, bool visible);
  void set_slice(std::size_t volume, std::size_t slice, const volume::SliceSpec& spec);
  void set_isosurface(std::size_t volume, std::size_t iso, const volume::IsoSpec& spec);

  // The legend of the first visible volume with a style: its first slice's colour map over the
  // slice's range, else a swatch per isosurface. Empty (no colours) when there is none.
  Legend legend() const;

 private:
  struct Loaded;
  std::vector<std::unique_ptr<Loaded>> volumes_;
  MergeFigures figures_;
  std::size_t max_triangles_ = kDefaultSurfaceTriangles;
};

}  // namespace terravol::app::scene
