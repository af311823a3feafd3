// OpenVDB's adaptive meshing of a volume (reduction.h, IsoReduction::kAdaptiveVdb). Private to
// volume/; vdb_mesh.cpp is, with vdb_file.cpp, the only file that includes OpenVDB (its
// headers are slow to compile).
#pragma once

#include <cstddef>

#include "volume/index_mesh.h"

namespace terravol::volume::detail {

// The surface where `volume` equals `value` by openvdb::tools::volumeToMesh on a grid of the
// lattice's points (index space), with the smallest adaptivity in [0, 1] (to 1/64) whose mesh
// has at most max_triangles triangles, else adaptivity 1. Quads are split along their shorter
// diagonal. Polygons with a vertex outside [0, dims - 1] on some axis (cells OpenVDB meshes
// against the grid's background) or in a cell with a NaN corner are dropped.
// Throws std::invalid_argument when `value` is not finite.
IndexMesh vdb_isosurface(const Volume& volume, float value, std::size_t max_triangles);

}  // namespace terravol::volume::detail
