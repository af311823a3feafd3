#include "io/geographic.h"

#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "io/bytes.h"
#include "io/error.h"

namespace terravol::io {

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;
}

Grid to_geographic(const Grid& src, const std::string& source) {
  if (src.georef.crs == Crs::kGeographic) return src;
  const Georef& g = src.georef;
  const int zone = g.utm_zone;
  const bool north = g.utm_north;
  if (zone < 1 || zone > 60) throw FormatError(source, "UTM zone " + std::to_string(zone) + " is not in 1..60");
  if (!(g.dx > 0 && g.dy > 0)) throw FormatError(source, "grid spacing must be positive");

  // Geographic bounding box of the footprint: the grid's rim samples, inverse-projected.
  double south = std::numeric_limits<double>::max(), northb = -south, west = south, east = -south;
  auto visit = [&](int r, int c) {
    double lat = 0, lon = 0;
    GeographicLib::UTMUPS::Reverse(zone, north, g.x0 + c * g.dx, g.y0 - r * g.dy, lat, lon);
    south = std::min(south, lat);
    northb = std::max(northb, lat);
    west = std::min(west, lon);
    east = std::max(east, lon);
  };
  for (int c = 0; c < src.cols; ++c) {
    visit(0, c);
    visit(src.rows - 1, c);
  }
  for (int r = 0; r < src.rows; ++r) {
    visit(r, 0);
    visit(r, src.cols - 1);
  }

  const auto& e = GeographicLib::Ellipsoid::WGS84();
  const double mid = 0.5 * (south + northb);
  const double dlat = g.dy / (e.MeridionalCurvatureRadius(mid) * kDeg);
  const double dlon = g.dx / (e.TransverseCurvatureRadius(mid) * std::cos(mid * kDeg) * kDeg);
  const long long rows = static_cast<long long>(std::floor((northb - south) / dlat + 1e-9)) + 1;
  const long long cols = static_cast<long long>(std::floor((east - west) / dlon + 1e-9)) + 1;
  check_dimensions(source, rows, cols, kMaxSamples);

  Grid out;
  out.format = src.format;
  out.vertical_datum = src.vertical_datum;
  out.checksum_errors = src.checksum_errors;
  out.notes = src.notes;
  out.georef = {Crs::kGeographic, 0, true, west, northb, dlon, dlat};
  out.allocate(static_cast<int>(rows), static_cast<int>(cols));

  for (int r = 0; r < out.rows; ++r) {
    const double lat = northb - r * dlat;
    for (int c = 0; c < out.cols; ++c) {
      const double lon = west + c * dlon;
      int zone_out = 0;
      bool north_out = true;
      double x = 0, y = 0, gamma = 0, k = 0;
      GeographicLib::UTMUPS::Forward(lat, lon, zone_out, north_out, x, y, gamma, k, zone);
      if (north_out != north) {  // keep the source hemisphere's false northing
        y += north ? -GeographicLib::UTMUPS::UTMShift() : GeographicLib::UTMUPS::UTMShift();
      }
      const double fc = (x - g.x0) / g.dx, fr = (g.y0 - y) / g.dy;
      const int c0 = static_cast<int>(std::floor(fc)), r0 = static_cast<int>(std::floor(fr));
      const double tc = fc - c0, tr = fr - r0;
      double sum = 0, wsum = 0;
      bool any_void = false;
      for (int k2 = 0; k2 < 4; ++k2) {
        const int rr = r0 + (k2 >> 1), cc = c0 + (k2 & 1);
        if (rr < 0 || rr >= src.rows || cc < 0 || cc >= src.cols) continue;
        const double w = ((k2 >> 1) ? tr : 1 - tr) * ((k2 & 1) ? tc : 1 - tc);
        const std::size_t j = src.index(rr, cc);
        if (src.mask[j] == Sample::kValid) {
          sum += w * src.heights[j];
          wsum += w;
        } else if (src.mask[j] == Sample::kVoid && w > 0) {
          any_void = true;
        }
      }
      const std::size_t i = out.index(r, c);
      if (wsum > 1e-9) {
        out.heights[i] = static_cast<float>(sum / wsum);
      } else {
        out.mask[i] = any_void ? Sample::kVoid : Sample::kOutside;
      }
    }
  }
  char note[200];
  std::snprintf(note, sizeof note,
                "resampled bilinearly from UTM zone %d%c (%.6g x %.6g m) to a geographic grid of "
                "%.4g\" x %.4g\"",
                zone, north ? 'N' : 'S', g.dx, g.dy, dlon * 3600.0, dlat * 3600.0);
  out.notes.emplace_back(note);
  return out;
}

}  // namespace terravol::io
