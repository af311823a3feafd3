// Isosurface reduction (reduction.h): edge collapse and grid clustering by meshoptimizer
// (A. Kapoulkine; meshopt_simplify follows M. Garland and P. S. Heckbert, "Surface
// simplification using quadric error metrics", SIGGRAPH 1997), vertex clustering by VTK's
// vtkQuadricClustering (P. Lindstrom, "Out-of-core simplification of large polygonal models",
// SIGGRAPH 2000), quadric decimation (decimate.cpp), contouring a coarser lattice, and
// OpenVDB's adaptive meshing (vdb_mesh.cpp).
//
// Bin widths for vtkQuadricClustering's budget: a surface of area A cut by cubes of width c
// meets about 1.5 A / c^2 of them (1 for a surface along the axes, up to sqrt(3) obliquely),
// and a clustered mesh has about twice as many triangles as vertices, so the first width is
// c = sqrt(3 A / N); while the result has more than N triangles, c grows by sqrt(count / N)
// (plus 2%) and the clustering runs again, and a result under 85% of N is tried once more
// with finer bins (two or three runs in all on the benchmark surfaces).
#include "volume/reduction.h"

#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkQuadricClustering.h>
#include <vtkStaticPointLocator.h>

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "volume/index_mesh.h"
#include "volume/vdb_mesh.h"
#include "volume/vtk_mesh.h"

namespace terravol::volume {

namespace {

constexpr std::array<std::pair<IsoReduction, std::string_view>, 7> kNames{{
    {IsoReduction::kCollapse, "collapse"},
    {IsoReduction::kFullCollapse, "full-collapse"},
    {IsoReduction::kSloppy, "sloppy"},
    {IsoReduction::kQuadricClustering, "quadric-clustering"},
    {IsoReduction::kQuadricDecimation, "decimation"},
    {IsoReduction::kCoarseLattice, "coarse"},
    {IsoReduction::kAdaptiveVdb, "vdb"},
}};

// kCollapse first clusters surfaces of more than kPrecluster * N triangles down to that many.
constexpr std::size_t kPrecluster = 4;

double area_of(const Mesh& m) {
  double a = 0.0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::dvec3 p = m.vertices[m.triangles[3 * t]];
    a += 0.5 * glm::length(glm::cross(m.vertices[m.triangles[3 * t + 1]] - p, m.vertices[m.triangles[3 * t + 2]] - p));
  }
  return a;
}

bool uniform_color(const Mesh& m) {
  for (const glm::u8vec4& c : m.colors)
    if (c != m.colors.front()) return false;
  return true;
}

// One vtkQuadricClustering of `poly` (points about the mesh's centre) in cubes of width `c`
// metres. It makes no point data: each vertex takes the colour of the nearest input vertex.
Mesh cluster_once(const Mesh& mesh, vtkPolyData* poly, const glm::dvec3& centre, double c) {
  double b[6];
  poly->GetBounds(b);
  int divisions[3];
  for (int a = 0; a < 3; ++a) {
    divisions[a] = static_cast<int>(std::clamp(std::ceil((b[2 * a + 1] - b[2 * a]) / c), 1.0, 1e5));
  }
  vtkNew<vtkQuadricClustering> cluster;
  cluster->SetInputData(poly);
  cluster->AutoAdjustNumberOfDivisionsOff();
  cluster->SetNumberOfDivisions(divisions);
  cluster->Update();
  vtkPolyData* out = cluster->GetOutput();
  if (uniform_color(mesh)) return detail::from_polydata(out, centre, mesh.colors.front());
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

Mesh quadric_cluster(const Mesh& mesh, std::size_t max_triangles) {
  const glm::dvec3 centre = detail::centre_of(mesh);
  const auto poly = detail::to_polydata(mesh, centre, /*colors=*/false);
  const double n = static_cast<double>(max_triangles);
  double c = std::sqrt(3.0 * area_of(mesh) / n);
  std::optional<Mesh> best;
  for (int attempt = 0; attempt < 20; ++attempt) {
    Mesh m = cluster_once(mesh, poly, centre, c);
    const double count = static_cast<double>(m.triangle_count());
    if (count <= n) {
      const bool first = !best;
      if (!best || m.triangle_count() > best->triangle_count()) best = std::move(m);
      if (!first || count >= 0.85 * n || count == 0.0) return *best;
      c *= std::sqrt(count / n) * 1.01;  // well under the budget: once more with finer bins
    } else {
      if (best) return *best;
      c *= std::sqrt(count / n) * 1.02;
    }
  }
  return best ? *best : Mesh{};
}

// Positions as meshoptimizer takes them: floats about the mesh's centre.
std::vector<float> float_positions(const Mesh& mesh) {
  const glm::dvec3 centre = detail::centre_of(mesh);
  std::vector<float> positions;
  positions.reserve(3 * mesh.vertices.size());
  for (const glm::dvec3& v : mesh.vertices) {
    const glm::dvec3 p = v - centre;
    positions.insert(positions.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
  }
  return positions;
}

// The triangles `indices` of `mesh`'s vertices as a Mesh with the invariants.
Mesh compact(const Mesh& mesh, const std::vector<unsigned>& indices) {
  Mesh result;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> remap(mesh.vertices.size(), kUnused);
  auto vertex = [&](std::uint32_t i) {
    if (remap[i] == kUnused) {
      remap[i] = static_cast<std::uint32_t>(result.vertices.size());
      result.vertices.push_back(mesh.vertices[i]);
      result.colors.push_back(mesh.colors[i]);
    }
    return remap[i];
  };
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const std::uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a == b || b == c || a == c) continue;
    const glm::dvec3 n = glm::cross(mesh.vertices[b] - mesh.vertices[a], mesh.vertices[c] - mesh.vertices[a]);
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) continue;
    result.triangles.insert(result.triangles.end(), {vertex(a), vertex(b), vertex(c)});
  }
  return result;
}

