// The path of a link profile drawn over the terrain (the viewer's Shift-click profile,
// volume/profile.h): a low wall that follows the ground from one end to the other, coloured by
// the clearance of the first Fresnel zone above each sample, merged into the terrain's tree as
// one more surface so that it is drawn in the tree's exact back-to-front order.
#pragma once

#include <cstdint>
#include <functional>

#include "io/scene_frame.h"
#include "volume/geometry.h"
#include "volume/profile.h"

namespace terravol::app::scene {

// The tree's surface id of the path: above every id VolumeLayer gives (volume << 16 | ..., for
// fewer than 65535 volumes).
inline constexpr std::uint32_t kProfilePathId = 0xFFFFu << 16;

// The wall's colours (opaque): 60% of F1 clear above the sample, the line of sight clear but
// not 60% of F1, and the terrain above the line of sight.
inline constexpr glm::u8vec4 kPathClear{0, 200, 255, 255};
inline constexpr glm::u8vec4 kPathGrazing{255, 200, 0, 255};
inline constexpr glm::u8vec4 kPathObstructed{255, 0, 200, 255};

// The wall's size for a path `distance_m` long: half of its width and its height above the
// ground, metres: max(15, distance / 250) and twice that, so that it stays a few pixels wide
// when the whole path is in view.
double path_half_width(double distance_m);

// The wall along `profile` (its samples' lat, lon and clearance, in order) from (from_lat,
// from_lon) to (to_lat, to_lon), degrees: at each end and each sample, a cross-section from 3 m
// below ground(lat, lon) (metres above the datum) up both sides to 2 * path_half_width above
// it, across the path (perpendicular to the ends' chord in the scene frame), and over the top;
// three quads (six triangles) between each pair of consecutive cross-sections. Each
// cross-section takes the colour of its sample's clearance (the ends, their nearest sample's;
// a profile without samples, kPathClear). Scene frame, metres, per-vertex RGBA.
// Precondition: the ends at least 1 m apart (std::invalid_argument).
volume::Mesh profile_path_mesh(const volume::LinkProfile& profile, double from_lat, double from_lon, double to_lat,
                               double to_lon, const io::SceneFrame& frame,
                               const std::function<double(double, double)>& ground);

}  // namespace terravol::app::scene
