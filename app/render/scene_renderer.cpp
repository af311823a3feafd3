#include "app/render/scene_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "app/scene/ground_grid.h"

namespace terravol::app::render {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

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

std::string degrees(double v, char positive, char negative) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f %c", std::abs(v), v < 0 ? negative : positive);
  return b;
}

}  // namespace

SceneRenderer::SceneRenderer(const scene::SceneSpec& scene, const RenderSettings& settings, int max_window, int levels,
                             const scene::ShadingOptions& shading, bool legend, std::size_t surface_triangles)
    : mosaic_(io::Mosaic::open(scene.dems)), settings_(settings), shading_(shading), legend_(legend) {
  const io::Georef& g = mosaic_.georef();
  double row = (mosaic_.rows() - 1) / 2.0, col = (mosaic_.cols() - 1) / 2.0;
  if (scene.camera) check_inside(scene.camera->pose);
  require_x_display();
  if (scene.camera) {
    row = (g.y0 - scene.camera->pose.lat) / g.dy;
    col = (std::remainder(scene.camera->pose.lon - g.x0 - 180.0, 360.0) + 180.0) / g.dx;
  }
  const scene::WindowChoice window = scene::choose_window(mosaic_.rows(), mosaic_.cols(), row, col, max_window);
  levels_ = levels > 0 ? levels : scene::default_levels(window.cells);
  scene_ = std::make_unique<scene::TerrainScene>(mosaic_, window, levels_);

  // Volumes: read once, placed in the scene frame (fixed for the session: slides keep it).
  volumes_ = scene::VolumeLayer(scene.volumes, mosaic_, scene_->frame(), surface_triangles);
  volumes_.merge_into(*scene_);
  lattice_ = scene::shade_terrain(scene_->cells(), scene_->xs(), scene_->ys(), scene_->z(), scene_->heights(), shading_);
  const scene::TerrainShading shading_all =
      scene::vertex_shading(lattice_, scene_->tree().merged_base(), scene_->tree().merged_colors());
  renderer_ = std::make_unique<TerrainRenderer>(scene_->tree().positions(), shading_all, settings_,
                                                ColorTexture{scene_->cells() + 1, lattice_.rgba});
  if (legend_) renderer_->set_legend(volumes_.legend());
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::check_inside(const scene::CameraPose& pose) const {
  const io::Georef& g = mosaic_.georef();
  const double row = (g.y0 - pose.lat) / g.dy;
  const double col = (std::remainder(pose.lon - g.x0 - 180.0, 360.0) + 180.0) / g.dx;
  if (row < 0 || row > mosaic_.rows() - 1 || col < 0 || col > mosaic_.cols() - 1) {
    const double south = g.y0 - (mosaic_.rows() - 1) * g.dy, east = g.x0 + (mosaic_.cols() - 1) * g.dx;
    throw std::runtime_error("camera " + degrees(pose.lat, 'N', 'S') + ", " + degrees(pose.lon, 'E', 'W') +
                             " is outside the DEM (" + degrees(south, 'N', 'S') + " .. " + degrees(g.y0, 'N', 'S') +
                             ", " + degrees(g.x0, 'E', 'W') + " .. " + degrees(east, 'E', 'W') + ")");
  }
}

void SceneRenderer::upload_vertices() {
  const scene::TerrainShading all = scene::vertex_shading(lattice_, scene_->tree().merged_base(), scene_->tree().merged_colors());
  renderer_->replace_vertices(scene_->tree().positions(), all, ColorTexture{scene_->cells() + 1, lattice_.rgba});
}

FrameStats SceneRenderer::render(const scene::CameraPose& pose, bool agl, double fov_y_deg,
                                 const mrbsp::TraversalOptions& traversal) {
  check_inside(pose);
  FrameStats stats;
  // Slide when the camera nears the window's edge, by whole coarsest-level cells.
  const io::Georef& g = mosaic_.georef();
  const double row = (g.y0 - pose.lat) / g.dy;
  const double col = (std::remainder(pose.lon - g.x0 - 180.0, 360.0) + 180.0) / g.dx;
  const int step = 1 << (levels_ - 1);
  const scene::WindowChoice next = scene::plan_slide(scene_->window(), mosaic_.rows(), mosaic_.cols(), row, col, step);
  if (next.row0 != scene_->window().row0 || next.col0 != scene_->window().col0) {
    const auto t0 = Clock::now();
    // Every vertex changes: the renderer's copies (and their GPU buffers) are freed before the
    // tree slides and merges again, so the merge's scratch does not come on top of them.
    renderer_->release_vertices();
    try {
      scene_->slide(mosaic_, next);  // merges the volumes' polygons again into the moved window
    } catch (...) {
      upload_vertices();  // the scene kept its window
      throw;
    }
    return_freed_memory();  // the old vertices and the merge's scratch
    lattice_ = scene::shade_terrain(scene_->cells(), scene_->xs(), scene_->ys(), scene_->z(), scene_->heights(), shading_);
    upload_vertices();
    return_freed_memory();  // the upload's shading copies
    ++slides_;
    stats.slide_ms = ms_since(t0);
  }
  stats.slides = slides_;

  stats.ground_height = ground_height(pose.lat, pose.lon);
  stats.eye_height = agl ? stats.ground_height + pose.alt : pose.alt;
  const double clearance = stats.eye_height - stats.ground_height;
  if (!(clearance > 0.0)) {
    char b[160];
    std::snprintf(b, sizeof b, "camera at %.1f m is not above the ground (%.1f m there)%s", stats.eye_height,
                  stats.ground_height, agl ? "" : "; use --agl for heights above ground");
    throw std::runtime_error(b);
  }
  const RenderSettings& s = renderer_->settings();
  camera_ = scene::make_scene_camera(scene_->frame(), pose, stats.eye_height, fov_y_deg, s.width, s.height,
                              scene::near_plane_for(clearance));
  renderer_->set_camera(camera_, scene_->far_plane(camera_.eye));
  if (s.gradient) {
    const auto sky = scene::sky_gradient(pose.pitch_deg, fov_y_deg);
    renderer_->set_background(sky[0], sky[1]);
  }

  auto t0 = Clock::now();
  scene_->tree().traverse(camera_, traversal, frame_);
  stats.traversal_ms = ms_since(t0);
  t0 = Clock::now();
  renderer_->set_frame(frame_);
  stats.upload_ms = ms_since(t0);
  stats.draw_ms = renderer_->render();
  stats.triangles = frame_.indices.size() / 3;
  stats.merged_triangles = static_cast<std::size_t>(
      std::count(frame_.level.begin(), frame_.level.end(), static_cast<std::int8_t>(mrbsp::kMergedLevel)));
  stats.nodes_visited = frame_.nodes_visited;
  return stats;
}

std::unique_ptr<TerrainRenderer> SceneRenderer::make_renderer(const RenderSettings& settings) const {
  const scene::TerrainShading all = scene::vertex_shading(lattice_, scene_->tree().merged_base(), scene_->tree().merged_colors());
  return std::make_unique<TerrainRenderer>(scene_->tree().positions(), all, settings,
                                           ColorTexture{scene_->cells() + 1, lattice_.rgba});
}

const scene::MergeFigures& SceneRenderer::remerge() {
  volumes_.merge_into(*scene_);
  upload_vertices();
  return volumes_.figures();
}

std::vector<std::uint8_t> SceneRenderer::rgb() const { return renderer_->rgb(); }

double SceneRenderer::ground_height(double lat, double lon) const {
  const scene::WindowBounds b = scene_->bounds();
  if (lat >= b.south && lat <= b.north && lon >= b.west && lon <= b.east) return scene_->ground_height(lat, lon);
  const io::Georef& g = mosaic_.georef();
  return scene::GroundGrid(mosaic_, lat - g.dy, lat + g.dy, lon - g.dx, lon + g.dx)(lat, lon);
}

}  // namespace terravol::app::render
