// Isosurface reduction (reduction.h): vertex clustering by VTK's vtkBinnedDecimation
// (Rossignac and Borrel 1993) and vtkQuadricClustering (Lindstrom 2000), quadric decimation
// (decimate.cpp), contouring a coarser lattice, and OpenVDB's adaptive meshing (vdb_mesh.cpp).
//
// Bin widths for a budget: a surface of area A cut by cubes of width c meets about 1.5 A / c^2
// of them (1 for a surface along the axes, up to sqrt(3) obliquely), and a clustered mesh has
// about twice as many triangles as vertices, so the first width is c = sqrt(3 A / N); while the
// result has more than N triangles, c grows by sqrt(count / N) (plus 2%) and the clustering
// runs again (on the benchmark surfaces once or twice in all).
#include "volume/reduction.h"

#include <vtkBinnedDecimation.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkQuadricClustering.h>
#include <vtkStaticPointLocator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "volume/index_mesh.h"
#include "volume/vdb_mesh.h"
#include "volume/vtk_mesh.h"

namespace terravol::volume {

namespace {

constexpr std::array<std::pair<IsoReduction, std::string_view>, 5> kNames{{
    {IsoReduction::kClustering, "clustering"},
    {IsoReduction::kQuadricClustering, "quadric-clustering"},
    {IsoReduction::kQuadricDecimation, "decimation"},
    {IsoReduction::kCoarseLattice, "coarse"},
    {IsoReduction::kAdaptiveVdb, "vdb"},
}};

double area_of(const Mesh& m) {
  double a = 0.0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::dvec3 p = m.vertices[m.triangles[3 * t]];
    a += 0.5 * glm::length(glm::cross(m.vertices[m.triangles[3 * t + 1]] - p, m.vertices[m.triangles[3 * t + 2]] - p));
  }
  return a;
}

std::optional<glm::u8vec4> uniform_color(const Mesh& m) {
  if (m.colors.empty()) return std::nullopt;
  for (const glm::u8vec4& c : m.colors)
    if (c != m.colors.front()) return std::nullopt;
  return m.colors.front();
}

// One clustering of `poly` (points about the mesh's centre) in cubes of width `c` metres.
Mesh cluster_once(const Mesh& mesh, vtkPolyData* poly, const glm::dvec3& centre, double c, bool quadric,
                  std::optional<glm::u8vec4> uniform) {
  double b[6];
  poly->GetBounds(b);
  int divisions[3];
  for (int a = 0; a < 3; ++a) {
    divisions[a] = static_cast<int>(std::clamp(std::ceil((b[2 * a + 1] - b[2 * a]) / c), 1.0, 1e5));
  }
  if (!quadric) {
    vtkNew<vtkBinnedDecimation> cluster;
    cluster->SetInputData(poly);
    cluster->AutoAdjustNumberOfDivisionsOff();
    cluster->SetNumberOfDivisions(divisions);
    cluster->SetPointGenerationModeToBinAverages();
    cluster->SetProducePointData(!uniform);
    cluster->Update();
    return detail::from_polydata(cluster->GetOutput(), centre, uniform);
  }
  vtkNew<vtkQuadricClustering> cluster;
  cluster->SetInputData(poly);
  cluster->AutoAdjustNumberOfDivisionsOff();
  cluster->SetNumberOfDivisions(divisions);
  cluster->Update();
  vtkPolyData* out = cluster->GetOutput();
  if (uniform) return detail::from_polydata(out, centre, uniform);
  // vtkQuadricClustering makes no point data: take the nearest input vertex's colour.
  Mesh result = detail::from_polydata(out, centre, glm::u8vec4(0));
  vtkNew<vtkStaticPointLocator> locator;
  locator->SetDataSet(poly);
  locator->BuildLocator();
  for (std::size_t k = 0; k < result.vertices.size(); ++k) {
    const glm::dvec3 p = result.vertices[k] - centre;
    const double x[3] = {p.x, p.y, p.z};
    result.colors[k] = mesh.colors[static_cast<std::size_t>(locator->FindClosestPoint(x))];
  }
  return result;
}

Mesh cluster(const Mesh& mesh, std::size_t max_triangles, bool quadric) {
  const glm::dvec3 centre = detail::centre_of(mesh);
  const std::optional<glm::u8vec4> uniform = uniform_color(mesh);
  const auto poly = detail::to_polydata(mesh, centre, /*colors=*/!uniform && !quadric);
  double c = std::sqrt(3.0 * area_of(mesh) / static_cast<double>(max_triangles));
  for (int attempt = 0;; ++attempt) {
    Mesh m = cluster_once(mesh, poly, centre, c, quadric, uniform);
    if (m.triangle_count() <= max_triangles || attempt == 20) return m;
    c *= std::sqrt(static_cast<double>(m.triangle_count()) / static_cast<double>(max_triangles)) * 1.02;
  }
}

// Every f-th point of each lattice axis, and the last: lattice coordinate of coarse point c.
struct Coarsening {
  int f;
  std::array<int, 3> fine_dims, dims;

