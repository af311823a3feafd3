#include "app/render/scene_renderer.h"

#include <vtkRenderWindow.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sys/resource.h>
#include <unistd.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/task_arena.h>

#include "app/scene/ground_grid.h"
#include "app/scene/mosaic_lattice.h"
#include "app/scene/profile_path.h"
#include "app/scene/timing.h"
#include "io/error.h"

namespace terravol::app::render {

namespace {

// Runs `work` on this thread at nice `nice` (at_lowest_priority: 19), its TBB loops on this
// thread alone: the viewer's worker then gets the cores mostly while the frames leave them idle
// (the main thread's traversal leaves one of llvmpipe's two), instead of taking one from the
// rasterizer threads for the length of a slide. The slide arrives a few frames later; the
// frames during it keep their pace. Nice 19, not SCHED_IDLE: a thread the frames wait for (a
// scene freed before the next slide swaps) still advances, if slowly, when other processes
// keep every core busy. On Linux the nice value is per thread. Lowering a priority needs no
// privilege (raising it back does, so a thread is lowered only for what it does last); when
// the system refuses, the work runs as it would have. Once lowered, a thread stays so.
template <class Work>
auto at_priority(int nice, Work&& work) {
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice);
  tbb::task_arena alone(1);
  return alone.execute(std::forward<Work>(work));
}

// The slide worker's read of the moved window (decoding new tiles: about 650 ms of CPU for two
// of Utah's .sdf.bz2) at nice 10, between the frames' 0 and the shading's 19: at 19 it starved
// while the frames kept both cores busy (the benchmark's flight left the window before a slide
// landed, and in one run of 1000 frames none landed); at 10 every run landed its slides, in
// 0.7-1.5 s against 0.5-0.8 at 0, and the frames lost less to it (measured: docs/
// architecture.md, the viewer's slides).
constexpr int kReadNice = 10;

template <class Work>
auto at_lowest_priority(Work&& work) {
  return at_priority(19, std::forward<Work>(work));
}

using scene::Clock;
using scene::ms_between;
using scene::ms_since;

// Gives the pages of freed heap memory back to the system (glibc; elsewhere nothing). The
// merge of a slide frees its scratch (about a million small polygon lists and the vertices in
// double precision), and glibc keeps the pages of free chunks below live ones: measured over
// examples/utah-flight.json at 320x180 (mallinfo2, VmRSS), the free bytes inside the heap grew
// from 42 MB to 160-176 MB at the first slides and RSS with them, by 136-153 MB per slide
// more than the new window's content; malloc_trim(0) after the slide brought RSS back to what
// the window holds. It costs 2 to 24 ms (measured), twice per slide of 2.5 to 4 s.
void return_freed_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace

SceneOptions scene_options(const scene::Style& style, int levels, Sliding sliding) {
  SceneOptions o;
  o.max_window = style.window;
  o.levels = levels;
  o.shading = style.shading;
  o.legend = style.legend;
  o.markers = style.markers;
  o.surface_triangles = style.surface_triangles;
  o.sliding = sliding;
  o.density.threshold_px = style.density_threshold;
  o.density.error_tolerance = style.density_error / 255.0;
  return o;
}

RenderSettings render_settings(const scene::Style& style) {
  RenderSettings s;
  s.width = style.width;
  s.height = style.height;
  s.order = style.order;
  s.gradient = true;
  s.haze_color = scene::kHorizon;
  s.haze_distance = style.haze_km * 1000.0;
  return s;
}

SceneRenderer::SceneRenderer(const scene::SceneSpec& scene, const RenderSettings& settings, const SceneOptions& options)
    : SceneRenderer(io::Mosaic::open(scene.dems), scene, settings, options) {}

SceneRenderer::SceneRenderer(io::Mosaic mosaic, const scene::SceneSpec& scene, const RenderSettings& settings,
                             const SceneOptions& options)
    : mosaic_(std::move(mosaic)), settings_(settings), options_(options), density_options_(options.density) {
  const scene::CameraPose at = scene.camera ? scene.camera->pose : scene::default_pose(mosaic_);
  scene::require_near(mosaic_, at.lat, at.lon);
  if (options_.engine == scene::Engine::kTiler) {
    if (settings_.order != scene::DrawOrder::kBsp || settings_.wireframe || settings_.lod_colors) {
      throw std::invalid_argument("the tiler draws filled triangles in the tree's order only (--order bsp, no "
                                  "--wireframe or --lod-colors)");
    }
    options_.tiler.width = settings_.width;
    options_.tiler.height = settings_.height;
    tiled_ = std::make_unique<TiledRenderer>(options_.tiler);  // throws for bad settings before the scene is read
  } else {
    require_x_display();
  }
  const scene::LatticePoint p = scene::lattice_point(mosaic_, at.lat, at.lon);
  const scene::WindowChoice window =
      scene::choose_window(mosaic_.rows(), mosaic_.cols(), p.row, p.col, options_.max_window);
  levels_ = options_.levels > 0 ? options_.levels : scene::default_levels(window.cells);
  scene_ = std::make_unique<scene::TerrainScene>(mosaic_, window, levels_);

  // Volumes: read once, placed in the scene frame (fixed for the session: slides keep it).
  volumes_ = scene::VolumeLayer(scene.volumes, mosaic_, scene_->frame(), options_.surface_triangles, options_.markers);
  volumes_.merge_into(*scene_);
  for (const scene::ObjectSpec& o : scene.objects) {
    if (!scene::inside(mosaic_, scene::lattice_point(mosaic_, o.pose.lat, o.pose.lon))) {
      char b[96];
      std::snprintf(b, sizeof b, ": placed at %.5f, %.5f, outside the DEM", o.pose.lat, o.pose.lon);
      throw std::invalid_argument(o.file.string() + b);
    }
  }
  objects_ = scene::ObjectLayer(
      scene.objects, [this](double lat, double lon) { return ground_height(lat, lon); }, scene_->frame(), options_.lod,
      objects::Sunlight{options_.shading.sun_azimuth_deg, options_.shading.sun_elevation_deg, options_.shading.ambient});
  lattice_ = scene::shade_terrain(scene_->cells(), scene_->xs(), scene_->ys(), scene_->z(), scene_->heights(),
                                  options_.shading);
  if (tiled_) {
    if (options_.legend) tiled_->set_legend(volumes_.legend());
    tiled_->set_labels(volumes_.marker_labels());
    return;
  }
  const mrbsp::TerrainTree& tree = scene_->tree();
  renderer_ = std::make_unique<TerrainRenderer>(
      tree.positions(), scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors()), settings_,
      ColorTexture{scene_->cells() + 1, lattice_.rgba});
  renderer_->set_vertex_version(tree.merged_version());
  if (options_.legend) renderer_->set_legend(volumes_.legend());
  renderer_->set_labels(volumes_.marker_labels());
}

