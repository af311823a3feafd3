#include "volume/surface_raster.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "volume/compare.h"

namespace terravol::volume {

namespace {

io::GeoRaster sized(int rows, int cols, double west, double north, double dlon, double dlat) {
  if (rows < 1 || cols < 1 || static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) > kMaxPoints) {
    throw std::invalid_argument("a raster of " + std::to_string(rows) + " x " + std::to_string(cols) +
                                " pixels is too large");
  }
  io::GeoRaster r;
  r.rows = rows;
  r.cols = cols;
  r.west = west;
  r.north = north;
  r.dlon = dlon;
  r.dlat = dlat;
  r.values.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols),
                  std::numeric_limits<float>::quiet_NaN());
  return r;
}

}  // namespace

io::GeoRaster footprint_raster(const Volume& volume) {
  const Lattice& l = volume.lattice;
  switch (volume.frame.kind) {
    case FrameKind::kNone:
      break;
    case FrameKind::kGeographic:
      return sized(l.dims[1], l.dims[0], l.origin[0] - 0.5 * l.spacing[0],
                   l.world(1, l.dims[1] - 1) + 0.5 * l.spacing[1], l.spacing[0], l.spacing[1]);
    case FrameKind::kEnu: {
      const VolumeFrame& f = volume.frame;
      const GeographicLib::LocalCartesian enu(f.origin_lat, f.origin_lon, f.origin_h);
      double south = 90, north = -90, west = 1e9, east = -1e9, lat = 0, lon = 0, h = 0;
      for (int c = 0; c < 8; ++c) {
        enu.Reverse(l.world(0, (c & 1) ? l.dims[0] - 1 : 0), l.world(1, (c & 2) ? l.dims[1] - 1 : 0),
                    l.world(2, (c & 4) ? l.dims[2] - 1 : 0), lat, lon, h);
        south = std::min(south, lat);
        north = std::max(north, lat);
        west = std::min(west, lon);
        east = std::max(east, lon);
      }
      double lat_n = 0, lon_e = 0;
      enu.Reverse(0.0, l.spacing[1], 0.0, lat_n, lon, h);
      enu.Reverse(l.spacing[0], 0.0, 0.0, lat, lon_e, h);
      const double dlat = lat_n - f.origin_lat, dlon = lon_e - f.origin_lon;
      const int rows = static_cast<int>(std::min(std::ceil((north - south) / dlat - 1e-6) + 1.0, 1e9));
      const int cols = static_cast<int>(std::min(std::ceil((east - west) / dlon - 1e-6) + 1.0, 1e9));
      return sized(rows, cols, west - 0.5 * dlon, north + 0.5 * dlat, dlon, dlat);
    }
  }
  throw std::invalid_argument(volume.name + ": the volume does not say where it lies (no frame)");
}

bool needs_ground(const Volume& volume, const SurfaceHeight& surface) {
  if (volume.frame.kind == FrameKind::kEnu) return surface.ref == HeightRef::kGround;
  return volume.frame.height != surface.ref;
}

std::size_t sample_surface(const Volume& volume, const SurfaceHeight& surface, const GroundFunction& ground,
                           io::GeoRaster& raster) {
  if (!std::isfinite(surface.metres)) throw std::invalid_argument("the surface's height must be finite");
  const bool with_ground = needs_ground(volume, surface);
  if (with_ground && !ground) {
    throw std::invalid_argument(volume.name + ": this height needs the ground under the volume (a DEM)");
  }
  const VolumeFrame& f = volume.frame;
  if (f.kind == FrameKind::kNone) throw std::invalid_argument(volume.name + ": the volume has no frame");
  std::unique_ptr<GeographicLib::LocalCartesian> enu;
  if (f.kind == FrameKind::kEnu) enu = std::make_unique<GeographicLib::LocalCartesian>(f.origin_lat, f.origin_lon, f.origin_h);
  // The surface's height in the volume's own height reference at (lat, lon).
  const HeightRef own = f.kind == FrameKind::kEnu ? HeightRef::kDatum : f.height;
  auto height = [&](double lat, double lon) {
    if (!with_ground) return surface.metres;
    const double g = ground(lat, lon);
    return own == HeightRef::kDatum ? surface.metres + g : surface.metres - g;
  };
  raster.values.assign(static_cast<std::size_t>(raster.rows) * static_cast<std::size_t>(raster.cols),
                       std::numeric_limits<float>::quiet_NaN());
  std::size_t filled = 0;
  for (int r = 0; r < raster.rows; ++r) {
    const double lat = raster.centre_lat(r);
    for (int c = 0; c < raster.cols; ++c) {
      const double lon = raster.centre_lon(c);
      const double h = height(lat, lon);
      double w0 = lon, w1 = lat, w2 = h;
      if (enu) enu->Forward(lat, lon, h, w0, w1, w2);
      const auto v = sample_trilinear(volume, w0, w1, w2);
      if (!v) continue;
      raster.values[static_cast<std::size_t>(r) * raster.cols + c] = static_cast<float>(*v);
      ++filled;
    }
  }
  return filled;
}

}  // namespace terravol::volume
