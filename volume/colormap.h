// Named colour maps for colour-coded slices and legends: matplotlib's perceptually uniform
// maps (viridis, plasma, inferno, magma), Google's turbo, Moreland's coolwarm, jet and grey.
#pragma once

#include <glm/vec3.hpp>

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

}  // namespace terravol::volume
