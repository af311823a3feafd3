// The geometry of volumes, ready for mrbsp::TerrainTree::merge(): isosurfaces and colour-coded
// slices as indexed triangle meshes in the scene frame (io/scene_frame.h), with per-vertex RGBA.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "volume/volume.h"

namespace terravol::volume {

// An indexed triangle mesh. Invariants: colors.size() == vertices.size(); triangles holds
// three indices per triangle, each < vertices.size(); no triangle repeats a vertex or has zero
// area; every vertex is used.
struct Mesh {
  std::vector<glm::dvec3> vertices;      // scene frame, metres
  std::vector<glm::u8vec4> colors;       // sRGB and alpha, one per vertex
  std::vector<std::uint32_t> triangles;  // 3 per triangle

  std::size_t triangle_count() const { return triangles.size() / 3; }
  bool empty() const { return triangles.empty(); }
};

// Appends `from` to `into` (indices offset), e.g. to merge several volumes' meshes in one
// TerrainTree::merge() call, which replaces what was merged before.
void append(Mesh& into, const Mesh& from);

// At most `max_triangles` triangles approximating `mesh` (vtkQuadricDecimation, with the
// colours as an attribute in its error metric, volume preserved), or `mesh` itself when it is
// small enough or max_triangles is 0. Merging into the terrain tree costs about 2 microseconds
// per stored piece, and a triangle becomes a few dozen pieces (split by the split planes, and
// one copy per LOD alternative), so full-resolution isosurfaces of 10^5 triangles would take
// tens of seconds to merge. Keeps the Mesh invariants. Takes seconds for 200k triangles:
// volume/reduction.h has faster reductions (this is IsoReduction::kQuadricDecimation there).
Mesh decimate(const Mesh& mesh, std::size_t max_triangles);

// ---- Isosurfaces -------------------------------------------------------------------------

// One isosurface level as given on a command line or in a scene file.
struct IsoSpec {
  float value = 0.0f;               // in the volume's units (dB, dBm, ...)
  glm::u8vec3 color{255, 0, 255};   // sRGB; default_isosurface_color(0)
  double opacity = 0.5;             // [0, 1]

  glm::u8vec4 rgba() const;  // alpha = round(opacity * 255)
};

// The surface where the volume equals `value`, by flying edges (VTK vtkFlyingEdges3D; Schroeder,
// Maynard and Geveci, "Flying edges", IEEE LDAV 2015) on the lattice, each vertex then mapped
// through `mapper` (LatticeMapper::scene), all vertices coloured `rgba`.
// - Vertices lie on lattice edges, placed by linear interpolation of the two end values, so on
//   a smooth field they are within O(spacing^2 * curvature) of the true surface.
// - Vertices at the same position are shared (so a surface inside the lattice is closed:
//   every edge belongs to exactly two triangles); zero-area triangles are dropped.
// - The surface ends at the lattice's boundary (it is not closed there).
// - NaN points: every triangle in a cell with a NaN corner is dropped (the surface has a hole
//   there); no vertex is ever NaN.
// - Winding: counter-clockwise (right-handed normal) pointing towards increasing values.
// Returns an empty mesh when the level is not crossed or a dimension is < 2.
// Throws std::invalid_argument when `value` is not finite.
Mesh isosurface(const Volume& volume, const LatticeMapper& mapper, float value, glm::u8vec4 rgba);

// The default colour of the index-th isosurface when none is given, cycling through five
// colours (magenta, pink, bronze, mint, green) that no slice colour map uses: each is at least
// 25 CIE76 Delta E*ab from every colour of every map of volume/colormap.h, and 60 from the
// others, so a surface never reads as part of a slice, whichever map the slice uses.
glm::u8vec3 default_isosurface_color(std::size_t index);

// Parses "VALUE[,color=R:G:B|#RRGGBB][,opacity=A]", e.g. "120" or "120,color=255:200:0,opacity=0.4".
// Without a colour, the colour is default_isosurface_color(index); the default opacity is 0.5.
// Throws std::invalid_argument("isosurface 'TEXT': ...") naming the bad part (one line).
IsoSpec parse_isosurface(std::string_view text, std::size_t index = 0);

// ---- Slices ------------------------------------------------------------------------------

enum class SliceKind : std::uint8_t {
  kLat,  // latitude = value (degrees): a vertical sheet
  kLon,  // longitude = value (degrees): a vertical sheet
  kAlt,  // height = value metres above the datum: horizontal, following the Earth's curvature
  kAgl,  // height = value metres above the ground (GroundFunction): follows the terrain
};

struct SliceSpec {
  SliceKind kind = SliceKind::kAgl;
  double value = 0.0;                // degrees (kLat, kLon) or metres (kAlt, kAgl)
  std::string colormap = "viridis";  // colormap_by_name(), or kCategorical (colormap.h)
  double opacity = 0.5;              // [0, 1]
  std::optional<float> lo, hi;       // the values mapped to the colour map's ends; each
                                     // defaults to the volume's finite minimum / maximum
};

// A colour-coded slice through the volume at its resolution: a grid of quads (two triangles
// each, split along the shorter diagonal) whose vertices lie on the slice surface, one per
// lattice line crossing it:
// - kLat: lattice lines along the latitude axis (fixed i, k); the sheet runs along the
//   volume's longitude and height axes. kLon likewise with fixed j, k. kAlt, kAgl: one vertex
//   per lattice column (i, j).
// - In a geographic frame the crossing is exact; in an ENU frame it is found by secant
//   iteration along the line to 1e-9 degrees or 1e-6 metres. Heights above the datum and above
//   the ground convert through `ground`, whatever the frame's own HeightRef.
// - Each vertex carries the volume's value trilinearly interpolated at its lattice position,
//   mapped through the colour map with t = (v - lo) / (hi - lo) clamped to [0, 1] (t = 0.5 when
//   lo == hi; lo > hi reverses the map), alpha = round(opacity * 255). With the colour map
//   "categorical" (an index field such as best_server) the vertex carries instead the value of
//   the nearest lattice point, coloured category_color(round(value)) (colormap.h); lo and hi
//   are then unused.
// - A quad is dropped when a corner's line does not cross the slice inside the volume, or its
//   value is NaN (an interpolation weight > 0 on a NaN point).
// Preconditions: `ground` is the ground `mapper` was built with (if any); it may be empty for
// kLat, kLon and kAlt slices of volumes with heights above the datum.
// Throws std::invalid_argument (one line) when the slice lies entirely outside the volume
// (naming the volume's extent in that quantity), for an unknown colour map, an opacity outside
// [0, 1], a non-finite value, or a missing ground function that is needed.
// volume/textured_slice.h draws the same sheet simplified, with the colours as a texture.
Mesh slice(const Volume& volume, const LatticeMapper& mapper, const SliceSpec& spec, const GroundFunction& ground);

// Parses "KIND=VALUE[,colormap=NAME|categorical][,opacity=A][,range=LO:HI]" with KIND one of lat, lon
// (degrees), alt, agl (metres), e.g. "agl=300" or "alt=2500,colormap=plasma,opacity=0.4,
// range=-140:-60". Either side of the range may be empty ("range=-140:") to keep the default.
// Throws std::invalid_argument("slice 'TEXT': ...") naming the bad part (one line).
SliceSpec parse_slice(std::string_view text);

// "lat", "lon", "alt" or "agl".
std::string_view slice_kind_name(SliceKind kind);

}  // namespace terravol::volume
