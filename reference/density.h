// The independent reference of a volume density (issue 15): a plain CPU ray marcher. Nothing of
// the octree (density/), the tree (mrbsp/) or the renderer (app/): the field is sampled where
// each ray is, through this folder's own scene frame (reference/frame.h) and the lattice's own
// definition (volume/volume.h), and the transfer function is written again from its definition
// (docs/scene-file.md, "density"; density/transfer.h), with volume/colormap.h's tables.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "reference/frame.h"
#include "volume/volume.h"

namespace terravol::reference {

// A density's transfer function: values in [lo, hi] take the colour map's colour at
// t = (v - lo) / (hi - lo) and extinction sigma_per_km / 1000 per metre times the ramp (1,
// t or 1 - t for "flat", "up", "down"); every other value, NaN and points outside the
// lattice are clear.
struct DensityTransfer {
  float lo = 0.0f, hi = 1.0f;
  std::string colormap = "viridis";
  double sigma_per_km = 1.0;
  std::string ramp = "flat";
};

// The field of a geographic volume in the scene frame: the lattice's value at a scene point,
// trilinear in (longitude, latitude, height) index space; heights above the datum, or above
// the ground given by `ground` (metres above the datum at lat, lon). NaN outside the lattice
// or where an interpolation weight > 0 falls on a NaN point. Throws std::invalid_argument for
// another frame or a missing ground.
class DensityField {
 public:
  DensityField(const volume::Volume& volume, const Frame& frame, std::function<double(double lat, double lon)> ground);
  float at(const glm::dvec3& p) const;
  // The scene-frame box holding every point of the lattice (its columns' lowest and highest
  // points), for the marcher's bounds.
  glm::dvec3 lo() const { return lo_; }
  glm::dvec3 hi() const { return hi_; }

 private:
  const volume::Volume* volume_;
  const Frame* frame_;
  std::function<double(double, double)> ground_;
  bool agl_;
  glm::dvec3 lo_, hi_;
};

// A pinhole camera in the scene frame (as the renderer's: forward and up unit and orthogonal,
// vertical field of view in degrees, pixel centres at (x + 0.5, y + 0.5) from the top left).
struct MarchCamera {
  glm::dvec3 eye{0.0}, forward{0.0, 1.0, 0.0}, up{0.0, 0.0, 1.0};
  double fov_y_deg = 45.0;
  int width = 320, height = 180;
};

// Marches every pixel's ray from the eye, front to back, in steps of `step` metres (the sample
// at each step's middle) through the field's box, until it leaves the box or reaches the
// ground: the first sample with z at or below terrain(x, y) (scene z of the opaque ground under
// (x, y); return -infinity where there is none). Per pixel (row 0 at the top): the
// emission-absorption integral, premultiplied RGBA in [0, 1] (colours sRGB as the colour
// map's, composited linearly, as the renderer blends them), and whether the ray met the field's
// box at all (`inside`, 1 or 0, as the footprint of the comparison).
struct MarchedImage {
  int width = 0, height = 0;
  std::vector<glm::vec4> rgba;
  std::vector<unsigned char> inside;
};
MarchedImage march_density(const DensityField& field, const DensityTransfer& transfer, const MarchCamera& camera, double step,
                           const std::function<double(double x, double y)>& terrain);

// The marched image over a background image (RGB, 3 bytes a pixel, row 0 at the top):
// rgb + (1 - a) background, rounded.
std::vector<unsigned char> composite_over(const MarchedImage& marched, const std::vector<unsigned char>& background);

// How far an image lies from the marcher's inside its footprint (pixels with `inside`): per
// pixel the largest channel difference in 1/255, their mean and 99th percentile (the issue's
// figures; the nearest rank below). All zero when no pixel is inside.
struct FootprintError {
  double mean = 0.0, p99 = 0.0;
  std::size_t pixels = 0;
};
// `worst(p)`: pixel p's largest channel difference, in 1/255.
FootprintError footprint_error(const MarchedImage& marched, const std::function<double(std::size_t p)>& worst);
// `ours` against `expected`, both RGB bytes (3 a pixel, row 0 at the top).
FootprintError footprint_error(const MarchedImage& marched, const std::vector<unsigned char>& ours,
                               const std::vector<unsigned char>& expected);

}  // namespace terravol::reference
