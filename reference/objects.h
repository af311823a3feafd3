// The scene's objects rebuilt for the independent reference (reference/check.h): each model read
// again with assimp here, not through objects/model.h, and turned, scaled and placed by this
// folder's own code, not objects/placement.h or io::SceneFrame, as docs/scene-file.md
// ("objects") defines them. Always the full model: the check renders with --full-res, which
// draws every instance at its finest level.
#pragma once

#include "reference/dem.h"
#include "reference/frame.h"
#include "reference/geometry.h"
#include "reference/scene.h"

namespace terravol::reference {

// The model `style.file` placed by `style`:
// - triangles of every mesh (polygons triangulated by assimp, points and lines left out), each
//   node's transform applied;
// - colours: a mesh's first vertex colour set where it has one (its alpha times the
//   material's), else the material's diffuse colour, else its base colour, else grey 0.6; the
//   material's alpha times its opacity; then the alpha times style.opacity;
// - placement: body axes (x right, y front, z up) from the model's (+Y up: (x, y, z) ->
//   (-x, z, y); +Z up: as they are), less the anchor (the centre of the bottom of the body-axes
//   bounding box), times the scale, turned by roll about y (right side down), pitch about x
//   (front up) and heading about z (clockwise from north), in that order; then east, north and
//   up metres about the anchor's point on the WGS84 ellipsoid (GeographicLib::LocalCartesian),
//   whose height is style.height or the ground's there plus style.agl; then `frame`;
// - sunlight (objects/shading.h's definition, written again here): each vertex's RGB times
//   min(ambient + (1 - ambient) |n . sun| / sin(elevation), 1.3), n the normal averaged over
//   its triangles joined across edges bent by at most 40 degrees (vertices split elsewhere).
// `ground` may be null when style.height is set. Throws std::runtime_error("FILE: what is
// wrong") when assimp cannot read the file or it holds no triangles, and what Dem::height
// throws.
Mesh object(const ObjectStyle& style, const Sun& sun, const Frame& frame, const Dem* ground);

}  // namespace terravol::reference
