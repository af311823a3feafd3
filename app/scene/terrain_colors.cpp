#include "app/scene/terrain_colors.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace terravol::app::scene {

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// std::lround for a colour channel, inline: libm's lroundf is a call, about 6 million of them
// for a 1024-cell window's lattice, which were half of its shading's instructions. Equal to
// std::lround for every finite x >= 0 below 2^31 (x - trunc(x) is exact there); a negative x
// gives 0 or above, which the callers' clamp to 0 makes the same.
long round_channel(float x) {
  long i = static_cast<long>(x);
  if (x - static_cast<float>(i) >= 0.5f) ++i;
  return i;
}

struct Stop {
  float height;  // metres
  float r, g, b;
};

// The atlas ramp: lowland green, olive, tan, brown, grey rock, snow.
constexpr std::array<Stop, 8> kAtlas{{
    {0.0f, 84, 138, 72},
    {300.0f, 104, 150, 78},
    {800.0f, 146, 164, 96},
    {1300.0f, 188, 172, 120},
    {1900.0f, 166, 134, 100},
    {2500.0f, 146, 126, 112},
    {3200.0f, 176, 174, 172},
    {4000.0f, 246, 246, 250},
}};
constexpr Rgba kWater{70, 120, 170, 255};
constexpr Rgba kGreyLand{200, 200, 200, 255};

Rgba ramp(float h) {
  if (h <= kAtlas.front().height) return {84, 138, 72, 255};
  for (std::size_t s = 1; s < kAtlas.size(); ++s) {
    if (h <= kAtlas[s].height) {
      const Stop& a = kAtlas[s - 1];
      const Stop& b = kAtlas[s];
      const float t = (h - a.height) / (b.height - a.height);
      auto mix = [t](float u, float v) { return static_cast<std::uint8_t>(round_channel(u + (v - u) * t)); };
      return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b), 255};
    }
  }
  return {246, 246, 250, 255};
}

}  // namespace

Rgba tint_of(float height, Tint tint, float lo, float hi) {
  if (height <= 0.0f) return kWater;
  switch (tint) {
    case Tint::kAtlas:
      return ramp(height);
    case Tint::kRelative: {
      const float span = std::max(hi - lo, 1.0f);
      return ramp((height - lo) / span * kAtlas.back().height);
    }
    case Tint::kGrey:
      return kGreyLand;
  }
  return kGreyLand;
}

Rgba shaded(const Rgba& c, float shade) {
  auto f = [shade](std::uint8_t v) {
    return static_cast<std::uint8_t>(std::clamp(round_channel(v * shade), 0L, 255L));
  };
  return {f(c[0]), f(c[1]), f(c[2]), c[3]};
}

Rgba lod_color(int level) {
  // Qualitative colours, coarse to fine; all with green > 60 so none is near magenta.
  static constexpr std::array<Rgba, 10> kLevels{{
      {70, 110, 200, 255},   // blue
      {90, 190, 220, 255},   // cyan
      {80, 170, 80, 255},    // green
      {190, 210, 70, 255},   // yellow-green
      {240, 200, 60, 255},   // yellow
      {240, 140, 60, 255},   // orange
      {215, 75, 70, 255},    // red
      {60, 160, 150, 255},   // teal
      {150, 100, 70, 255},   // brown
      {230, 230, 230, 255},  // white
  }};
  if (level < 0) return kCrackColor;
  return kLevels[static_cast<std::size_t>(level) % kLevels.size()];
}

TerrainShading shade_terrain(int cells, std::span<const double> xs, std::span<const double> ys,
                             std::span<const float> z, std::span<const float> heights,
                             const ShadingOptions& options) {
  const int side = cells + 1;
  const std::size_t count = static_cast<std::size_t>(side) * side;
  TerrainShading out;
  out.shade.resize(count);
  out.rgba.resize(count);

  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (float h : heights) {
    if (h > 0.0f) {
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
  }
  if (lo > hi) lo = hi = 0.0f;

  const double az = options.sun_azimuth_deg * kDegree, el = options.sun_elevation_deg * kDegree;
  const glm::dvec3 sun(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  const double flat = std::max(std::sin(el), 1e-3);
  const double ambient = std::clamp(options.ambient, 0.0, 1.0);

  const auto x = [&](int i) { return xs[static_cast<std::size_t>(i)]; };
  const auto y = [&](int j) { return ys[static_cast<std::size_t>(j)]; };
  const auto zat = [&](int i, int j) { return z[static_cast<std::size_t>(j) * side + static_cast<std::size_t>(i)]; };
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const glm::dvec3 n = lattice_normal(cells, i, j, x, y, zat);
      const std::size_t t = static_cast<std::size_t>(j) * side + i;
      const float h = heights[t];
      // Lambert against the sun, normalised so that flat ground keeps its tint.
      const double lambert = std::max(glm::dot(n, sun), 0.0) / flat;
      const float s = h <= 0.0f ? 1.0f : static_cast<float>(std::min(ambient + (1.0 - ambient) * lambert, 1.3));
      out.shade[t] = s;
      out.rgba[t] = shaded(tint_of(h, options.tint, lo, hi), s);
    }
  }
  return out;
}

