// Mesh helpers, isosurface colours and the command-line forms of isosurfaces and slices.
#include "volume/geometry.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "volume/colormap.h"

namespace terravol::volume {

void append(Mesh& into, const Mesh& from) {
  const auto offset = static_cast<std::uint32_t>(into.vertices.size());
  into.vertices.insert(into.vertices.end(), from.vertices.begin(), from.vertices.end());
  into.colors.insert(into.colors.end(), from.colors.begin(), from.colors.end());
  into.triangles.reserve(into.triangles.size() + from.triangles.size());
  for (std::uint32_t i : from.triangles) into.triangles.push_back(i + offset);
}

glm::u8vec4 IsoSpec::rgba() const {
  const double a = std::clamp(opacity, 0.0, 1.0);
  return {color, static_cast<std::uint8_t>(std::lround(a * 255.0))};
}

glm::u8vec3 default_isosurface_color(std::size_t index) {
  // Chosen by a greedy search over the sRGB cube (steps of 15): each colour as far (CIE76
  // Delta E*ab) from every colour of every slice map as possible, and from the colours before
  // it, with lightness L* >= 50 and at least 30 from the terrain atlas (app/scene/terrain_colors.cpp)
  // so that it reads over the ground. Nearest slice map colours: plasma (42.7, 35.8), turbo
  // (32.9, 26.6, 26.3). The maps cover most of the cube (turbo, jet and grey alone span every
  // hue and every grey), which is why these are magentas, pinks, a bronze and greens.
  static constexpr std::array<glm::u8vec3, 5> kPalette{{
      {255, 0, 255}, {255, 165, 225}, {150, 120, 15}, {180, 255, 210}, {0, 255, 0},
  }};
  return kPalette[index % kPalette.size()];
}

std::string_view slice_kind_name(SliceKind kind) {
  switch (kind) {
    case SliceKind::kLat:
      return "lat";
    case SliceKind::kLon:
      return "lon";
    case SliceKind::kAlt:
      return "alt";
    case SliceKind::kAgl:
      return "agl";
  }
  return "?";
}

namespace {

// Splits "a,b,c" at commas (empty parts kept, so that "1,,2" is reported).
std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(sep, start);
    parts.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

// A whole string as a finite number.
bool to_double(std::string_view s, double& out) {
  if (s.empty()) return false;
  if (s.front() == '+') s.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(out);
}

// Builds one-line errors "WHAT 'TEXT': MESSAGE".
struct Errors {
  std::string prefix;
  [[noreturn]] void fail(const std::string& message) const { throw std::invalid_argument(prefix + message); }
};

double number(const Errors& e, std::string_view key, std::string_view s) {
  double x = 0.0;
  if (!to_double(s, x)) e.fail(std::string(key) + " '" + std::string(s) + "' is not a number");
  return x;
}

double opacity_of(const Errors& e, std::string_view s) {
  const double a = number(e, "opacity", s);
  if (a < 0.0 || a > 1.0) e.fail("opacity '" + std::string(s) + "' is not within [0, 1]");
  return a;
}

glm::u8vec3 color_of(const Errors& e, std::string_view s) {
  const std::string bad = "color '" + std::string(s) + "'";
  glm::u8vec3 c;
  if (!s.empty() && s.front() == '#') {
    unsigned v = 0;
    const auto [ptr, ec] = std::from_chars(s.data() + 1, s.data() + s.size(), v, 16);
    if (s.size() != 7 || ec != std::errc() || ptr != s.data() + s.size()) e.fail(bad + " is not #RRGGBB");
    return {(v >> 16) & 0xff, (v >> 8) & 0xff, v & 0xff};
  }
  const auto parts = split(s, ':');
  if (parts.size() != 3) e.fail(bad + " is not R:G:B or #RRGGBB");
  for (int i = 0; i < 3; ++i) {
    const std::string_view p = parts[i];
    int v = -1;
    const auto [ptr, ec] = std::from_chars(p.data(), p.data() + p.size(), v);
    if (p.empty() || ec != std::errc() || ptr != p.data() + p.size() || v < 0 || v > 255) {
      e.fail(bad + ": '" + std::string(p) + "' is not an integer in [0, 255]");
    }
    c[i] = static_cast<std::uint8_t>(v);
  }
  return c;
}

// Splits "key=value"; fails naming the part without '='.
std::pair<std::string_view, std::string_view> key_value(const Errors& e, std::string_view part) {
  const std::size_t eq = part.find('=');
  if (eq == std::string_view::npos) e.fail("'" + std::string(part) + "' is not KEY=VALUE");
  return {part.substr(0, eq), part.substr(eq + 1)};
}

void once(const Errors& e, bool& seen, std::string_view key) {
  if (seen) e.fail(std::string(key) + " is given twice");
  seen = true;
}

}  // namespace

IsoSpec parse_isosurface(std::string_view text, std::size_t index) {
  const Errors e{"isosurface '" + std::string(text) + "': "};
  const auto parts = split(text, ',');
  IsoSpec spec;
  spec.color = default_isosurface_color(index);
  double v = 0.0;
  if (!to_double(parts[0], v)) e.fail("value '" + std::string(parts[0]) + "' is not a number");
  if (std::abs(v) > 3.0e38) e.fail("value '" + std::string(parts[0]) + "' is out of range");
  spec.value = static_cast<float>(v);
  bool seen_color = false, seen_opacity = false;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const auto [key, value] = key_value(e, parts[i]);
    if (key == "color" || key == "colour") {
      once(e, seen_color, key);
      spec.color = color_of(e, value);
    } else if (key == "opacity") {
      once(e, seen_opacity, key);
      spec.opacity = opacity_of(e, value);
    } else {
      e.fail("unknown key '" + std::string(key) + "' (known: color, opacity)");
    }
  }
  return spec;
}