TerrainRenderer& SceneRenderer::renderer() {
  if (!renderer_) throw std::logic_error("SceneRenderer::renderer: the scene is drawn by the tiler, not VTK");
  return *renderer_;
}

const TiledRenderer& SceneRenderer::tiled() const {
  if (!tiled_) throw std::logic_error("SceneRenderer::tiled: the scene is drawn by VTK, not the tiler");
  return *tiled_;
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::sync_vertices(TerrainRenderer& renderer) const {
  const mrbsp::TerrainTree& tree = scene_->tree();
  const std::vector<glm::vec3>& positions = tree.positions();
  if (renderer.vertex_version() != tree.merged_version() || renderer.vertex_count() > positions.size()) {
    // A renumbering over the same terrain (a compaction after edits): the merged vertices alone.
    if (renderer.replace_merged_vertices(positions, tree.merged_base(), tree.merged_colors())) {
      renderer.set_vertex_version(tree.merged_version());
      return;
    }
    renderer.replace_vertices(
        positions, scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors()),
        ColorTexture{scene_->cells() + 1, lattice_.rgba});
  } else if (renderer.vertex_count() < positions.size()) {
    const std::size_t have = renderer.vertex_count();
    renderer.append_merged_vertices(std::span(positions).subspan(have),
                                    std::span(tree.merged_colors()).subspan(have - tree.merged_base()));
  }
  renderer.set_vertex_version(tree.merged_version());
}

