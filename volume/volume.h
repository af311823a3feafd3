// A scalar volume (path loss, signal strength, or any float field) on a regular lattice, with
// the frame that places it over the Earth, and the map from lattice points to the scene frame.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/scene_frame.h"

namespace GeographicLib {
class LocalCartesian;
}

namespace terravol::volume {

// What the lattice's world coordinates (w0, w1, w2) mean.
enum class FrameKind : std::uint8_t {
  kNone,        // the file says nothing: the volume can be read and inspected, not placed
  kGeographic,  // w0 = longitude, w1 = latitude (degrees, WGS84), w2 = height (metres)
  kEnu,         // w0 = east, w1 = north, w2 = up (metres) in the local tangent frame about
                // VolumeFrame::origin (GeographicLib LocalCartesian)
};

// What a geographic frame's heights are measured from.
enum class HeightRef : std::uint8_t {
  kDatum,   // metres in the DEM's vertical datum (SRTM: EGM96 geoid)
  kGround,  // metres above the ground under the point (terrain-following lattice)
};

struct VolumeFrame {
  FrameKind kind = FrameKind::kNone;
  HeightRef height = HeightRef::kDatum;  // kGround only with kGeographic
  // kEnu only: the origin, lat and lon in degrees, h in metres in the DEM's vertical datum.
  // The ENU-to-geodetic conversion treats h as ellipsoidal, i.e. takes the geoid undulation
  // as constant over the volume (its variation is well under a metre over tens of km).
  double origin_lat = 0.0, origin_lon = 0.0, origin_h = 0.0;

  bool operator==(const VolumeFrame&) const = default;
};

// Parses a frame as given on a command line: "geographic" (heights above the datum),
// "geographic-agl" (heights above ground), "enu:LAT,LON,H", "none".
// Throws std::invalid_argument("...: what is wrong").
VolumeFrame parse_frame(const std::string& text);
std::string format_frame(const VolumeFrame& frame);  // the inverse of parse_frame

// A regular axis-aligned lattice: point (i, j, k), 0 <= i < dims[0] etc., lies at world
// coordinates origin[a] + index[a] * spacing[a]. Readers normalise to spacing > 0, so index
// axes run east (or with longitude), north and up.
struct Lattice {
  std::array<int, 3> dims{0, 0, 0};
  std::array<double, 3> origin{0.0, 0.0, 0.0};
  std::array<double, 3> spacing{1.0, 1.0, 1.0};

  std::size_t size() const {
    return static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
           static_cast<std::size_t>(dims[2]);
  }
  // Values are stored x fastest, then y, then z (VTK image data order).
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims[0]) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(k));
  }
  double world(int axis, double index) const { return origin[axis] + index * spacing[axis]; }
  bool operator==(const Lattice&) const = default;
};

// The largest lattice any reader or the propagation model accepts: 2^28 points (1 GiB of floats).
inline constexpr std::size_t kMaxPoints = std::size_t{1} << 28;

// Invariants: values.size() == lattice.size(); every dim >= 1.
struct Volume {
  std::string name;   // the scalar's name, e.g. "path_loss_db"
  std::string units;  // e.g. "dB", "dBm"; empty when unknown
  VolumeFrame frame;
  Lattice lattice;
  std::vector<float> values;
  float background = 0.0f;          // the value of voxels a sparse file leaves inactive
  std::size_t active_points = 0;    // how many points the file held as active (all, when dense)
  std::map<std::string, std::string> attributes;  // provenance (transmitter, model, ...)

  float at(int i, int j, int k) const { return values[lattice.index(i, j, k)]; }
};

// Metadata keys of the file frame. VDB grids carry them as grid metadata; VTK image data
// (.vti, legacy .vtk) as field-data arrays of the same names. See docs/architecture.md.
namespace keys {
inline constexpr char kFrame[] = "terravol:frame";    // string: "geographic" | "enu"
inline constexpr char kHeight[] = "terravol:height";  // string: "datum" | "ground"
inline constexpr char kOrigin[] = "terravol:origin";  // 3 doubles: lat, lon, h (enu only)
inline constexpr char kUnits[] = "terravol:units";    // string, e.g. "dB"
inline constexpr char kAttributePrefix[] = "terravol:attr:";  // + name: one string attribute
}  // namespace keys

// Ground height (metres, the DEM's vertical datum) at a latitude and longitude (degrees).
using GroundFunction = std::function<double(double lat, double lon)>;

// Maps lattice coordinates (fractional allowed, for isosurface vertices between points) to the
// geodetic position and to the scene frame. Thread-safe once built (const calls only).
class LatticeMapper {
 public:
  // Throws std::invalid_argument when the volume's frame is kNone, or heights are above
  // ground (kGround) and no ground function is given.
  LatticeMapper(const Volume& volume, const io::SceneFrame& scene, GroundFunction ground = {});
  ~LatticeMapper();
  LatticeMapper(LatticeMapper&&) noexcept;
  LatticeMapper& operator=(LatticeMapper&&) noexcept;

  io::Geodetic geodetic(double i, double j, double k) const;
  io::ScenePoint scene(double i, double j, double k) const { return scene_.to_scene(geodetic(i, j, k)); }

 private:
  VolumeFrame frame_;
  Lattice lattice_;
  io::SceneFrame scene_;
  GroundFunction ground_;
  std::unique_ptr<GeographicLib::LocalCartesian> enu_;
};

}  // namespace terravol::volume