std::array<std::array<std::uint8_t, 3>, 2> sky_gradient(double pitch_deg, double fov_y_deg) {
  using Rgb3 = std::array<std::uint8_t, 3>;
  // Sky colour at elevation e (degrees): haze at and below the horizon, zenith blue above ~50.
  auto sky = [](double e) {
    const double t = std::sqrt(std::clamp(e / 50.0, 0.0, 1.0));
    return std::array<double, 3>{kHorizon[0] + (kZenith[0] - kHorizon[0]) * t,
                                 kHorizon[1] + (kZenith[1] - kHorizon[1]) * t,
                                 kHorizon[2] + (kZenith[2] - kHorizon[2]) * t};
  };
  auto to_rgb = [](const std::array<double, 3>& c) {
    Rgb3 out{};
    for (int k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::clamp(std::lround(c[k]), 0L, 255L));
    return out;
  };
  // Fraction of the image height (from the bottom) where elevation e appears, centre column.
  const double half = std::tan(fov_y_deg * kDegree / 2.0);
  auto row_of = [&](double e) { return 0.5 + std::tan((e - pitch_deg) * kDegree) / (2.0 * half); };
  const double top_e = pitch_deg + fov_y_deg / 2.0;
  const std::array<double, 3> top = sky(top_e);
  const double yh = std::abs(pitch_deg) < 89.9 ? row_of(0.0) : (pitch_deg > 0 ? -1.0 : 2.0);
  if (yh >= 1.0) return {to_rgb(sky(0.0)), to_rgb(sky(0.0))};  // the horizon is above the image
  if (yh <= 0.0) return {to_rgb(sky(pitch_deg - fov_y_deg / 2.0)), to_rgb(top)};
  // Linear through (yh, horizon) and (1, top), extrapolated to the bottom (hidden by terrain).
  const std::array<double, 3> h = sky(0.0);
  std::array<double, 3> bottom{};
  for (int k = 0; k < 3; ++k) bottom[k] = h[k] - (top[k] - h[k]) * yh / (1.0 - yh);
  return {to_rgb(bottom), to_rgb(top)};
}

TerrainShading vertex_shading(const TerrainShading& lattice, std::size_t terrain_vertices,
                              std::span<const glm::u8vec4> merged_colors) {
  const std::size_t samples = lattice.rgba.size();
  const std::size_t total = terrain_vertices + merged_colors.size();
  const auto side = static_cast<std::size_t>(std::lround(std::sqrt(static_cast<double>(samples))));
  TerrainShading out;
  // The renderer keeps `shade` and `rgba` and appends the vertices of low alternatives built
  // when first drawn, in the room its vertex arrays keep; these get the same room (reserved,
  // not touched: no memory is used until they grow into it). Made exactly, the first such
  // append after a slide over the benchmark's Utah volumes reallocated both (1.7 M vertices)
  // on the viewer's thread: 20-30 ms of that frame, most of it fresh pages.
  out.shade.reserve(total + total / kVertexRoom);
  out.rgba.reserve(total + total / kVertexRoom);
  out.shade.resize(total);
  out.rgba.resize(total);
  out.tcoords.resize(total, glm::vec2(-1.0f));
  for (std::size_t v = samples; v < terrain_vertices; ++v) {
    out.shade[v] = 1.0f;
    out.rgba[v] = kWallColor;
  }
  for (std::size_t v = 0; v < std::min(terrain_vertices, samples); ++v) {
    const std::size_t t = v;
    out.shade[v] = lattice.shade[t];
    out.rgba[v] = lattice.rgba[t];
    out.tcoords[v] = glm::vec2((static_cast<float>(t % side) + 0.5f) / static_cast<float>(side),
                               (static_cast<float>(t / side) + 0.5f) / static_cast<float>(side));
  }
  for (std::size_t k = 0; k < merged_colors.size(); ++k) {
    const glm::u8vec4 c = merged_colors[k];
    out.shade[terrain_vertices + k] = 1.0f;
    out.rgba[terrain_vertices + k] = {c.r, c.g, c.b, c.a};
  }
  return out;
}

}  // namespace terravol::app::scene
