// --export-vtp: the triangles a render drew, as a VTK XML PolyData file.
#pragma once

#include <filesystem>

#include "app/render/terrain_renderer.h"

class vtkCamera;
class vtkPolyData;

namespace terravol::app::output {

// Writes the triangles of `scene` (TerrainRenderer::scene()) exactly as drawn: the same
// triangles in draw order, with only the points they use, renumbered in order of first use.
// Coordinates are the scene frame's (metres). Point data: "rgba" (4 x uint8) and "normals"
// (scene::lattice_normal of the lattice's points, the first (lattice_cells + 1)^2 of `scene`'s;
// +z for the others: walls, merged polygons);
// cell data: "level" (LOD level, -1 for crack fills) and, with --lod-colors, "lod_rgba".
// Field data: camera_position, camera_focal_point, camera_view_up (3 doubles each, scene
// frame), camera_view_angle (vertical, degrees), camera_clipping_range, background (3 x uint8,
// 0..255; the bottom colour of a gradient) and, for a gradient sky, background_top.
// Written through a temporary file in the same folder and a rename. Throws
// std::runtime_error when `path` exists and !overwrite, or when writing fails, and
// std::invalid_argument when `scene` has fewer points than the lattice.
void export_vtp(const std::filesystem::path& path, vtkPolyData* scene, int lattice_cells, vtkCamera* camera,
                const render::RenderSettings& settings, bool overwrite);

}  // namespace terravol::app::output
