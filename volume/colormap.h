// Named colour maps for colour-coded slices and legends: matplotlib's perceptually uniform
// maps (viridis, plasma, inferno, magma), Google's turbo, Moreland's coolwarm, jet and grey.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace terravol::volume {

// One control point: the colour (sRGB, 0..255) at position t in [0, 1].
struct ColorStop {
  float t;
  glm::u8vec3 rgb;
};

// A piecewise-linear colour map over [0, 1], interpolated in sRGB between its stops. A
// Colormap is a view of static tables: cheap to copy, valid for the whole program.
class Colormap {
 public:
  // Precondition: at least two stops, t strictly increasing from 0 to 1; `stops` and `name`
  // outlive the map (static storage).
  Colormap(std::string_view name, std::span<const ColorStop> stops) : name_(name), stops_(stops) {}

  std::string_view name() const { return name_; }
  std::span<const ColorStop> stops() const { return stops_; }

  // The colour at t; t is clamped to [0, 1], NaN maps as 0. Each channel is rounded to the
  // nearest integer.
  glm::u8vec3 map(double t) const;

 private:
  std::string_view name_;
  std::span<const ColorStop> stops_;
};

// The map of that name: "viridis", "plasma", "inferno", "magma", "turbo", "coolwarm", "jet",
// "grey" (alias "gray"). Names are case-sensitive.
// Throws std::invalid_argument("unknown colour map 'x' (known: viridis, ...)").
Colormap colormap_by_name(std::string_view name);

// The known names, in the order the error message lists them (aliases excluded).
std::vector<std::string> colormap_names();

// "categorical": the colour scheme of index-valued fields such as `terravol rf`'s best_server
// (1 = the first transmitter), which a slice draws without interpolating (geometry.h). It is
// not a Colormap (no continuum between its colours); colormap_by_name() rejects it, slices and
// scene files accept it beside the names above.
inline constexpr std::string_view kCategorical = "categorical";
inline bool is_categorical(std::string_view name) { return name == kCategorical; }

// The colour of category k (k = 1, 2, ...): matplotlib's "tab20" qualitative palette (Tableau
// 20) in the order dark 1, dark 2, ..., dark 10, light 1, ..., light 10, so that the first ten
// categories get ten distinct hues; cycled after 20 (k and k + 20 share a colour). k <= 0 maps
// like k + 20 * n with n making it positive.
glm::u8vec3 category_color(std::int64_t k);

}  // namespace terravol::volume
