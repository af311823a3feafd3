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

// Layers of points added on each side, and how far out (in cells) a point still belongs to the
// surface rather than to a lid: lid points lie at the outer layer (-2), the surface's own in the
// cells of the layers (-1.5 and -0.5 for an unmerged surface).
constexpr int kPad = 2;
constexpr float kLid = 1.75f;

// One volumeToMesh at `adaptivity`, polygons cut to the lattice and its non-NaN cells.
IndexMesh mesh_at(const Volume& volume, const openvdb::FloatGrid& grid, float value, double adaptivity,
                  bool has_nan) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, static_cast<double>(value), adaptivity);

  // Points more than kLid cells outside the lattice are the lids' and drop their polygons; the
  // others are clamped onto the lattice's box, so that the surface ends at its boundary as
  // flying edges' does (the polygons inside the padding become degenerate and are dropped).
  const auto& dims = volume.lattice.dims;
  std::vector<std::uint8_t> keep(points.size(), 1);
  for (std::size_t p = 0; p < points.size(); ++p) {
    std::array<int, 3> cell{};
    for (int a = 0; a < 3; ++a) {
      float& x = points[p][a];
      const float last = static_cast<float>(dims[a] - 1);
      if (!(x >= -kLid && x <= last + kLid)) keep[p] = 0;
      x = std::clamp(x, 0.0f, last);
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

  // The lattice, NaN points set to the isovalue (as for flying edges; their cells are dropped
  // afterwards), with two more layers of points on every side repeating the boundary values:
  // OpenVDB meshes against the grid's background outside the lattice, so without them every
  // region below the isovalue at the boundary would be closed by a lid. With them the lids
  // lie in the outermost layer, and the surface runs straight through the inner one.
  const int pad = kPad;
  const openvdb::CoordBBox box(openvdb::Coord(-pad, -pad, -pad),
                               openvdb::Coord(dims[0] - 1 + pad, dims[1] - 1 + pad, dims[2] - 1 + pad));
  const std::array<int, 3> n{dims[0] + 2 * pad, dims[1] + 2 * pad, dims[2] + 2 * pad};
  std::vector<float> padded(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  bool has_nan = false;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        float x = volume.at(std::clamp(i - pad, 0, dims[0] - 1), std::clamp(j - pad, 0, dims[1] - 1),
                            std::clamp(k - pad, 0, dims[2] - 1));
        if (std::isnan(x)) {
          has_nan = true;
          x = value;
        }
        padded[i + static_cast<std::size_t>(n[0]) * (j + static_cast<std::size_t>(n[1]) * k)] = x;
      }
  // Every point active (no value equals the background), x fastest as Volume stores it.
  const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, padded.data());
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