namespace {

// The eye's height in the datum over ground `ground`; throws when it is not above it.
double eye_above(double ground, const scene::CameraPose& pose, bool agl) {
  const double eye = agl ? ground + pose.alt : pose.alt;
  if (!(eye - ground > 0.0)) {
    char b[160];
    std::snprintf(b, sizeof b, "camera at %.1f m is not above the ground (%.1f m there)%s", eye, ground,
                  agl ? "" : "; use --agl for heights above ground");
    throw std::runtime_error(b);
  }
  return eye;
}

}  // namespace

double SceneRenderer::eye_height(const scene::CameraPose& pose, bool agl) const {
  return eye_above(ground_height(pose.lat, pose.lon), pose, agl);
}

// Sliding (section 4.3), the same steps in both modes: next_window() decides, prepare_slide()
// reads the moved window (on this thread, or on a worker with kAsynchronous, which also shades
// it there: shade_slide()), finish_slide() slides the tree and replaces the renderer's vertices
// on this thread.
std::optional<scene::WindowChoice> SceneRenderer::next_window(const scene::CameraPose& pose) const {
  const scene::LatticePoint p = scene::lattice_point(mosaic_, pose.lat, pose.lon);
  const scene::WindowChoice& now = scene_->window();
  const int step = 1 << (levels_ - 1);  // samples across one coarsest-level cell
  const scene::WindowChoice next = scene::plan_slide(now, mosaic_.rows(), mosaic_.cols(), p.row, p.col, step);
  if (next.row0 == now.row0 && next.col0 == now.col0) return std::nullopt;
  return next;
}

// Reads `next` from the mosaic in `frame`. Touches nothing of the pipeline, so it may run on a
// worker thread while the pipeline draws.
SceneRenderer::PreparedSlide SceneRenderer::prepare_slide(const io::Mosaic& mosaic,
                                                          const scene::WindowChoice& next,
                                                          const io::SceneFrame& frame) {
  PreparedSlide p;
  const auto t0 = Clock::now();
  p.window = scene::read_scene_window(mosaic, next, frame);
  p.read_ms = ms_since(t0);
  return p;
}

void SceneRenderer::shade_slide(PreparedSlide& p, const scene::ShadingOptions& shading,
                                std::size_t terrain_vertices) {
  const auto t0 = Clock::now();
  const scene::SceneWindow& w = p.window;
  p.lattice = scene::shade_terrain(w.window.cells, w.xs, w.ys, w.z, w.heights, shading);
  if (terrain_vertices > 0) p.vertices = scene::vertex_shading(p.lattice, terrain_vertices, {});
  p.shade_ms = ms_since(t0);
}

void SceneRenderer::slide_copy(PreparedSlide& p) const {
  // The copy waits for a frame's preparation to end, so that it is taken while that frame
  // draws: taken whenever the read ended, it came at the next preparation as often as not,
  // which then waited for it (29-62 ms with the benchmark's volumes, whose copy took 43-140 ms
  // until the copy shared the small BSPs; 25-61 ms since).
  // Not for long: with no frames coming (the viewer idle) it is taken anyway.
  {
    std::unique_lock<std::mutex> wait(prepared_mutex_);
    const std::uint64_t seen = frames_prepared_;
    frame_prepared_.wait_for(wait, std::chrono::milliseconds(100),
                             [&] { return frames_prepared_ != seen; });
  }
  const auto t0 = Clock::now();
  {
    const std::lock_guard<std::mutex> lock(scene_mutex_);
    p.slid = std::make_unique<scene::TerrainScene>(*scene_);
    p.edits = edits_;
  }
  const auto t1 = Clock::now();
  p.copy_ms = ms_between(t0, t1);
  // A copy of the window: p.window stays for finish_slide's other way. This thread ends with
  // the slide, so its priority stays lowered.
  at_lowest_priority([&] {
    p.slid->slide(scene::SceneWindow(p.window));
    const mrbsp::TerrainTree& tree = p.slid->tree();
    if (p.vertices.rgba.size() != tree.positions().size() && !p.lattice.rgba.empty()) {
      p.vertices = scene::vertex_shading(p.lattice, tree.merged_base(), tree.merged_colors());
    }
  });
  p.tree_ms = ms_since(t1);
}

