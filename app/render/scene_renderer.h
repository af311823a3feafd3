// A whole scene drawn frame after frame: the DEM mosaic's window and its MRBSP tree, the RF
// volumes' isosurfaces and slices merged into the tree (Wiley et al. 1997, section 4.2), and
// the VTK renderer. The window slides (section 4.3) whenever the camera nears its edge, in the
// same scene frame, so a long flight over a large mosaic holds one window in memory.
// Used by `terravol render` and `terravol fly`.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "app/render/terrain_renderer.h"
#include "app/scene/camera.h"
#include "app/scene/scene_file.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "app/scene/volume_layer.h"
#include "io/mosaic.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::app::render {

struct FrameStats {
  std::size_t triangles = 0;         // drawn, merged ones included
  std::size_t merged_triangles = 0;  // of those, pieces of isosurfaces and slices
  std::size_t nodes_visited = 0;
  double traversal_ms = 0, upload_ms = 0, draw_ms = 0;
  int slides = 0;        // window slides so far (this frame's included)
  double slide_ms = 0;   // this frame's slide and re-merge, 0 when none
  double eye_height = 0, ground_height = 0;  // metres, DEM datum
};

class SceneRenderer {
 public:
  // Opens the mosaic (scene.dems), chooses the first window around scene.camera (else the
  // mosaic's centre), builds the tree, reads every volume and merges the visible ones'
  // geometry. settings.gradient: the sky follows each frame's pitch. Throws io::FormatError
  // for bad DEM or volume files, std::invalid_argument for bad styles (a slice outside its
  // volume, ...) and std::runtime_error without an X display.
  SceneRenderer(const scene::SceneSpec& scene, const RenderSettings& settings, int max_window = 1024, int levels = 0,
                const scene::ShadingOptions& shading = {}, bool legend = true,
                std::size_t surface_triangles = scene::kDefaultSurfaceTriangles);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Renders the view of `pose` (alt above the ground when agl). Slides the window first when
  // the camera is within a quarter of its side of an edge. Throws std::runtime_error when the
  // camera is outside the mosaic or not above the ground.
  FrameStats render(const scene::CameraPose& pose, bool agl, double fov_y_deg, const mrbsp::TraversalOptions& traversal);

  std::vector<std::uint8_t> rgb() const;  // the last image: width * height * 3 bytes, top row first

  // Bilinear ground height (metres, DEM datum) anywhere in the mosaic, voids filled.
  double ground_height(double lat, double lon) const;
  const io::SceneFrame& frame() const { return scene_->frame(); }
  const scene::TerrainScene& terrain() const { return *scene_; }
  TerrainRenderer& renderer() { return *renderer_; }
  const mrbsp::Camera& camera() const { return camera_; }
  const mrbsp::Frame& last_frame() const { return frame_; }
  const scene::MergeFigures& merge_figures() const { return volumes_.figures(); }
  std::size_t volume_count() const { return volumes_.size(); }

  // Another renderer over the same tree, vertices, shading and texture, with other settings
  // (terravol bench draws one traversal in several orders). It is not told of later slides or
  // merges: make it again after render() reports a slide or after remerge().
  std::unique_ptr<TerrainRenderer> make_renderer(const RenderSettings& settings) const;
  // The lattice's shading (per sample, row 0 south): the colours the terrain is drawn in.
  const scene::TerrainShading& lattice_shading() const { return lattice_; }

  // Interactive changes to the volumes (VolumeLayer::set_slice, ...), then remerge(): merges
  // every visible volume into the tree again and uploads the vertices (what terravol view
  // does after a key). Returns what the merge cost.
  scene::VolumeLayer& volumes() { return volumes_; }
  const scene::MergeFigures& remerge();

 private:
  void upload_vertices();
  void check_inside(const scene::CameraPose& pose) const;

  io::Mosaic mosaic_;
  RenderSettings settings_;
  scene::ShadingOptions shading_;
  bool legend_ = true;
  int levels_ = 0;
  std::unique_ptr<scene::TerrainScene> scene_;
  scene::TerrainShading lattice_;
  scene::VolumeLayer volumes_;
  std::unique_ptr<TerrainRenderer> renderer_;
  mrbsp::Frame frame_;
  mrbsp::Camera camera_;
  int slides_ = 0;
};

}  // namespace terravol::app::render
