// Silhouettes of node boxes for Pyramid::hidden() (Greene 1996, section 5.2: "it is only
// necessary to tile a cube's polygonal silhouette"): the projection of a box's corners to window
// coordinates, and the exact convex hull of projected points.
#pragma once

#include <span>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace terravol::coverage {

// Maps points in clip coordinates (a GL projection matrix times eye coordinates: x, y, z, w) to
// window coordinates of a glViewport(0, 0, width, height): x_w = (x / w + 1) * width / 2,
// y_w = (y / w + 1) * height / 2 (pixels, origin bottom-left, as Pyramid takes them).
// Points behind the eye: returns false, and writes nothing, when any point has w <= 0 or a
// coordinate that is not finite. The projection of a box is the hull of its projected corners
// only when the whole box lies in front of the eye (w > 0 everywhere on it, which w > 0 at the
// corners ensures, w being linear): a box reaching the eye plane has no such silhouette, and the caller
// treats it as visible (such boxes contain or touch the eye's neighbourhood, so they are visible
// in practice; clipping them against the near plane would gain nothing). Points between the eye
// and the near plane (0 < w < near) project normally; their window coordinates may be huge, and
// Pyramid::hidden() answers false (visible) beyond kMaxCoordinate.
// window must hold clip.size() points.
bool project_to_window(std::span<const glm::dvec4> clip, int width, int height,
                       std::span<glm::dvec2> window);

// The convex hull of points (window coordinates, pixels) after snapping them to 1/256 px as the
// pyramid does, counterclockwise, without repeated or collinear vertices, every turn decided
// exactly. The vertices written are the snapped points (exact multiples of 1/256 px), so
// Pyramid::hidden(hull) tests exactly the region Pyramid::hidden(points) does: hidden() takes
// this hull of its points itself, and projected box corners may be passed to it directly.
// Writes at most points.size() vertices to hull (which must hold that many) and returns their
// number: 0 for no points, 1 when all coincide, 2 when all are collinear.
// Throws std::invalid_argument when there are more than kMaxVertices points or a point is not
// finite or beyond kMaxCoordinate.
int convex_hull(std::span<const glm::dvec2> points, std::span<glm::dvec2> hull);

}  // namespace terravol::coverage
