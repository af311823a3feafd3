// Sunlight baked into a placed model's colours: the terrain's hillshade (app/scene/
// terrain_colors.h, shade_terrain) applied to the model's surface, so that a mast, a building or
// a vehicle shows its form instead of one flat colour. The sun is fixed for a scene, so the
// shading is made once per placed level, like the terrain's.
#pragma once

#include "volume/geometry.h"

namespace terravol::objects {

struct Sunlight {
  double azimuth_deg = 315.0;  // where the light comes from, clockwise from north
  double elevation_deg = 35.0; // above the horizon, (0, 90]
  double ambient = 0.35;       // share of light that ignores the surface's direction, [0, 1]
};

// `mesh` (scene frame: x east, y north, z up) with each vertex's RGB times
//   min(ambient + (1 - ambient) |n . sun| / sin(elevation), 1.3),
// the terrain's hillshade (1 on a face turned straight up), with n the vertex's normal and sun
// the unit vector towards the light. Two-sided (|n . sun|): a face is lit alike from either
// side, as VTK's two-sided lighting lights back faces, because translucent objects show their
// insides and open models (a plate, a sign) have no outside. Normals by vtkPolyDataNormals:
// the triangles' own normals averaged at each vertex, vertices split where the surface bends
// by more than 40 degrees (a box's faces stay flat, a curved hull smooth), so the result may
// have more vertices than `mesh` (duplicates at the same positions); the triangles are the
// same, in the same order. Alphas are kept. Throws std::invalid_argument for an elevation
// outside (0, 90] or an ambient outside [0, 1].
volume::Mesh sunlit(const volume::Mesh& mesh, const Sunlight& sun);

}  // namespace terravol::objects
