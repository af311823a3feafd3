// The scene pipeline: a whole scene drawn frame after frame, the one that `terravol render`,
// `view`, `fly` and `bench` share. It owns the DEM mosaic, the window of it and the window's
// MRBSP tree, the RF volumes' isosurfaces and slices merged into the tree (Wiley et al. 1997,
// section 4.2), the slides and the VTK renderer. The window slides (section 4.3) whenever the
// camera nears its edge, in the same scene frame, so a long flight over a large mosaic holds
// one window in memory: synchronously, within the frame (render, fly, bench), or read ahead and
// shaded on a worker thread and finished at the first frame after that (view), through the
// same code.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/render/terrain_renderer.h"
#include "app/render/tiled_renderer.h"
#include "app/scene/camera.h"
#include "app/scene/object_layer.h"
#include "app/scene/pick.h"
#include "app/scene/scene_file.h"
#include "app/scene/style.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "app/scene/volume_layer.h"
#include "io/mosaic.h"
#include "mrbsp/terrain_tree.h"
#include "volume/profile.h"

namespace terravol::app::render {

struct FrameStats {
  std::size_t triangles = 0;         // drawn, merged ones included
  std::size_t merged_triangles = 0;  // of those, pieces of isosurfaces and slices
  std::size_t nodes_visited = 0;
  double traversal_ms = 0, upload_ms = 0, draw_ms = 0;
  int slides = 0;        // window slides so far (this frame's included)
  double slide_ms = 0;   // this frame's slide on the calling thread (re-merge included), 0 when none
  double eye_height = 0, ground_height = 0;  // metres, DEM datum
  double objects_ms = 0;          // choosing the objects' levels and merging those that changed
  std::size_t objects_merged = 0; // instances merged again this frame
  // The density (colour cubes; VolumeLayer::density_boxes): refining the octree, the cells
  // drawn, and what ordering them in the tree cost (mrbsp::BoxStats).
  double density_ms = 0;
  density::RefineStats density;
  mrbsp::BoxStats boxes;
  std::size_t box_triangles = 0;  // of triangles: the boxes' faces
};

// When the window slides, once the camera is within a quarter of its side of an edge.
enum class Sliding : std::uint8_t {
  kSynchronous,   // within the frame: read the moved window, shade it, slide the tree
  kAsynchronous,  // read and shade on a worker thread; the first frame after that slides the tree
};

// The density refinement of a style left at its defaults (scene::kDefaultDensityThreshold and
// scene::kDefaultDensityError).
inline density::RefineOptions default_density_refinement() {
  density::RefineOptions o;
  o.threshold_px = scene::kDefaultDensityThreshold;
  o.error_tolerance = scene::kDefaultDensityError / 255.0;
  return o;
}

struct SceneOptions {
  int max_window = 1024;  // cells, a power of two >= 2
  int levels = 0;         // 0: scene::default_levels(window)
  scene::ShadingOptions shading;
  bool legend = true;     // a colour legend for the volumes
  bool markers = true;    // a marker at each transmitter the volumes record (VolumeLayer)
  std::size_t surface_triangles = scene::kDefaultSurfaceTriangles;  // per isosurface or slice; 0: all
  objects::LodOptions lod;  // the objects' levels of detail (scene::ObjectLayer)
  Sliding sliding = Sliding::kSynchronous;
  // What draws the frames: VTK (TerrainRenderer), or the coverage-mask tiler (TiledRenderer:
  // no VTK window, no X display; the traversal runs front to back, tiled_traversal). The
  // tiler draws filled triangles in the tree's order only: RenderSettings' order must be kBsp,
  // without wireframe or LOD colours.
  scene::Engine engine = scene::Engine::kVtk;
  tiler::Settings tiler;  // kTiler: aa, texel rate, bands, threads (the size is the RenderSettings')
  // How the density is refined (threshold: epsilon, pixels; the error tolerance Style's default).
  density::RefineOptions density = default_density_refinement();
  // The camera's near plane, metres; 0: scene::near_plane_for(the eye's clearance). The tree's
  // order draws without a depth buffer, so only clipping depends on it; the depth-tested
  // orders' precision does (24 bits over [near, far]).
  double near_plane = 0;
};

// The pipeline's options and the renderer's settings as a resolved style gives them (window,
// shading, legend, surface triangles; size, order, the sky gradient and its haze), for the
// commands to adjust.
SceneOptions scene_options(const scene::Style& style, int levels = 0, Sliding sliding = Sliding::kSynchronous);
RenderSettings render_settings(const scene::Style& style);

// The last slide's parts, milliseconds.
struct SlideFigures {
  double read_ms = 0;   // reading the moved window (kAsynchronous: on the worker thread)
  double shade_ms = 0;  // shading it (kAsynchronous: on the worker; kSynchronous: after the tree)
  double tree_ms = 0, vertices_ms = 0;  // sliding the tree (merging again), replacing the renderer's vertices
  // kAsynchronous: copying the scene and sliding the copy, on the worker (both 0 when the tree
  // slid on the calling thread: kSynchronous, or the scene was edited during the read ahead).
  // tree_ms is then what swapping the slid copy in cost the calling thread.
  double copy_ms = 0, worker_tree_ms = 0;
};

// What is under a pixel (SceneRenderer::pick).
struct Pick {
  scene::PickPoint point;                 // where, and whether on a surface or the terrain
  double ground = 0;                      // the DEM's ground under it, metres above the datum
  std::vector<scene::PointValue> values;  // each visible volume's value there
  double ms = 0;                          // what the pick took, wall clock
};

class SceneRenderer {
 public:
  // Chooses the first window around scene.camera (else scene::default_pose(mosaic), above the
  // mosaic's centre), builds the tree, reads every volume and merges the visible ones'
  // geometry, reads every object's model and makes its levels (merged at the first frame, in
  // the levels its camera asks for; scene::ObjectLayer) (scene.dems is not read: the mosaic is
  // given). settings.gradient: the sky follows
  // each frame's pitch. Throws std::runtime_error when the camera is outside the mosaic or
  // without an X display, io::FormatError for bad DEM, volume or model files and
  // std::invalid_argument for bad styles (a slice outside its volume, a bad level count, ...)
  // and objects placed outside the mosaic or too large (scene::ObjectLayer).
  SceneRenderer(io::Mosaic mosaic, const scene::SceneSpec& scene, const RenderSettings& settings,
                const SceneOptions& options = {});
  // The same, opening the mosaic of scene.dems.
  SceneRenderer(const scene::SceneSpec& scene, const RenderSettings& settings, const SceneOptions& options = {});
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Renders the view of `pose` (alt above the ground when agl): prepare(), then draw().
  FrameStats render(const scene::CameraPose& pose, bool agl, double fov_y_deg,
                    const mrbsp::TraversalOptions& traversal);
  // Everything of a frame but the draw: slides the window first (see Sliding) when auto-slide is
  // on and the camera is within a quarter of the window's side of an edge, sets the camera (the
  // window's current size in pixels) and the sky, traverses the tree and replaces the triangle
  // list. Before the traversal the objects' levels are chosen for the camera and the instances
  // whose level changed merged again (scene::ObjectLayer::update, with `traversal`'s metric and
  // threshold). A camera beyond the mosaic is allowed (up to scene::kMaxKmBeyond): the window is
  // then the part of the mosaic nearest it, with walls closing the sides it sees
  // (mrbsp::TerrainTree::traverse()). Throws std::runtime_error when the camera is farther, or
  // not above the ground, and, with kSynchronous, io::FormatError when the moved window cannot
  // be read.
  FrameStats prepare(const scene::CameraPose& pose, bool agl, double fov_y_deg,
                     const mrbsp::TraversalOptions& traversal);
  // Draws the prepared frame (and waits for it); returns wall milliseconds.
  double draw();
  // The slide prepare() would make for a camera at `pose`, without a frame (terravol fly
  // --resume makes the slides of the frames it skips). Returns whether the window moved.
  bool slide_for(const scene::CameraPose& pose);

