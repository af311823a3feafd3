// The profile path's wall (profile_path.h). Built by hand: four vertices per cross-section and
// six triangles between two need no library.
#include "app/scene/profile_path.h"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace terravol::app::scene {

namespace {

glm::u8vec4 clearance_color(const volume::FresnelAnalysis& f, std::size_t sample) {
  if (sample >= f.clearance_m.size()) return kPathClear;
  const double clearance = f.clearance_m[sample], f1 = f.f1_m[sample];
  if (clearance < 0.0) return kPathObstructed;
  return clearance >= 0.6 * f1 ? kPathClear : kPathGrazing;
}

}  // namespace

double path_half_width(double distance_m) { return std::max(15.0, distance_m / 250.0); }

volume::Mesh profile_path_mesh(const volume::LinkProfile& profile, double from_lat, double from_lon, double to_lat,
                               double to_lon, const io::SceneFrame& frame,
                               const std::function<double(double, double)>& ground) {
  const io::ScenePoint a = frame.to_scene({from_lat, from_lon, 0.0}), b = frame.to_scene({to_lat, to_lon, 0.0});
  const glm::dvec2 chord(b.x - a.x, b.y - a.y);
  const double length = std::hypot(chord.x, chord.y);
  if (!(length >= 1.0)) throw std::invalid_argument("profile_path_mesh: the ends are less than 1 m apart");
  const glm::dvec3 across(-chord.y / length, chord.x / length, 0.0);
  const double w = path_half_width(profile.path.profile.distance_m), top = 2.0 * w, base = -3.0;

  // The cross-sections: the start, each sample, the end.
  const std::size_t samples = profile.lat.size();
  volume::Mesh m;
  const auto section = [&](double lat, double lon, glm::u8vec4 color) {
    const double g = ground(lat, lon);
    const io::ScenePoint lo = frame.to_scene({lat, lon, g + base}), hi = frame.to_scene({lat, lon, g + top});
    const glm::dvec3 l(lo.x, lo.y, lo.z), h(hi.x, hi.y, hi.z);
    for (const glm::dvec3& p : {l - w * across, h - w * across, h + w * across, l + w * across}) {
      m.vertices.push_back(p);
      m.colors.push_back(color);
    }
  };
  section(from_lat, from_lon, clearance_color(profile.fresnel, 0));
  for (std::size_t i = 0; i < samples; ++i) section(profile.lat[i], profile.lon[i], clearance_color(profile.fresnel, i));
  section(to_lat, to_lon, clearance_color(profile.fresnel, samples == 0 ? 0 : samples - 1));
  // Between sections s and s + 1: the near side (0-1), the top (1-2), the far side (2-3).
  const std::size_t sections = samples + 2;
  for (std::size_t s = 0; s + 1 < sections; ++s) {
    const auto i = static_cast<std::uint32_t>(4 * s), j = i + 4;
    for (std::uint32_t k = 0; k < 3; ++k) {
      for (const std::uint32_t v : {i + k, j + k, j + k + 1, i + k, j + k + 1, i + k + 1}) m.triangles.push_back(v);
    }
  }
  return m;
}

}  // namespace terravol::app::scene
