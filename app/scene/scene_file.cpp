#include "app/scene/scene_file.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/scene/json_reader.h"
#include "app/scene/style.h"
#include "volume/colormap.h"

namespace terravol::app::scene {

namespace {

using nlohmann::json;

using Reader = JsonReader;

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& text) {
  const std::filesystem::path p(text);
  return p.is_absolute() ? p : base / p;
}

glm::u8vec3 rgb_of(const Reader& r, const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) r.fail(where, "expected [R, G, B] with each 0..255");
  glm::u8vec3 c;
  for (int k = 0; k < 3; ++k) c[k] = static_cast<std::uint8_t>(r.number(j[static_cast<std::size_t>(k)], Reader::at(where, static_cast<std::size_t>(k)), 0, 255));
  return c;
}

volume::IsoSpec iso_of(const Reader& r, const json& j, const std::string& where, std::size_t index) {
  r.only_keys(j, where, {"value", "color", "opacity"});
  if (!j.contains("value")) r.fail(where, "missing \"value\"");
  volume::IsoSpec s;
  s.value = static_cast<float>(r.number(j["value"], Reader::join(where, "value"), -1e30, 1e30));
  const glm::u8vec3 palette = volume::default_isosurface_color(index);
  s.color = j.contains("color") ? rgb_of(r, j["color"], Reader::join(where, "color")) : palette;
  s.opacity = j.contains("opacity") ? r.number(j["opacity"], Reader::join(where, "opacity"), 0.0, 1.0) : 0.5;
  return s;
}

volume::SliceSpec slice_of(const Reader& r, const json& j, const std::string& where) {
  r.only_keys(j, where, {"lat", "lon", "alt", "agl", "opacity", "colormap", "range"});
  volume::SliceSpec s;
  int kinds = 0;
  const std::pair<const char*, volume::SliceKind> names[] = {{"lat", volume::SliceKind::kLat},
                                                             {"lon", volume::SliceKind::kLon},
                                                             {"alt", volume::SliceKind::kAlt},
                                                             {"agl", volume::SliceKind::kAgl}};
  for (const auto& [name, kind] : names) {
    if (!j.contains(name)) continue;
    ++kinds;
    s.kind = kind;
    const bool degrees = kind == volume::SliceKind::kLat || kind == volume::SliceKind::kLon;
    s.value = r.number(j[name], Reader::join(where, name), degrees ? -360.0 : -1e5, degrees ? 360.0 : 1e5);
  }
  if (kinds != 1) r.fail(where, "needs exactly one of lat, lon, alt, agl");
  if (j.contains("opacity")) s.opacity = r.number(j["opacity"], Reader::join(where, "opacity"), 0.0, 1.0);
  if (j.contains("colormap")) {
    s.colormap = r.string(j["colormap"], Reader::join(where, "colormap"));
    try {
      if (!volume::is_categorical(s.colormap)) volume::colormap_by_name(s.colormap);
    } catch (const std::invalid_argument& e) {
      r.fail(Reader::join(where, "colormap"), e.what());
    }
  }
  if (j.contains("range")) {
    const json& range = j["range"];
    const std::string w = Reader::join(where, "range");
    if (!range.is_array() || range.size() != 2) r.fail(w, "expected [LOW, HIGH]");
    s.lo = static_cast<float>(r.number(range[0], Reader::at(w, 0), -1e30, 1e30));
    s.hi = static_cast<float>(r.number(range[1], Reader::at(w, 1), -1e30, 1e30));
    if (!(*s.lo < *s.hi)) r.fail(w, "LOW must be below HIGH");
  }
  return s;
}

