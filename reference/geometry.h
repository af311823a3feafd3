// The volumes' geometry rebuilt for the independent reference (reference/check.h): each
// isosurface extracted again from the volume file's lattice with VTK directly, each slice cut
// from the lattice by its own crossing code, every vertex placed in the scene frame by this
// folder's Frame (reference/frame.h), never through volume::LatticeMapper, volume::isosurface
// or volume::slice, which are what the check measures.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <memory>
#include <vector>

#include "reference/dem.h"
#include "reference/frame.h"
#include "reference/scene.h"
#include "volume/volume.h"

namespace GeographicLib {
class LocalCartesian;
}

namespace terravol::reference {

// Triangles with a colour per vertex: positions in the scene frame (metres), sRGBA.
struct Mesh {
  std::vector<glm::dvec3> vertices;
  std::vector<glm::u8vec4> colors;
  std::vector<std::uint32_t> triangles;  // 3 indices per triangle

  std::size_t triangle_count() const { return triangles.size() / 3; }
};

void append(Mesh& into, const Mesh& from);

// A geodetic position: degrees, metres in the DEM's datum.
struct Geodetic {
  double lat = 0, lon = 0, h = 0;
};

// Where a volume's lattice points lie, from its frame (docs/architecture.md, "volume/: RF
// volumes"): lattice coordinates (i, j, k), fractional allowed, are world coordinates
// w = origin + index * spacing; geographic: lon = w0, lat = w1, h = w2, plus the ground under
// (lat, lon) when heights are above the ground; ENU: GeographicLib::LocalCartesian about the
// frame's origin, h taken as ellipsoidal.
class Placement {
 public:
  // `ground` must outlive the placement; it may be null unless the volume's heights are above
  // the ground. Throws std::invalid_argument for a volume without a frame, or a missing ground.
  Placement(const volume::Volume& volume, const Frame& frame, const Dem* ground);
  ~Placement();
  Placement(const Placement&) = delete;
  Placement& operator=(const Placement&) = delete;

  Geodetic geodetic(double i, double j, double k) const;
  glm::dvec3 scene(double i, double j, double k) const;
  // Metres above the ground at a geodetic point; throws std::invalid_argument without a ground.
  double above_ground(const Geodetic& g) const;

 private:
  volume::VolumeFrame kind_;
  volume::Lattice lattice_;
  const Frame& frame_;
  const Dem* ground_;
  std::unique_ptr<GeographicLib::LocalCartesian> enu_;
};

// The surface where the volume equals style.value: vtkFlyingEdges3D on the lattice in index
// space, vertices placed by `placement`, every vertex style.color with alpha
// round(opacity * 255). Triangles touching a NaN lattice point are dropped (the filter sees the
// NaN points patched with a finite value).
Mesh isosurface(const volume::Volume& volume, const Placement& placement, const IsoStyle& style);

// The slice as docs/scene-file.md and volume/geometry.h define it: one vertex where each
// lattice line crosses the slice surface (lat: lines along the latitude axis j; lon: along i;
// alt, agl: the vertical columns k), found on the first lattice segment whose ends straddle the
// value, by regula falsi (exact in one step where the quantity is linear along the line, as in
// geographic frames); its value linear between the segment's ends; a quad per sheet cell whose
// four corners exist and are not NaN, split along its shorter diagonal (in the scene frame);
// colour: the named map at t = (v - lo) / (hi - lo) clamped to [0, 1] (0.5 when lo == hi),
// alpha round(opacity * 255). `ground` is needed for agl slices and for alt slices of
// terrain-following volumes. Throws std::invalid_argument when no line crosses the slice, for an
// unknown colour map, or a missing ground.
Mesh slice(const volume::Volume& volume, const Placement& placement, const SliceStyle& style);

}  // namespace terravol::reference
