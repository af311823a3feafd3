// Isosurfaces reduced to a triangle budget fast enough for an interaction (an isovalue change
// re-extracts and re-merges one surface). The methods, their cost and their error on real
// volumes are compared in docs/architecture.md ("Volume geometry"); the figures below come from
// there (CPU time on the shared 2-core machine, RelWithDebInfo; errors are distances to the full
// flying-edges surface sampled on both surfaces).
#pragma once

#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "volume/geometry.h"

namespace terravol::volume {

enum class IsoReduction : std::uint8_t {
  // Edge collapse by quadric error (M. Garland and P. S. Heckbert, SIGGRAPH 1997) by
  // meshoptimizer's meshopt_simplify, after clustering a surface of more than 4 N triangles to
  // 4 N by meshopt_simplifySloppy (grid clustering onto existing vertices), which leaves
  // components of under 256 triangles alone. Both keep input vertices only, so every vertex of
  // the result is a vertex of the full surface, on a lattice edge, with its colour. The default:
  // 11-26 ms for 32-68k-triangle surfaces of the N44W072 volumes, 63-73 ms for the default
  // scene's 200k-triangle ones (to 12,000 triangles), a mean distance of 1.2-3.6 m from the
  // full surface (cells of 130-190 x 185 x 50-100 m), the 99th percentile 6-17 m.
  kCollapse,
  // The same edge collapse on the whole surface, without the clustering first: about as
  // accurate on average, a smaller largest error (no thin part is clustered away), two to three
  // times slower on surfaces of more than 4 N triangles (136-190 ms for 200k; largest error 42-48
  // m there against kCollapse's 148-181 m).
  kFullCollapse,
  // meshopt_simplifySloppy alone: grid clustering onto existing vertices. The fastest mesh
  // method; does not keep the topology (small parts vanish, thin ones close up).
  kSloppy,
  // Vertex clustering with each bin's vertex where it minimises the bin's quadric error
  // (P. Lindstrom, "Out-of-core simplification of large polygonal models", SIGGRAPH 2000) by
  // vtkQuadricClustering, cubic bins sized for the budget. Colours: the nearest full-surface
  // vertex's. Does not keep the topology.
  kQuadricClustering,
  // Edge collapse with vertex placement by vtkQuadricDecimation (decimate()): as accurate as
  // kCollapse on average, with larger largest errors, and by far the slowest (150-600 ms for
  // 32-68k triangles, 2.4-2.7 s for 200k).
  kQuadricDecimation,
  // Flying edges on every f-th lattice point along each axis (f = 2, 3, ...: the smallest that
  // meets the budget), the last point of each axis always kept so the surface still reaches the
  // lattice's boundary. No full-resolution surface is made, so it is the cheapest; its error is
  // that of contouring a lattice f times coarser (features under f cells are lost). Falls back
  // to kSloppy when the lattice cannot get coarser.
  kCoarseLattice,
  // OpenVDB's adaptive dual contouring (openvdb::tools::volumeToMesh with an adaptivity in
  // [0, 1], the smallest that meets the budget, found by bisection): quads merged within each
  // 8^3 leaf node where the surface is flat. Its vertices lie inside lattice cells, not on
  // their edges. When even adaptivity 1 exceeds the budget, the result goes through kSloppy.
  kAdaptiveVdb,
};

// The default: the best trade-off of time and error measured (docs/architecture.md).
inline constexpr IsoReduction kDefaultReduction = IsoReduction::kCollapse;

// "collapse", "full-collapse", "sloppy", "quadric-clustering", "decimation", "coarse", "vdb".
std::string_view reduction_name(IsoReduction method);
// The inverse of reduction_name(); nullopt for an unknown name.
std::optional<IsoReduction> reduction_by_name(std::string_view name);

// At most `max_triangles` triangles approximating `mesh` by a mesh method (kCollapse,
// kFullCollapse, kSloppy, kQuadricClustering, kQuadricDecimation), or `mesh` itself when it has
// at most that many or max_triangles is 0. Keeps the Mesh invariants. kQuadricDecimation's
// budget is approximate (VTK's target reduction), the others' exact.
// Throws std::invalid_argument for kCoarseLattice and kAdaptiveVdb, which need the volume
// (reduced_isosurface()).
Mesh reduce(const Mesh& mesh, std::size_t max_triangles, IsoReduction method = kDefaultReduction);

// The isosurface of isosurface() (same contract: `value` in the volume's units, colour `rgba`,
// scene frame through `mapper`) with at most `max_triangles` triangles (0: the full surface)
// by `method`. The full surface is returned when it has at most max_triangles triangles
// (kCoarseLattice: when its surface on the 2x coarser lattice has at most a third of the
// budget, so that the full one may fit; kAdaptiveVdb: its own surface at adaptivity 0).
// Throws std::invalid_argument when `value` is not finite.
Mesh reduced_isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba,
                        std::size_t max_triangles, IsoReduction method = kDefaultReduction);

}  // namespace terravol::volume