void SceneRenderer::finish_slide(PreparedSlide&& p) {
  const auto t0 = Clock::now();
  if (p.slid && p.edits == edits_) {
    // The tree slid on the worker, on a copy of the scene taken after the last edit: the same
    // tree this thread's slide would make (TerrainTree's copy is independent). Swapped in; the old
    // scene is freed on a worker (its small BSPs are tens of thousands of allocations).
    std::swap(scene_, p.slid);
    if (retired_.valid()) retired_.wait();
    retired_ = std::async(std::launch::async, [this, old = std::move(p.slid)]() mutable {
      at_lowest_priority([&] { old.reset(); });
      freed_ = true;
    });
    // The freed pages go back to the system at the next slide's start or when the viewer rests
    // (return_memory()), not here: malloc_trim walks every arena under its lock, and trimming
    // beside the landing frame (which allocates the low alternatives it builds) made that frame
    // 30-70 ms slower, at the lowest priority or at normal.
    memory_to_return_ = true;
    const double tree_ms = ms_since(t0);
    lattice_ = std::move(p.lattice);
    const auto t1 = Clock::now();
    const mrbsp::TerrainTree& tree = scene_->tree();
    if (renderer_) {
      renderer_->replace_vertices(tree.positions(), std::move(p.vertices),
                                  ColorTexture{scene_->cells() + 1, lattice_.rgba});
      renderer_->set_vertex_version(tree.merged_version());
    }
    last_slide_ = {p.read_ms, p.shade_ms, tree_ms, ms_since(t1), p.copy_ms, p.tree_ms};
    ++slides_;
    return;
  }
  // Slid here (kSynchronous, or edited since the copy was taken). What prepare_slide left out
  // (with kSynchronous: the shading, so that it is made after the old vertices and the merge's
  // scratch are gone, not held across the merge) is made here.
  p.slid.reset();
  p.vertices = {};
  // Every vertex changes. With volumes or objects the renderer's copies (and their GPU
  // buffers) are freed before the tree slides and merges again, so the merge's scratch does not
  // come on top of them; without, the tree merges nothing and keeps its vertex count, and the
  // renderer writes the new vertices over the old ones (TerrainRenderer::replace_vertices).
  if (renderer_ && (volumes_.size() > 0 || objects_.size() > 0)) renderer_->release_vertices();
  try {
    scene_->slide(std::move(p.window));  // merges the volumes' polygons again into the moved window
  } catch (...) {
    if (renderer_) sync_vertices(*renderer_);  // the scene kept its window: all of its vertices again
    throw;
  }
  return_freed_memory();  // the old vertices and the merge's scratch
  const double tree_ms = ms_since(t0);
  if (p.lattice.rgba.empty()) {
    const auto s0 = Clock::now();
    p.lattice = scene::shade_terrain(scene_->cells(), scene_->xs(), scene_->ys(), scene_->z(), scene_->heights(),
                                     options_.shading);
    p.shade_ms = ms_since(s0);
  }
  lattice_ = std::move(p.lattice);
  const auto t1 = Clock::now();
  const mrbsp::TerrainTree& tree = scene_->tree();
  if (renderer_) {
    if (p.vertices.rgba.empty()) p.vertices = scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors());
    renderer_->replace_vertices(tree.positions(), std::move(p.vertices),
                                ColorTexture{scene_->cells() + 1, lattice_.rgba});
    renderer_->set_vertex_version(tree.merged_version());
  }
  p.vertices = {};
  return_freed_memory();  // the upload's shading copies
  last_slide_ = {p.read_ms, p.shade_ms, tree_ms, ms_since(t1)};
  ++slides_;
}

