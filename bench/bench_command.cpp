#include "bench/bench_command.h"

#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "app/output/sample_dem.h"
#include "app/render/terrain_renderer.h"
#include "bench/report.h"
#include "bench/stats.h"
#include "bench/suites.h"

namespace terravol::bench {

namespace {

struct BenchOptions {
  bool quick = false;
  std::filesystem::path out = "bench/results";
  std::filesystem::path data;
  std::vector<std::filesystem::path> dems;
  std::filesystem::path under_test;
  std::string exactness_views;
  std::string suites = "terrain,translucency,scaling,build,exactness,rf,objects,lowalt,aa,density";
  int views = 0, repeats = 0, frames = 0;
};

// The first line of `file` that starts with `key`, after the colon; empty when absent.
std::string proc_field(const char* file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) {
      const auto colon = line.find(':');
      std::string v = colon == std::string::npos ? "" : line.substr(colon + 1);
      v.erase(0, v.find_first_not_of(" \t"));
      return v;
    }
  return "";
}

// What draws the frames: the OpenGL renderer string of an offscreen VTK window.
std::string gl_renderer() {
  app::render::require_x_display();
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(16, 16);
  vtkNew<vtkRenderer> renderer;
  window->AddRenderer(renderer);
  window->Render();
  std::istringstream caps(window->ReportCapabilities());
  for (std::string line; std::getline(caps, line);)
    if (const auto at = line.find("OpenGL renderer string:"); at != std::string::npos) {
      std::string name = line.substr(line.find(':', at) + 1);
      name.erase(0, name.find_first_not_of(" \t"));
      return name;
    }
  return "unknown OpenGL renderer";
}

nlohmann::json machine() {
  const std::string kb = proc_field("/proc/meminfo", "MemTotal");
  return {{"cpu", proc_field("/proc/cpuinfo", "model name")},
          {"cores", static_cast<int>(std::thread::hardware_concurrency())},
          {"memory_gib", std::atof(kb.c_str()) / 1048576.0},
          {"renderer", gl_renderer()}};
}

std::string today() {
  const std::time_t now = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%d %H:%M", std::localtime(&now));
  return b;
}

std::set<std::string> parse_suites(const std::string& list) {
  static const std::set<std::string> known{"terrain", "translucency", "scaling", "build", "exactness", "rf", "objects", "lowalt", "aa", "density"};
  std::set<std::string> out;
  std::stringstream in(list);
  for (std::string s; std::getline(in, s, ',');) {
    if (!known.count(s)) {
      throw std::runtime_error("--suites " + list + ": unknown suite '" + s +
                               "' (terrain, translucency, scaling, build, exactness, rf, objects, lowalt, aa, density)");
    }
    out.insert(s);
  }
  if (out.empty()) throw std::runtime_error("--suites: empty list");
  return out;
}

void run_bench(const BenchOptions& o, const std::string& command) {
  const std::set<std::string> suites = parse_suites(o.suites);
  const auto t0 = Clock::now();
  BenchConfig c;
  c.views = o.quick ? 12 : 60;
  c.volume_views = o.quick ? 3 : 8;
  c.repeats = o.quick ? 2 : 3;
  c.plain_largest = !o.quick;
  c.quick = o.quick;
  c.flight_frames = o.frames ? o.frames : o.quick ? 100 : 1000;
  c.out = o.out;
  c.under_test = o.under_test;
  c.exactness_views = o.exactness_views;
  if (o.views) c.views = o.views;
  if (o.repeats) {
    c.repeats = o.repeats;
    c.volume_views = std::min(c.volume_views, o.views ? o.views : c.volume_views);
  }
  c.cache = o.out / "cache";
  c.log = [t0](const std::string& line) {
    std::fprintf(stderr, "[bench %6.0f s] %s\n", ms_since(t0) / 1000.0, line.c_str());
  };

  // The terrains: the user's DEMs as one terrain, else the shared data.
  std::filesystem::path data = o.data;
  if (data.empty()) {
    const char* env = std::getenv("TERRAVOL_SHARED_DATA");
    data = env ? env : "../shared/data";
  }
  std::vector<Terrain> real;
  std::vector<std::vector<volume::Transmitter>> transmitters;
  if (!o.dems.empty()) {
    for (const auto& d : o.dems)
      if (!std::filesystem::exists(d)) throw std::runtime_error(d.string() + ": no such file or folder");
    real.push_back({o.dems.front().stem().string(), o.dems, static_cast<int>(o.dems.size())});
  } else if (std::filesystem::is_directory(data / "dem")) {
    real.push_back({"n44w072", {data / "dem" / "N44W072.hgt"}, 1});
    transmitters.push_back(benchmark_transmitters("n44w072"));
    real.push_back({"utah", {data / "dem" / "utah_sdf"}, 6});
    transmitters.push_back(benchmark_transmitters("utah"));
  } else {
    c.log(data.string() + "/dem not found: the terrain, translucency and build suites are skipped "
          "(give --data or --dem)");
  }

  nlohmann::json results;
  results["date"] = today();
  results["command"] = command;
  results["quick"] = o.quick;
  results["width"] = c.width;
  results["height"] = c.height;
  results["repeats"] = c.repeats;
  results["machine"] = machine();
  std::vector<const Terrain*> exact;  // the terrains the exactness suite draws
  if (suites.count("exactness")) {
    std::set<std::string> unknown;
    std::stringstream in(c.exactness_views);
    for (std::string n; std::getline(in, n, ',');)
      if (!n.empty()) unknown.insert(n);
    for (const Terrain& t : real) {
      const std::vector<std::string> names = exactness_views(c, t.name);
      for (const std::string& n : names) {
        unknown.erase(n);
        unknown.erase(t.name + "-" + n);
      }
      if (!names.empty()) exact.push_back(&t);
    }
    if (!unknown.empty())
      throw std::runtime_error("--exactness-views: no view '" + *unknown.begin() + "' on these terrains");
  }
  if (suites.count("build"))
    for (const Terrain& t : real) results["build"].push_back(build_suite(c, t));
  if (suites.count("terrain"))
    for (const Terrain& t : real) results["terrain"].push_back(terrain_suite(c, t));
  if (suites.count("lowalt"))
    for (const Terrain& t : real) results["lowalt"].push_back(lowalt_suite(c, t));
  if (suites.count("translucency")) {
    for (std::size_t k = 0; k < transmitters.size(); ++k)
      results["translucency"].push_back(translucency_suite(c, real[k], transmitters[k]));
    const std::filesystem::path bundled = "data/dem/N45E006.hgt",
                                hydrogen = data / "volume" / "hydrogen.vtk";
    if (!std::filesystem::exists(bundled) || !std::filesystem::exists(hydrogen)) {
      c.log(bundled.string() + " or " + hydrogen.string() +
            " not found: the hydrogen.vtk figure is skipped");
    } else {
      c.log("translucency: hydrogen.vtk over the bundled DEM, five cameras");
      results["hydrogen"] = hydrogen_pieces(c, bundled, hydrogen);
    }
  }
  if (suites.count("exactness"))
    for (const Terrain& t : real) {
      if (std::find(exact.begin(), exact.end(), &t) != exact.end()) {
        results["exactness"].push_back(exactness_suite(c, t));
      } else if (has_exactness_scene(t.name)) {
        c.log("exactness: no view selected on " + t.name);
      } else {
        c.log("exactness: no scene for " + t.name + " (only the shared N44W072 and Utah terrains have one)");
      }
    }
  if (suites.count("aa")) {
    if (real.empty()) {
      c.log("aa: no terrain (give --data or --dem): skipped");
    } else {
      results["aa"] = aa_suite(c, real.front(), transmitters.empty() ? std::vector<volume::Transmitter>{} : transmitters.front());
    }
  }
  if (suites.count("objects")) {
    const std::filesystem::path models = "/usr/share/assimp/models";
    const auto truck = models / "glTF/CesiumMilkTruck/CesiumMilkTruck.gltf", wuson = models / "PLY/Wuson.ply";
    if (!std::filesystem::exists(truck) || !std::filesystem::exists(wuson)) {
      c.log("assimp-testmodels is not installed: the objects suite is skipped (apt-get install assimp-testmodels)");
    } else if (real.empty() || real.front().name != "n44w072") {
      c.log("objects: the suite draws over the shared N44W072 tile, which is absent: skipped");
    } else {
      results["objects"] = object_suite(c, real.front(), truck, wuson);
    }
  }
  if (suites.count("density")) {
    // The bundled DEM, as the project's scripts make it (scripts/setup-and-run.sh).
    const std::filesystem::path bundled = "data/dem/N45E006.hgt";
    if (!std::filesystem::exists(bundled)) {
      c.log(bundled.string() + " not found (run from the project root; terravol sample-dem -o data/dem makes it): the density suite is skipped");
    } else {
      results["density"] = density_suite(c, Terrain{"n45e006", {bundled}, 1});
    }
  }
  if (suites.count("scaling")) {
    // One tile, the six Utah tiles when there, and 16 tiles of the project's own generator.
    const auto tiles = c.cache / "tiles";
    std::vector<std::filesystem::path> all;
    if (!std::filesystem::exists(tiles / "N48E009.hgt")) {
      c.log("writing 16 generated tiles into " + tiles.string());
      all = app::output::write_sample_dem(tiles, 4, 4, true);
    } else {
      for (int r = 0; r < 4; ++r)
        for (int col = 0; col < 4; ++col) {
          char name[16];
          std::snprintf(name, sizeof name, "N%02dE%03d.hgt", 45 + r, 6 + col);
          all.push_back(tiles / name);
        }
    }
    // all: rows from N45 north, columns from E006 east; the 2 x 2 block is the south-west one.
    std::vector<Terrain> sizes{{"generated-1", {all[0]}, 1}, {"generated-4", {all[0], all[1], all[4], all[5]}, 4}};
    if (std::filesystem::is_directory(data / "dem" / "utah_sdf")) sizes.push_back({"utah-6", {data / "dem" / "utah_sdf"}, 6});
    sizes.push_back({"generated-16", all, 16});
    results["scaling"] = scaling_suite(c, sizes);
  }
  if (suites.count("rf")) {
    if (std::filesystem::is_directory(data / "dem" / "utah_sdf")) {
      volume::Transmitter t = transmitter(40.76, -111.89, 30);
      t.frequency_mhz = 900.0;
      results["rf"] = rf_suite(c, data / "dem" / "utah_sdf", t, o.quick ? 2 : 3);
    } else {
      c.log(data.string() + "/dem/utah_sdf not found: the rf suite is skipped");
    }
  }
  results["seconds"] = ms_since(t0) / 1000.0;
  write_report(results, o.out);
  c.log("wrote " + (o.out / "report.md").string() + " and " + (o.out / "results.json").string());
  std::printf("%s", headline(results).c_str());
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* cmd = app.add_subcommand("bench", "Run the standing benchmarks and write a JSON and Markdown report with plots");
  cmd->add_flag("--quick", o->quick, "A few minutes: 12 views, 3 orbit views, 2 repetitions, a 100-frame low flight, no plain VTK on the largest terrain");
  cmd->add_option("-o,--output-dir", o->out, "Folder for results.json, report.md and the plots (and cache/)")->capture_default_str();
  cmd->add_option("--data", o->data, "The shared data folder (with dem/); default $TERRAVOL_SHARED_DATA or ../shared/data");
  cmd->add_option("--dem", o->dems, "Benchmark these DEM files as one terrain instead of the shared ones");
  cmd->add_option("--suites", o->suites, "Comma-separated: terrain, translucency, scaling, build, exactness, rf, objects, lowalt, aa, density")->capture_default_str();
  cmd->add_option("--under-test", o->under_test,
                  "The terravol executable whose render the exactness suite measures (default: this one)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--exactness-views", o->exactness_views,
                  "Exactness: only these views, comma-separated VIEW or TERRAIN-VIEW (e.g. n44w072-inside)");
  cmd->add_option("--views", o->views, "Views of each terrain flythrough (default 60, quick 12)")->check(CLI::Range(1, 10000));
  cmd->add_option("--frames", o->frames, "Frames of the low-altitude suite's flight (default 1000, quick 100)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--repeats", o->repeats, "Timed repetitions per frame (default 3, quick 2)")->check(CLI::Range(1, 100));
  cmd->callback([o] {
    std::string command = "terravol bench";  // as given, for the report
    if (o->quick) command += " --quick";
    if (o->suites != BenchOptions{}.suites) command += " --suites " + o->suites;
    if (o->views) command += " --views " + std::to_string(o->views);
    if (o->repeats) command += " --repeats " + std::to_string(o->repeats);
    if (o->frames) command += " --frames " + std::to_string(o->frames);
    for (const auto& d : o->dems) command += " --dem " + d.string();
    if (!o->under_test.empty()) command += " --under-test " + o->under_test.string();
    if (!o->exactness_views.empty()) command += " --exactness-views " + o->exactness_views;
    run_bench(*o, command);
  });
}

}  // namespace terravol::bench