SliceSpec parse_slice(std::string_view text) {
  const Errors e{"slice '" + std::string(text) + "': "};
  SliceSpec spec;
  bool seen_kind = false, seen_map = false, seen_opacity = false, seen_range = false;
  for (std::string_view part : split(text, ',')) {
    const auto [key, value] = key_value(e, part);
    std::optional<SliceKind> kind;
    for (SliceKind k : {SliceKind::kLat, SliceKind::kLon, SliceKind::kAlt, SliceKind::kAgl}) {
      if (key == slice_kind_name(k)) kind = k;
    }
    if (kind) {
      if (seen_kind) e.fail("'" + std::string(part) + "': give one of lat, lon, alt, agl only");
      seen_kind = true;
      spec.kind = *kind;
      spec.value = number(e, key, value);
      if ((*kind == SliceKind::kLat && std::abs(spec.value) > 90.0) ||
          (*kind == SliceKind::kLon && std::abs(spec.value) > 360.0)) {
        e.fail(std::string(key) + " '" + std::string(value) + "' is not a valid " +
               (*kind == SliceKind::kLat ? "latitude" : "longitude"));
      }
    } else if (key == "colormap" || key == "colourmap") {
      once(e, seen_map, key);
      try {
        spec.colormap = is_categorical(value) ? std::string(kCategorical) : std::string(colormap_by_name(value).name());
      } catch (const std::invalid_argument& x) {
        e.fail(x.what());
      }
    } else if (key == "opacity") {
      once(e, seen_opacity, key);
      spec.opacity = opacity_of(e, value);
    } else if (key == "range") {
      once(e, seen_range, key);
      const std::size_t colon = value.find(':');
      if (colon == std::string_view::npos) e.fail("range '" + std::string(value) + "' is not LO:HI");
      const std::string_view lo = value.substr(0, colon), hi = value.substr(colon + 1);
      if (!lo.empty()) spec.lo = static_cast<float>(number(e, "range low end", lo));
      if (!hi.empty()) spec.hi = static_cast<float>(number(e, "range high end", hi));
      if (spec.lo && spec.hi && !(*spec.lo < *spec.hi)) e.fail("range '" + std::string(value) + "' needs LO < HI");
    } else {
      e.fail("unknown key '" + std::string(key) + "' (known: lat, lon, alt, agl, colormap, opacity, range)");
    }
  }
  if (!seen_kind) e.fail("no position (give one of lat=, lon=, alt=, agl=)");
  return spec;
}

}  // namespace terravol::volume
