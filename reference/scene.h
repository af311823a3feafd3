// What the independent reference (reference/check.h) reads of a scene file (docs/scene-file.md):
// the DEMs, per volume its file, field, frame and visible styles, and the objects' placements. Parsed here with
// nlohmann-json rather than through app/scene_file.h, which is part of what is checked. Only the
// keys the reference draws are read; the camera and render style come from the render's own
// outputs (its --export-vtp and --stats), and validating the file is the renderer's job: unknown
// keys are ignored here.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace terravol::reference {

struct IsoStyle {
  float value = 0;                       // the field's units
  std::array<std::uint8_t, 3> color{};   // sRGB
  double opacity = 0.5;                  // alpha = round(opacity * 255)
};

enum class SliceKind : std::uint8_t { kLat, kLon, kAlt, kAgl };

struct SliceStyle {
  SliceKind kind = SliceKind::kAgl;
  double value = 0;                  // degrees (lat, lon) or metres (alt above the datum, agl)
  std::string colormap = "viridis";  // volume::colormap_by_name
  double opacity = 0.5;
  std::optional<float> lo, hi;       // default: the volume's finite minimum and maximum
};

struct VolumeStyle {
  std::filesystem::path file;        // resolved against the scene file's folder
  std::string field;                 // empty: the file's first grid or array
  std::optional<std::string> frame;  // "geographic", "geographic-agl", "enu:LAT,LON,H"
  bool visible = true;
  std::vector<IsoStyle> isosurfaces;
  std::vector<SliceStyle> slices;
};

// A model placed on the terrain (docs/scene-file.md, "objects").
struct ObjectStyle {
  std::filesystem::path file;   // resolved against the scene file's folder
  double lat = 0, lon = 0;      // degrees: where the anchor stands
  double agl = 0;               // metres above the ground there, unless `height` is given
  std::optional<double> height; // metres above the DEM's datum
  double heading = 0, pitch = 0, roll = 0;  // degrees
  double scale = 1, opacity = 1;
  bool up_z = false;            // "up": "z" (else "y")
};

// The sun the terrain and the objects are lit by (the scene file's render.sun_azimuth and
// render.sun_elevation; the renderer's ambient share).
struct Sun {
  double azimuth_deg = 315, elevation_deg = 35, ambient = 0.35;
};

struct Scene {
  std::vector<std::filesystem::path> dems;  // resolved against the scene file's folder
  std::vector<VolumeStyle> volumes;
  std::vector<ObjectStyle> objects;
  Sun sun;
};

// Reads a scene file. Isosurfaces without a colour take volume::default_isosurface_color of
// their index within the volume, as docs/scene-file.md says ("a colour-blind-safe palette by
// index"). Throws std::runtime_error("FILE: what is wrong") when the file cannot be read, is not
// JSON, or a key the reference needs has the wrong type or is missing.
Scene read_scene(const std::filesystem::path& file);

}  // namespace terravol::reference
