// Isosurfaces reduced to a triangle budget fast enough for an interaction (an isovalue change
// re-extracts and re-merges one surface). The methods, their cost and their error on real
// volumes are compared in docs/architecture.md ("Volume geometry"); the figures below are from
// there (RelWithDebInfo, CPU time on the shared 2-core machine, a 200k-triangle surface
// reduced to 12,000 triangles, errors against the full flying-edges surface).
#pragma once

#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "volume/geometry.h"

namespace terravol::volume {

enum class IsoReduction : std::uint8_t {
  // Vertex clustering (J. Rossignac and P. Borrel, "Multi-resolution 3D approximations for
  // rendering complex scenes", 1993) by vtkBinnedDecimation: the full surface's vertices
  // binned in cubes, one vertex per bin at the mean of its vertices (colours averaged too),
  // triangles with two vertices in one bin dropped. Linear time. Every vertex moves at most a
  // bin diagonal, so the surface stays within sqrt(3) bin widths of the full one; the bin width
  // is chosen for the budget (see reduce()).
  kClustering,
  // Vertex clustering with each bin's vertex placed where it minimises the bin's quadric error
  // (P. Lindstrom, "Out-of-core simplification of large polygonal models", SIGGRAPH 2000) by
  // vtkQuadricClustering. Colours: the nearest full-surface vertex's.
  kQuadricClustering,
  // Edge collapse by quadric error (decimate(), vtkQuadricDecimation). The most accurate for
  // the count and by far the slowest (seconds for 200k triangles).
  kQuadricDecimation,
  // Flying edges on every f-th lattice point along each axis (f = 2, 3, ...: the smallest that
  // meets the budget), the last point of each axis always kept so the surface still reaches the
  // lattice's boundary. No full-resolution surface is made, so it is the cheapest; the error is
  // that of contouring a lattice f times coarser (features under f cells are lost).
  kCoarseLattice,
  // OpenVDB's adaptive dual contouring (openvdb::tools::volumeToMesh with an adaptivity in
  // [0, 1], the smallest that meets the budget, found by bisection): quads merged within each
  // 8^3 leaf node where the surface is flat. Its vertices lie inside lattice cells, not on
  // their edges; polygons reaching the outermost cells are dropped, so the surface stops up to
  // a cell short of the lattice boundary. When even adaptivity 1 exceeds the budget, the
  // result is clustered (kClustering) to it.
  kAdaptiveVdb,
};

// The default: the best trade-off of time and error measured (docs/architecture.md).
inline constexpr IsoReduction kDefaultReduction = IsoReduction::kClustering;

// "clustering", "quadric-clustering", "decimation", "coarse", "vdb".
std::string_view reduction_name(IsoReduction method);
// The inverse of reduction_name(); nullopt for an unknown name.
std::optional<IsoReduction> reduction_by_name(std::string_view name);

// At most `max_triangles` triangles approximating `mesh` by a mesh method (kClustering,
// kQuadricClustering, kQuadricDecimation), or `mesh` itself when it has at most that many or
// max_triangles is 0. Keeps the Mesh invariants; colours as the method says (uniform colours
// stay uniform). Clustering does not keep the topology (small handles and thin parts may
// close or vanish).
// Throws std::invalid_argument for kCoarseLattice and kAdaptiveVdb, which need the volume
// (reduced_isosurface()).
Mesh reduce(const Mesh& mesh, std::size_t max_triangles, IsoReduction method = kDefaultReduction);

// The isosurface of isosurface() (same contract: `value` in the volume's units, colour `rgba`,
// scene frame through `mapper`) with at most `max_triangles` triangles (0: the full surface)
// by `method`. The full surface is returned when it has at most max_triangles triangles
// (kCoarseLattice and kAdaptiveVdb: when the method's own finest surface has).
// Throws std::invalid_argument when `value` is not finite.
Mesh reduced_isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba,
                        std::size_t max_triangles, IsoReduction method = kDefaultReduction);

}  // namespace terravol::volume
