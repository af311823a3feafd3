// `terravol fly PATH.json -o out.mp4 | -o frames/`: a scripted flythrough (docs/camera-paths.md).
// Everything that can be wrong with the path, the scene or the outputs is found before the
// first frame: the path file, the scene, existing outputs, ffmpeg, and the camera at every frame
// time (inside the mosaic, above the ground). Frames are numbered from the path's first key
// (frame k at t0 + k / fps) whatever --start says, so partial runs and resumed runs name and
// draw the same frames.
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <csignal>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "app/cli/commands.h"
#include "app/cli/scene_options.h"
#include "app/output/frame_sink.h"
#include "app/output/write_file.h"
#include "app/render/scene_renderer.h"
#include "app/scene/camera_path.h"
#include "app/scene/mosaic_lattice.h"
#include "app/scene/scene_file.h"
#include "app/scene/style.h"
#include "density/transfer.h"
#include "io/mosaic.h"

namespace terravol::app::cli {

namespace {

using nlohmann::json;

constexpr const char* kManifest = ".terravol-fly.json";

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int) { g_stop = 1; }

struct FlyOptions {
  std::filesystem::path path, output, stats;
  double fps = 30.0;
  std::string size;  // empty: the scene's, else 1280x720
  std::optional<double> threshold, start, end;
  int crf = 20;
  // zlib's fastest: the default level (5) took 38% of a tiled 8 x 8 export's wall time over
  // N44W072 at 1280x720 in frames 22% smaller (81 frames: 13.0 s and 45 MB against 8.1 s and 55 MB).
  int png_level = 1;
  int samples = 1;
  RendererChoice drawn;  // --renderer, --aa
  bool resume = false, force = false;
  std::vector<std::string> objects;  // --object, added to the scene's
  std::string density;               // --density: replaces every volume's density style
  std::optional<double> density_threshold, density_error;
};

bool is_video(const std::filesystem::path& p) {
  const std::string e = p.extension().string();
  return e == ".mp4" || e == ".mkv" || e == ".mov" || e == ".m4v";
}

std::string fixed(double v, int decimals) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

// FNV-1a of a file's bytes (0 when unreadable): enough to tell a changed path or scene file.
std::uint64_t file_hash(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::uint64_t h = 1469598103934665603ull;
  for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) {
    h = (h ^ static_cast<unsigned char>(*it)) * 1099511628211ull;
  }
  return h;
}

// Throws std::invalid_argument("WHERE: LAT, LON is 250.0 km beyond the DEM (at most 200 km)")
// for a camera farther beyond the mosaic than scene::kMaxKmBeyond.
void require_near(const io::Mosaic& m, const std::string& where, double lat, double lon) {
  const double km = scene::km_beyond(m, lat, lon);
  if (km <= scene::kMaxKmBeyond) return;
  throw std::invalid_argument(where + ": " + fixed(lat, 5) + ", " + fixed(lon, 5) + " is " + fixed(km, 1) +
                              " km beyond the DEM (at most " + fixed(scene::kMaxKmBeyond, 0) + " km)");
}

// The keys around time t, for messages: "keys[2] and keys[3]" or "keys[2]".
std::string keys_around(const std::vector<scene::PathKey>& keys, double t) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (std::abs(keys[i].t - t) < 1e-9) return "keys[" + std::to_string(i) + "]";
    if (i + 1 < keys.size() && keys[i].t < t && t < keys[i + 1].t) {
      return "keys[" + std::to_string(i) + "] and keys[" + std::to_string(i + 1) + "]";
    }
  }
  return "the last key";
}

