// Picking: the point under a pixel, on the terrain or on the nearest isosurface or slice in
// front of it (what a Ctrl-click in `terravol view` shows). A ray cast on the CPU, since the
// tree is drawn without a depth buffer: the ray marched against the DEM's ground, and tested
// against every triangle of the visible volumes' geometry (Moller and Trumbore 1997, "Fast,
// minimum storage ray/triangle intersection", J. Graphics Tools 2(1)).
#pragma once

#include <glm/vec3.hpp>

#include <functional>
#include <optional>

#include "io/scene_frame.h"
#include "mrbsp/terrain_tree.h"
#include "volume/geometry.h"

namespace terravol::app::scene {

// The ray through the centre of pixel (x, y) of `camera`'s viewport, x from the left and y from
// the BOTTOM row (VTK's event positions): origin the eye, direction a unit vector in the scene
// frame.
struct Ray {
  glm::dvec3 origin{0.0}, direction{0.0, 1.0, 0.0};
};
Ray pixel_ray(const mrbsp::Camera& camera, double x, double y);

struct PickPoint {
  io::Geodetic where;      // lat, lon and height above the datum of the point hit
  double distance = 0;     // from the ray's origin, metres
  bool on_surface = false; // on an isosurface or slice (else on the terrain)
};

// The nearest hit along `ray` of the terrain (ground(lat, lon), metres above the datum, tried
// where `inside(lat, lon)`; the ray is marched in steps of 2 m + 0.2% of the distance out to
// max_distance, and the crossing refined by bisection to the last point above it, within 1 mm)
// or of a triangle of `surfaces`
// (scene frame). Nothing when the ray hits neither.
std::optional<PickPoint> pick(const Ray& ray, const io::SceneFrame& frame,
                              const std::function<double(double, double)>& ground,
                              const std::function<bool(double, double)>& inside, const volume::Mesh& surfaces,
                              double max_distance);

}  // namespace terravol::app::scene
