// The flight controls of `terravol view`: a geodetic camera pose moved by the keys held down and
// turned by mouse drags, at a speed proportional to the height above the ground. No VTK here:
// the viewer turns key and mouse events into FlightInput and look(), and these into poses.
#pragma once

#include <functional>

#include "app/scene/camera.h"
#include "io/scene_frame.h"

namespace terravol::app::scene {

// What is held down at one instant; each axis is -1, 0 or +1 (both keys of an axis cancel).
struct FlightInput {
  int forward = 0;     // +1 forward along the view (W), -1 back (S)
  int right = 0;       // +1 strafe right (D), -1 left (A); horizontal, across the heading
  int up = 0;          // +1 up (R, PageUp), -1 down (F, PageDown); vertical
  int turn = 0;        // +1 turn right (Right arrow), -1 left (Left arrow)
  int tilt = 0;        // +1 look up (Up arrow), -1 down (Down arrow)
  bool boost = false;  // Shift: FlightSettings::boost times faster

  bool moving() const { return forward != 0 || right != 0 || up != 0 || turn != 0 || tilt != 0; }
};

struct FlightSettings {
  double speed_factor = 1.0;     // metres per second for each metre above the ground
  double min_speed = 20.0;       // m/s, however near the ground
  double max_speed = 20000.0;    // m/s
  double boost = 4.0;            // speed multiplier while Shift is held
  double turn_rate = 60.0;       // degrees of heading per second
  double tilt_rate = 45.0;       // degrees of pitch per second
  double look_deg_per_px = 0.15; // mouse drag, degrees per pixel
  double max_pitch = 89.0;       // degrees, |pitch| is kept below it
  double min_clearance = 2.0;    // metres the eye is kept above the ground
};

// Metres per second at `clearance` metres above the ground: clearance * speed_factor (times
// boost), within [min_speed, max_speed] (also times boost).
double flight_speed(double clearance, const FlightSettings& settings, bool boost);

// The pose after `dt` seconds (>= 0) of `input`. Displacements are taken in the scene frame's
// metres (`frame`'s metres per degree at its origin, the same scale the terrain is drawn at):
// forward and back along the view direction, pitch included (a flight camera: looking down and
// pressing W descends); strafing horizontally at right angles to the heading; up and down along
// the vertical. Turning and tilting happen first, at turn_rate and tilt_rate. The speed is
// flight_speed() at the clearance above ground(lat, lon) (metres in the DEM's datum) before the
// move, and the eye ends at least min_clearance above the ground at its new place. Heading is
// returned in [0, 360), pitch within +-max_pitch; lat and lon are not clamped.
CameraPose fly(const CameraPose& pose, const FlightInput& input, double dt, const io::SceneFrame& frame,
               const std::function<double(double lat, double lon)>& ground, const FlightSettings& settings);

// The pose after a mouse drag of (dx, dy) pixels, x to the right and y UP (VTK's display
// coordinates): dragging right turns right, dragging up looks up, look_deg_per_px per pixel.
// Heading in [0, 360), pitch within +-max_pitch.
CameraPose look(const CameraPose& pose, double dx_px, double dy_px, const FlightSettings& settings);

}  // namespace terravol::app::scene
