// Camera paths for `terravol fly` (docs/camera-paths.md): a JSON file of keyframes (time, position,
// orientation or a look-at target, field of view, LOD threshold) and the smooth camera between
// them. Positions follow a centripetal Catmull-Rom spline (Yuksel, Schaefer and Keyser, "On the
// parameterization of Catmull-Rom curves", 2009) in the scene frame; orientations a squad-style
// quaternion spline (Shoemake, "Animating rotation with quaternion curves", 1985) with tangents
// taken for unequal key spacing, so the camera is C1 in time at every key.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "app/scene/camera.h"
#include "io/scene_frame.h"

namespace terravol::app::scene {

// A point the camera looks at.
struct LookAt {
  double lat = 0.0, lon = 0.0;  // degrees
  double alt = 0.0;             // metres in the DEM's datum, or above the ground when agl
  bool agl = false;
};

// One keyframe as the file gives it.
struct PathKey {
  double t = 0.0;               // seconds; keys strictly increasing, at least kMinKeyGap apart
  double lat = 0.0, lon = 0.0;  // degrees, lat in [-85, 85]
  double alt = 0.0;             // metres in the DEM's datum, or above the ground (> 0) when agl
  bool agl = false;
  // Orientation: degrees, heading clockwise from north, pitch above the local horizon in
  // [-90, 90], roll positive banking right in [-180, 180]. With look_at, heading and pitch are
  // those of the line from the eye to the target at this key (roll still applies).
  double heading_deg = 0.0, pitch_deg = 0.0, roll_deg = 0.0;
  std::optional<LookAt> look_at;
  std::optional<double> fov_y_deg;  // vertical, (0, 180); absent: the path's default
  std::optional<double> threshold;  // LOD threshold in pixels (> 0); absent: the export's
};

// kKeys: the camera is at each key's position at the key's time. kConstant: it moves at one
// speed from the first key to the last (same start and end times); the other keys' times only
// order them, and every other quantity (orientation, fov, threshold) stays attached to the
// place along the path where its key is.
enum class PathSpeed { kKeys, kConstant };

inline constexpr double kMinKeyGap = 0.01;  // seconds between consecutive keys

// A path file: the scene (a file, or a scene document inline) and the keys.
struct CameraPathFile {
  std::filesystem::path scene_file;  // resolved against base_dir; empty when the scene is inline
  nlohmann::json scene;              // the inline scene document (null with scene_file)
  std::filesystem::path base_dir;    // the path file's folder: relative paths of an inline scene
  std::vector<PathKey> keys;         // at least two
  PathSpeed speed = PathSpeed::kKeys;
};

// Parses a path document: {"scene": "FILE" | {...}, "keys": [{...}, ...], "speed": "keys" |
// "constant"}. Throws std::invalid_argument("SOURCE: keys[3].pitch: what is wrong") for
// unknown fields, wrong types, values out of range, missing fields, keys out of order or
// closer than kMinKeyGap. Does not read the scene.
CameraPathFile parse_camera_path(const nlohmann::json& doc, const std::filesystem::path& base_dir,
                                 const std::string& source);

// Reads and parses a path file (at most 16 MiB). Throws std::invalid_argument("PATH: ...") for a
// missing file, malformed JSON (with the byte offset) and whatever parse_camera_path rejects.
CameraPathFile load_camera_path(const std::filesystem::path& path);

// The path document for keys recorded elsewhere (the viewer): "scene" is `scene` as given (a
// path string, relative to where the path file will be, or an inline scene object); keys with
// only the fields they use; parse_camera_path reads it back to the same keys.
nlohmann::json path_to_json(const nlohmann::json& scene, const std::vector<PathKey>& keys,
                            PathSpeed speed = PathSpeed::kKeys);

// The camera at one instant.
struct PathSample {
  CameraPose pose;        // alt: above the ground when CameraPath::agl(), else in the datum;
                          // roll_deg within [-180, 180]
  double fov_y_deg = 45.0;
  double threshold = 0.0;  // pixels
};

class CameraPath {
 public:
  // Metres in the DEM's datum at a point (the scene's ground).
  using Ground = std::function<double(double lat, double lon)>;

  // Positions are interpolated in `frame` (x and y metres, and the altitude channel). When every
  // key is agl, the altitude channel is the height above the ground (the camera follows the
  // terrain between keys); otherwise it is the height in the datum, agl keys resolved with
  // `ground` at their own point. `ground` is also used for look-at targets and eyes with agl;
  // it may be empty when no key needs it. Missing fov and threshold take the defaults.
  // Throws std::invalid_argument ("keys[2]: ...") for fewer than two keys, keys out of order or
  // too close, and, with kConstant, consecutive keys at the same position or a look-at target at
  // the eye.
  CameraPath(std::vector<PathKey> keys, const io::SceneFrame& frame, const Ground& ground, PathSpeed speed,
             double default_fov_deg, double default_threshold);

  double start() const { return times_.front(); }  // seconds: the first key's time
  double end() const { return times_.back(); }     // seconds: the last key's time
  bool agl() const { return agl_; }
  double length_m() const { return length_; }  // along the spline in the frame (altitude included)

  // The camera at time t (clamped to [start, end]): exactly each key's position, orientation,
  // fov and threshold at its time (kKeys), C1 in between. Heading in [0, 360).
  PathSample at(double t) const;

 private:
  double knot_of_time(double t) const;  // spline parameter u of time t
  double time_of_knot(double u) const;  // key time tau of parameter u (kConstant)
  glm::dvec3 position(double u) const;    // x, y and the altitude channel at u

  io::SceneFrame frame_;
  PathSpeed speed_;
  bool agl_ = false;
  std::vector<double> times_;                      // key times
  std::vector<double> knots_;                      // centripetal knots u_i, one per key
  std::vector<glm::dvec3> points_;                 // x, y, altitude channel, one per key
  std::vector<glm::dquat> rotations_;              // east-north-up, one hemisphere along the path
  std::vector<glm::dquat> out_ctrl_, in_ctrl_;     // squad inner points per key
  std::vector<double> fov_, threshold_;
  std::vector<double> u_slope_, t_slope_, fov_slope_, threshold_slope_;  // Hermite slopes per key
  std::vector<double> arc_u_, arc_s_;  // arc-length table (kConstant)
  double length_ = 0.0;
};

}  // namespace terravol::app::scene