  // How densities are refined (density::RefineOptions: epsilon, or every leaf); from the next
  // prepare().
  void set_density_options(const density::RefineOptions& options) { density_options_ = options; }
  const density::RefineOptions& density_options() const { return density_options_; }

  // The eye's height in the DEM's datum for `pose` (pose.alt plus the ground under it when agl).
  // Throws std::runtime_error("camera at H m is not above the ground (G m there)...") when it is
  // not above the ground.
  double eye_height(const scene::CameraPose& pose, bool agl) const;

  // Automatic sliding (on at the start). Off, the window stays where it is; a slide already
  // read ahead still finishes.
  void set_auto_slide(bool on) { auto_slide_ = on; }
  bool auto_slide() const { return auto_slide_; }
  // kAsynchronous: a moved window is being read (or waits to be slid to); it is ready when
  // the next prepare() would slide to it.
  bool slide_pending() const { return pending_.valid(); }
  bool slide_ready() const;
  // kAsynchronous: the error of a read ahead that failed (its one line), once; sliding is then
  // off (set_auto_slide(true) tries again).
  std::optional<std::string> take_slide_error();
  int slides() const { return slides_; }
  const SlideFigures& last_slide() const { return last_slide_; }

  std::vector<std::uint8_t> rgb() const;  // the last image: width * height * 3 bytes, top row first
  scene::Engine engine() const { return options_.engine; }
  // With scene::Engine::kTiler: the tiler and its last frame's figures (else std::logic_error).
  const TiledRenderer& tiled() const;

