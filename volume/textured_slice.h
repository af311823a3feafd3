// Slices for interaction: a simplified sheet carrying the colour-mapped values as a texture at
// the lattice's own resolution, instead of a quad per lattice cell (slice() in geometry.h).
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <cstddef>
#include <vector>

#include "volume/geometry.h"

namespace terravol::volume {

// A mesh with per-vertex texture coordinates into one RGBA image.
// Invariants: mesh keeps the Mesh invariants; tcoords.size() == mesh.vertices.size(), each in
// [0, 1]^2; texels.size() == width * height.
struct TexturedMesh {
  Mesh mesh;                       // colours: the colour-mapped value at each vertex (for
                                   // exports and renderers without the texture)
  std::vector<glm::vec2> tcoords;  // (s, t) per vertex
  int width = 0, height = 0;       // texels
  std::vector<glm::u8vec4> texels;  // sRGB and alpha, row-major: texel (a, b) at b * width + a,
                                    // its centre at (s, t) = ((a + 0.5) / width, (b + 0.5) / height)
  double tolerance_m = 0.0;  // textured_slice(): the tolerance the sheet meets (SheetOptions)
};

struct SheetOptions {
  // Largest distance (scene metres) from any sample of the exact sheet to the point of the
  // simplified sheet at the same sheet coordinates. >= 0; 0 merges only cells that are exactly
  // planar.
  //
  // Default 2 m: the sheet's vertices are exact and its colours come from the texture, so the
  // tolerance only moves the sheet's surface, and 2 m is well under what the picture resolves
  // of it: a fiftieth of the vertical lattice spacing of the benchmark volumes (100 m), about
  // 2 pixels at 1 km in a 1280-pixel, 50-degree view, and below SRTM's own height error
  // (16 m absolute, 90% of points), which an agl sheet follows. It merges lat/lon sheets of
  // datum volumes and alt sheets far (the Earth's curvature is all there is to follow), but
  // almost nothing of an agl sheet over mountains, whose ground changes by tens of metres
  // between lattice columns: on the benchmark volumes over N44W072, 46,022 of 46,080
  // triangles. Interaction needs the cap there (12,000 triangles: the exact vertices 7 m from
  // the sheet on average, 62 m at most; docs/architecture.md, "Volume geometry").
  double tolerance_m = 2.0;
  // At most this many triangles (0: no cap): when the tolerance gives more, the smallest larger
  // tolerance that gives at most this many is used. Where the sheet's holes (NaN values, lines
  // that miss the slice) need more triangles than the cap even at the largest tolerance, the
  // result is that fewest.
  std::size_t max_triangles = 0;
};

// The slice of `spec` (the same sheet as slice(), same preconditions and exceptions) as a
// simplified sheet with the colours as a texture:
// - Texture: width = the samples of the sheet's u axis, height = those of its v axis (kLat:
//   longitude and height lattice axes; kLon: latitude and height; kAlt, kAgl: longitude and
//   latitude), texel (a, b) the colour slice() gives the vertex where lattice line (a, b)
//   crosses the slice, alpha 0 where the line misses the slice or the value is NaN.
// - Sheet: a subset of slice()'s vertices, at the same positions, each with the texture
//   coordinates of its own texel centre, so the texture is exact at every vertex and
//   interpolates bilinearly between lattice lines. It covers exactly the cells slice() draws
//   (never more: no cell with a missing or NaN corner, nothing outside the volume), with no
//   crack and no T-junction: its boundary edges run along slice()'s boundary edges only.
// - Error: every vertex of slice() lies within `tolerance_m` of the point of the simplified
//   sheet at the same sheet coordinates (so within that distance of the sheet), tolerance_m
//   being options.tolerance_m or the larger one the triangle cap needed (returned in
//   TexturedMesh::tolerance_m).
// - Cost: linear in the lattice lines, and what slice() costs, the crossings and colours (7-9
//   ms for 181 x 129 lines, 20-28 ms for 307 x 215); the quadtree adds 1-2 ms, and a cap at
//   most about 20 passes over it.
// Throws std::invalid_argument as slice() does, and for a tolerance < 0 or not finite.
TexturedMesh textured_slice(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec,
                            const GroundFunction& ground, const SheetOptions& options = {});

}  // namespace terravol::volume
