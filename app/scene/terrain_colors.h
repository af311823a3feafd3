// Terrain colours: a hypsometric tint with hillshading (the paper's "pseudo sun-angle
// shading", Wiley et al. 1997, section 6), water at or below 0 m, and the per-level colours
// of --lod-colors (the paper's figure 4).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace terravol::app::scene {

using Rgba = std::array<std::uint8_t, 4>;
using Rgb = std::array<std::uint8_t, 3>;

enum class Tint : std::uint8_t {
  kAtlas,     // absolute: green lowlands, tan and brown hills, grey rock, snow above ~3800 m
  kRelative,  // the atlas ramp stretched over the window's land heights (small relief shows)
  kGrey,      // no tint: hillshade only
};

struct ShadingOptions {
  double sun_azimuth_deg = 315.0;   // where the light comes from, clockwise from north
  double sun_elevation_deg = 35.0;  // degrees above the horizon, (0, 90]
  double ambient = 0.35;            // share of light that ignores the slope, [0, 1]
  Tint tint = Tint::kAtlas;
};

// Per-vertex shading and colours: of the (n+1)^2 lattice samples (index j * (n + 1) + i, row 0
// south) from shade_terrain, or of every vertex of the tree from vertex_shading. No normals: the
// drawing is unlit (the shading is baked into the colours), and a 4096-cell window's would take
// 200 MB in each copy; lattice_normal gives them where they are written (--export-vtp).
struct TerrainShading {
  std::vector<float> shade;        // hillshade factor, 1 on flat ground, ambient .. 1.3
  std::vector<Rgba> rgba;          // tint times shade; alpha 255
  // vertex_shading only: where the vertex's sample lies in a (n+1) x (n+1) texture of the
  // lattice colours (texel centres; row 0 south), for drawing colours independent of the LOD.
  std::vector<glm::vec2> tcoords;
};

// The unit normal (scene frame) of lattice sample (i, j) of an n-cell lattice, by central
// differences of z (one-sided at the edges): x(i) and y(j) are the samples' plane offsets,
// z(i, j) their heights (with the curvature drop). Precondition: cells >= 1, 0 <= i, j <= cells.
template <typename X, typename Y, typename Z>
glm::dvec3 lattice_normal(int cells, int i, int j, const X& x, const Y& y, const Z& z) {
  const int i0 = i > 0 ? i - 1 : 0, i1 = i < cells ? i + 1 : cells;
  const int j0 = j > 0 ? j - 1 : 0, j1 = j < cells ? j + 1 : cells;
  const double dzdx = (static_cast<double>(z(i1, j)) - static_cast<double>(z(i0, j))) / (static_cast<double>(x(i1)) - static_cast<double>(x(i0)));
  const double dzdy = (static_cast<double>(z(i, j1)) - static_cast<double>(z(i, j0))) / (static_cast<double>(y(j1)) - static_cast<double>(y(j0)));
  return glm::normalize(glm::dvec3(-dzdx, -dzdy, 1.0));
}

// cells: n; xs, ys: plane offsets (metres, increasing); z: (n+1)^2 scene-frame heights (with
// the curvature drop), used for the normals (central differences inside, one-sided at the
// edges); heights: (n+1)^2 heights in the DEM's datum, used for the tint and for water
// (height <= 0 m is water, drawn flat-shaded in a water colour).
TerrainShading shade_terrain(int cells, std::span<const double> xs, std::span<const double> ys,
                             std::span<const float> z, std::span<const float> heights,
                             const ShadingOptions& options);

// The room kept after the tree's vertices for those appended later (merged pieces built when
// first drawn, a frame's own faces), as a divisor of their count: the renderer's vertex arrays
// keep count / kVertexRoom more, and so do vertex_shading's `shade` and `rgba`.
inline constexpr std::size_t kVertexRoom = 8;

// The attributes of the tree's vertices (TerrainTree::positions()): vertex v below the
// lattice's sample count is lattice sample v and copies its attributes; the vertices from there
// up to `terrain_vertices` (TerrainTree::merged_base()) are the walls' (the tree's window sides
// seen from beyond), kWallColor; the vertices after it are merged polygons', with
// `merged_colors`. Walls and merged polygons have normal +z, shade 1 and texture coordinates
// (-1, -1) (the renderer draws their own colour there, not the texture). `shade` and `rgba`
// have room for total / kVertexRoom more vertices, untouched. Precondition:
// lattice from shade_terrain.
TerrainShading vertex_shading(const TerrainShading& lattice, std::size_t terrain_vertices,
                              std::span<const glm::u8vec4> merged_colors);

// The tint of a height (metres) with no shading; `lo`, `hi` are the window's land height range
// (used by Tint::kRelative only).
Rgba tint_of(float height, Tint tint, float lo, float hi);

// --lod-colors: a distinct colour per LOD level (0 coarsest), cycling after 10 levels; never
// magenta-like (green channel > 60), so a magenta background shows every crack.
Rgba lod_color(int level);
// The colour of crack fills (Frame::level -1) under --lod-colors: neutral grey.
inline constexpr Rgba kCrackColor{150, 150, 150, 255};
inline constexpr Rgba kWallColor{112, 96, 78, 255};  // the earth of a window side seen from beyond it

// The sky behind the terrain as VTK's linear background gradient (bottom to top of the image):
// the haze colour kHorizon at the horizon line, deepening toward kZenith with elevation, so
// that the visible sky is exact at the horizon and at the top of the image. pitch_deg: the
// view's pitch; fov_y_deg: vertical field of view. Returns {bottom, top}.
inline constexpr std::array<std::uint8_t, 3> kHorizon{214, 226, 238};
inline constexpr std::array<std::uint8_t, 3> kZenith{64, 118, 196};
std::array<std::array<std::uint8_t, 3>, 2> sky_gradient(double pitch_deg, double fov_y_deg);

// Scales the RGB of a colour by `shade`, clamped to 255; alpha kept.
Rgba shaded(const Rgba& c, float shade);

}  // namespace terravol::app::scene
