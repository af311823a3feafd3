// The RF volumes of a scene as drawn: each volume read once and placed in the scene frame, the
// geometry of its isosurfaces and slices (volume/geometry.h, volume/reduction.h), and their
// merge into the terrain's tree (Wiley et al. 1997, section 4.2), each isosurface and slice
// under its own id. Interactive changes re-extract the one surface that changed, and the
// next merge_into() re-merges that surface alone (TerrainTree::set_surfaces).
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "app/scene/scene_file.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "density/octree.h"
#include "io/mosaic.h"
#include "io/scene_frame.h"
#include "volume/geometry.h"

namespace terravol::app::scene {

// What merging the volumes cost: the geometry (extraction) and the tree's merge.
struct MergeFigures {
  std::size_t input_triangles = 0;  // the visible isosurfaces and slices as extracted
  std::size_t tree_triangles = 0;   // pieces stored in the tree, all LOD copies
  std::size_t merged_surfaces = 0;  // of the last merge_into(): surfaces (re-)merged
  double geometry_ms = 0;           // of the last extraction (all, or the one surface changed)
  double merge_ms = 0;              // of the last merge_into()
};

// One isosurface level in the legend: its label ("110 dB"), colour and value.
struct LegendLevel {
  std::string label;
  Rgb color;
  double value = 0.0;
};

// The colour legend of the volumes (the renderer draws it as a card, app/render/legend_image.h):
// the field of the first visible volume that draws anything, its first slice's colour map over
// [lo, hi] (named in the subtitle), and the isosurface levels of every visible volume of that
// field (each label preceded by the volume's file name when more than one volume has levels).
// Empty (no map, no levels): no legend.
struct Legend {
  std::string title;     // "path_loss_db (dB)"
  std::string subtitle;  // "slice 300 m above ground: viridis"; empty without a slice
  std::string colormap;  // volume::colormap_by_name; empty: no slice, no bar
  double lo = 0.0, hi = 1.0;
  std::vector<LegendLevel> levels;
  // A categorical slice's swatches (value: the category), headed by categories_title.
  std::vector<LegendLevel> categories;
  std::string categories_title;  // "transmitters", "categories"

  bool empty() const { return colormap.empty() && levels.empty() && categories.empty(); }
};

// The density drawn (VolumeLayer::density_boxes): its octree and what building it cost.
struct DensityFigures {
  bool drawn = false;      // a visible volume has a density style
  std::size_t volume = 0;  // which
  density::BoxGrid grid;   // its leaves (scene frame)
  int levels = 0;
  std::size_t bytes = 0;
  double resample_ms = 0;  // the columns, when read
  double build_ms = 0;     // the faces, after the last transfer function (set_density)
};

// A transmitter marker's label: the transmitter's name ("tx" for an unnamed one), anchored
// 20 m above the top of its marker (scene frame, metres).
struct MarkerLabel {
  glm::dvec3 at{0.0};
  std::string text;
};

struct PointValue {
  std::string volume;  // the file's name, and the field
  std::string units;
  double value = 0;    // NaN outside the volume
};

class VolumeLayer {
 public:
  VolumeLayer();
  // Reads every volume (volume::read_volume, with the spec's field and frame), reads the ground
  // under each from the mosaic (for heights above ground and terrain-following slices) and
  // extracts the geometry of its styles in `frame`. Throws io::FormatError for bad files and
  // std::invalid_argument("FILE: ...") for a volume without a frame or a slice outside it.
  // Each isosurface is reduced to at most `max_triangles` (volume::reduced_isosurface with the
  // default edge collapse; 0: never), so that an isovalue change fits an interaction. Slices
  // are kept at the volume's resolution (volume::slice), never decimated.
  // Each transmitter the volume records (its "transmitters" attribute, or
  // tx_lat/tx_lon/tx_height_agl_m of a single one) gets an opaque red mast from the ground to
  // the antenna with a diamond at its top, merged like the surfaces (hidden with its volume);
  // `markers` says whether they are shown at the start (set_markers).
  VolumeLayer(const std::vector<VolumeSpec>& specs, const io::Mosaic& mosaic, const io::SceneFrame& frame,
              std::size_t max_triangles = kDefaultSurfaceTriangles, bool markers = true);
  ~VolumeLayer();
  VolumeLayer(VolumeLayer&&) noexcept;
  VolumeLayer& operator=(VolumeLayer&&) noexcept;

