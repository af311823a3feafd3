#include "density/transfer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "volume/colormap.h"

namespace terravol::density {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<double> number(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

std::string_view ramp_name(Ramp ramp) {
  switch (ramp) {
    case Ramp::kUp:
      return "up";
    case Ramp::kDown:
      return "down";
    case Ramp::kFlat:
      break;
  }
  return "flat";
}

Ramp parse_ramp(std::string_view text) {
  for (Ramp r : {Ramp::kFlat, Ramp::kUp, Ramp::kDown})
    if (text == ramp_name(r)) return r;
  throw std::invalid_argument("unknown ramp '" + std::string(text) + "' (known: flat, up, down)");
}

DensitySpec parse_density(std::string_view text) {
  const std::string prefix = "density '" + std::string(text) + "': ";
  const auto fail = [&](const std::string& what) { throw std::invalid_argument(prefix + what); };
  DensitySpec spec;
  bool seen_range = false, seen_map = false, seen_opacity = false, seen_ramp = false;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view part = trim(text.substr(start, end - start));
    start = end + 1;
    if (part.empty()) fail("an empty part");
    const std::size_t eq = part.find('=');
    if (eq == std::string_view::npos) fail("'" + std::string(part) + "' is not KEY=VALUE");
    const std::string_view key = trim(part.substr(0, eq)), value = trim(part.substr(eq + 1));
    const auto once = [&](bool& seen) {
      if (seen) fail(std::string(key) + " given twice");
      seen = true;
    };
    if (key == "range") {
      once(seen_range);
      const std::size_t colon = value.find(':');
      if (colon == std::string_view::npos) fail("range '" + std::string(value) + "' is not LO:HI");
      const auto lo = number(value.substr(0, colon)), hi = number(value.substr(colon + 1));
      if (!lo || !hi) fail("range '" + std::string(value) + "' is not two numbers LO:HI");
      if (!(*lo < *hi)) fail("range '" + std::string(value) + "' needs LO < HI");
      spec.lo = static_cast<float>(*lo);
      spec.hi = static_cast<float>(*hi);
    } else if (key == "colormap" || key == "colourmap") {
      once(seen_map);
      try {
        spec.colormap = std::string(volume::colormap_by_name(value).name());
      } catch (const std::invalid_argument& e) {
        fail(e.what());
      }
    } else if (key == "opacity") {
      once(seen_opacity);
      const auto v = number(value);
      if (!v || !(*v > 0.0) || *v > 1e6) fail("opacity '" + std::string(value) + "' is not an extinction in (0, 1e6] per km");
      spec.sigma_per_km = *v;
    } else if (key == "ramp") {
      once(seen_ramp);
      try {
        spec.ramp = parse_ramp(value);
      } catch (const std::invalid_argument& e) {
        fail(e.what());
      }
    } else {
      fail("unknown key '" + std::string(key) + "' (known: range, colormap, opacity, ramp)");
    }
  }
  if (!seen_range) fail("no range (give range=LO:HI)");
  if (!seen_map) fail("no colour map (give colormap=NAME)");
  if (!seen_opacity) fail("no opacity (give opacity=SIGMA_PER_KM)");
  return spec;
}

std::string format_density(const DensitySpec& spec) {
  char b[160];
  std::snprintf(b, sizeof b, "range=%g:%g,colormap=%s,opacity=%g,ramp=%s", static_cast<double>(spec.lo),
                static_cast<double>(spec.hi), spec.colormap.c_str(), spec.sigma_per_km, std::string(ramp_name(spec.ramp)).c_str());
  return b;
}

TransferTable::TransferTable(const DensitySpec& spec, const glm::dvec3& half_size)
    : lo_(spec.lo), scale_(1.0f / (spec.hi - spec.lo)), color_(kEntries), sigma_(kEntries), half_alpha_(kEntries) {
  const volume::Colormap map = volume::colormap_by_name(spec.colormap);
  for (int k = 0; k < kEntries; ++k) {
    const double t = static_cast<double>(k) / (kEntries - 1);
    const glm::u8vec3 c = map.map(t);
    color_[static_cast<std::size_t>(k)] = glm::vec3(c) / 255.0f;
    const double ramp = spec.ramp == Ramp::kUp ? t : spec.ramp == Ramp::kDown ? 1.0 - t : 1.0;
    const double sigma = spec.sigma_per_km / 1000.0 * ramp;
    sigma_[static_cast<std::size_t>(k)] = static_cast<float>(sigma);
    for (int a = 0; a < 3; ++a) half_alpha_[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)] = static_cast<float>(-std::expm1(-sigma * half_size[a]));
  }
}

}  // namespace terravol::density