// {"range": [LO, HI], "colormap": NAME, "opacity": SIGMA_PER_KM, "ramp": "flat" | "up" | "down"}:
// the same keys and checks as --density (density::parse_density).
density::DensitySpec density_of(const Reader& r, const json& j, const std::string& where) {
  r.only_keys(j, where, {"range", "colormap", "opacity", "ramp"});
  density::DensitySpec d;
  const json& range = r.required(j, where, "range");
  const std::string w = Reader::join(where, "range");
  if (!range.is_array() || range.size() != 2) r.fail(w, "expected [LOW, HIGH]");
  d.lo = static_cast<float>(r.number(range[0], Reader::at(w, 0), -1e30, 1e30));
  d.hi = static_cast<float>(r.number(range[1], Reader::at(w, 1), -1e30, 1e30));
  if (!(d.lo < d.hi)) r.fail(w, "LOW must be below HIGH");
  d.colormap = r.string(r.required(j, where, "colormap"), Reader::join(where, "colormap"));
  try {
    d.colormap = std::string(volume::colormap_by_name(d.colormap).name());
  } catch (const std::invalid_argument& e) {
    r.fail(Reader::join(where, "colormap"), e.what());
  }
  d.sigma_per_km = r.number(r.required(j, where, "opacity"), Reader::join(where, "opacity"), 1e-9, 1e6);
  if (j.contains("ramp")) {
    try {
      d.ramp = density::parse_ramp(r.string(j["ramp"], Reader::join(where, "ramp")));
    } catch (const std::invalid_argument& e) {
      r.fail(Reader::join(where, "ramp"), e.what());
    }
  }
  return d;
}

// `isosurfaces_before`: how many isosurfaces the volumes before this one have (an isosurface
// without a colour takes the palette's colour of its place among all of the file's, so that
// the surfaces of different volumes differ); counted on.
VolumeSpec volume_of(const Reader& r, const json& j, const std::string& where, const std::filesystem::path& base,
                     std::size_t& isosurfaces_before) {
  r.only_keys(j, where, {"file", "field", "frame", "visible", "isosurfaces", "slices", "density"});
  if (!j.contains("file")) r.fail(where, "missing \"file\"");
  VolumeSpec v;
  v.file = resolve(base, r.string(j["file"], Reader::join(where, "file")));
  if (j.contains("field")) v.field = r.string(j["field"], Reader::join(where, "field"));
  if (j.contains("frame")) {
    v.frame = r.string(j["frame"], Reader::join(where, "frame"));
    try {
      volume::parse_frame(v.frame);
    } catch (const std::invalid_argument& e) {
      r.fail(Reader::join(where, "frame"), e.what());
    }
  }
  if (j.contains("visible")) v.visible = r.boolean(j["visible"], Reader::join(where, "visible"));
  if (j.contains("density")) v.density = density_of(r, j["density"], Reader::join(where, "density"));
  for (const char* list : {"isosurfaces", "slices"}) {
    if (!j.contains(list)) continue;
    const std::string w = Reader::join(where, list);
    if (!j[list].is_array()) r.fail(w, "expected a list");
    for (std::size_t k = 0; k < j[list].size(); ++k) {
      if (list[0] == 'i') {
        v.isosurfaces.push_back(iso_of(r, j[list][k], Reader::at(w, k), isosurfaces_before++));
      } else {
        v.slices.push_back(slice_of(r, j[list][k], Reader::at(w, k)));
      }
    }
  }
  return v;
}

// The ranges both the scene file and --object check.
constexpr double kMaxObjectHeight = 1e5, kMaxScale = 1e6, kMaxAngle = 720.0;

ObjectSpec object_of(const Reader& r, const json& j, const std::string& where, const std::filesystem::path& base) {
  r.only_keys(j, where, {"file", "lat", "lon", "height", "agl", "heading", "pitch", "roll", "scale", "opacity", "up"});
  for (const char* key : {"file", "lat", "lon"}) r.required(j, where, key);
  ObjectSpec o;
  o.file = resolve(base, r.string(j["file"], Reader::join(where, "file")));
  o.pose.lat = r.number(j["lat"], Reader::join(where, "lat"), -85.0, 85.0);
  o.pose.lon = r.number(j["lon"], Reader::join(where, "lon"), -360.0, 360.0);
  if (j.contains("height") && j.contains("agl")) r.fail(where, "give height (above the datum) or agl (above the ground), not both");
  o.agl = !j.contains("height");
  const char* h = o.agl ? "agl" : "height";
  if (j.contains(h)) o.pose.height = r.number(j[h], Reader::join(where, h), -kMaxObjectHeight, kMaxObjectHeight);
  if (j.contains("heading")) o.pose.heading_deg = r.number(j["heading"], Reader::join(where, "heading"), -kMaxAngle, kMaxAngle);
  if (j.contains("pitch")) o.pose.pitch_deg = r.number(j["pitch"], Reader::join(where, "pitch"), -kMaxAngle, kMaxAngle);
  if (j.contains("roll")) o.pose.roll_deg = r.number(j["roll"], Reader::join(where, "roll"), -kMaxAngle, kMaxAngle);
  if (j.contains("scale")) {
    o.pose.scale = r.number(j["scale"], Reader::join(where, "scale"), 0.0, kMaxScale);
    if (!(o.pose.scale > 0.0)) r.fail(Reader::join(where, "scale"), "must be > 0");
  }
  if (j.contains("opacity")) o.opacity = r.number(j["opacity"], Reader::join(where, "opacity"), 0.0, 1.0);
  if (j.contains("up")) {
    const std::string up = r.string(j["up"], Reader::join(where, "up"));
    if (up != "y" && up != "z") r.fail(Reader::join(where, "up"), "expected \"y\" or \"z\", got \"" + up + "\"");
    o.pose.up = up == "y" ? objects::UpAxis::kY : objects::UpAxis::kZ;
  }
  return o;
}