bool SceneRenderer::slide_ready() const {
  return pending_.valid() && pending_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

std::optional<std::string> SceneRenderer::take_slide_error() { return std::exchange(slide_error_, std::nullopt); }

void SceneRenderer::slide(const scene::CameraPose& pose, FrameStats& stats) {
  const auto t0 = Clock::now();
  bool slid = false;
  if (options_.sliding == Sliding::kSynchronous) {
    if (const auto next = auto_slide_ ? next_window(pose) : std::nullopt) {
      finish_slide(prepare_slide(mosaic_, *next, scene_->frame()));
      slid = true;
    }
  } else {
    if (slide_ready()) {
      std::optional<PreparedSlide> p;
      try {
        p = pending_.get();
      } catch (const io::FormatError& e) {
        slide_error_ = e.what();
        auto_slide_ = false;
      }
      if (p) {
        finish_slide(std::move(*p));
        slid = true;
      }
    }
    if (auto_slide_ && !pending_.valid()) {
      if (const auto next = next_window(pose)) {
        // Without volumes or objects the tree has no merged vertices, before the slide or after it: the
        // worker can make the vertices' shading with the lattice's.
        const std::size_t terrain_vertices = volumes_.size() == 0 && objects_.size() == 0 ? scene_->tree().merged_base() : 0;
        pending_ = std::async(std::launch::async, [this, w = *next, frame = scene_->frame(),
                                                   shading = options_.shading, terrain_vertices] {
          // The pages the last landing freed, given back while the frames are quiet (a few ms;
          // without it a flight that never rests holds 120-320 MB more).
          if (freed_.exchange(false)) return_freed_memory();
          // The read at nice kReadNice and the shading at the lowest priority (on a thread of
          // their own, waited for), the copy at this thread's own, its slide (slide_copy) at the
          // lowest again. The copy holds the scene's lock, which every frame's preparation waits
          // for: a starved thread holding it would stall frames. The read holds no lock a frame
          // waits for (ground_height() beyond the window does not wait for its decode; an
          // earlier read under one lock of the mosaic stalled such frames for 70-235 ms).
          PreparedSlide p =
              std::async(std::launch::async, [&] {
                PreparedSlide read =
                    at_priority(kReadNice, [&] { return prepare_slide(mosaic_, w, frame); });
                at_lowest_priority([&] { shade_slide(read, shading, terrain_vertices); });
                return read;
              }).get();
          slide_copy(p);
          return p;
        });
      }
    }
  }
  if (slid) stats.slide_ms = ms_since(t0);
  stats.slides = slides_;
}

FrameStats SceneRenderer::prepare(const scene::CameraPose& pose, bool agl, double fov_y_deg,
                                  const mrbsp::TraversalOptions& traversal) {
  scene::require_near(mosaic_, pose.lat, pose.lon);
  FrameStats stats;
  slide(pose, stats);
  std::unique_lock<std::mutex> lock(scene_mutex_);  // the worker copies the scene while frames draw

  stats.ground_height = ground_height(pose.lat, pose.lon);
  stats.eye_height = eye_above(stats.ground_height, pose, agl);
  // The near plane from the eye's distance to the terrain: its height above the ground, or
  // from a camera beyond the window its distance to the window's box, if that is more.
  const double ex = scene_->frame().x_of_lon(pose.lon), ey = scene_->frame().y_of_lat(pose.lat);
  const double beyond_x = std::max({scene_->xs().front() - ex, ex - scene_->xs().back(), 0.0});
  const double beyond_y = std::max({scene_->ys().front() - ey, ey - scene_->ys().back(), 0.0});
  const double clearance = std::max(stats.eye_height - stats.ground_height, std::hypot(beyond_x, beyond_y));
  const int* size = renderer_ ? renderer_->window()->GetSize() : nullptr;
  camera_ = scene::make_scene_camera(scene_->frame(), pose, stats.eye_height, fov_y_deg,
                                     size ? std::max(size[0], 1) : settings_.width, size ? std::max(size[1], 1) : settings_.height,
                                     options_.near_plane > 0 ? options_.near_plane : scene::near_plane_for(clearance));
  const auto sky = settings_.gradient ? scene::sky_gradient(pose.pitch_deg, fov_y_deg)
                                      : std::array<scene::Rgb, 2>{settings_.background, settings_.background};
  // The density's cells of this view (refined for the output's pixels, whatever draws them);
  // the far plane holds them as it holds the window and the merged surfaces (they may lie
  // beyond).
  auto t0 = Clock::now();
  boxes_.clear();
  volumes_.density_boxes(camera_, density_options_, boxes_, stats.density);
  double far = scene_->far_plane(camera_.eye);
  if (!boxes_.empty()) {
    double farthest = 0.0;
    for (const mrbsp::ColorBox& b : boxes_) {
      const glm::dvec3 d = glm::max(glm::abs(glm::dvec3(b.lo) - camera_.eye), glm::abs(glm::dvec3(b.hi) - camera_.eye));
      farthest = std::max(farthest, glm::dot(d, d));
    }
    far = std::max(far, std::sqrt(farthest) * 1.05 + 100.0);
  }
  stats.density_ms = ms_since(t0);
  if (renderer_) {
    renderer_->set_camera(camera_, far);
    if (renderer_->settings().gradient) renderer_->set_background(sky[0], sky[1]);
  } else {
    sky_ = sky;
    far_plane_ = far;
  }

  t0 = Clock::now();
  objects_.update(*scene_, camera_, traversal);
  stats.objects_ms = ms_since(t0);
  stats.objects_merged = objects_.figures().remerged;
  if (stats.objects_merged > 0) ++edits_;
  t0 = Clock::now();
  if (tiled_) {
    const int aa = tiled_->settings().aa;
    scene_->tree().traverse(tiled_traversal_camera(camera_, traversal, aa), tiled_traversal(traversal, aa), frame_, boxes_);
  } else {
    scene_->tree().traverse(camera_, traversal, frame_, boxes_);
  }
  stats.traversal_ms = ms_since(t0);
  stats.boxes = frame_.boxes;
  t0 = Clock::now();
  if (renderer_) {
    sync_vertices(*renderer_);  // the low alternatives the traversal built appended vertices
    renderer_->set_frame(frame_);
  }
  stats.upload_ms = ms_since(t0);
  stats.triangles = frame_.indices.size() / 3;
  stats.merged_triangles = static_cast<std::size_t>(
      std::count(frame_.level.begin(), frame_.level.end(), static_cast<std::int8_t>(mrbsp::kMergedLevel)));
  stats.box_triangles = static_cast<std::size_t>(
      std::count(frame_.level.begin(), frame_.level.end(), static_cast<std::int8_t>(mrbsp::kBoxLevel)));
  stats.nodes_visited = frame_.nodes_visited;
  lock.unlock();
  {
    const std::lock_guard<std::mutex> prepared(prepared_mutex_);
    ++frames_prepared_;
  }
  frame_prepared_.notify_all();
  return stats;
}

double SceneRenderer::draw() {
  if (tiled_) {
    return tiled_->draw(scene_->tree(), lattice_, frame_, camera_, far_plane_, sky_[0], sky_[1], settings_.haze_distance,
                        settings_.haze_color);
  }
  return renderer_->render();
}

bool SceneRenderer::slide_for(const scene::CameraPose& pose) {
  scene::require_near(mosaic_, pose.lat, pose.lon);
  const int before = slides_;
  FrameStats stats;
  slide(pose, stats);
  return slides_ > before;
}

FrameStats SceneRenderer::render(const scene::CameraPose& pose, bool agl, double fov_y_deg,
                                 const mrbsp::TraversalOptions& traversal) {
  FrameStats stats = prepare(pose, agl, fov_y_deg, traversal);
  stats.draw_ms = draw();
  return stats;
}

std::unique_ptr<TerrainRenderer> SceneRenderer::make_renderer(const RenderSettings& settings) const {
  const mrbsp::TerrainTree& tree = scene_->tree();
  const scene::TerrainShading all = scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors());
  auto renderer = std::make_unique<TerrainRenderer>(tree.positions(), all, settings,
                                                    ColorTexture{scene_->cells() + 1, lattice_.rgba});
  renderer->set_vertex_version(tree.merged_version());
  return renderer;
}