void run_fly(const FlyOptions& o) {
  const std::string source = o.path.string();
  const scene::CameraPathFile file = scene::load_camera_path(o.path);
  scene::SceneSpec scene = file.scene_file.empty()
                               ? scene::parse_scene_json(file.scene, file.base_dir, source + ": scene")
                               : scene::load_scene_file(file.scene_file);
  if (scene.dems.empty()) throw std::invalid_argument(source + ": scene: no \"dem\"; the flight needs terrain");
  for (const auto& d : scene.dems) {
    if (!std::filesystem::exists(d)) throw std::invalid_argument(source + ": scene: " + d.string() + ": no such file");
  }
  for (const auto& v : scene.volumes) {
    if (!std::filesystem::exists(v.file)) throw std::invalid_argument(source + ": scene: " + v.file.string() + ": no such file");
  }
  for (scene::ObjectSpec& obj : parse_objects(o.objects)) scene.objects.push_back(std::move(obj));
  if (!o.density.empty()) {
    const density::DensitySpec d = density::parse_density(o.density);
    for (scene::VolumeSpec& v : scene.volumes) v.density = d;
  }
  // Size and LOD: --size and --threshold over the scene's "render" object over the defaults.
  scene::SceneStyle given;
  if (!o.size.empty()) {
    int w = 0, h = 0;
    scene::parse_size(o.size, w, h);
    given.width = w;
    given.height = h;
  }
  given.threshold = o.threshold;
  given.density_threshold = o.density_threshold;
  given.density_error = o.density_error;
  const scene::SceneStyle style = scene::overlay(scene.style, given);
  const scene::Style st = scene::resolve_style(style);
  const int width = st.width, height = st.height;
  const bool video = is_video(o.output);
  if (video && (width % 2 != 0 || height % 2 != 0)) {
    throw std::invalid_argument("--size " + std::to_string(width) + "x" + std::to_string(height) +
                                ": H.264 in yuv420p needs an even width and height");
  }
  const int factor = static_cast<int>(std::lround(std::sqrt(o.samples)));
  if (static_cast<long long>(width) * factor > 16384 || static_cast<long long>(height) * factor > 16384) {
    throw std::invalid_argument("--samples " + std::to_string(o.samples) + ": " + std::to_string(width * factor) + "x" +
                                std::to_string(height * factor) + " is too large to render");
  }
  mrbsp::TraversalOptions traversal = st.traversal;
  traversal.crack_fills = true;
  const double default_threshold = style.threshold.value_or(mrbsp::default_threshold(traversal.metric));
  // Thresholds are in output pixels; the supersampled image has factor times as many per side.
  const double threshold_scale = traversal.metric == mrbsp::LodMetric::kError ? factor : factor * factor;
  const double default_fov = scene.camera ? scene.camera->fov_y_deg : 45.0;

  const bool tiled = o.drawn.engine == scene::Engine::kTiler;
  check_tiler_size(o.drawn, width, height);
  if (tiled && st.order != scene::DrawOrder::kBsp) {
    throw std::invalid_argument(source + ": scene: \"order\": \"" + scene::order_name(st.order) +
                                "\": --renderer tiler draws in the tree's own order (bsp)");
  }
  if (!tiled) render::require_x_display("fly");
  // Outputs: nothing is replaced without --force; a PNG folder resumes only what it started.
  if (!o.stats.empty() && !o.force && std::filesystem::exists(o.stats)) {
    throw std::runtime_error(o.stats.string() + ": exists (use --force to overwrite)");
  }
  json manifest = {{"path_file", std::filesystem::absolute(o.path).lexically_normal().string()},
                   {"path_hash", std::to_string(file_hash(o.path))},
                   {"scene_hash", file.scene_file.empty() ? "inline" : std::to_string(file_hash(file.scene_file))},
                   {"size", std::to_string(width) + "x" + std::to_string(height)},
                   {"fps", o.fps},
                   {"threshold", default_threshold},
                   {"samples", o.samples}};
  // What the command line adds to the scene draws other frames too (absent when not given, as
  // in manifests written before these keys).
  if (!o.objects.empty()) manifest["objects"] = o.objects;
  if (!o.density.empty()) manifest["density"] = o.density;
  if (o.density_threshold) manifest["density_threshold"] = *o.density_threshold;
  if (o.density_error) manifest["density_error"] = *o.density_error;
  if (tiled) {  // frames of another renderer or sampling are other frames (absent: VTK, as before)
    manifest["renderer"] = scene::engine_name(o.drawn.engine);
    manifest["aa"] = o.drawn.aa;
    manifest["texel_rate"] = o.drawn.texel_rate;
  }
  if (video) {
    if (o.resume) throw std::invalid_argument("--resume: only a PNG folder export resumes; a video is written whole");
    if (!o.force && std::filesystem::exists(o.output)) {
      throw std::runtime_error(o.output.string() + ": exists (use --force to overwrite)");
    }
    const auto parent = o.output.parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw std::runtime_error(o.output.string() + ": no folder " + parent.string());
    }
    if (!output::find_program("ffmpeg")) {
      throw std::runtime_error("ffmpeg not found on PATH (needed for " + o.output.string() + "; use -o FOLDER/ for PNG frames)");
    }
  } else {
    if (!o.output.extension().empty() && !std::filesystem::is_directory(o.output)) {
      throw std::invalid_argument(o.output.string() + ": not a video (.mp4, .mkv, .mov, .m4v) nor a folder for PNG frames");
    }
    if (std::filesystem::exists(o.output) && !std::filesystem::is_directory(o.output)) {
      throw std::runtime_error(o.output.string() + ": exists and is not a folder");
    }
  }

  // Frame times.
  const double t0 = file.keys.front().t, t1 = file.keys.back().t;
  const double start = o.start.value_or(t0), end = o.end.value_or(t1);
  if (start < t0 || start > t1) throw std::invalid_argument("--start " + fixed(start, 3) + ": outside the path (" + fixed(t0, 3) + " .. " + fixed(t1, 3) + " s)");
  if (end < start || end > t1) throw std::invalid_argument("--end " + fixed(end, 3) + ": must be within --start .. " + fixed(t1, 3) + " s");
  const long first = static_cast<long>(std::ceil((start - t0) * o.fps - 1e-6));
  const long last = static_cast<long>(std::floor((end - t0) * o.fps + 1e-6));
  if (last < first) throw std::invalid_argument("--start/--end: no frame between them at " + fixed(o.fps, 3) + " fps");
  const int digits = output::frame_digits(static_cast<long>(std::floor((t1 - t0) * o.fps + 1e-6)));

  long from = first;
  if (!video && std::filesystem::is_directory(o.output)) {
    const long present = output::existing_frames(o.output, first, last, digits);
    const auto manifest_path = o.output / kManifest;
    if (o.resume) {
      if (!std::filesystem::exists(manifest_path)) {
        if (present > 0) {
          throw std::runtime_error(o.output.string() + ": has no " + kManifest +
                                   "; cannot tell whether its frames match this export (use --force)");
        }
      } else {
        json before;
        try {
          std::ifstream in(manifest_path);
          before = json::parse(in);
        } catch (const json::exception&) {
          throw std::runtime_error(manifest_path.string() + ": not valid JSON; use --force to start over");
        }
        for (const auto& [key, value] : manifest.items()) {
          if (!before.contains(key) || before[key] != value) {
            throw std::runtime_error(o.output.string() + ": its frames were made with another " + key + " (" +
                                     (before.contains(key) ? before[key].dump() : "none") + ", now " + value.dump() +
                                     "); use --force to start over");
          }
        }
        // A key only the folder's manifest has (its frames are the tiler's, this run VTK's).
        for (const auto& [key, value] : before.items()) {
          if (!manifest.contains(key)) {
            throw std::runtime_error(o.output.string() + ": its frames were made with another " + key + " (" +
                                     value.dump() + ", now none); use --force to start over");
          }
        }
      }
      const auto missing = output::first_missing_frame(o.output, first, last, digits);
      if (!missing) {
        std::printf("%s: all %ld frames present; nothing to do\n", o.output.string().c_str(), last - first + 1);
        return;
      }
      from = *missing;
    } else if (present > 0 && !o.force) {
      throw std::runtime_error(o.output.string() + ": holds " + std::to_string(present) +
                               " frames of this range (use --resume to continue or --force to overwrite)");
    }
  }

  // The scene: its first window around the path's first key.
  const scene::PathKey& k0 = file.keys.front();
  scene.camera = scene::SceneCamera{scene::CameraPose{k0.lat, k0.lon, k0.alt, 0.0, 0.0}, k0.agl, default_fov};
  io::Mosaic mosaic = io::Mosaic::open(scene.dems);
  require_near(mosaic, source + ": keys[0]", k0.lat, k0.lon);
  render::RenderSettings settings = render::render_settings(st);
  settings.width = width * factor;
  settings.height = height * factor;
  render::SceneOptions scene_opts = render::scene_options(st);
  scene_opts.engine = o.drawn.engine;
  scene_opts.tiler.aa = o.drawn.aa;
  scene_opts.tiler.texel_rate = o.drawn.texel_rate;
  scene_opts.density.threshold_px *= factor;  // in output pixels, like the LOD threshold
  render::SceneRenderer renderer(std::move(mosaic), scene, settings, scene_opts);

  const scene::CameraPath path(
      file.keys, renderer.frame(), [&renderer](double lat, double lon) { return renderer.ground_height(lat, lon); },
      file.speed, default_fov, default_threshold);
  const auto time_of = [&](long k) { return t0 + static_cast<double>(k) / o.fps; };

  // Every frame's camera, checked before the first is drawn.
  for (long k = first; k <= last; ++k) {
    const double t = time_of(k);
    const scene::PathSample s = path.at(t);
    const std::string when = source + ": at t=" + fixed(t, 2) + " s (frame " + std::to_string(k) + ", " +
                             keys_around(file.keys, t) + ")";
    require_near(renderer.mosaic(), when + " the camera", s.pose.lat, s.pose.lon);
    const double ground = renderer.ground_height(s.pose.lat, s.pose.lon);
    const double clearance = path.agl() ? s.pose.alt : s.pose.alt - ground;
    if (!(clearance > 0.0)) {
      throw std::invalid_argument(when + " the camera is " + fixed(-clearance, 1) + " m below the ground (" +
                                  fixed(ground, 1) + " m there); raise the keys or give \"agl\": true");
    }
  }

  // Frames before `from` are not drawn, but the window slides they would have made are made,
  // so that the window (and so every pixel) at `from` is that of an uninterrupted run.
  for (long k = 0; k < from; ++k) renderer.slide_for(path.at(time_of(k)).pose);

  // Outputs.
  std::unique_ptr<output::FrameSink> sink;
  if (video) {
    sink = std::make_unique<output::VideoSink>(o.output, width, height, o.fps, o.crf, o.force);
  } else {
    sink = std::make_unique<output::PngSequenceSink>(o.output, width, height, digits, o.png_level);
    const std::string text = manifest.dump(2) + "\n";
    output::write_file_atomically(o.output / kManifest, std::vector<std::uint8_t>(text.begin(), text.end()), true);
  }
  std::filesystem::path stats_tmp;
  std::ofstream stats;
  if (!o.stats.empty()) {
    stats_tmp = o.stats;
    stats_tmp += ".tmp-" + std::to_string(::getpid());
    stats.open(stats_tmp, std::ios::binary | std::ios::trunc);
    if (!stats) throw std::runtime_error(o.stats.string() + ": cannot write");
    stats << "frame,t,lat,lon,alt,agl,heading,pitch,fov,threshold,eye_height,ground_height,triangles,"
             "merged_triangles,nodes_visited,traversal_ms,upload_ms,draw_ms,slides,slide_ms\n";
  }
  struct StatsCleanup {
    std::filesystem::path tmp;
    ~StatsCleanup() {
      std::error_code ec;
      if (!tmp.empty()) std::filesystem::remove(tmp, ec);
    }
  } cleanup{stats_tmp};

  g_stop = 0;
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  output::Progress progress(stderr, last - first + 1, from - first);
  for (long k = from; k <= last; ++k) {
    if (g_stop != 0) {
      progress.finish();
      throw std::runtime_error("interrupted after frame " + std::to_string(k - 1) +
                               (video ? "; " + o.output.string() + " not written"
                                      : "; run again with --resume to continue"));
    }
    const double t = time_of(k);
    const scene::PathSample s = path.at(t);
    mrbsp::TraversalOptions tr = traversal;
    tr.threshold_px = static_cast<float>(s.threshold * threshold_scale);
    const render::FrameStats f = renderer.render(s.pose, path.agl(), s.fov_y_deg, tr);
    const std::vector<std::uint8_t> rgb = renderer.rgb();
    sink->write(k, factor == 1 ? rgb : output::downsample_box(rgb, width, height, factor));
    if (stats.is_open()) {
      char b[512];
      std::snprintf(b, sizeof b, "%ld,%.4f,%.7f,%.7f,%.2f,%d,%.3f,%.3f,%.3f,%.3f,%.2f,%.2f,%zu,%zu,%zu,%.3f,%.3f,%.3f,%d,%.1f\n",
                    k, t, s.pose.lat, s.pose.lon, s.pose.alt, path.agl() ? 1 : 0, s.pose.heading_deg, s.pose.pitch_deg,
                    s.fov_y_deg, s.threshold, f.eye_height, f.ground_height, f.triangles, f.merged_triangles,
                    f.nodes_visited, f.traversal_ms, f.upload_ms, f.draw_ms, f.slides, f.slide_ms);
      stats << b;
    }
    progress.update(k - first + 1);
  }
  progress.finish();
  sink->finish();
  if (stats.is_open()) {
    stats.close();
    if (!stats) throw std::runtime_error(o.stats.string() + ": cannot write");
    std::filesystem::rename(stats_tmp, o.stats);
    cleanup.tmp.clear();
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  std::printf("wrote %s (%ld frames)\n", o.output.string().c_str(), last - from + 1);
  if (!o.stats.empty()) std::printf("wrote %s\n", o.stats.string().c_str());
}

}  // namespace

