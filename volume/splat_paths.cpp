// SPLAT!'s profiles of an area map (splat_paths.h). Written from SPLAT! 1.4.2's behaviour as
// splat_paths.h states it; the checks are SPLAT!'s own -ano files (every point it wrote must be
// reproduced at its position, `terravol splat-volume --check-itm`, tests/volume/splat_cli_test.cpp).
// Longitudes are SPLAT!'s here: degrees west-positive, [0, 360).
#include "volume/splat_paths.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "volume/itm.h"

namespace terravol::volume {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kEarthMiles = 3959.0;        // SPLAT!'s sphere
constexpr double kMetresPerMile = 1609.344;
constexpr double kFeetPerMetre = 3.28084;     // SPLAT! keeps heights in feet in between
constexpr double kMetresPerFoot = 0.3048;

// a - b, degrees, wrapped into (-180, 180).
double lon_diff(double a, double b) {
  double d = a - b;
  if (d <= -180.0) d += 360.0;
  if (d >= 180.0) d -= 360.0;
  return d;
}

// Great-circle distance (miles) and azimuth (radians from north, clockwise) on SPLAT!'s
// sphere; longitudes west-positive.
double distance_miles(double lat1, double lon1, double lat2, double lon2) {
  lat1 *= kDeg, lon1 *= kDeg, lat2 *= kDeg, lon2 *= kDeg;
  return kEarthMiles * std::acos(std::sin(lat1) * std::sin(lat2) + std::cos(lat1) * std::cos(lat2) * std::cos(lon1 - lon2));
}

double azimuth_rad(double lat1, double lon1, double lat2, double lon2) {
  lat1 *= kDeg, lon1 *= kDeg, lat2 *= kDeg, lon2 *= kDeg;
  const double beta = std::acos(std::sin(lat1) * std::sin(lat2) + std::cos(lat1) * std::cos(lat2) * std::cos(lon1 - lon2));
  const double fraction = std::clamp((std::sin(lat2) - std::sin(lat1) * std::cos(beta)) / (std::cos(lat1) * std::sin(beta)), -1.0, 1.0);
  double azimuth = std::acos(fraction);
  double diff = lon2 - lon1;
  if (diff <= -M_PI) diff += 2.0 * M_PI;
  if (diff >= M_PI) diff -= 2.0 * M_PI;
  if (diff > 0.0) azimuth = 2.0 * M_PI - azimuth;  // westward
  return azimuth;
}

// acos(x / y) in [0, 2 pi): pi + acos(x / y) for y < 0.
double arc_cos(double x, double y) {
  if (y > 0.0) return std::acos(x / y);
  if (y < 0.0) return M_PI + std::acos(x / y);
  return 0.0;
}

class Radials {
 public:
  Radials(const io::Grid& dem, double tx_lat, double tx_lon_west, double range_miles, int cells_per_degree)
      : dem_(dem), tx_lat_(tx_lat), tx_lon_(tx_lon_west), range_(range_miles), ppd_(cells_per_degree),
        marked_(dem.size(), 0) {
    if (cells_per_degree == 1200) {
      samples_per_radian_ = 68755.0;
    } else if (cells_per_degree == 3600) {
      samples_per_radian_ = 206265.0;
    } else {
      throw std::invalid_argument("SPLAT! profiles: cells per degree must be 1200 or 3600");
    }
  }

  // One radial to (lat, lon_west), its new points to visit.
  void run(double lat, double lon_west, const std::function<void(const SplatPathPoint&)>& visit) {
    read_path(lat, lon_west);
    const std::size_t length = lat_.size();
    for (std::size_t y = 2; y + 1 < length && dist_[y] <= range_; ++y) {
      const long cell = cell_of(lat_[y], lon_[y]);
      if (cell >= 0) {
        if (marked_[static_cast<std::size_t>(cell)]) continue;
        marked_[static_cast<std::size_t>(cell)] = 1;
      }
      SplatPathPoint p;
      p.lat = lat_[y];
      p.lon = lon_[y] > 180.0 ? 360.0 - lon_[y] : -lon_[y];
      if (p.lon >= 180.0) p.lon -= 360.0;
      p.ground_m = std::span<const double>(z_.data(), y);
      p.spacing_m = kMetresPerMile * (dist_[y] - dist_[y - 1]);
      visit(p);
    }
  }

