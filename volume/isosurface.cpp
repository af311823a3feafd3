// Isosurfaces by VTK's flying edges (W. Schroeder, R. Maynard, B. Geveci, "Flying edges: A
// high-performance scalable isocontouring algorithm", IEEE LDAV 2015), run on the lattice in
// index space (origin 0, spacing 1) and mapped to the scene frame afterwards, so the frame
// (geographic, above ground, ENU) never enters the contouring.
//
// Departures from the plain filter output:
// - NaN points are replaced by a finite value before contouring (flying edges compares and
//   interpolates them otherwise), and every triangle in a cell with a NaN corner is dropped.
//   A triangle's cell is found from its centroid; when the centroid lies on a lattice plane
//   (a triangle in a cell face, possible when values equal the isovalue) both cells sharing
//   that plane are tested.
// - Flying edges makes one point per crossed lattice edge; where a point's value equals the
//   isovalue, the crossings of all its edges coincide. Coincident points are welded, and
//   triangles that become degenerate (repeated vertex or zero area) are dropped.
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "volume/geometry.h"
#include "volume/index_mesh.h"

namespace terravol::volume {

using detail::cell_has_nan;

namespace {

struct PointKey {
  float x, y, z;
  bool operator==(const PointKey&) const = default;
};

struct PointKeyHash {
  std::size_t operator()(const PointKey& k) const {
    auto bits = [](float f) {
      std::uint32_t u;
      static_assert(sizeof u == sizeof f);
      std::memcpy(&u, &f, sizeof u);
      return std::size_t{u};
    };
    return (bits(k.x) * 73856093u) ^ (bits(k.y) * 19349663u) ^ (bits(k.z) * 83492791u);
  }
};

// The cells a triangle with this centroid (index space) may lie in: one per axis, or the two
// either side of a lattice plane the centroid lies on.
bool triangle_touches_nan(const Volume& v, const std::array<double, 3>& centroid) {
  std::array<std::array<int, 2>, 3> cells{};
  std::array<int, 3> count{};
  for (int a = 0; a < 3; ++a) {
    const int last_cell = v.lattice.dims[a] - 2;
    const double c = centroid[a];
    const double r = std::round(c);
    auto clamp = [&](double x) { return std::clamp(static_cast<int>(x), 0, last_cell); };
    if (std::abs(c - r) < 1e-4) {
      cells[a][0] = clamp(r - 1.0);
      cells[a][1] = clamp(r);
      count[a] = cells[a][0] == cells[a][1] ? 1 : 2;
    } else {
      cells[a][0] = clamp(std::floor(c));
      count[a] = 1;
    }
  }
  for (int z = 0; z < count[2]; ++z)
    for (int y = 0; y < count[1]; ++y)
      for (int x = 0; x < count[0]; ++x)
        if (cell_has_nan(v, cells[0][x], cells[1][y], cells[2][z])) return true;
  return false;
}

}  // namespace

namespace detail {

bool cell_has_nan(const Volume& v, int i, int j, int k) {
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        if (std::isnan(v.at(i + dx, j + dy, k + dz))) return true;
  return false;
}

IndexMesh flying_edges(const Volume& volume, float value) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument(volume.name + ": the isovalue must be finite");
  }
  IndexMesh mesh;
  const auto& dims = volume.lattice.dims;
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2) return mesh;

  // The scalars, read in place when there is no NaN (the filter does not write its input).
  const bool has_nan = std::any_of(volume.values.begin(), volume.values.end(), [](float x) { return std::isnan(x); });
  std::vector<float> patched;
  float* data = const_cast<float*>(volume.values.data());
  if (has_nan) {
    patched = volume.values;
    for (float& x : patched)
      if (std::isnan(x)) x = value;
    data = patched.data();
  }
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("values");
  scalars->SetArray(data, static_cast<vtkIdType>(volume.values.size()), /*save=*/1);
  vtkNew<vtkImageData> image;
  image->SetDimensions(dims[0], dims[1], dims[2]);
  image->SetOrigin(0.0, 0.0, 0.0);
  image->SetSpacing(1.0, 1.0, 1.0);
  image->GetPointData()->SetScalars(scalars);

  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(image);
  contour->SetValue(0, value);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->InterpolateAttributesOff();
  contour->Update();
  vtkPolyData* poly = contour->GetOutput();
  vtkPoints* points = poly->GetPoints();
  vtkCellArray* polys = poly->GetPolys();
  if (points == nullptr || polys == nullptr || polys->GetNumberOfCells() == 0) return mesh;

  // Weld coincident points: weld[p] is the welded index of VTK point p.
  const vtkIdType n_points = points->GetNumberOfPoints();
  std::vector<std::uint32_t> weld(static_cast<std::size_t>(n_points));
  std::vector<std::array<double, 3>> unique;  // index space
  unique.reserve(static_cast<std::size_t>(n_points));
  std::unordered_map<PointKey, std::uint32_t, PointKeyHash> seen;
  seen.reserve(static_cast<std::size_t>(n_points));
  for (vtkIdType p = 0; p < n_points; ++p) {
    double x[3];
    points->GetPoint(p, x);
    const PointKey key{static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2])};
    const auto [it, inserted] = seen.try_emplace(key, static_cast<std::uint32_t>(unique.size()));
    if (inserted) unique.push_back({x[0], x[1], x[2]});
    weld[static_cast<std::size_t>(p)] = it->second;
  }

  // Keep the triangles that are not degenerate and not in a NaN cell.
  std::vector<std::uint32_t> kept;
  kept.reserve(static_cast<std::size_t>(polys->GetNumberOfCells()) * 3);
  vtkIdType n_ids = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(n_ids, ids);) {
    if (n_ids != 3) continue;  // flying edges emits triangles only
    const std::uint32_t t[3] = {weld[ids[0]], weld[ids[1]], weld[ids[2]]};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    const auto &a = unique[t[0]], &b = unique[t[1]], &c = unique[t[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) continue;
    if (has_nan && triangle_touches_nan(volume, {(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
                                                 (a[2] + b[2] + c[2]) / 3.0})) {
      continue;
    }
    // VTK's winding gives normals towards decreasing values; ours point towards increasing.
    kept.insert(kept.end(), {t[0], t[2], t[1]});
  }

  // Compact to the used vertices.
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> remap(unique.size(), kUnused);
  mesh.triangles.reserve(kept.size());
  for (std::uint32_t idx : kept) {
    if (remap[idx] == kUnused) {
      remap[idx] = static_cast<std::uint32_t>(mesh.points.size());
      const auto& p = unique[idx];
      mesh.points.emplace_back(p[0], p[1], p[2]);
    }
    mesh.triangles.push_back(remap[idx]);
  }
  return mesh;
}

Mesh to_scene(IndexMesh&& index_mesh, const LatticeMapper& mapper, glm::u8vec4 rgba) {
  Mesh mesh;
  mesh.vertices.reserve(index_mesh.points.size());
  for (const glm::dvec3& p : index_mesh.points) {
    const io::ScenePoint s = mapper.scene(p.x, p.y, p.z);
    mesh.vertices.emplace_back(s.x, s.y, s.z);
  }
  mesh.colors.assign(mesh.vertices.size(), rgba);
  mesh.triangles = std::move(index_mesh.triangles);
  return mesh;
}

}  // namespace detail

Mesh isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba) {
  return detail::to_scene(detail::flying_edges(volume, value), mapper, rgba);
}

}  // namespace terravol::volume
