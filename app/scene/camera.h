// The render camera: a geodetic pose (latitude, longitude, altitude, heading, pitch) turned into
// a pinhole camera in the scene frame (io/scene_frame.h), for the tree and (render/vtk_camera.h)
// for VTK alike.
#pragma once

#include <string_view>

#include "io/scene_frame.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::app::scene {

// Where the camera is and where it looks, as the user gives it.
struct CameraPose {
  double lat = 0.0;          // degrees, [-85, 85] (the scene frame's limit)
  double lon = 0.0;          // degrees; any value, taken modulo 360
  double alt = 0.0;          // metres in the DEM's vertical datum, or above ground (--agl)
  double heading_deg = 0.0;  // degrees clockwise from north (0 north, 90 east); any value
  double pitch_deg = 0.0;    // degrees above the local horizon, [-90, 90] (-90 looks straight down)
  double roll_deg = 0.0;     // degrees, banking right: the view's up turns toward its right about
                             // the view direction; any value (camera paths: [-180, 180])
};

// Parses "LAT,LON,ALT,HEADING,PITCH" (five decimal numbers, no spaces required or allowed
// between them beyond what strtod skips). Throws std::invalid_argument with a one-line message
// naming the text and what is wrong (count, not a number, out of range).
CameraPose parse_camera_pose(std::string_view text);

// The near clipping plane for an eye `clearance` metres above the ground under it: 1/20 of the
// clearance, kept within [0.5, 200] m. Small enough that terrain rising in front of the eye is
// not clipped, large enough for a 24-bit depth buffer (the --order zbuffer reference).
double near_plane_for(double clearance_m);

// The camera in the scene frame. The eye is at (x_of_lon(lon), y_of_lat(lat), eye_height -
// curvature drop), the same drop the terrain gets. The view direction is built in the local
// tangent frame of the dropped surface at the eye (up = its normal, north = the meridian's
// tangent), so HEADING and PITCH are against the true local horizon, not the frame's xy plane
// (they differ by at most r/R: 0.5 degrees 32 km from the frame's origin).
// eye_height: metres in the DEM's datum (AGL already resolved). fov_y_deg in (0, 180);
// width, height > 0 pixels; near_plane > 0 metres.
mrbsp::Camera make_scene_camera(const io::SceneFrame& frame, const CameraPose& pose, double eye_height,
                                double fov_y_deg, int width, int height, double near_plane);

}  // namespace terravol::app::scene