// meshopt_simplifySloppy of `indices` to at most `target` triangles.
std::vector<unsigned> sloppy(const std::vector<unsigned>& indices, const std::vector<float>& positions,
                             std::size_t target) {
  std::vector<unsigned> out(indices.size());
  out.resize(meshopt_simplifySloppy(out.data(), indices.data(), indices.size(), positions.data(), positions.size() / 3,
                                    3 * sizeof(float), 3 * target, /*target_error=*/1.0f, nullptr));
  return out;
}

// The triangles of components of fewer than `small` triangles, and the others (union-find
// over the vertices).
std::pair<std::vector<unsigned>, std::vector<unsigned>> split_small_components(const std::vector<unsigned>& indices,
                                                                               std::size_t vertices, std::uint32_t small) {
  std::vector<std::uint32_t> parent(vertices);
  for (std::uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    parent[find(indices[t + 1])] = find(indices[t]);
    parent[find(indices[t + 2])] = find(indices[t]);
  }
  std::vector<std::uint32_t> size(vertices, 0);
  for (std::size_t t = 0; t < indices.size(); t += 3) ++size[find(indices[t])];
  std::pair<std::vector<unsigned>, std::vector<unsigned>> parts;
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    auto& to = size[find(indices[t])] < small ? parts.first : parts.second;
    to.insert(to.end(), {indices[t], indices[t + 1], indices[t + 2]});
  }
  return parts;
}

// meshopt_simplify's edge collapses to the budget, after clustering the surface to
// `precluster` triangles first when it has more (0: never). The clustering leaves components
// of under 256 triangles (closed blobs up to about 5 cells across) alone: it would collapse
// them to nothing. Collapses keep the topology, so they may stop short of the budget; the rest
// is then clustered.
Mesh collapse(const Mesh& mesh, std::size_t max_triangles, std::size_t precluster) {
  const std::vector<float> positions = float_positions(mesh);
  std::vector<unsigned> indices(mesh.triangles.begin(), mesh.triangles.end());
  if (precluster > 0 && indices.size() > 3 * precluster) {
    auto [small, big] = split_small_components(indices, mesh.vertices.size(), 256);
    if (small.size() < 3 * precluster) {
      const std::vector<unsigned> clustered = sloppy(big, positions, precluster - small.size() / 3);
      small.insert(small.end(), clustered.begin(), clustered.end());
      indices = std::move(small);
    }
  }
  if (indices.size() > 3 * max_triangles) {  // (meshoptimizer asserts that the target is below the count)
    std::vector<unsigned> out(indices.size());
    out.resize(meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(), mesh.vertices.size(),
                                3 * sizeof(float), 3 * max_triangles, /*target_error=*/1.0f, /*options=*/0, nullptr));
    indices = std::move(out);
  }
  if (indices.size() > 3 * max_triangles) indices = sloppy(indices, positions, max_triangles);
  return compact(mesh, indices);
}

Mesh sloppy(const Mesh& mesh, std::size_t max_triangles) {
  return compact(mesh, sloppy(std::vector<unsigned>(mesh.triangles.begin(), mesh.triangles.end()), float_positions(mesh),
                              max_triangles));
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
  if (m.triangle_count() * 3 <= max_triangles) {  // the full surface may fit: it has 3 to 5 times as many
    Mesh full = isosurface(volume, mapper, value, rgba);
    if (full.triangle_count() <= max_triangles) return full;
    return m;
  }
  while (m.triangle_count() > max_triangles) {
    const double ratio = std::sqrt(static_cast<double>(m.triangle_count()) / static_cast<double>(max_triangles));
    const int next = std::max(f + 1, static_cast<int>(std::ceil(f * ratio)));
    if (Coarsening(next, volume.lattice.dims).dims == Coarsening(f, volume.lattice.dims).dims) {
      return sloppy(m, max_triangles);  // the lattice cannot get coarser
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
    case IsoReduction::kCollapse:
      return collapse(mesh, max_triangles, kPrecluster * max_triangles);
    case IsoReduction::kFullCollapse:
      return collapse(mesh, max_triangles, 0);
    case IsoReduction::kSloppy:
      return sloppy(mesh, max_triangles);
    case IsoReduction::kQuadricClustering:
      return quadric_cluster(mesh, max_triangles);
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
      return m.triangle_count() <= max_triangles ? m : sloppy(m, max_triangles);
    }
    default:
      return reduce(isosurface(volume, mapper, value, rgba), max_triangles, method);
  }
}

}  // namespace terravol::volume
