// Where a model stands on the terrain: its pose (position, orientation, scale) and its
// vertices placed in the scene frame (io/scene_frame.h).
#pragma once

#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

#include "io/scene_frame.h"
#include "volume/geometry.h"

namespace terravol::objects {

// Which of the model's axes points up. glTF says +Y up with the front facing +Z, and most
// interchange formats (OBJ, FBX, Collada after assimp) use +Y up; STL and PLY files from CAD
// and scanners are often +Z up with the front facing +Y.
enum class UpAxis : std::uint8_t { kY, kZ };

struct Pose {
  double lat = 0.0, lon = 0.0;  // degrees
  double height = 0.0;          // metres above the datum of the anchor (see place())
  double heading_deg = 0.0;     // the front's direction, clockwise from north
  double pitch_deg = 0.0;       // front up, about the model's right axis
  double roll_deg = 0.0;        // right side down, about the model's front axis
  double scale = 1.0;           // metres per model unit, > 0
  UpAxis up = UpAxis::kY;
};

// The model's frame turned to body axes (x right, y front, z up): +Y up (front +Z) maps
// (x, y, z) to (-x, z, y); +Z up (front +Y) is the identity. Both are rotations.
glm::dvec3 body_of(const glm::dvec3& model, UpAxis up);

// The anchor in the model's frame: the centre of the bottom face of the model's axis-aligned
// bounding box in body axes, given back in the model's frame. That point stands at (lat, lon,
// height), so height = the ground puts the model on the ground. Precondition: a non-empty mesh.
glm::dvec3 anchor_of(const volume::Mesh& model, UpAxis up);

// Places `model` (its frame, units) in `frame`: each vertex v goes to body axes, less the
// anchor, times scale, turned by roll (about y), then pitch (about x), then heading (about z,
// clockwise), as east-north-up metres about the pose's point (lat, lon, height) on the
// WGS84 ellipsoid's local tangent plane (GeographicLib::LocalCartesian), then to geodetic
// coordinates and into the scene frame (SceneFrame::to_scene), so it follows the frame's
// curvature drop exactly. Colours are kept, alphas times `opacity` in [0, 1]. Throws
// std::invalid_argument for scale <= 0 or not finite, opacity outside [0, 1] or a latitude
// outside (-90, 90).
volume::Mesh place(const volume::Mesh& model, const glm::dvec3& anchor, const Pose& pose, const io::SceneFrame& frame,
                   double opacity = 1.0);

}  // namespace terravol::objects