  Coarsening(int factor, const std::array<int, 3>& fine) : f(factor), fine_dims(fine) {
    for (int a = 0; a < 3; ++a) dims[a] = fine[a] < 2 ? fine[a] : std::max(2, (fine[a] - 1 + f - 1) / f + 1);
  }
  int fine(int axis, int c) const { return std::min(c * f, fine_dims[axis] - 1); }
  // A fractional coarse coordinate to the fine lattice (linear between the two coarse points,
  // as flying edges interpolates along the coarse edge).
  double fine(int axis, double c) const {
    const int c0 = std::clamp(static_cast<int>(std::floor(c)), 0, std::max(0, dims[axis] - 2));
    const double t = c - c0;
    return fine(axis, c0) + t * (fine(axis, std::min(c0 + 1, dims[axis] - 1)) - fine(axis, c0));
  }
};

Mesh coarse_isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba, int f) {
  const Coarsening c(f, volume.lattice.dims);
  Volume coarse;
  coarse.name = volume.name;
  coarse.lattice.dims = c.dims;
  coarse.values.resize(coarse.lattice.size());
  for (int k = 0; k < c.dims[2]; ++k)
    for (int j = 0; j < c.dims[1]; ++j)
      for (int i = 0; i < c.dims[0]; ++i)
        coarse.values[coarse.lattice.index(i, j, k)] = volume.at(c.fine(0, i), c.fine(1, j), c.fine(2, k));
  detail::IndexMesh m = detail::flying_edges(coarse, value);
  for (glm::dvec3& p : m.points) p = {c.fine(0, p.x), c.fine(1, p.y), c.fine(2, p.z)};
  return detail::to_scene(std::move(m), mapper, rgba);
}

Mesh coarse_lattice(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba,
                    std::size_t max_triangles) {
  int f = 2;
  Mesh m = coarse_isosurface(volume, mapper, value, rgba, f);
  if (m.triangle_count() * 4 <= max_triangles) {  // the full surface may fit: about 4x as many
    Mesh full = isosurface(volume, mapper, value, rgba);
    if (full.triangle_count() <= max_triangles) return full;
    return m;
  }
  while (m.triangle_count() > max_triangles) {
    const double ratio = std::sqrt(static_cast<double>(m.triangle_count()) / static_cast<double>(max_triangles));
    const int next = std::max(f + 1, static_cast<int>(std::ceil(f * ratio)));
    if (Coarsening(next, volume.lattice.dims).dims == Coarsening(f, volume.lattice.dims).dims) {
      return cluster(m, max_triangles, false);  // the lattice cannot get coarser
    }
    f = next;
    m = coarse_isosurface(volume, mapper, value, rgba, f);
  }
  return m;
}

}  // namespace

std::string_view reduction_name(IsoReduction method) {
  for (const auto& [m, name] : kNames)
    if (m == method) return name;
  return "?";
}

std::optional<IsoReduction> reduction_by_name(std::string_view name) {
  for (const auto& [m, n] : kNames)
    if (n == name) return m;
  return std::nullopt;
}

Mesh reduce(const Mesh& mesh, std::size_t max_triangles, IsoReduction method) {
  if (method == IsoReduction::kCoarseLattice || method == IsoReduction::kAdaptiveVdb) {
    throw std::invalid_argument("reduction '" + std::string(reduction_name(method)) +
                                "' works on the volume, not on a mesh (use reduced_isosurface)");
  }
  if (max_triangles == 0 || mesh.triangle_count() <= max_triangles) return mesh;
  switch (method) {
    case IsoReduction::kClustering:
      return cluster(mesh, max_triangles, false);
    case IsoReduction::kQuadricClustering:
      return cluster(mesh, max_triangles, true);
    default:
      return decimate(mesh, max_triangles);
  }
}

Mesh reduced_isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba,
                        std::size_t max_triangles, IsoReduction method) {
  if (!std::isfinite(value)) throw std::invalid_argument(volume.name + ": the isovalue must be finite");
  if (max_triangles == 0) return isosurface(volume, mapper, value, rgba);
  switch (method) {
    case IsoReduction::kCoarseLattice:
      return coarse_lattice(volume, mapper, value, rgba, max_triangles);
    case IsoReduction::kAdaptiveVdb: {
      Mesh m = detail::to_scene(detail::vdb_isosurface(volume, value, max_triangles), mapper, rgba);
      return m.triangle_count() <= max_triangles ? m : cluster(m, max_triangles, false);
    }
    default:
      return reduce(isosurface(volume, mapper, value, rgba), max_triangles, method);
  }
}

}  // namespace terravol::volume