SceneCamera camera_of(const Reader& r, const json& j) {
  r.only_keys(j, "camera", {"lat", "lon", "alt", "agl", "heading", "pitch", "fov"});
  SceneCamera c;
  for (const char* key : {"lat", "lon", "alt"}) r.required(j, "camera", key);
  c.pose.lat = r.number(j["lat"], "camera.lat", -85.0, 85.0);
  c.pose.lon = r.number(j["lon"], "camera.lon", -360.0, 360.0);
  c.pose.alt = r.number(j["alt"], "camera.alt", -500.0, 1e6);
  if (j.contains("agl")) c.agl = r.boolean(j["agl"], "camera.agl");
  if (j.contains("heading")) c.pose.heading_deg = r.number(j["heading"], "camera.heading", -720.0, 720.0);
  if (j.contains("pitch")) c.pose.pitch_deg = r.number(j["pitch"], "camera.pitch", -90.0, 90.0);
  if (j.contains("fov")) c.fov_y_deg = r.number(j["fov"], "camera.fov", 1.0, 179.0);
  return c;
}

SceneStyle style_of(const Reader& r, const json& j) {
  r.only_keys(j, "render", {"size", "threshold", "lod_metric", "order", "tint", "window", "haze_km", "sun_azimuth",
                            "sun_elevation", "legend", "markers", "surface_triangles", "occlusion", "coherence",
                            "density_threshold", "density_error"});
  SceneStyle s;
  auto text = [&](const char* key, auto check) -> std::optional<std::string> {
    if (!j.contains(key)) return std::nullopt;
    const std::string v = r.string(j[key], std::string("render.") + key);
    try {
      check(v);
    } catch (const std::invalid_argument& e) {
      r.fail(std::string("render.") + key, e.what());
    }
    return v;
  };
  if (j.contains("size")) {
    int w = 0, h = 0;
    try {
      parse_size(r.string(j["size"], "render.size"), w, h);
    } catch (const std::invalid_argument& e) {
      r.fail("render.size", e.what());
    }
    s.width = w;
    s.height = h;
  }
  if (j.contains("threshold")) s.threshold = r.number(j["threshold"], "render.threshold", 1e-3, 1e7);
  if (j.contains("density_threshold")) {
    s.density_threshold = r.number(j["density_threshold"], "render.density_threshold", kMinDensityThreshold, kMaxDensityThreshold);
  }
  if (j.contains("density_error")) s.density_error = r.number(j["density_error"], "render.density_error", 0.0, kMaxDensityError);
  s.lod_metric = text("lod_metric", [](const std::string& v) { parse_metric(v); });
  s.order = text("order", [](const std::string& v) { parse_order(v); });
  s.tint = text("tint", [](const std::string& v) { parse_tint(v); });
  s.occlusion = text("occlusion", [](const std::string& v) { parse_on_off("occlusion", v); });
  s.coherence = text("coherence", [](const std::string& v) { parse_coherence(v); });
  if (j.contains("window")) {
    const double w = r.number(j["window"], "render.window", 2, 32768);
    const int n = static_cast<int>(w);
    if (n != w || (n & (n - 1)) != 0) r.fail("render.window", "must be a power of two");
    s.window = n;
  }
  if (j.contains("haze_km")) s.haze_km = r.number(j["haze_km"], "render.haze_km", 0.0, 1e5);
  if (j.contains("sun_azimuth")) s.sun_azimuth = r.number(j["sun_azimuth"], "render.sun_azimuth", -360.0, 360.0);
  if (j.contains("sun_elevation")) s.sun_elevation = r.number(j["sun_elevation"], "render.sun_elevation", 1e-3, 90.0);
  if (j.contains("legend")) s.legend = r.boolean(j["legend"], "render.legend");
  if (j.contains("markers")) s.markers = r.boolean(j["markers"], "render.markers");
  if (j.contains("surface_triangles")) {
    s.surface_triangles = static_cast<std::size_t>(r.number(j["surface_triangles"], "render.surface_triangles", 0, 1e8));
  }
  return s;
}

}  // namespace