  std::size_t size() const { return volumes_.size(); }
  const VolumeSpec& spec(std::size_t volume) const;  // throws std::invalid_argument when out of range

  // The geometry of every visible volume (isosurfaces, then slices, volume by volume), in the
  // scene frame with per-vertex RGBA: what merge_into() merges.
  volume::Mesh visible_mesh() const;
  // Brings the scene's tree up to the volumes: into a tree it has not merged into before,
  // every visible surface; else only the surfaces changed (set_*) since the last call (a
  // hidden volume's surfaces are removed). Ids: volume << 16 | kind << 14 | index, kind 0 for
  // isosurfaces, 1 for slices, 2 for the volume's transmitter markers.
  void merge_into(TerrainScene& scene);
  const MergeFigures& figures() const { return figures_; }

  // Interactive changes: re-extract the one surface (call merge_into() after).
  // Throw std::invalid_argument for indices out of range and slices outside the volume.
  void set_visible(std::size_t volume, bool visible);
  void set_slice(std::size_t volume, std::size_t slice, const volume::SliceSpec& spec);
  void set_isosurface(std::size_t volume, std::size_t iso, const volume::IsoSpec& spec);
  // Shows or hides every volume's transmitter markers: only the marker surfaces change (the
  // next merge_into() removes or merges them alone).
  void set_markers(bool shown);
  bool markers_shown() const { return markers_shown_; }
  // The labels of the markers shown now (visible volumes' transmitters, with markers on), in
  // volume order, for the renderer to draw over the scene.
  std::vector<MarkerLabel> marker_labels() const;

  // The legend of the first visible volume with a style: its first slice's colour map over the
  // slice's range, and every isosurface level with its colour; for a "categorical" slice no
  // bar but a swatch per category (`categories`), labelled with the names of the transmitters
  // the volume records (volume::recorded_transmitters: best_server), else with the whole
  // numbers in the volume's range. Empty when there is none. Throws std::invalid_argument for
  // a malformed "transmitters" attribute.
  Legend legend() const;

  // Densities (issue 15): each volume with a density style gets a colour-cube octree
  // (density::ColorCubeOctree, built when the volume is read, in the scene frame, over the
  // ground under it). One density is drawn: the first visible volume's that has one (two
  // densities would overlap, and their cells' orders could not be merged). Appends its cells
  // refined for `camera` to `out`, in back-to-front order; false (nothing appended) when no
  // visible volume has a density.
  bool density_boxes(const mrbsp::Camera& camera, const density::RefineOptions& options, std::vector<mrbsp::ColorBox>& out,
                     density::RefineStats& stats) const;
  // A new transfer function for a volume's density (every cell's faces built again; the next
  // frame draws them). Throws std::invalid_argument for an index out of range, a volume
  // without a density, or a colour map that does not exist.
  void set_density(std::size_t volume, const density::DensitySpec& spec);
  // The density density_boxes() draws now, and its cost.
  DensityFigures density_figures() const;

  // Each visible volume's value at (lat, lon) and height_agl metres above the ground there,
  // ground_m metres above the datum (volume::PointQuery: trilinear, NaN outside), in order.
  std::vector<PointValue> values_at(double lat, double lon, double height_agl, double ground_m) const;

 private:
  struct Loaded;
  std::vector<std::unique_ptr<Loaded>> volumes_;
  MergeFigures figures_;
  const void* merged_tree_ = nullptr;  // the tree merge_into() last brought up to date
  std::size_t max_triangles_ = kDefaultSurfaceTriangles;
  bool markers_shown_ = true;
};

}  // namespace terravol::app::scene
