#include "reference/check.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <thread>

#include "reference/dem.h"
#include "reference/frame.h"
#include "reference/geometry.h"
#include "reference/objects.h"
#include "reference/scene.h"
#include "volume/readers.h"

extern char** environ;

namespace terravol::reference {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A scene file's "frame" (docs/scene-file.md): geographic, geographic-agl, enu:LAT,LON,H, none.
volume::VolumeFrame frame_of(const std::string& text, const fs::path& scene) {
  volume::VolumeFrame f;
  if (text == "geographic" || text == "geographic-agl") {
    f.kind = volume::FrameKind::kGeographic;
    f.height = text == "geographic" ? volume::HeightRef::kDatum : volume::HeightRef::kGround;
  } else if (text.rfind("enu:", 0) == 0) {
    f.kind = volume::FrameKind::kEnu;
    char tail = 0;
    if (std::sscanf(text.c_str() + 4, "%lf,%lf,%lf%c", &f.origin_lat, &f.origin_lon, &f.origin_h, &tail) != 3) {
      throw std::runtime_error(scene.string() + ": frame '" + text + "' is not enu:LAT,LON,H");
    }
  } else if (text != "none") {
    throw std::runtime_error(scene.string() + ": unknown frame '" + text + "'");
  }
  return f;
}

bool needs_ground(const volume::Volume& v, const VolumeStyle& s) {
  if (v.frame.kind == volume::FrameKind::kGeographic && v.frame.height == volume::HeightRef::kGround) return true;
  return std::any_of(s.slices.begin(), s.slices.end(), [](const SliceStyle& x) { return x.kind == SliceKind::kAgl; });
}

// The geographic box of a volume's lattice (its corners; heights do not matter for the box
// except in ENU, where all eight corners are taken).
Box footprint(const volume::Volume& v, const Frame& frame) {
  Box b{90, -90, 180, -180};
  auto add = [&](double lat, double lon) {
    b.south = std::min(b.south, lat), b.north = std::max(b.north, lat);
    b.west = std::min(b.west, lon), b.east = std::max(b.east, lon);
  };
  const auto& l = v.lattice;
  const double ni = l.dims[0] - 1, nj = l.dims[1] - 1, nk = l.dims[2] - 1;
  if (v.frame.kind == volume::FrameKind::kEnu) {
    const Placement p(v, frame, nullptr);
    for (double i : {0.0, ni})
      for (double j : {0.0, nj})
        for (double k : {0.0, nk}) {
          const Geodetic g = p.geodetic(i, j, k);
          add(g.lat, g.lon);
        }
  } else {
    add(l.origin[1], l.origin[0]);
    add(l.origin[1] + nj * l.spacing[1], l.origin[0] + ni * l.spacing[0]);
  }
  return b;
}

std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

RenderStats read_stats(const fs::path& stats) {
  std::ifstream in(stats);
  if (!in) throw std::runtime_error(stats.string() + ": cannot open");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    RenderStats s;
    s.width = j.at("width").get<int>();
    s.height = j.at("height").get<int>();
    s.origin_lat = j.at("window").at("origin_lat").get<double>();
    s.origin_lon = j.at("window").at("origin_lon").get<double>();
    const auto& w = j.at("window");
    s.window = {w.at("cells").get<int>(), w.at("south").get<double>(), w.at("north").get<double>(),
                w.at("west").get<double>(), w.at("east").get<double>()};
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(stats.string() + ": " + e.what());
  }
}

Reference reference_image(const fs::path& scene_file, const fs::path& vtp, const fs::path& stats_file) {
  const auto t0 = Clock::now();
  const Scene scene = read_scene(scene_file);
  const RenderStats stats = read_stats(stats_file);
  const Frame frame(stats.origin_lat, stats.origin_lon);

  // The volumes, then the DEM samples under those that need the ground.
  std::vector<volume::Volume> volumes;
  std::vector<const VolumeStyle*> styles;
  Box box{90, -90, 180, -180};
  bool ground = false;
  for (const VolumeStyle& s : scene.volumes) {
    if (!s.visible) continue;
    volume::ReadOptions o;
    o.field = s.field;
    if (s.frame) o.frame = frame_of(*s.frame, scene_file);
    volumes.push_back(volume::read_volume(s.file, o));
    styles.push_back(&s);
    if (needs_ground(volumes.back(), s)) {
      ground = true;
      const Box b = footprint(volumes.back(), frame);
      box = {std::min(box.south, b.south), std::max(box.north, b.north), std::min(box.west, b.west),
             std::max(box.east, b.east)};
    }
  }
  for (const ObjectStyle& o : scene.objects) {
    if (o.height) continue;
    ground = true;
    box = {std::min(box.south, o.lat), std::max(box.north, o.lat), std::min(box.west, o.lon), std::max(box.east, o.lon)};
  }
  std::unique_ptr<Dem> dem;
  if (ground) {
    if (scene.dems.empty()) throw std::runtime_error(scene_file.string() + ": volumes or objects need the ground and the scene names no DEM");
    dem = std::make_unique<Dem>(Dem::read(scene.dems, box));
  }

  Reference r;
  Mesh all;
  for (std::size_t v = 0; v < volumes.size(); ++v) {
    const Placement placement(volumes[v], frame, dem.get());
    for (const IsoStyle& iso : styles[v]->isosurfaces) append(all, isosurface(volumes[v], placement, iso));
    for (const SliceStyle& sl : styles[v]->slices) append(all, slice(volumes[v], placement, sl));
  }
  r.volume_triangles = all.triangle_count();
  for (const ObjectStyle& o : scene.objects) append(all, object(o, scene.sun, frame, dem.get()));
  r.object_triangles = all.triangle_count() - r.volume_triangles;
  r.drawn = read_drawn(vtp);
  texture_terrain(r.drawn, frame, stats.window);
  r.geometry_ms = ms_since(t0);
  const auto t1 = Clock::now();
  r.image = draw(r.drawn, all, stats.width, stats.height);
  r.draw_ms = ms_since(t1);
  return r;
}

