#include "reference/scene.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "volume/geometry.h"

namespace terravol::reference {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path resolve(const fs::path& base, const std::string& p) {
  const fs::path path(p);
  return path.is_absolute() ? path : base / path;
}

IsoStyle iso_of(const json& j, std::size_t index) {
  IsoStyle s;
  s.value = j.at("value").get<float>();
  if (j.contains("color")) {
    const auto c = j.at("color").get<std::vector<int>>();
    if (c.size() != 3) throw std::runtime_error("an isosurface colour is not [R, G, B]");
    for (int k = 0; k < 3; ++k) s.color[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(c[static_cast<std::size_t>(k)]);
  } else {
    const auto c = volume::default_isosurface_color(index);
    s.color = {c.r, c.g, c.b};
  }
  if (j.contains("opacity")) s.opacity = j.at("opacity").get<double>();
  return s;
}

SliceStyle slice_of(const json& j) {
  SliceStyle s;
  int kinds = 0;
  for (const auto& [name, kind] : {std::pair{"lat", SliceKind::kLat}, std::pair{"lon", SliceKind::kLon},
                                   std::pair{"alt", SliceKind::kAlt}, std::pair{"agl", SliceKind::kAgl}}) {
    if (!j.contains(name)) continue;
    ++kinds;
    s.kind = kind;
    s.value = j.at(name).get<double>();
  }
  if (kinds != 1) throw std::runtime_error("a slice needs exactly one of lat, lon, alt, agl");
  if (j.contains("colormap")) s.colormap = j.at("colormap").get<std::string>();
  if (j.contains("opacity")) s.opacity = j.at("opacity").get<double>();
  if (j.contains("range")) {
    const auto r = j.at("range").get<std::vector<float>>();
    if (r.size() != 2) throw std::runtime_error("a slice range is not [LOW, HIGH]");
    s.lo = r[0];
    s.hi = r[1];
  }
  return s;
}

}  // namespace

Scene read_scene(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open");
  const fs::path base = file.parent_path();
  try {
    const json j = json::parse(in);
    Scene scene;
    if (j.contains("dem")) {
      const json& dem = j.at("dem");
      if (dem.is_string()) {
        scene.dems.push_back(resolve(base, dem.get<std::string>()));
      } else {
        for (const json& d : dem) scene.dems.push_back(resolve(base, d.get<std::string>()));
      }
    }
    if (j.contains("volumes")) {
      for (const json& v : j.at("volumes")) {
        VolumeStyle s;
        s.file = resolve(base, v.at("file").get<std::string>());
        if (v.contains("field")) s.field = v.at("field").get<std::string>();
        if (v.contains("frame")) s.frame = v.at("frame").get<std::string>();
        if (v.contains("visible")) s.visible = v.at("visible").get<bool>();
        if (v.contains("isosurfaces"))
          for (const json& iso : v.at("isosurfaces")) s.isosurfaces.push_back(iso_of(iso, s.isosurfaces.size()));
        if (v.contains("slices"))
          for (const json& slice : v.at("slices")) s.slices.push_back(slice_of(slice));
        scene.volumes.push_back(std::move(s));
      }
    }
    if (j.contains("render")) {
      const json& r = j.at("render");
      if (r.contains("sun_azimuth")) scene.sun.azimuth_deg = r.at("sun_azimuth").get<double>();
      if (r.contains("sun_elevation")) scene.sun.elevation_deg = r.at("sun_elevation").get<double>();
    }
    if (j.contains("objects")) {
      for (const json& o : j.at("objects")) {
        ObjectStyle s;
        s.file = resolve(base, o.at("file").get<std::string>());
        s.lat = o.at("lat").get<double>();
        s.lon = o.at("lon").get<double>();
        if (o.contains("agl")) s.agl = o.at("agl").get<double>();
        if (o.contains("height")) s.height = o.at("height").get<double>();
        for (const auto& [key, to] : {std::pair{"heading", &s.heading}, std::pair{"pitch", &s.pitch},
                                      std::pair{"roll", &s.roll}, std::pair{"scale", &s.scale},
                                      std::pair{"opacity", &s.opacity}}) {
          if (o.contains(key)) *to = o.at(key).get<double>();
        }
        if (o.contains("up")) s.up_z = o.at("up").get<std::string>() == "z";
        scene.objects.push_back(std::move(s));
      }
    }
    return scene;
  } catch (const json::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
}

}  // namespace terravol::reference