SceneSpec parse_scene_json(const json& doc, const std::filesystem::path& base, const std::string& source) {
  const Reader r(source, "key");
  r.only_keys(doc, "", {"dem", "volumes", "objects", "camera", "render"});
  SceneSpec s;
  if (doc.contains("dem")) {
    const json& d = doc["dem"];
    if (d.is_string()) {
      s.dems.push_back(resolve(base, r.string(d, "dem")));
    } else if (d.is_array()) {
      for (std::size_t k = 0; k < d.size(); ++k) s.dems.push_back(resolve(base, r.string(d[k], Reader::at("dem", k))));
    } else {
      r.fail("dem", "expected a path or a list of paths");
    }
  }
  if (doc.contains("volumes")) {
    if (!doc["volumes"].is_array()) r.fail("volumes", "expected a list");
    std::size_t isosurfaces = 0;
    for (std::size_t k = 0; k < doc["volumes"].size(); ++k) {
      s.volumes.push_back(volume_of(r, doc["volumes"][k], Reader::at("volumes", k), base, isosurfaces));
    }
  }
  if (doc.contains("objects")) {
    if (!doc["objects"].is_array()) r.fail("objects", "expected a list");
    for (std::size_t k = 0; k < doc["objects"].size(); ++k) {
      s.objects.push_back(object_of(r, doc["objects"][k], Reader::at("objects", k), base));
    }
  }
  if (doc.contains("camera")) s.camera = camera_of(r, doc["camera"]);
  if (doc.contains("render")) s.style = style_of(r, doc["render"]);
  return s;
}

ObjectSpec parse_object(const std::string& text) {
  const auto fail = [&](const std::string& what) -> void {
    throw std::invalid_argument("--object '" + text + "': " + what);
  };
  const std::size_t at = text.rfind('@');
  if (at == std::string::npos || at == 0) fail("expected FILE@LAT,LON,AGL[,heading=..][,scale=..]");
  std::vector<std::string> parts;
  for (std::size_t b = at + 1;;) {
    const std::size_t e = text.find(',', b);
    parts.push_back(text.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  if (parts.size() < 3) fail("expected LAT,LON,AGL after '@'");
  // Built as the scene file's object and checked by the same code, so both accept the same values.
  json j = json::object();
  j["file"] = text.substr(0, at);
  const char* numbers[] = {"lat", "lon", "agl"};
  for (std::size_t k = 0; k < parts.size(); ++k) {
    std::string key, value = parts[k];
    if (k < 3) {
      key = numbers[k];
    } else {
      const std::size_t eq = value.find('=');
      if (eq == std::string::npos) fail("'" + value + "' is not KEY=VALUE");
      key = value.substr(0, eq);
      value = value.substr(eq + 1);
      if (key != "heading" && key != "pitch" && key != "roll" && key != "scale" && key != "opacity" && key != "up") {
        fail("unknown key '" + key + "' (known: heading, pitch, roll, scale, opacity, up)");
      }
      if (j.contains(key)) fail("'" + key + "' given twice");
    }
    if (key == "up") {
      j[key] = value;
      continue;
    }
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != value.size()) fail("'" + value + "' is not a number");
    j[key] = v;
  }
  return object_of(Reader("--object '" + text + "'", "key"), j, "", "");
}

SceneSpec load_scene_file(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw std::invalid_argument(source + ": cannot read (" + ec.message() + ")");
  if (size > (16u << 20)) throw std::invalid_argument(source + ": larger than 16 MiB; not a scene file");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(source + ": not valid JSON (byte " + std::to_string(e.byte) + ")");
  }
  return parse_scene_json(doc, path.parent_path(), source);
}

}  // namespace terravol::app::scene
