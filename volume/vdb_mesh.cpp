// Adaptive isosurfaces by OpenVDB (openvdb::tools::volumeToMesh; its adaptive meshing merges
// the dual-contouring quads of flat regions within each leaf node). The lattice becomes a
// float grid with the identity transform, so the mesh comes out in index space.
#include "volume/vdb_mesh.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>

namespace terravol::volume::detail {

namespace {

bool cell_has_nan(const Volume& v, int i, int j, int k) {
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        if (std::isnan(v.at(i + dx, j + dy, k + dz))) return true;
  return false;
}

// One volumeToMesh at `adaptivity`, polygons cut to the lattice and its non-NaN cells.
IndexMesh mesh_at(const Volume& volume, const openvdb::FloatGrid& grid, float value, double adaptivity,
                  bool has_nan) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, static_cast<double>(value), adaptivity);

  const auto& dims = volume.lattice.dims;
  std::vector<std::uint8_t> keep(points.size(), 1);
  for (std::size_t p = 0; p < points.size(); ++p) {
    std::array<int, 3> cell{};
    for (int a = 0; a < 3; ++a) {
      const float x = points[p][a];
      if (!(x >= 0.0f && x <= static_cast<float>(dims[a] - 1))) keep[p] = 0;
      cell[a] = std::clamp(static_cast<int>(std::floor(x)), 0, dims[a] - 2);
    }
    if (keep[p] && has_nan && cell_has_nan(volume, cell[0], cell[1], cell[2])) keep[p] = 0;
  }
  IndexMesh mesh;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> remap(points.size(), kUnused);
  auto vertex = [&](std::uint32_t p) {
    if (remap[p] == kUnused) {
      remap[p] = static_cast<std::uint32_t>(mesh.points.size());
      mesh.points.emplace_back(points[p][0], points[p][1], points[p][2]);
    }
    return remap[p];
  };
  auto at = [&](std::uint32_t p) { return glm::dvec3(points[p][0], points[p][1], points[p][2]); };
  // OpenVDB winds polygons with normals towards greater values, as ours do.
  auto triangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (!keep[a] || !keep[b] || !keep[c] || a == b || b == c || a == c) return;
    const glm::dvec3 n = glm::cross(at(b) - at(a), at(c) - at(a));
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return;
    mesh.triangles.insert(mesh.triangles.end(), {vertex(a), vertex(b), vertex(c)});
  };
  for (const auto& t : triangles) triangle(t[0], t[1], t[2]);
  for (const auto& q : quads) {
    const glm::dvec3 d02 = at(q[2]) - at(q[0]), d13 = at(q[3]) - at(q[1]);
    if (glm::dot(d02, d02) <= glm::dot(d13, d13)) {
      triangle(q[0], q[1], q[2]);
      triangle(q[0], q[2], q[3]);
    } else {
      triangle(q[0], q[1], q[3]);
      triangle(q[1], q[2], q[3]);
    }
  }
  return mesh;
}

}  // namespace

IndexMesh vdb_isosurface(const Volume& volume, float value, std::size_t max_triangles) {
  if (!std::isfinite(value)) throw std::invalid_argument(volume.name + ": the isovalue must be finite");
  const auto& dims = volume.lattice.dims;
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2) return {};
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });

  // NaN points take the isovalue (as for flying edges); their cells are dropped afterwards.
  const bool has_nan = std::any_of(volume.values.begin(), volume.values.end(), [](float x) { return std::isnan(x); });
  std::vector<float> patched;
  const float* data = volume.values.data();
  if (has_nan) {
    patched = volume.values;
    for (float& x : patched)
      if (std::isnan(x)) x = value;
    data = patched.data();
  }
  // Every lattice point active (no value equals the background), x fastest as Volume stores it.
  const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0), openvdb::Coord(dims[0] - 1, dims[1] - 1, dims[2] - 1));
  // Dense only reads through this pointer here (copyFromDense).
  const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, const_cast<float*>(data));
  auto grid = openvdb::FloatGrid::create(std::numeric_limits<float>::max());
  openvdb::tools::copyFromDense(dense, *grid, 0.0f);

  IndexMesh mesh = mesh_at(volume, *grid, value, 0.0, has_nan);
  if (max_triangles == 0 || mesh.triangles.size() / 3 <= max_triangles) return mesh;
  IndexMesh coarsest = mesh_at(volume, *grid, value, 1.0, has_nan);
  if (coarsest.triangles.size() / 3 > max_triangles) return coarsest;
  // Bisection on the adaptivity, to 1/64: the smallest that meets the budget.
  double lo = 0.0, hi = 1.0;
  while (hi - lo > 1.0 / 64.0) {
    const double mid = 0.5 * (lo + hi);
    IndexMesh m = mesh_at(volume, *grid, value, mid, has_nan);
    if (m.triangles.size() / 3 <= max_triangles) {
      hi = mid;
      coarsest = std::move(m);
    } else {
      lo = mid;
    }
  }
  return coarsest;
}

}  // namespace terravol::volume::detail
