// Isosurfaces in the lattice's index space, before they are mapped to the scene frame. Private
// to volume/: isosurface() (volume/isosurface.cpp) and the reductions (volume/reduction.cpp,
// volume/vdb_mesh.cpp) share them.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

#include "volume/geometry.h"

namespace terravol::volume::detail {

// Points in lattice coordinates (i, j, k), three indices per triangle; every point used, no
// triangle repeats a point or has zero area (in index space), normals towards increasing
// values.
struct IndexMesh {
  std::vector<glm::dvec3> points;
  std::vector<std::uint32_t> triangles;
};

// Whether lattice cell (i, j, k) (corners i..i + 1 etc.) has a NaN corner.
bool cell_has_nan(const Volume& v, int i, int j, int k);

// isosurface() before mapping (same contract, same exceptions).
IndexMesh flying_edges(const Volume& volume, float value);

// Maps every point through `mapper`, all coloured `rgba`.
Mesh to_scene(IndexMesh&& mesh, const LatticeMapper& mapper, glm::u8vec4 rgba);

}  // namespace terravol::volume::detail