  // The point under pixel (x, y) of the last frame (x from the left, y from the bottom: VTK's
  // event positions), on the window's terrain or on the nearest isosurface, slice or object in
  // front of it (scene::pick over the volumes' and objects' visible_mesh()), with the ground under it and the visible volumes'
  // values there. Nothing when the pixel shows sky or lies beyond the window.
  std::optional<Pick> pick(int x, int y) const;

  // Bilinear ground height (metres, DEM datum) anywhere in the mosaic, voids filled; beyond
  // the mosaic, the height at its nearest point (the ground a camera out there is above).
  double ground_height(double lat, double lon) const;
  const io::Mosaic& mosaic() const { return mosaic_; }
  const io::SceneFrame& frame() const { return scene_->frame(); }
  const scene::TerrainScene& terrain() const { return *scene_; }
  // The VTK renderer (std::logic_error with scene::Engine::kTiler, which has none).
  TerrainRenderer& renderer();
  const mrbsp::Camera& camera() const { return camera_; }
  const mrbsp::Frame& last_frame() const { return frame_; }
  const scene::MergeFigures& merge_figures() const { return volumes_.figures(); }
  std::size_t volume_count() const { return volumes_.size(); }

  // Another renderer over the same tree, vertices, shading and texture, with other settings
  // (terravol bench draws one traversal in several orders). It is not told of later slides or
  // merges: make it again after render() reports a slide or after remerge().
  std::unique_ptr<TerrainRenderer> make_renderer(const RenderSettings& settings) const;
  // Brings a renderer's vertices up to the tree's: all of them again when the tree renumbered
  // its merged vertices (TerrainTree::merged_version()), else only the tail it appended (edits,
  // low alternatives built by the last traversal). prepare() does this for its own renderer;
  // call it for make_renderer()'s before drawing them a frame of frame().
  void sync_vertices(TerrainRenderer& renderer) const;
  // The lattice's shading (per sample, row 0 south): the colours the terrain is drawn in.
  const scene::TerrainShading& lattice_shading() const { return lattice_; }

  // Interactive changes to the volumes (VolumeLayer::set_slice, ...), then remerge(): merges
  // every visible volume into the tree again, uploads the vertices and updates the legend
  // (what terravol view does after a key). Returns what the merge cost.
  scene::VolumeLayer& volumes() { return volumes_; }
  const scene::MergeFigures& remerge();
  // When edits wore small BSPs (the tree's MergeStats::worn_slots), builds them anew and brings
  // the renderer's vertices up to date; the image does not change, later frames draw fewer
  // pieces. For idle moments (terravol view between keys). Returns the tree's figures.
  mrbsp::MergeStats tidy();
  // Whether slides (kAsynchronous) have freed memory that return_memory() would give back to
  // the system: true after a slide lands, until return_memory(); false while a slide is under
  // way (its worker gives back at its start what the landing before freed). return_memory()
  // runs malloc_trim (glibc; elsewhere nothing), 2-24 ms on this thread: for a viewer at rest
  // (a trim beside the landing frame slows it; see finish_slide).
  bool memory_to_return() const;
  void return_memory();
  // The objects on the terrain (set_fixed_level for benchmarks and tests; takes effect at the
  // next prepare()).
  scene::ObjectLayer& objects() { return objects_; }
  const scene::ObjectLayer& objects() const { return objects_; }