const scene::MergeFigures& SceneRenderer::remerge() {
  const std::lock_guard<std::mutex> lock(scene_mutex_);
  volumes_.merge_into(*scene_);
  ++edits_;
  if (tiled_) {
    if (options_.legend) tiled_->set_legend(volumes_.legend());
    tiled_->set_labels(volumes_.marker_labels());
    return volumes_.figures();
  }
  sync_vertices(*renderer_);
  if (options_.legend) renderer_->set_legend(volumes_.legend());
  renderer_->set_labels(volumes_.marker_labels());
  return volumes_.figures();
}

bool SceneRenderer::memory_to_return() const {
  return memory_to_return_ && !pending_.valid();
}

void SceneRenderer::return_memory() {
  if (retired_.valid()) retired_.wait();
  return_freed_memory();
  freed_ = false;
  memory_to_return_ = false;
}

mrbsp::MergeStats SceneRenderer::tidy() {
  const std::lock_guard<std::mutex> lock(scene_mutex_);
  if (scene_->tree().merge_stats().worn_slots == 0) return scene_->tree().merge_stats();
  const mrbsp::MergeStats stats = scene_->tidy();  // the image does not change: not an edit
  if (renderer_) sync_vertices(*renderer_);
  return stats;
}

volume::LinkProfile SceneRenderer::link_profile(const volume::Transmitter& tx, double rx_lat, double rx_lon,
                                                double rx_height_agl, const volume::RfOptions& options) const {
  const volume::DemExtent area{std::min(tx.lat, rx_lat), std::max(tx.lat, rx_lat), std::min(tx.lon, rx_lon),
                               std::max(tx.lon, rx_lon)};
  const volume::RfWindow window = volume::read_rf_window(mosaic_, area);
  return volume::link_profile(window.grid, tx, rx_lat, rx_lon, rx_height_agl, options);
}

