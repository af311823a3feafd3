// terravol_geometry_bench: the cost and the error of volume geometry on a real volume, with
// medians over repetitions (CPU time of the process, all threads, since the machine is shared;
// wall time beside it). No rendering and no tree: this measures volume/ alone.
//
// - Isosurfaces: the full flying-edges surface, then each reduction of reduction.h to the
//   budget, with its triangle count and its distance to the full surface, sampled on both
//   (area-weighted random points and every vertex of the reduced surface, distances to the
//   other surface by vtkStaticCellLocator): the mean of both directions, the 99th and 99.9th
//   percentiles and the largest (the symmetric Hausdorff distance of the samples), in metres.
// - Slices: slice() (the exact sheet) and textured_slice() at several tolerances.
//
// Usage: terravol_geometry_bench VOLUME [--frame FRAME] [--dem DEM] [--iso V]... [--slice SPEC]...
//        [--max-triangles N] [--repeat N] [--samples N] [--methods LIST]
// Prints one JSON object per line (one per measured item).
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticCellLocator.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "io/dem_file.h"
#include "io/error.h"
#include "volume/geometry.h"
#include "volume/propagation.h"
#include "volume/readers.h"
#include "volume/reduction.h"
#include "volume/textured_slice.h"

namespace {

using namespace terravol;

double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}
double wall_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Timing {
  std::vector<double> cpu, wall;
  static double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  }
  std::string json() const {
    char b[200];
    std::snprintf(b, sizeof b, "\"cpu_ms\": %.1f, \"cpu_ms_min\": %.1f, \"cpu_ms_max\": %.1f, \"wall_ms\": %.1f", median(cpu),
                  *std::min_element(cpu.begin(), cpu.end()), *std::max_element(cpu.begin(), cpu.end()), median(wall));
    return b;
  }
};

// Runs f `repeat` times; returns the last result and the timings.
template <class F>
auto timed(int repeat, Timing& t, F f) {
  decltype(f()) result{};
  for (int r = 0; r < repeat; ++r) {
    const double c0 = cpu_ms(), w0 = wall_ms();
    result = f();
    t.cpu.push_back(cpu_ms() - c0);
    t.wall.push_back(wall_ms() - w0);
  }
  return result;
}

// A surface for distance queries.
class Surface {
 public:
  explicit Surface(const volume::Mesh& m) : mesh_(m) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    for (const auto& v : m.vertices) points->InsertNextPoint(v.x - origin().x, v.y - origin().y, v.z - origin().z);
    vtkNew<vtkCellArray> cells;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const vtkIdType ids[3] = {m.triangles[3 * t], m.triangles[3 * t + 1], m.triangles[3 * t + 2]};
      cells->InsertNextCell(3, ids);
    }
    poly_->SetPoints(points);
    poly_->SetPolys(cells);
    locator_->SetDataSet(poly_);
    locator_->BuildLocator();
  }
  glm::dvec3 origin() const { return mesh_.vertices.empty() ? glm::dvec3(0) : mesh_.vertices.front(); }
  double distance(const glm::dvec3& p) const {
    const glm::dvec3 q = p - origin();
    double x[3] = {q.x, q.y, q.z}, closest[3], d2 = 0.0;
    vtkIdType cell = 0;
    int sub = 0;
    locator_->FindClosestPoint(x, closest, cell, sub, d2);
    return std::sqrt(d2);
  }
  // Area-weighted random points, and (with `vertices`) every vertex.
  std::vector<glm::dvec3> samples(std::size_t n, unsigned seed, bool vertices) const {
    std::vector<double> cumulative;
    double total = 0.0;
    for (std::size_t t = 0; t < mesh_.triangle_count(); ++t) {
      total += glm::length(glm::cross(b(t) - a(t), c(t) - a(t)));
      cumulative.push_back(total);
    }
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<glm::dvec3> out;
    for (std::size_t k = 0; k < n && total > 0.0; ++k) {
      const auto t = static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * total) - cumulative.begin());
      double r1 = u(rng), r2 = u(rng);
      if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
      const std::size_t tt = std::min(t, mesh_.triangle_count() - 1);
      out.push_back(a(tt) + r1 * (b(tt) - a(tt)) + r2 * (c(tt) - a(tt)));
    }
    if (vertices) out.insert(out.end(), mesh_.vertices.begin(), mesh_.vertices.end());
    return out;
  }

 private:
  glm::dvec3 a(std::size_t t) const { return mesh_.vertices[mesh_.triangles[3 * t]]; }
  glm::dvec3 b(std::size_t t) const { return mesh_.vertices[mesh_.triangles[3 * t + 1]]; }
  glm::dvec3 c(std::size_t t) const { return mesh_.vertices[mesh_.triangles[3 * t + 2]]; }
  const volume::Mesh& mesh_;
  vtkNew<vtkPolyData> poly_;
  vtkNew<vtkStaticCellLocator> locator_;
};