void add_fly_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("fly", "Export a scripted flythrough (camera path JSON) to a video or PNG frames "
                                        "(VTK needs an X display, --renderer tiler does not; docs/camera-paths.md)");
  auto o = std::make_shared<FlyOptions>();
  struct Raw {
    double threshold = 0, start = 0, end = 0, density_threshold = 0, density_error = 0;
    RendererArgs renderer;
  };
  auto raw = std::make_shared<Raw>();
  cmd->add_option("path", o->path, "Camera path file (JSON)")->required();
  cmd->add_option("-o,--output", o->output, "Video (.mp4, .mkv, .mov) or a folder for PNG frames")->required();
  cmd->add_option("--fps", o->fps, "Frames per second")->capture_default_str();
  cmd->add_option("--size", o->size, "Frame size WIDTHxHEIGHT, pixels (default: the scene's, else 1280x720)");
  auto* threshold = cmd->add_option("--threshold", raw->threshold,
                                    "LOD threshold in pixels for keys without their own (default: the scene's, else 2)");
  add_density_option(*cmd, o->density);
  auto* density_threshold = add_density_threshold_option(*cmd, raw->density_threshold);
  auto* density_error = add_density_error_option(*cmd, raw->density_error);
  cmd->add_option("--crf", o->crf, "H.264 quality, 0 (lossless) .. 51 (worst)")->capture_default_str();
  auto* png_level = cmd->add_option("--png-level", o->png_level,
                                    "PNG frames' zlib compression, 0 (none) .. 9 (smallest, slowest)")
                        ->capture_default_str();
  auto* start = cmd->add_option("--start", raw->start, "First time to export, seconds on the path's clock");
  auto* end = cmd->add_option("--end", raw->end, "Last time to export, seconds on the path's clock");
  cmd->add_option("--stats", o->stats, "Per-frame figures (CSV)");
  add_object_option(*cmd, o->objects);
  cmd->add_flag("--resume", o->resume, "Continue a PNG export from its first missing frame");
  cmd->add_flag("--force", o->force, "Replace existing outputs");
  cmd->add_option("--samples", o->samples,
                  "Antialiasing: samples per pixel, 1, 4, 9 or 16 (supersampling: rendered at 1x, 2x, 3x or 4x "
                  "the size and box-filtered down)")
      ->capture_default_str();
  add_renderer_options(*cmd, raw->renderer);
  cmd->callback([o, raw, threshold, start, end, density_threshold, density_error, png_level] {
    if (!(o->fps > 0.0 && o->fps <= 240.0)) throw std::invalid_argument("--fps " + fixed(o->fps, 3) + ": must be within (0, 240]");
    if (o->crf < 0 || o->crf > 51) throw std::invalid_argument("--crf " + std::to_string(o->crf) + ": must be within 0..51");
    if (o->png_level < 0 || o->png_level > 9) {
      throw std::invalid_argument("--png-level " + std::to_string(o->png_level) + ": must be within 0..9");
    }
    if (png_level->count() > 0 && is_video(o->output)) {
      throw std::invalid_argument("--png-level: for PNG frames; " + o->output.string() + " is a video (--crf sets its quality)");
    }
    if (o->samples != 1 && o->samples != 4 && o->samples != 9 && o->samples != 16) {
      throw std::invalid_argument("--samples " + std::to_string(o->samples) + ": must be 1, 4, 9 or 16");
    }
    o->drawn = resolve_renderer(raw->renderer);
    if (o->drawn.engine == scene::Engine::kTiler && o->samples != 1) {
      throw std::invalid_argument("--samples " + std::to_string(o->samples) +
                                  ": VTK's supersampling; --renderer tiler antialiases with --aa");
    }
    if (o->resume && o->force) throw std::invalid_argument("--resume and --force: give one (continue, or start over)");
    if (threshold->count() > 0) {
      if (!(raw->threshold > 0.0) || !std::isfinite(raw->threshold)) {
        throw std::invalid_argument("--threshold " + fixed(raw->threshold, 3) + ": must be a positive number of pixels");
      }
      o->threshold = raw->threshold;
    }
    if (density_threshold->count() > 0) o->density_threshold = raw->density_threshold;
    if (density_error->count() > 0) o->density_error = raw->density_error;
    if (!o->density.empty()) density::parse_density(o->density);  // bad text fails before any work
    if (start->count() > 0) o->start = raw->start;
    if (end->count() > 0) o->end = raw->end;
    if (!o->size.empty()) {
      int w = 0, h = 0;
      scene::parse_size(o->size, w, h);
    }
    run_fly(*o);
  });
}

}  // namespace terravol::app::cli