  // A link profile (volume::link_profile) from tx to a receiver rx_height_agl metres above the
  // ground at (rx_lat, rx_lon), over the mosaic's samples around the path
  // (volume::read_rf_window, under the mosaic's lock, so that a slide read ahead may run).
  // Throws std::invalid_argument for bad parameters or ends off the mosaic, io::FormatError for
  // tiles that fail to load.
  volume::LinkProfile link_profile(const volume::Transmitter& tx, double rx_lat, double rx_lon, double rx_height_agl,
                                   const volume::RfOptions& options = {}) const;
  // Merges `path` (e.g. scene::profile_path_mesh) into the tree under scene::kProfilePathId,
  // replacing the one before (an empty mesh removes it; slides merge it again), and uploads
  // the vertices. Returns the merge's wall milliseconds.
  double set_path(const volume::Mesh& path);

 private:
  // A moved window read from the mosaic (and, read ahead, shaded), ready to slide to.
  struct PreparedSlide {
    scene::SceneWindow window;
    scene::TerrainShading lattice;   // empty: made after the slide
    // Of the tree slid (`slid`, or one without merged polygons); empty: made after the slide.
    scene::TerrainShading vertices;
    double read_ms = 0, shade_ms = 0;
    // kAsynchronous: a copy of the scene slid to `window` on the worker (taken between two
    // frames), and edits_ when it was taken. finish_slide() swaps it in unless the scene was
    // edited since; else it slides the scene itself to `window`.
    std::unique_ptr<scene::TerrainScene> slid;
    std::uint64_t edits = 0;
    double copy_ms = 0, tree_ms = 0;  // the copy and its slide, on the worker
  };
  void slide(const scene::CameraPose& pose, FrameStats& stats);
  std::optional<scene::WindowChoice> next_window(const scene::CameraPose& pose) const;
  static PreparedSlide prepare_slide(const io::Mosaic& mosaic, const scene::WindowChoice& next,
                                     const io::SceneFrame& frame);
  // The read window's shading and, with terrain_vertices > 0 (a tree without merged polygons,
  // whose vertices are the lattice's only), the vertices' shading; on the worker.
  static void shade_slide(PreparedSlide& prepared, const scene::ShadingOptions& shading,
                          std::size_t terrain_vertices);
  // On the worker, after prepare_slide() and shade_slide(): the scene copied (under
  // scene_mutex_) and slid to the prepared window, and the vertices' shading made for the slid
  // tree.
  void slide_copy(PreparedSlide& prepared) const;
  void finish_slide(PreparedSlide&& prepared);

  io::Mosaic mosaic_;  // read by the worker and this thread at once (its cache has a lock)
  RenderSettings settings_;
  SceneOptions options_;
  int levels_ = 0;
  std::unique_ptr<scene::TerrainScene> scene_;
  scene::TerrainShading lattice_;
  scene::VolumeLayer volumes_;
  scene::ObjectLayer objects_;
  std::unique_ptr<TerrainRenderer> renderer_;  // kVtk
  std::unique_ptr<TiledRenderer> tiled_;       // kTiler
  std::array<scene::Rgb, 2> sky_{};            // kTiler: the background of the prepared frame, bottom and top
  double far_plane_ = 0;                       // kTiler: of the prepared frame
  mrbsp::Frame frame_;
  mrbsp::Camera camera_;
  bool memory_to_return_ = false;
  std::atomic<bool> freed_{false};  // the retired scene freed, its pages not yet given back
  density::RefineOptions density_options_;
  std::vector<mrbsp::ColorBox> boxes_;  // the density's cells of the last frame
  bool auto_slide_ = true;
  int slides_ = 0;
  SlideFigures last_slide_;
  std::optional<std::string> slide_error_;
  // The worker copies the scene (slide_copy) under this lock; this thread holds it whenever it
  // changes the scene (a frame's preparation, whose traversal builds low alternatives and whose
  // objects may merge again; edits; tidying; a pick's far plane, which updates a cache).
  mutable std::mutex scene_mutex_;
  // Changes to the merged surfaces (remerge, set_path, objects merged again), counted under
  // scene_mutex_: a copy slid on the worker from before one is not swapped in.
  std::uint64_t edits_ = 0;
  // Frames whose preparation ended (the scene unlocked: the frame draws now); slide_copy waits
  // for the next one.
  mutable std::mutex prepared_mutex_;
  mutable std::condition_variable frame_prepared_;
  std::uint64_t frames_prepared_ = 0;
  std::future<void> retired_;  // the scene a swap replaced, freed on a worker
  std::future<PreparedSlide> pending_;  // declared last: waited for before anything it reads goes
};

}  // namespace terravol::app::render
