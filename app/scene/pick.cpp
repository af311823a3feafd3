// Picking by ray casting (pick.h): Moller and Trumbore 1997 for the triangles.
#include "app/scene/pick.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <limits>

namespace terravol::app::scene {

Ray pixel_ray(const mrbsp::Camera& camera, double x, double y) {
  const glm::dvec3 f = glm::normalize(camera.forward), up = glm::normalize(camera.up);
  const glm::dvec3 right = glm::normalize(glm::cross(f, up));
  const double half = std::tan(camera.fov_y_deg * 0.5 * std::acos(-1.0) / 180.0);
  const double aspect = static_cast<double>(camera.width) / static_cast<double>(camera.height);
  const double sx = (2.0 * (x + 0.5) / camera.width - 1.0) * half * aspect;
  const double sy = (2.0 * (y + 0.5) / camera.height - 1.0) * half;
  return {camera.eye, glm::normalize(f + sx * right + sy * up)};
}

namespace {

// Distance along the ray to triangle (a, b, c), or infinity when it misses (both sides count).
double hit_triangle(const Ray& r, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const glm::dvec3 e1 = b - a, e2 = c - a;
  const glm::dvec3 p = glm::cross(r.direction, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-12) return kInf;
  const double inv = 1.0 / det;
  const glm::dvec3 s = r.origin - a;
  const double u = glm::dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return kInf;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(r.direction, q) * inv;
  if (v < 0.0 || u + v > 1.0) return kInf;
  const double t = glm::dot(e2, q) * inv;
  return t > 0.0 ? t : kInf;
}

}  // namespace

std::optional<PickPoint> pick(const Ray& ray, const io::SceneFrame& frame,
                              const std::function<double(double, double)>& ground,
                              const std::function<bool(double, double)>& inside, const volume::Mesh& surfaces,
                              double max_distance) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto at = [&](double t) {
    const glm::dvec3 p = ray.origin + t * ray.direction;
    return frame.to_geodetic({p.x, p.y, p.z});
  };
  // Above the ground at t (outside the window counts as above: nothing to hit there).
  auto above = [&](double t) {
    const io::Geodetic g = at(t);
    return !inside(g.lat, g.lon) || g.h > ground(g.lat, g.lon);
  };
  double terrain = kInf;
  if (above(0.0)) {
    for (double t0 = 0.0, t = 2.0; t0 < max_distance; t0 = t, t += 2.0 + 0.002 * t) {
      if (above(t)) continue;
      double lo = t0, hi = t;  // above at lo, below at hi
      while (hi - lo > 1e-3) {
        const double mid = 0.5 * (lo + hi);
        (above(mid) ? lo : hi) = mid;
      }
      terrain = lo;  // the last point above: never below the ground, so heights above it are >= 0
      break;
    }
  }
  double surface = kInf;
  for (std::size_t n = 0; n + 2 < surfaces.triangles.size(); n += 3) {
    const double t = hit_triangle(ray, surfaces.vertices[surfaces.triangles[n]], surfaces.vertices[surfaces.triangles[n + 1]],
                                  surfaces.vertices[surfaces.triangles[n + 2]]);
    if (t < surface) surface = t;
  }
  const double t = std::min(terrain, surface);
  if (!std::isfinite(t)) return std::nullopt;
  PickPoint p;
  p.where = at(t);
  p.distance = t;
  p.on_surface = surface < terrain;
  return p;
}

}  // namespace terravol::app::scene