double SceneRenderer::set_path(const volume::Mesh& path) {
  const auto t0 = Clock::now();
  const std::uint32_t id = scene::kProfilePathId;
  const mrbsp::SurfaceInput input{path.vertices, path.colors, path.triangles};
  const std::lock_guard<std::mutex> lock(scene_mutex_);
  scene_->set_surfaces(std::span(&id, 1), std::span(&input, 1));
  ++edits_;
  if (renderer_) sync_vertices(*renderer_);
  return ms_since(t0);
}

std::vector<std::uint8_t> SceneRenderer::rgb() const { return tiled_ ? tiled_->rgb() : renderer_->rgb(); }

std::optional<Pick> SceneRenderer::pick(int x, int y) const {
  const auto t0 = scene::Clock::now();
  const scene::WindowBounds b = scene_->bounds();
  const auto inside = [&](double lat, double lon) { return lat >= b.south && lat <= b.north && lon >= b.west && lon <= b.east; };
  const auto ground = [&](double lat, double lon) { return scene_->ground_height(lat, lon); };
  const glm::dvec3 eye = camera_.eye;
  volume::Mesh surfaces = volumes_.visible_mesh();
  volume::append(surfaces, objects_.visible_mesh());
  double far = 0;
  {
    const std::lock_guard<std::mutex> lock(scene_mutex_);  // far_plane() updates the scene's cache
    far = scene_->far_plane(eye);
  }
  const std::optional<scene::PickPoint> p = scene::pick(scene::pixel_ray(camera_, x, y), scene_->frame(), ground, inside,
                                                        surfaces, far);
  if (!p) return std::nullopt;
  Pick out;
  out.point = *p;
  out.ground = ground_height(p->where.lat, p->where.lon);
  out.values = volumes_.values_at(p->where.lat, p->where.lon, p->where.h - out.ground, out.ground);
  out.ms = scene::ms_since(t0);
  return out;
}

double SceneRenderer::ground_height(double lat, double lon) const {
  scene::clamp_to_mosaic(mosaic_, lat, lon);  // beyond the DEM: the ground at its nearest point
  const scene::WindowBounds b = scene_->bounds();
  if (lat >= b.south && lat <= b.north && lon >= b.west && lon <= b.east) return scene_->ground_height(lat, lon);
  const io::Georef& g = mosaic_.georef();
  if (pending_.valid()) {
    // A slide is under way: its worker may be decoding the tiles here at a low priority.
    // A frame does not wait for that: until they are decoded, the ground of the window's
    // nearest point (beyond the window, the eye sees only its walls and what lies outside).
    if (const auto near =
            scene::GroundGrid::cached(mosaic_, lat - g.dy, lat + g.dy, lon - g.dx, lon + g.dx)) {
      return (*near)(lat, lon);
    }
    return scene_->ground_height(std::clamp(lat, b.south, b.north),
                                 std::clamp(lon, b.west, b.east));
  }
  return scene::GroundGrid(mosaic_, lat - g.dy, lat + g.dy, lon - g.dx, lon + g.dx)(lat, lon);
}

}  // namespace terravol::app::render
