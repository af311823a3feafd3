#include "app/scene/camera.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

namespace terravol::app::scene {

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

}  // namespace

CameraPose parse_camera_pose(std::string_view text) {
  const std::string s(text);
  const std::string what = "--camera " + s + ": ";
  std::vector<double> v;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = s.find(',', start);
    const std::string field = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(field.c_str(), &end);
    if (field.empty() || end != field.c_str() + field.size() || errno == ERANGE || !std::isfinite(x)) {
      throw std::invalid_argument(what + "'" + field + "' is not a number (expected LAT,LON,ALT,HEADING,PITCH)");
    }
    v.push_back(x);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 5) {
    throw std::invalid_argument(what + "expected 5 numbers LAT,LON,ALT,HEADING,PITCH, got " + std::to_string(v.size()));
  }
  CameraPose p{v[0], v[1], v[2], v[3], v[4]};
  if (p.lat < -85.0 || p.lat > 85.0) throw std::invalid_argument(what + "latitude must be within -85..85 degrees");
  if (p.pitch_deg < -90.0 || p.pitch_deg > 90.0) throw std::invalid_argument(what + "pitch must be within -90..90 degrees");
  return p;
}

double near_plane_for(double clearance_m) { return std::clamp(clearance_m / 20.0, 0.5, 200.0); }

mrbsp::Camera make_scene_camera(const io::SceneFrame& frame, const CameraPose& pose, double eye_height,
                                double fov_y_deg, int width, int height, double near_plane) {
  const double x = frame.x_of_lon(pose.lon), y = frame.y_of_lat(pose.lat);
  const double r = frame.curvature_radius();
  mrbsp::Camera c;
  c.eye = glm::dvec3(x, y, eye_height - frame.curvature_drop(x, y));
  // Local tangent frame of z = -(x^2 + y^2) / 2R at the eye.
  const glm::dvec3 up = glm::normalize(glm::dvec3(x / r, y / r, 1.0));
  const glm::dvec3 north = glm::normalize(glm::dvec3(0.0, 1.0, 0.0) - up.y * up);
  const glm::dvec3 east = glm::cross(north, up);
  const double h = pose.heading_deg * kDegree, p = pose.pitch_deg * kDegree;
  const glm::dvec3 level = std::sin(h) * east + std::cos(h) * north;  // horizontal, along the heading
  c.forward = glm::normalize(std::cos(p) * level + std::sin(p) * up);
  c.up = glm::normalize(std::cos(p) * up - std::sin(p) * level);
  if (pose.roll_deg != 0.0) {
    const double roll = pose.roll_deg * kDegree;
    c.up = glm::normalize(std::cos(roll) * c.up + std::sin(roll) * glm::cross(c.forward, c.up));
  }
  c.fov_y_deg = fov_y_deg;
  c.width = width;
  c.height = height;
  c.near_plane = near_plane;
  return c;
}

}  // namespace terravol::app::scene