struct Distances {
  double mean = 0, p99 = 0, p999 = 0, max = 0;
};
Distances distances(const Surface& full, const Surface& reduced, std::size_t n) {
  std::vector<double> d;
  double sum_full = 0.0, sum_reduced = 0.0;
  const auto on_full = full.samples(n, 1, false), on_reduced = reduced.samples(n, 2, true);
  for (const auto& p : on_full) {
    d.push_back(reduced.distance(p));
    sum_full += d.back();
  }
  for (const auto& p : on_reduced) {
    d.push_back(full.distance(p));
    sum_reduced += d.back();
  }
  std::sort(d.begin(), d.end());
  Distances r;
  if (d.empty()) return r;
  r.mean = 0.5 * (sum_full / std::max<std::size_t>(1, on_full.size()) + sum_reduced / std::max<std::size_t>(1, on_reduced.size()));
  r.p99 = d[d.size() * 99 / 100];
  r.p999 = d[d.size() * 999 / 1000];
  r.max = d.back();
  return r;
}

volume::GroundFunction bilinear_ground(const io::Grid& g) {
  return [&g](double lat, double lon) { return volume::dem_height(g, lat, lon); };
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, frame_text, dem_path, methods_text = "collapse,full-collapse,sloppy,quadric-clustering,decimation,coarse,vdb";
  std::vector<float> isos;
  std::vector<std::string> slices;
  std::size_t max_triangles = 12000, samples = 20000;
  int repeat = 5;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    auto next = [&]() -> std::string {
      if (a + 1 >= argc) {
        std::fprintf(stderr, "terravol_geometry_bench: %s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++a];
    };
    if (arg == "--frame") frame_text = next();
    else if (arg == "--dem") dem_path = next();
    else if (arg == "--iso") isos.push_back(std::stof(next()));
    else if (arg == "--slice") slices.push_back(next());
    else if (arg == "--max-triangles") max_triangles = std::stoul(next());
    else if (arg == "--repeat") repeat = std::stoi(next());
    else if (arg == "--samples") samples = std::stoul(next());
    else if (arg == "--methods") methods_text = next();
    else if (!arg.empty() && arg[0] != '-' && file.empty()) file = arg;
    else {
      std::fprintf(stderr, "terravol_geometry_bench: unknown argument '%s'\n", arg.c_str());
      return 2;
    }
  }
  if (file.empty() || repeat < 1) {
    std::fprintf(stderr,
                 "usage: terravol_geometry_bench VOLUME [--frame FRAME] [--dem DEM] [--iso V]... [--slice SPEC]... "
                 "[--max-triangles N] [--repeat N] [--samples N] [--methods LIST]\n");
    return 2;
  }
  try {
    std::vector<volume::IsoReduction> methods;
    for (std::size_t s = 0; s <= methods_text.size();) {
      const std::size_t e = std::min(methods_text.find(',', s), methods_text.size());
      const auto m = volume::reduction_by_name(methods_text.substr(s, e - s));
      if (!m) throw std::invalid_argument("unknown method '" + methods_text.substr(s, e - s) + "'");
      methods.push_back(*m);
      s = e + 1;
    }
    volume::ReadOptions read;
    if (!frame_text.empty()) read.frame = volume::parse_frame(frame_text);
    const volume::Volume v = volume::read_volume(file, read);
    io::Grid dem;
    volume::GroundFunction ground;
    if (!dem_path.empty()) {
      dem = io::read_dem(dem_path);
      ground = bilinear_ground(dem);
    }
    const volume::LatticeMapper flat(v, io::SceneFrame(0, 0), [](double, double) { return 0.0; });
    const auto& d = v.lattice.dims;
    const io::Geodetic c = flat.geodetic(0.5 * (d[0] - 1), 0.5 * (d[1] - 1), 0);
    const io::SceneFrame frame(c.lat, c.lon);
    const volume::LatticeMapper mapper(v, frame, ground);
    auto length = [&](double i, double j, double k, double i2, double j2, double k2) {
      const io::ScenePoint p = mapper.scene(i, j, k), q = mapper.scene(i2, j2, k2);
      return std::hypot(p.x - q.x, p.y - q.y, p.z - q.z);
    };
    const double ci = 0.5 * (d[0] - 1), cj = 0.5 * (d[1] - 1);
    std::printf("{\"volume\": \"%s\", \"dims\": [%d, %d, %d], \"cell_m\": [%.1f, %.1f, %.1f]}\n", file.c_str(), d[0], d[1], d[2],
                length(ci, cj, 0, ci + 1, cj, 0), length(ci, cj, 0, ci, cj + 1, 0), length(ci, cj, 0, ci, cj, 1));
    const glm::u8vec4 rgba(255, 200, 0, 128);
    for (float iso : isos) {
      Timing t_full;
      const volume::Mesh full = timed(repeat, t_full, [&] { return volume::isosurface(v, mapper, iso, rgba); });
      std::printf("{\"iso\": %g, \"method\": \"full\", \"triangles\": %zu, %s}\n", iso, full.triangle_count(), t_full.json().c_str());
      if (full.empty()) continue;
      const Surface full_surface(full);
      for (volume::IsoReduction m : methods) {
        // Decimation takes seconds: fewer repetitions.
        const int r = m == volume::IsoReduction::kQuadricDecimation ? std::min(repeat, 3) : repeat;
        Timing t;
        const volume::Mesh reduced =
            timed(r, t, [&] { return volume::reduced_isosurface(v, mapper, iso, rgba, max_triangles, m); });
        // The reduction alone, for the mesh methods (the extraction is the "full" line).
        std::string alone;
        if (m != volume::IsoReduction::kCoarseLattice && m != volume::IsoReduction::kAdaptiveVdb) {
          Timing t2;
          timed(r, t2, [&] { return volume::reduce(full, max_triangles, m); });
          alone = ", \"reduce_cpu_ms\": " + std::to_string(Timing::median(t2.cpu));
        }
        const Distances e = reduced.empty() ? Distances{} : distances(full_surface, Surface(reduced), samples);
        std::printf("{\"iso\": %g, \"method\": \"%s\", \"triangles\": %zu, %s%s, \"mean_m\": %.2f, \"p99_m\": %.2f, "
                    "\"p999_m\": %.2f, \"max_m\": %.2f}\n",
                    iso, std::string(volume::reduction_name(m)).c_str(), reduced.triangle_count(), t.json().c_str(),
                    alone.c_str(), e.mean, e.p99, e.p999, e.max);
        std::fflush(stdout);
      }
    }
    for (const std::string& text : slices) {
      const volume::SliceSpec spec = volume::parse_slice(text);
      Timing t_exact;
      const volume::Mesh exact = timed(repeat, t_exact, [&] { return volume::slice(v, mapper, spec, ground); });
      std::printf("{\"slice\": \"%s\", \"method\": \"exact\", \"triangles\": %zu, %s}\n", text.c_str(), exact.triangle_count(),
                  t_exact.json().c_str());
      // The distance of every exact vertex from the simplified sheet: mean and largest.
      auto sheet_error = [&](const volume::Mesh& simplified) {
        const Surface surface(simplified);
        double sum = 0.0, worst = 0.0;
        for (const glm::dvec3& p : exact.vertices) {
          const double e = surface.distance(p);
          sum += e;
          worst = std::max(worst, e);
        }
        char b[96];
        std::snprintf(b, sizeof b, "\"mean_m\": %.2f, \"max_m\": %.2f", sum / std::max<std::size_t>(1, exact.vertices.size()), worst);
        return std::string(b);
      };
      for (double tol : {0.5, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0}) {
        volume::SheetOptions o;
        o.tolerance_m = tol;
        Timing t;
        const volume::TexturedMesh m = timed(repeat, t, [&] { return volume::textured_slice(v, mapper, spec, ground, o); });
        std::printf("{\"slice\": \"%s\", \"method\": \"textured\", \"tolerance_m\": %g, \"triangles\": %zu, \"texture\": [%d, %d], %s, %s}\n",
                    text.c_str(), tol, m.mesh.triangle_count(), m.width, m.height, t.json().c_str(), sheet_error(m.mesh).c_str());
      }
      for (std::size_t cap : {4000, 8000, 12000}) {
        volume::SheetOptions capped;
        capped.max_triangles = cap;
        Timing t;
        const volume::TexturedMesh m = timed(repeat, t, [&] { return volume::textured_slice(v, mapper, spec, ground, capped); });
        std::printf("{\"slice\": \"%s\", \"method\": \"textured\", \"cap\": %zu, \"tolerance_m\": %.1f, \"triangles\": %zu, %s, %s}\n",
                    text.c_str(), cap, m.tolerance_m, m.mesh.triangle_count(), t.json().c_str(), sheet_error(m.mesh).c_str());
      }
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol_geometry_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
