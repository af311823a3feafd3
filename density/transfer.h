// The transfer function of a volume drawn as a density (issue 15): each value of the field is
// a colour and an extinction coefficient, and the volume an emission-absorption medium (the
// optical model of Max, "Optical models for direct volume rendering", 1995, section 4): light
// along a ray through a homogeneous stretch of length L with extinction sigma and colour c
// leaves opacity alpha = 1 - exp(-sigma L) and colour c alpha (premultiplied).
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace terravol::density {

// How the extinction varies over the range, t = (value - lo) / (hi - lo) in [0, 1].
enum class Ramp : std::uint8_t {
  kFlat,  // sigma everywhere in the range
  kUp,    // sigma t: clear at lo, densest at hi
  kDown,  // sigma (1 - t): densest at lo, clear at hi (path loss: dense where the signal is strong)
};

// A density style: `range=LO:HI,colormap=NAME,opacity=SIGMA_PER_KM[,ramp=flat|up|down]`.
// Values in [lo, hi] take the colour map's colour at t (volume/colormap.h) and extinction
// sigma_per_km / 1000 per metre times the ramp; values outside the range, NaN and points
// outside the lattice are clear (no extinction, no colour).
struct DensitySpec {
  float lo = 0.0f, hi = 1.0f;       // in the field's units (dB, dBm); lo < hi
  std::string colormap = "viridis";  // a name of volume::colormap_by_name (not "categorical")
  double sigma_per_km = 1.0;         // extinction, per kilometre, > 0 and finite
  Ramp ramp = Ramp::kFlat;

  bool operator==(const DensitySpec&) const = default;
};

// Parses the command line's text (keys in any order; range, colormap and opacity required,
// e.g. "range=80:160,colormap=viridis,opacity=2"). Throws std::invalid_argument("density
// 'TEXT': what is wrong", one line) for a missing or repeated key, an unknown key, colour map
// or ramp, a range that is not LO:HI with LO < HI, or an opacity that is not a positive
// finite number.
DensitySpec parse_density(std::string_view text);
// The inverse of parse_density (for status files and legends).
std::string format_density(const DensitySpec& spec);
std::string_view ramp_name(Ramp ramp);
// "flat", "up" or "down"; throws std::invalid_argument naming the known ramps.
Ramp parse_ramp(std::string_view text);

// The transfer function as a table over the range: kEntries colours and extinctions at
// t = k / (kEntries - 1), looked up at the nearest entry (a step of at most 1/2046 of the
// range: 0.04 dB over 80 dB). For each entry also the opacity of half a box along each axis,
// alpha = 1 - exp(-sigma h), h = half the box's size on that axis (the octree's leaves
// composite two half-lengths per edge: octree.h).
class TransferTable {
 public:
  static constexpr int kEntries = 1024;
  // half_size: half the leaf boxes' size along x, y and z, metres (> 0).
  TransferTable(const DensitySpec& spec, const glm::dvec3& half_size);

  // The entry of a value: -1 when it is clear (outside the range, NaN).
  int entry(float value) const {
    const float t = (value - lo_) * scale_;
    if (!(t >= 0.0f && t <= 1.0f)) return -1;
    return static_cast<int>(t * static_cast<float>(kEntries - 1) + 0.5f);
  }
  const glm::vec3& color(int entry) const { return color_[static_cast<std::size_t>(entry)]; }  // sRGB in [0, 1]
  float sigma(int entry) const { return sigma_[static_cast<std::size_t>(entry)]; }               // per metre
  // The opacity of half a leaf along axis a (0 x, 1 y, 2 z).
  float half_alpha(int entry, int axis) const { return half_alpha_[static_cast<std::size_t>(entry)][static_cast<std::size_t>(axis)]; }

 private:
  float lo_, scale_;
  std::vector<glm::vec3> color_;
  std::vector<float> sigma_;
  std::vector<std::array<float, 3>> half_alpha_;
};

}  // namespace terravol::density