 private:
  // The nearest cell's index in the grid, or -1 outside it.
  long cell_of(double lat, double lon_west) const {
    const double lon_east = -lon_west;
    const double r = std::rint((dem_.georef.y0 - lat) / dem_.georef.dy);
    double c = std::rint((lon_east - dem_.georef.x0) / dem_.georef.dx);
    if (c < 0.0) c = std::rint((lon_east + 360.0 - dem_.georef.x0) / dem_.georef.dx);
    if (r < 0.0 || c < 0.0 || r >= dem_.rows || c >= dem_.cols) return -1;
    return static_cast<long>(dem_.index(static_cast<int>(r), static_cast<int>(c)));
  }

  double ground(double lat, double lon_west) const {
    const long cell = cell_of(lat, lon_west);
    const double feet = cell < 0 ? -5000.0 : kFeetPerMetre * dem_.heights[static_cast<std::size_t>(cell)];
    return feet * kMetresPerFoot;
  }

  void push(double lat, double lon_west, double distance) {
    lat_.push_back(lat);
    lon_.push_back(lon_west);
    z_.push_back(ground(lat, lon_west));
    dist_.push_back(distance);
  }

  // The radial's samples, up to the first one beyond the range (or to its end, the
  // destination itself appended as SPLAT! does).
  void read_path(double lat, double lon_west) {
    lat_.clear(), lon_.clear(), z_.clear(), dist_.clear();
    const double lat1 = tx_lat_ * kDeg, lon1 = tx_lon_ * kDeg;
    const double azimuth = azimuth_rad(tx_lat_, tx_lon_, lat, lon_west);
    const double total = distance_miles(tx_lat_, tx_lon_, lat, lon_west);
    if (!(total > 30.0 / ppd_)) return;  // within half a cell: no path
    const double dx = samples_per_radian_ * std::acos(std::cos(lon1 - lon_west * kDeg));
    const double dy = samples_per_radian_ * std::acos(std::cos(lat1 - lat * kDeg));
    const double miles_per_sample = total / std::sqrt(dx * dx + dy * dy);
    bool beyond = false;
    for (int c = 0;; ++c) {
      const double distance = miles_per_sample * c;
      if (distance > total) break;
      const double beta = distance / kEarthMiles;
      const double lat2 = std::asin(std::sin(lat1) * std::cos(beta) + std::cos(azimuth) * std::sin(beta) * std::cos(lat1));
      const double num = std::cos(beta) - std::sin(lat1) * std::sin(lat2);
      const double den = std::cos(lat1) * std::cos(lat2);
      double lon2 = 0.0;
      if (azimuth == 0.0 && beta > M_PI / 2 - lat1) {
        lon2 = lon1 + M_PI;
      } else if (azimuth == M_PI / 2 && beta > M_PI / 2 + lat1) {
        lon2 = lon1 + M_PI;
      } else if (std::abs(num / den) > 1.0) {
        lon2 = lon1;
      } else {
        lon2 = (M_PI - azimuth) >= 0.0 ? lon1 - arc_cos(num, den) : lon1 + arc_cos(num, den);
      }
      while (lon2 < 0.0) lon2 += 2.0 * M_PI;
      while (lon2 > 2.0 * M_PI) lon2 -= 2.0 * M_PI;
      push(lat2 / kDeg, lon2 / kDeg, distance);
      if (distance > range_) {
        beyond = true;
        break;
      }
    }
    if (!beyond) push(lat, lon_west, total);
  }

  const io::Grid& dem_;
  double tx_lat_, tx_lon_, range_;
  int ppd_;
  double samples_per_radian_ = 0.0;
  std::vector<unsigned char> marked_;
  std::vector<double> lat_, lon_, z_, dist_;
};

}  // namespace

