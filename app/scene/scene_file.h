// The scene file (JSON): everything a render shows — DEMs, RF volumes with their isosurfaces
// and slices, the camera and the render style — in one document (docs/scene-file.md).
// `terravol render --scene FILE` and `terravol view --scene FILE` read it; command-line
// options override what it says; relative paths are relative to the file.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/scene/camera.h"
#include "app/scene/style.h"
#include "density/transfer.h"
#include "objects/placement.h"
#include "volume/geometry.h"

namespace terravol::app::scene {

struct VolumeSpec {
  std::filesystem::path file;
  std::string field;              // grid or array name; empty: the file's first
  std::string frame;              // volume::parse_frame text overriding the file's; empty: the file's
  bool visible = true;
  std::vector<volume::IsoSpec> isosurfaces;
  std::vector<volume::SliceSpec> slices;
  // Drawn as a density (colour cubes, density/octree.h) with this transfer function.
  std::optional<density::DensitySpec> density;
};

// A model placed on the terrain (objects/). pose.height is metres above the ground under
// (lat, lon) when agl, else above the DEM's datum; the model's anchor (objects::anchor_of: the
// bottom centre of its box) stands there.
struct ObjectSpec {
  std::filesystem::path file;
  objects::Pose pose;
  bool agl = true;
  double opacity = 1.0;  // [0, 1], times the model's own alphas
};

// Parses the command line's "FILE@LAT,LON,AGL[,heading=DEG][,pitch=DEG][,roll=DEG][,scale=S]
// [,opacity=A][,up=y|z]" (heights above the ground). Throws std::invalid_argument("--object
// 'TEXT': what is wrong", one line).
ObjectSpec parse_object(const std::string& text);

struct SceneCamera {
  CameraPose pose;
  bool agl = false;  // pose.alt is above the ground under the camera
  double fov_y_deg = 45.0;
};

struct SceneSpec {
  std::vector<std::filesystem::path> dems;
  std::vector<VolumeSpec> volumes;
  std::vector<ObjectSpec> objects;
  std::optional<SceneCamera> camera;
  SceneStyle style;  // the "render" object
};

// Parses a scene document. `base` resolves relative paths; `source` names the document in
// errors. Throws std::invalid_argument("SOURCE: KEY.PATH: what is wrong") for unknown keys,
// wrong types and out-of-range values.
SceneSpec parse_scene_json(const nlohmann::json& doc, const std::filesystem::path& base, const std::string& source);

// Reads and parses a scene file (at most 16 MiB). Throws std::invalid_argument("PATH: ...")
// for a missing file, malformed JSON (with the byte offset) and whatever parse_scene_json rejects.
SceneSpec load_scene_file(const std::filesystem::path& path);

}  // namespace terravol::app::scene