Image read_png(const fs::path& png) {
  if (!fs::exists(png)) throw std::runtime_error(png.string() + ": no such file");
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(png.c_str())) throw std::runtime_error(png.string() + ": not a PNG file");
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  vtkDataArray* scalars = data->GetPointData()->GetScalars();
  if (scalars == nullptr || dims[0] <= 0 || dims[1] <= 0) throw std::runtime_error(png.string() + ": cannot decode");
  const int comps = scalars->GetNumberOfComponents();
  Image image;
  image.width = dims[0];
  image.height = dims[1];
  image.rgb.resize(static_cast<std::size_t>(dims[0]) * dims[1] * 3);
  for (int y = 0; y < dims[1]; ++y) {  // VTK's rows run from the bottom
    for (int x = 0; x < dims[0]; ++x) {
      const vtkIdType from = static_cast<vtkIdType>(y) * dims[0] + x;
      const std::size_t to = 3 * (static_cast<std::size_t>(dims[1] - 1 - y) * dims[0] + x);
      for (int c = 0; c < 3; ++c) {
        image.rgb[to + c] = static_cast<std::uint8_t>(scalars->GetComponent(from, comps >= 3 ? c : 0));
      }
    }
  }
  return image;
}

void write_png(const fs::path& png, const Image& image) {
  vtkNew<vtkImageData> data;
  data->SetDimensions(image.width, image.height, 1);
  data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* out = static_cast<std::uint8_t*>(data->GetScalarPointer());
  const std::size_t row = 3 * static_cast<std::size_t>(image.width);
  for (int y = 0; y < image.height; ++y)
    std::copy_n(image.rgb.data() + static_cast<std::size_t>(image.height - 1 - y) * row, row, out + y * row);
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(data);
  writer->SetFileName(png.c_str());
  writer->Write();
  if (writer->GetErrorCode() != 0) throw std::runtime_error(png.string() + ": cannot write");
}

namespace {
void check_same_size(const Image& a, const Image& b, int tolerance) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size()) {
    throw std::invalid_argument("images of " + std::to_string(a.width) + "x" + std::to_string(a.height) + " and " +
                                std::to_string(b.width) + "x" + std::to_string(b.height) + " pixels");
  }
  if (tolerance < 0) throw std::invalid_argument("negative tolerance " + std::to_string(tolerance));
}
bool within(const std::uint8_t* p, const std::uint8_t* q, int tolerance) {
  return std::abs(p[0] - q[0]) <= tolerance && std::abs(p[1] - q[1]) <= tolerance && std::abs(p[2] - q[2]) <= tolerance;
}
}  // namespace

double share_within(const Image& a, const Image& b, int tolerance) {
  check_same_size(a, b, tolerance);
  std::size_t good = 0;
  for (std::size_t i = 0; i < a.rgb.size(); i += 3) good += within(&a.rgb[i], &b.rgb[i], tolerance);
  return a.rgb.empty() ? 1.0 : static_cast<double>(good) / static_cast<double>(a.rgb.size() / 3);
}

Image difference_image(const Image& a, const Image& b, int tolerance) {
  check_same_size(a, b, tolerance);
  Image d = b;
  for (std::size_t i = 0; i < a.rgb.size(); i += 3) {
    if (within(&a.rgb[i], &b.rgb[i], tolerance)) {
      const auto grey = static_cast<std::uint8_t>(128 + (b.rgb[i] + b.rgb[i + 1] + b.rgb[i + 2]) / 6);
      d.rgb[i] = d.rgb[i + 1] = d.rgb[i + 2] = grey;
    } else {
      d.rgb[i] = 255, d.rgb[i + 1] = 0, d.rgb[i + 2] = 0;
    }
  }
  return d;
}

RenderRun run_render(const fs::path& exe, const fs::path& scene, const fs::path& dir, const std::string& name,
                     const std::vector<std::string>& extra, int timeout_s) {
  fs::create_directories(dir);
  RenderRun run;
  run.png = dir / (name + ".png");
  run.vtp = dir / (name + ".vtp");
  run.stats = dir / (name + ".json");
  run.log = dir / (name + ".log");
  // --no-markers: the reference draws the volumes' surfaces, not the transmitter masts.
  std::vector<std::string> args{exe.string(), "render", "--scene", scene.string(), "--full-res",
                                "--surface-triangles", "0", "--haze", "0", "--no-markers", "--export-vtp", run.vtp.string(),
                                "--stats", run.stats.string(), "-o", run.png.string(), "--force"};
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, run.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const auto t0 = Clock::now();
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error(exe.string() + ": cannot start (" + std::strerror(rc) + ")");
  int status = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0) throw std::runtime_error(exe.string() + " render: lost the process");
    if (ms_since(t0) > 1000.0 * timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      throw std::runtime_error(exe.string() + " render " + name + ": no result after " + std::to_string(timeout_s) + " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  run.seconds = ms_since(t0) / 1000.0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(exe.string() + " render " + name + " failed: " + last_line(run.log));
  }
  return run;
}

}  // namespace terravol::reference
