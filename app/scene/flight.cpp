#include "app/scene/flight.h"

#include <algorithm>
#include <cmath>

namespace terravol::app::scene {

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

CameraPose turned(CameraPose p, double heading_delta, double pitch_delta, const FlightSettings& s) {
  p.heading_deg = std::fmod(p.heading_deg + heading_delta, 360.0);
  if (p.heading_deg < 0.0) p.heading_deg += 360.0;
  p.pitch_deg = std::clamp(p.pitch_deg + pitch_delta, -s.max_pitch, s.max_pitch);
  return p;
}

}  // namespace

double flight_speed(double clearance, const FlightSettings& settings, bool boost) {
  const double v = std::clamp(clearance * settings.speed_factor, settings.min_speed, settings.max_speed);
  return boost ? v * settings.boost : v;
}

CameraPose fly(const CameraPose& pose, const FlightInput& input, double dt, const io::SceneFrame& frame,
               const std::function<double(double lat, double lon)>& ground, const FlightSettings& settings) {
  CameraPose p = turned(pose, input.turn * settings.turn_rate * dt, input.tilt * settings.tilt_rate * dt, settings);
  if (input.forward != 0 || input.right != 0 || input.up != 0) {
    const double step = flight_speed(pose.alt - ground(pose.lat, pose.lon), settings, input.boost) * dt;
    const double h = p.heading_deg * kDegree, pitch = p.pitch_deg * kDegree;
    // Metres east, north and up.
    const double along = input.forward * step;
    const double east = along * std::cos(pitch) * std::sin(h) + input.right * step * std::cos(h);
    const double north = along * std::cos(pitch) * std::cos(h) - input.right * step * std::sin(h);
    const double up = along * std::sin(pitch) + input.up * step;
    p.lat += north / frame.metres_per_degree_lat();
    p.lon += east / frame.metres_per_degree_lon();
    p.alt += up;
  }
  p.alt = std::max(p.alt, ground(p.lat, p.lon) + settings.min_clearance);
  return p;
}

CameraPose look(const CameraPose& pose, double dx_px, double dy_px, const FlightSettings& settings) {
  return turned(pose, dx_px * settings.look_deg_per_px, dy_px * settings.look_deg_per_px, settings);
}

}  // namespace terravol::app::scene