void for_each_splat_point(const io::Grid& dem, const AnoMap& bounds, double tx_lat, double tx_lon, double radius_km,
                          int cells_per_degree, const std::function<void(const SplatPathPoint&)>& visit) {
  double tx_west = -tx_lon;
  if (tx_west < 0.0) tx_west += 360.0;
  const double min_north = bounds.min_north, max_north = bounds.max_north;
  const double min_west = bounds.min_west, max_west = bounds.max_west;
  if (tx_lat < min_north || tx_lat > max_north || lon_diff(tx_west, min_west) < 0.0 || lon_diff(tx_west, max_west) > 0.0) {
    throw std::invalid_argument("SPLAT! profiles: the transmitter lies outside the map's region");
  }
  Radials radials(dem, tx_lat, tx_west, radius_km * 1000.0 / kMetresPerMile, cells_per_degree);
  const double dpp = 1.0 / cells_per_degree;
  const double first_west = dpp + min_west, last_north = max_north - dpp;
  auto wrap = [](double lon) { return lon >= 360.0 ? lon - 360.0 : lon; };
  // North edge, then east, south and west, as SPLAT!'s PlotLRMap().
  for (int y = 0;; ++y) {
    const double lon = wrap(first_west + dpp * y);
    if (lon_diff(lon, max_west) > 0.0) break;
    radials.run(max_north, lon, visit);
  }
  for (int y = 0;; ++y) {
    const double lat = last_north - dpp * y;
    if (lat < min_north) break;
    radials.run(lat, min_west, visit);
  }
  for (int y = 0;; ++y) {
    const double lon = wrap(first_west + dpp * y);
    if (lon_diff(lon, max_west) > 0.0) break;
    radials.run(min_north, lon, visit);
  }
  for (int y = 0;; ++y) {
    const double lat = min_north + dpp * y;
    if (lat >= max_north) break;
    radials.run(lat, max_west, visit);
  }
}

SplatItmCheck check_itm_on_splat_profiles(const io::Grid& dem, const AnoMap& map, const SplatSite& site,
                                          const SplatLrp& lrp, double rx_height_agl_m, double radius_km,
                                          int cells_per_degree) {
  ItmParameters p;
  p.polarization = lrp.polarization == 1 ? ItmPolarization::kVertical : ItmPolarization::kHorizontal;
  p.permittivity = lrp.dielectric;
  p.conductivity = lrp.conductivity;
  p.refractivity = lrp.bending;
  p.climate = static_cast<ItmClimate>(lrp.climate);
  p.time = lrp.time;
  p.situation = lrp.situations;
  ItmPath itm(lrp.frequency_mhz, p);
  // SPLAT!'s points by the cell they fall in (one each but for a few at cell boundaries).
  auto key = [&](double lat, double lon) {
    return static_cast<long long>(std::llround((dem.georef.y0 - lat) / dem.georef.dy)) * 1000003LL +
           std::llround((lon - dem.georef.x0) / dem.georef.dx);
  };
  std::unordered_multimap<long long, std::size_t> by_cell;
  by_cell.reserve(map.points.size());
  for (std::size_t i = 0; i < map.points.size(); ++i) by_cell.emplace(key(map.points[i].lat, map.points[i].lon), i);
  SplatItmCheck out;
  out.reported = map.points.size();
  std::vector<double> ours, theirs;
  std::vector<char> used(map.points.size(), 0);
  for_each_splat_point(dem, map, site.lat, site.lon, radius_km, cells_per_degree, [&](const SplatPathPoint& q) {
    const auto [first, last] = by_cell.equal_range(key(q.lat, q.lon));
    for (auto it = first; it != last; ++it) {
      const AnoPoint& a = map.points[it->second];
      if (used[it->second] || std::abs(a.lat - q.lat) > 1e-6 || std::abs(a.lon - q.lon) > 1e-6) continue;
      used[it->second] = 1;
      itm.set_profile(q.ground_m, q.spacing_m, site.height_agl_m);
      const double loss = itm.loss(rx_height_agl_m).loss_db;
      ours.push_back(loss);
      theirs.push_back(a.value);
      out.max_abs_difference = std::max(out.max_abs_difference, std::abs(a.value - loss));
      return;
    }
    ++out.unmatched;
  });
  out.reproduced = ours.size();
  out.comparison = compare_values(ours, theirs, rx_height_agl_m);
  return out;
}

}  // namespace terravol::volume
