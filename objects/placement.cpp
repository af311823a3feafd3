#include "objects/placement.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace terravol::objects {

glm::dvec3 body_of(const glm::dvec3& m, UpAxis up) { return up == UpAxis::kY ? glm::dvec3(-m.x, m.z, m.y) : m; }

glm::dvec3 anchor_of(const volume::Mesh& model, UpAxis up) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::dvec3& v : model.vertices) {
    const glm::dvec3 b = body_of(v, up);
    lo = glm::min(lo, b);
    hi = glm::max(hi, b);
  }
  const glm::dvec3 a((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, lo.z);
  // body_of is its own inverse for kY ((-x, z, y) twice is (x, y, z)) and the identity for kZ.
  return body_of(a, up);
}

volume::Mesh place(const volume::Mesh& model, const glm::dvec3& anchor, const Pose& pose, const io::SceneFrame& frame,
                   double opacity) {
  if (!(pose.scale > 0.0) || !std::isfinite(pose.scale)) throw std::invalid_argument("scale must be > 0");
  if (!(opacity >= 0.0 && opacity <= 1.0)) throw std::invalid_argument("opacity must be within [0, 1]");
  if (!(std::abs(pose.lat) < 90.0)) throw std::invalid_argument("latitude must be within (-90, 90)");
  const double d = glm::pi<double>() / 180.0;
  const double ch = std::cos(pose.heading_deg * d), sh = std::sin(pose.heading_deg * d);
  const double cp = std::cos(pose.pitch_deg * d), sp = std::sin(pose.pitch_deg * d);
  const double cr = std::cos(pose.roll_deg * d), sr = std::sin(pose.roll_deg * d);
  const glm::dvec3 a = body_of(anchor, pose.up);
  const GeographicLib::LocalCartesian enu(pose.lat, pose.lon, pose.height);
  volume::Mesh out;
  out.triangles = model.triangles;
  out.vertices.reserve(model.vertices.size());
  for (const glm::dvec3& v : model.vertices) {
    const glm::dvec3 b = (body_of(v, pose.up) - a) * pose.scale;
    // Roll about y (right side down: +x towards -z), pitch about x (front up: +y towards +z),
    // heading about z clockwise (+y, north, towards +x, east).
    const glm::dvec3 r(cr * b.x + sr * b.z, b.y, -sr * b.x + cr * b.z);
    const glm::dvec3 p(r.x, cp * r.y - sp * r.z, sp * r.y + cp * r.z);
    const glm::dvec3 e(ch * p.x + sh * p.y, -sh * p.x + ch * p.y, p.z);
    double lat = 0, lon = 0, h = 0;
    enu.Reverse(e.x, e.y, e.z, lat, lon, h);
    const io::ScenePoint s = frame.to_scene({lat, lon, h});
    out.vertices.emplace_back(s.x, s.y, s.z);
  }
  out.colors = model.colors;
  if (opacity < 1.0) {
    for (glm::u8vec4& c : out.colors) c.a = static_cast<std::uint8_t>(std::lround(c.a * opacity));
  }
  return out;
}

}  // namespace terravol::objects
