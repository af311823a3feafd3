// The built-in propagation model (propagation.h).
//
// Model. For each receiver the basic transmission loss is L = L_fs + L_d (dB):
//  - L_fs, free-space loss 20 log10(4 pi r / lambda) over the slant distance r between the
//    antennas (ITU-R P.525);
//  - L_d, diffraction over the terrain profile by Deygout's construction (J. Deygout,
//    "Multiple knife-edge diffraction of microwaves", IEEE Trans. Antennas Propag. AP-14(4),
//    pp. 480-489, 1966): every profile sample is a knife edge; the one with the largest
//    Fresnel-Kirchhoff parameter v = h sqrt(2 (d1 + d2) / (lambda d1 d2)) (h its height above
//    the line joining the path's ends, d1 and d2 its distances to them) is the principal edge;
//    its loss J(v) is added to the losses of the sub-paths end -> edge and edge -> end, found
//    the same way with the edge's top as their end, to `edge_depth` levels (2 by default:
//    principal plus one secondary edge each side, Deygout's three-edge form). J(v) is
//    ITU-R P.526's approximation of the Fresnel-integral loss of a single knife edge,
//    6.9 + 20 log10(sqrt((v - 0.1)^2 + 1) + v - 0.1) for v > -0.78, else 0.
//  - Obstacles, not samples: on a sub-path, the samples joined to its bounding edge by
//    unbroken obstruction (v > -0.78 on that sub-path, from the edge inward) belong to that
//    edge's obstacle and cannot be secondary edges. Deygout's method assumes isolated edges;
//    without this rule the DEM sample next to a principal edge grazes the sub-path and adds
//    about 6 dB (11.5 dB of spurious loss over flat ground with half a Fresnel zone of
//    clearance; jumps of 9 dB between neighbouring receivers behind a rounded summit).
//  - Earth curvature: each terrain sample is raised by the bulge d1 d2 / (2 k a), a = 6371 km,
//    k = 4/3 (the standard atmosphere's effective Earth radius), after which the geometry is
//    flat. The bulge is a parabola in d, so the same raised profile is exact for sub-paths too.
//  - Profile: the straight line in latitude and longitude from transmitter to receiver,
//    sampled at the DEM's finer spacing (in metres at the transmitter), heights bilinear in
//    the DEM. D is the WGS84 geodesic distance (GeographicLib).
//
// Limits, to keep in mind when reading the numbers:
//  - No ground reflection (no two-ray interference lobes), no clutter (trees, buildings), no
//    atmospheric absorption, rain, ducting or tropospheric scatter; an isotropic receiving
//    antenna, the transmitting one isotropic unless it has a pattern; polarisation ignored. Beyond the radio horizon over smooth ground the bulge acts as
//    knife edges, not P.526's smooth-Earth method.
//  - Knife edges: a rounded hill is a knife edge at its most obstructing sample (no
//    rounded-obstacle term), and a flat-topped ridge is one obstacle, not two edges (its far
//    edge is joined to the near one by unbroken obstruction), so both are underestimated a
//    little; separate ridges each count. Deygout is discontinuous where the principal edge
//    moves from one ridge to another. Limiting the recursion to three edges keeps its known
//    overestimate on many-edge paths moderate. Models of this kind typically show 6-10 dB
//    standard deviation against measurements.
//  - Free-space loss is a far-field quantity: meaningless within a few wavelengths of the
//    transmitter. The slant distance is clamped to 1 m.
//  - The line in latitude and longitude departs from the geodesic by metres over tens of km,
//    far less than a DEM sample.
//  - Antenna pattern (antenna.h), a per-path term: the loss grows by the pattern's attenuation
//    in the path's azimuth (the geodesic's at the transmitter) and departure elevation. The
//    departure is the first leg of the path the construction traces, the string from the
//    transmitter stretched over the knife edges to the receiver: the steepest of the lines from
//    the transmitter to the edges and to the receiver (their elevation above the local
//    horizontal of the k-factor Earth). SPLAT! (PlotLRPath) instead takes the line to the first
//    terrain sample above the line of sight; on a diffracted path the two differ by up to the
//    angle between the first obstruction and the highest edge.
#include "volume/propagation.h"

#include <GeographicLib/Geodesic.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "io/scene_frame.h"
#include "io/void_fill.h"

namespace terravol::volume {

namespace {

constexpr double kEarthRadius = 6371000.0;       // metres (ITU-R P.526's a)
constexpr double kSpeedOfLight = 299792458.0;    // m/s
constexpr double kDipoleGainDbi = 2.15;          // half-wave dipole over isotropic
constexpr double kDegree = M_PI / 180.0;

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// Deygout's construction over samples a..b of (x, y): x distances (increasing), y heights
// (terrain already raised by the bulge; y[a] and y[b] are the ends: antennas at the top level,
// edges below). edge_a / edge_b: that end is a knife edge, so the samples joined to it by
// unbroken obstruction of this path (v > -0.78 from the end inward) belong to its obstacle and
// are not edges of their own. Each edge used is appended to `edges` when given (sample = its
// index in x, y).
double deygout(const double* x, const double* y, int a, int b, bool edge_a, bool edge_b, double lambda, int depth,
               std::vector<KnifeEdge>* edges, int level = 1) {
  if (b - a < 2 || depth < 1) return 0.0;
  const double xa = x[a], ya = y[a], xb = x[b];
  const double length = xb - xa;
  const double slope = (y[b] - ya) / length;
  // sign(v) v^2 = key * 2 length / lambda: the same order as v, without a square root.
  auto key_of = [&](int i) {
    const double d1 = x[i] - xa, d2 = xb - x[i];
    const double h = y[i] - (ya + slope * d1);
    return h * std::abs(h) / (d1 * d2);
  };
  const double clear_key = -0.78 * 0.78 * lambda / (2.0 * length);  // v = -0.78
  int lo = a + 1, hi = b - 1;
  if (edge_a)
    while (lo <= hi && key_of(lo) > clear_key) ++lo;
  if (edge_b)
    while (hi >= lo && key_of(hi) > clear_key) --hi;
  int best = -1;
  double best_key = -std::numeric_limits<double>::infinity();
  for (int i = lo; i <= hi; ++i) {
    const double key = key_of(i);
    if (key > best_key) {
      best_key = key;
      best = i;
    }
  }
  if (best < 0 || best_key <= clear_key) return 0.0;
  const double v2 = best_key * 2.0 * length / lambda;
  const double v = best_key < 0.0 ? -std::sqrt(-v2) : std::sqrt(v2);
  const double principal = knife_edge_loss_db(v);
  if (edges) edges->push_back({static_cast<std::size_t>(best), v, principal, level});
  if (depth == 1) return principal;
  return principal + deygout(x, y, a, best, edge_a, true, lambda, depth - 1, edges, level + 1) +
         deygout(x, y, best, b, true, edge_b, lambda, depth - 1, edges, level + 1);
}

double wavelength(double frequency_mhz) { return kSpeedOfLight / (frequency_mhz * 1e6); }

// Bilinear height of a geographic grid at (lat, lon), clamped to its edges.
class DemSampler {
 public:
  explicit DemSampler(const io::Grid& g) : g_(g) {}
  double operator()(double lat, double lon) const {
    const double c = std::clamp((lon - g_.georef.x0) / g_.georef.dx, 0.0, static_cast<double>(g_.cols - 1));
    const double r = std::clamp((g_.georef.y0 - lat) / g_.georef.dy, 0.0, static_cast<double>(g_.rows - 1));
    const int c0 = std::min(static_cast<int>(c), g_.cols - 2), r0 = std::min(static_cast<int>(r), g_.rows - 2);
    const double fc = c - c0, fr = r - r0;
    const float* row0 = &g_.heights[g_.index(r0, c0)];
    const float* row1 = row0 + g_.cols;
    const double top = row0[0] + fc * (row0[1] - row0[0]);
    const double bottom = row1[0] + fc * (row1[1] - row1[0]);
    return top + fr * (bottom - top);
  }

 private:
  const io::Grid& g_;
};

}  // namespace

void check_rf_parameters(const Transmitter& tx, const RfGrid& grid, const RfOptions& options) {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (!std::isfinite(tx.lat) || std::abs(tx.lat) > 85.0) bad("transmitter latitude " + num(tx.lat) + ": must be within [-85, 85]");
  if (!std::isfinite(tx.lon) || std::abs(tx.lon) > 360.0) bad("transmitter longitude " + num(tx.lon) + ": must be within [-360, 360]");
  if (!std::isfinite(tx.height_agl) || tx.height_agl < 0.0 || tx.height_agl > 100000.0) {
    bad("transmitter height " + num(tx.height_agl) + ": must be within [0, 100000] m above ground");
  }
  if (!std::isfinite(tx.frequency_mhz) || tx.frequency_mhz <= 0.0 || tx.frequency_mhz > 100000.0) {
    bad("frequency " + num(tx.frequency_mhz) + ": must be within (0, 100000] MHz");
  }
  if (tx.erp_w && (!std::isfinite(*tx.erp_w) || *tx.erp_w <= 0.0 || *tx.erp_w > 1e9)) {
    bad("ERP " + num(*tx.erp_w) + ": must be within (0, 1e9] W");
  }
  if (!std::isfinite(grid.radius_km) || grid.radius_km <= 0.0 || grid.radius_km > 500.0) {
    bad("radius " + num(grid.radius_km) + ": must be within (0, 500] km");
  }
  if (!std::isfinite(grid.spacing_arcsec) || grid.spacing_arcsec < 0.0 || grid.spacing_arcsec > 3600.0) {
    bad("spacing " + num(grid.spacing_arcsec) + ": must be within (0, 3600] arc seconds");
  }
  const auto& h = grid.heights_agl;
  for (std::size_t n = 0; n < h.size(); ++n) {
    if (!std::isfinite(h[n]) || h[n] < 0.0 || h[n] > 100000.0) bad("height " + num(h[n]) + ": must be within [0, 100000] m");
    if (n > 0 && h[n] <= h[n - 1]) bad("heights must increase");
    if (n > 1 && std::abs((h[n] - h[n - 1]) - (h[1] - h[0])) > 1e-6) bad("heights must be evenly spaced");
  }
  if (!std::isfinite(options.k_factor) || options.k_factor <= 0.0) bad("k-factor " + num(options.k_factor) + ": must be > 0");
  if (options.edge_depth < 1 || options.edge_depth > 16) bad("edge depth " + std::to_string(options.edge_depth) + ": must be within [1, 16]");
}

namespace {

void check_dem(const io::Grid& dem) {
  if (dem.georef.crs != io::Crs::kGeographic || dem.rows < 2 || dem.cols < 2 || dem.heights.size() != dem.size()) {
    throw std::invalid_argument("the DEM must be a geographic grid of at least 2 x 2 samples");
  }
}

void check_inside(const DemExtent& e, double lat, double lon, const std::string& what) {
  if (lat < e.south || lat > e.north || lon < e.west || lon > e.east) {
    throw std::invalid_argument(what + " at " + num(lat) + ", " + num(lon) + " lies outside the DEM (" + num(e.south) +
                                ".." + num(e.north) + " N, " + num(e.west) + ".." + num(e.east) + " E)");
  }
}

std::vector<double> default_heights() {
  std::vector<double> h;
  for (int n = 0; n <= 40; ++n) h.push_back(50.0 * n);
  return h;
}

// The model's geometry for one transmitter: every path is built and evaluated here, for
// compute_rf_rows and rf_path alike.
class PathModel {
 public:
  PathModel(const io::Grid& dem, const Transmitter& tx, const RfOptions& options)
      : tx_(tx), options_(options), ground_(dem), geod_(GeographicLib::Geodesic::WGS84()) {
    const io::SceneFrame frame(tx.lat, tx.lon);
    step_m_ = std::min(dem.georef.dx * frame.metres_per_degree_lon(), dem.georef.dy * frame.metres_per_degree_lat());
    lambda_ = wavelength(tx.frequency_mhz);
    two_ka_ = 2.0 * options.k_factor * kEarthRadius;
    tx_top_ = ground_(tx.lat, tx.lon) + tx.height_agl;
  }

  // A receiver column: x = distances and y = terrain raised by the bulge, both of segments + 1
  // entries, x[0] = 0, y[0] = the transmitter's top, x[segments] = distance; y[segments] is the
  // receiver's top, set by loss().
  struct Column {
    double distance = 0.0, azimuth = 0.0, rx_ground = 0.0;
    int segments = 0;
  };
  Column column(double rx_lat, double rx_lon, std::vector<double>& x, std::vector<double>& y) const {
    Column c;
    double azi2 = 0.0;
    geod_.Inverse(tx_.lat, tx_.lon, rx_lat, rx_lon, c.distance, c.azimuth, azi2);
    c.segments = std::max(1, static_cast<int>(std::ceil(c.distance / step_m_)));
    x.resize(static_cast<std::size_t>(c.segments) + 1);
    y.resize(static_cast<std::size_t>(c.segments) + 1);
    x[0] = 0.0;
    y[0] = tx_top_;
    for (int m = 1; m < c.segments; ++m) {
      const double t = static_cast<double>(m) / c.segments;
      const double d = t * c.distance;
      x[m] = d;
      y[m] = ground_(tx_.lat + t * (rx_lat - tx_.lat), tx_.lon + t * (rx_lon - tx_.lon)) + d * (c.distance - d) / two_ka_;
    }
    x[c.segments] = c.distance;
    c.rx_ground = ground_(rx_lat, rx_lon);
    return c;
  }

  struct Loss {
    double free_space = 0.0, diffraction = 0.0, gain = 0.0, departure = 0.0;
    double total() const { return free_space + diffraction - gain; }
  };
  // The loss to a receiver `rx_top` metres above the datum in column c. `edges` receives
  // Deygout's edges when given; they are needed (and found) anyway with an antenna pattern.
  Loss loss(const Column& c, const std::vector<double>& x, std::vector<double>& y, double rx_top,
            std::vector<KnifeEdge>* edges) const {
    y[c.segments] = rx_top;
    const double dh = rx_top - tx_top_;
    const double slant = std::max(1.0, std::sqrt(c.distance * c.distance + dh * dh));
    Loss l;
    l.free_space = free_space_loss_db(slant, tx_.frequency_mhz);
    if (edges) edges->clear();
    l.diffraction = deygout(x.data(), y.data(), 0, c.segments, false, false, lambda_, options_.edge_depth, edges);
    if (edges || tx_.antenna) {
      // The steepest line from the transmitter, in the raised frame, less the tilt of the
      // transmitter's local horizontal there (the bulge's slope at d = 0).
      double slope = c.distance > 0.0 ? dh / c.distance : 0.0;
      if (edges) {
        for (const KnifeEdge& e : *edges) slope = std::max(slope, (y[e.sample] - tx_top_) / x[e.sample]);
      }
      l.departure = (std::atan(slope) - std::atan(c.distance / two_ka_)) / kDegree;
      if (tx_.antenna) l.gain = tx_.antenna->gain_db(c.azimuth < 0.0 ? c.azimuth + 360.0 : c.azimuth, l.departure);
    }
    return l;
  }

  double tx_top() const { return tx_top_; }
  double ground(double lat, double lon) const { return ground_(lat, lon); }
  double two_ka() const { return two_ka_; }

 private:
  const Transmitter& tx_;
  const RfOptions& options_;
  DemSampler ground_;
  const GeographicLib::Geodesic& geod_;
  double step_m_ = 0.0, lambda_ = 0.0, two_ka_ = 0.0, tx_top_ = 0.0;
};

}  // namespace

double free_space_loss_db(double distance_m, double frequency_mhz) {
  return 20.0 * std::log10(4.0 * M_PI * distance_m / wavelength(frequency_mhz));
}

double knife_edge_loss_db(double v) {
  if (v <= -0.78) return 0.0;
  const double a = v - 0.1;
  return 6.9 + 20.0 * std::log10(std::sqrt(a * a + 1.0) + a);
}

double diffraction_loss_db(const PathProfile& p, double frequency_mhz, double k_factor, int edge_depth) {
  const std::size_t n = p.d_m.size() + 1;
  std::vector<double> x(n + 1), y(n + 1);
  x[0] = 0.0;
  y[0] = p.tx_height_m;
  const double two_ka = 2.0 * k_factor * kEarthRadius;
  for (std::size_t i = 0; i < p.d_m.size(); ++i) {
    x[i + 1] = p.d_m[i];
    y[i + 1] = p.z_m[i] + p.d_m[i] * (p.distance_m - p.d_m[i]) / two_ka;
  }
  x[n] = p.distance_m;
  y[n] = p.rx_height_m;
  return deygout(x.data(), y.data(), 0, static_cast<int>(n), false, false, wavelength(frequency_mhz), edge_depth,
                 nullptr);
}

double path_loss_db(const PathProfile& p, double frequency_mhz, double k_factor, int edge_depth) {
  const double dh = p.rx_height_m - p.tx_height_m;
  const double r = std::max(1.0, std::sqrt(p.distance_m * p.distance_m + dh * dh));
  return free_space_loss_db(r, frequency_mhz) + diffraction_loss_db(p, frequency_mhz, k_factor, edge_depth);
}

double default_spacing_arcsec(double dem_spacing_arcsec, double radius_km) {
  const double dem_m = dem_spacing_arcsec / 3600.0 * (M_PI / 180.0) * kEarthRadius;
  const double wanted_m = 2.0 * radius_km * 1000.0 / 256.0;
  return dem_spacing_arcsec * std::max(1.0, std::ceil(wanted_m / dem_m - 1e-9));
}

double dem_height(const io::Grid& dem, double lat, double lon) {
  check_dem(dem);
  return DemSampler(dem)(lat, lon);
}

RfGrid resolve_grid(const RfGrid& grid, double dem_spacing_arcsec) {
  RfGrid r = grid;
  if (r.heights_agl.empty()) r.heights_agl = default_heights();
  if (r.spacing_arcsec == 0.0) r.spacing_arcsec = default_spacing_arcsec(dem_spacing_arcsec, r.radius_km);
  return r;
}

DemExtent dem_extent(const io::Georef& g, int rows, int cols) {
  return {g.y0 - (rows - 1) * g.dy, g.y0, g.x0, g.x0 + (cols - 1) * g.dx};
}

RfBox rf_box(const DemExtent& e, const Transmitter& tx, const RfGrid& grid, double anchor_lat, double anchor_lon) {
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double mlat = frame.metres_per_degree_lat(), mlon = frame.metres_per_degree_lon();
  const double s = grid.spacing_arcsec / 3600.0;
  const double radius_m = grid.radius_km * 1000.0;
  constexpr double eps = 1e-9;
  const double half_lon = std::floor(radius_m / (s * mlon) + eps) * s;
  const double half_lat = std::floor(radius_m / (s * mlat) + eps) * s;
  // Box indices relative to the anchor; with the transmitter as the anchor these are
  // -n .. n (the half sides are whole steps).
  const int i_box_lo = static_cast<int>(std::ceil((tx.lon - half_lon - anchor_lon) / s - eps));
  const int i_box_hi = static_cast<int>(std::floor((tx.lon + half_lon - anchor_lon) / s + eps));
  const int j_box_lo = static_cast<int>(std::ceil((tx.lat - half_lat - anchor_lat) / s - eps));
  const int j_box_hi = static_cast<int>(std::floor((tx.lat + half_lat - anchor_lat) / s + eps));
  const int i_lo = std::max(i_box_lo, static_cast<int>(std::ceil((e.west - anchor_lon) / s - eps)));
  const int i_hi = std::min(i_box_hi, static_cast<int>(std::floor((e.east - anchor_lon) / s + eps)));
  const int j_lo = std::max(j_box_lo, static_cast<int>(std::ceil((e.south - anchor_lat) / s - eps)));
  const int j_hi = std::min(j_box_hi, static_cast<int>(std::floor((e.north - anchor_lat) / s + eps)));
  RfBox box;
  box.clipped = i_lo != i_box_lo || i_hi != i_box_hi || j_lo != j_box_lo || j_hi != j_box_hi;
  const auto& heights = grid.heights_agl;
  const int nh = static_cast<int>(heights.size());
  Lattice& l = box.lattice;
  l.dims = {i_hi - i_lo + 1, j_hi - j_lo + 1, nh};
  l.origin = {anchor_lon + i_lo * s, anchor_lat + j_lo * s, heights[0]};
  l.spacing = {s, s, nh > 1 ? heights[1] - heights[0] : 1.0};
  if (l.dims[0] < 1 || l.dims[1] < 1) {
    throw std::invalid_argument("the box around the transmitter at " + num(tx.lat) + ", " + num(tx.lon) +
                                " holds no lattice column inside the DEM");
  }
  if (static_cast<double>(l.dims[0]) * l.dims[1] * l.dims[2] > static_cast<double>(kMaxPoints)) {
    throw std::invalid_argument("the lattice " + std::to_string(l.dims[0]) + " x " + std::to_string(l.dims[1]) + " x " +
                                std::to_string(nh) + " is too large (at most 2^28 points): use a coarser spacing");
  }
  return box;
}

RfPath rf_path(const io::Grid& dem, const Transmitter& tx, double rx_lat, double rx_lon, double rx_height_agl,
               const RfOptions& options) {
  RfGrid grid;
  grid.heights_agl = {rx_height_agl};
  check_rf_parameters(tx, grid, options);
  check_dem(dem);
  const DemExtent e = dem_extent(dem.georef, dem.rows, dem.cols);
  check_inside(e, tx.lat, tx.lon, "transmitter");
  check_inside(e, rx_lat, rx_lon, "receiver");
  const PathModel model(dem, tx, options);
  std::vector<double> x, y;
  const PathModel::Column c = model.column(rx_lat, rx_lon, x, y);
  RfPath path;
  const double rx_top = c.rx_ground + rx_height_agl;
  const PathModel::Loss l = model.loss(c, x, y, rx_top, &path.edges);
  std::sort(path.edges.begin(), path.edges.end(), [](const KnifeEdge& a, const KnifeEdge& b) { return a.sample < b.sample; });
  for (KnifeEdge& edge : path.edges) --edge.sample;  // x[0] is the transmitter
  PathProfile& p = path.profile;
  p.distance_m = c.distance;
  p.tx_height_m = model.tx_top();
  p.rx_height_m = rx_top;
  for (int m = 1; m < c.segments; ++m) {
    p.d_m.push_back(x[m]);
    p.z_m.push_back(y[m] - x[m] * (c.distance - x[m]) / model.two_ka());
  }
  path.azimuth_deg = c.azimuth < 0.0 ? c.azimuth + 360.0 : c.azimuth;
  path.free_space_db = l.free_space;
  path.diffraction_db = l.diffraction;
  path.departure_deg = l.departure;
  path.antenna_gain_db = l.gain;
  path.path_loss_db = l.total();
  return path;
}

RfStats compute_rf_rows(const io::Grid& dem, const Transmitter& tx, const Lattice& l, std::span<const int> rows,
                        const RfOptions& options, std::span<float> out) {
  RfGrid grid;
  for (int k = 0; k < l.dims[2]; ++k) grid.heights_agl.push_back(l.world(2, k));
  check_rf_parameters(tx, grid, options);
  check_dem(dem);
  const DemExtent e = dem_extent(dem.georef, dem.rows, dem.cols);
  check_inside(e, tx.lat, tx.lon, "transmitter");
  const std::size_t nx = static_cast<std::size_t>(l.dims[0]), nr = rows.size();
  const int nh = l.dims[2];
  if (out.size() != nx * nr * static_cast<std::size_t>(nh)) {
    throw std::invalid_argument("compute_rf_rows: the output holds " + std::to_string(out.size()) + " values, not " +
                                std::to_string(nx * nr * static_cast<std::size_t>(nh)));
  }
  for (const int j : rows) {
    if (j < 0 || j >= l.dims[1]) throw std::invalid_argument("compute_rf_rows: row " + std::to_string(j) + " is outside the lattice");
  }
  const PathModel model(dem, tx, options);
  const std::size_t n_columns = nx * nr;
  const std::size_t layer = n_columns;
  const bool with_edges = tx.antenna.has_value();

  RfStats stats;
  std::atomic<std::size_t> done{0}, samples{0};
  std::mutex progress_mutex;
  int reported = -1;
  const auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_columns, 64), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<double> x, y;
    std::vector<KnifeEdge> edges;
    std::size_t local_samples = 0;
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const int i = static_cast<int>(c % nx);
      const int j = rows[c / nx];
      const PathModel::Column column = model.column(l.world(1, j), l.world(0, i), x, y);
      local_samples += static_cast<std::size_t>(column.segments - 1);
      for (int k = 0; k < nh; ++k) {
        const PathModel::Loss loss = model.loss(column, x, y, column.rx_ground + l.world(2, k), with_edges ? &edges : nullptr);
        out[c + layer * static_cast<std::size_t>(k)] = static_cast<float>(loss.total());
      }
    }
    samples += local_samples;
    const std::size_t now = done += r.size();
    if (options.progress) {
      const int percent = static_cast<int>(100.0 * static_cast<double>(now) / static_cast<double>(n_columns));
      std::lock_guard<std::mutex> lock(progress_mutex);
      if (percent > reported) {
        reported = percent;
        options.progress(static_cast<double>(now) / static_cast<double>(n_columns));
      }
    }
  });
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stats.columns = n_columns;
  stats.samples = samples.load();
  return stats;
}

Volume path_loss_volume(const Transmitter& tx, const Lattice& lattice, const RfOptions& options,
                        const std::string& vertical_datum) {
  Volume loss;
  loss.name = "path_loss_db";
  loss.units = "dB";
  loss.frame.kind = FrameKind::kGeographic;
  loss.frame.height = HeightRef::kGround;
  loss.lattice = lattice;
  loss.values.assign(lattice.size(), 0.0f);
  loss.active_points = lattice.size();
  loss.attributes = {
      {"tx_lat", num(tx.lat)},
      {"tx_lon", num(tx.lon)},
      {"tx_height_agl_m", num(tx.height_agl)},
      {"frequency_mhz", num(tx.frequency_mhz)},
      {"k_factor", num(options.k_factor)},
      {"model", "free space + Deygout knife-edge diffraction (ITU-R P.526 J(v)), " +
                    std::to_string(options.edge_depth) + " levels, earth bulge with k = " + num(options.k_factor)},
      {"vertical_datum", vertical_datum},
  };
  if (tx.erp_w) loss.attributes["erp_w"] = num(*tx.erp_w);
  if (!tx.name.empty()) loss.attributes["tx_name"] = tx.name;
  if (tx.antenna) {
    loss.attributes["antenna_pattern"] = tx.antenna->describe() +
                                         "; the loss includes the pattern's attenuation along each path's departure";
  }
  return loss;
}

Volume signal_from_path_loss(Volume s, double erp_w) {
  if (!(erp_w > 0.0) || !std::isfinite(erp_w)) throw std::invalid_argument("signal_from_path_loss: ERP must be > 0 W");
  s.name = "signal_dbm";
  s.units = "dBm";
  // ERP is relative to a half-wave dipole: EIRP = ERP + 2.15 dB; the signal is the power an
  // isotropic (0 dBi) receiving antenna delivers.
  const double eirp_dbm = 10.0 * std::log10(erp_w) + 30.0 + kDipoleGainDbi;
  for (float& x : s.values) x = static_cast<float>(eirp_dbm - x);
  s.background = static_cast<float>(eirp_dbm - s.background);
  s.attributes["erp_w"] = num(erp_w);
  s.attributes["eirp_dbm"] = num(eirp_dbm);
  s.attributes["signal"] = "EIRP (ERP + 2.15 dB) minus path loss: power at an isotropic receiving antenna";
  return s;
}

RfResult compute_rf(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid_in, const RfOptions& options) {
  check_rf_parameters(tx, grid_in, options);
  check_dem(dem);
  const DemExtent e = dem_extent(dem.georef, dem.rows, dem.cols);
  check_inside(e, tx.lat, tx.lon, "transmitter");
  const RfGrid grid = resolve_grid(grid_in, dem.georef.dy * 3600.0);
  const RfBox box = rf_box(e, tx, grid, tx.lat, tx.lon);
  RfResult result;
  if (box.clipped) result.notes.push_back("the box was clipped to the DEM's extent");
  result.path_loss = path_loss_volume(tx, box.lattice, options, dem.vertical_datum);
  std::vector<int> rows(static_cast<std::size_t>(box.lattice.dims[1]));
  for (std::size_t j = 0; j < rows.size(); ++j) rows[j] = static_cast<int>(j);
  const RfStats stats = compute_rf_rows(dem, tx, box.lattice, rows, options, result.path_loss.values);
  result.seconds = stats.seconds;
  result.columns = stats.columns;
  result.mean_profile_samples = static_cast<double>(stats.samples) / static_cast<double>(stats.columns);
  if (tx.erp_w) result.signal = signal_from_path_loss(result.path_loss, *tx.erp_w);
  return result;
}

RfWindow read_rf_window(const io::Mosaic& dem, const DemExtent& box) {
  const io::Georef& g = dem.georef();
  const int r0 = std::max(0, static_cast<int>(std::floor((g.y0 - (box.north + 2.0 * g.dy)) / g.dy)));
  const int r1 = std::min(dem.rows() - 1, static_cast<int>(std::ceil((g.y0 - (box.south - 2.0 * g.dy)) / g.dy)));
  const int c0 = std::max(0, static_cast<int>(std::floor((box.west - 2.0 * g.dx - g.x0) / g.dx)));
  const int c1 = std::min(dem.cols() - 1, static_cast<int>(std::ceil((box.east + 2.0 * g.dx - g.x0) / g.dx)));
  if (r1 <= r0 || c1 <= c0) throw std::invalid_argument("the area lies outside the DEM");
  RfWindow w;
  w.grid = dem.read_window(r0, c0, r1 - r0 + 1, c1 - c0 + 1);
  const std::size_t voids = io::count(w.grid, io::Sample::kVoid), outside = io::count(w.grid, io::Sample::kOutside);
  io::fill_voids(w.grid);
  if (voids + outside > 0) {
    w.notes.push_back(std::to_string(voids) + " void and " + std::to_string(outside) +
                      " uncovered DEM samples were filled by interpolation");
  }
  for (const auto& t : dem.tiles()) {
    if (t.row0 + t.rows <= r0 || t.row0 > r1 || t.col0 + t.cols <= c0 || t.col0 > c1) continue;
    w.tiles += (w.tiles.empty() ? "" : ", ") + t.path.filename().string();
  }
  return w;
}

DemExtent rf_area(const Transmitter& tx, double radius_km) {
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double half_lat = radius_km * 1000.0 / frame.metres_per_degree_lat();
  const double half_lon = radius_km * 1000.0 / frame.metres_per_degree_lon();
  return {tx.lat - half_lat, tx.lat + half_lat, tx.lon - half_lon, tx.lon + half_lon};
}

RfResult compute_rf(const io::Mosaic& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options) {
  check_rf_parameters(tx, grid, options);
  check_inside(dem_extent(dem.georef(), dem.rows(), dem.cols()), tx.lat, tx.lon, "transmitter");
  RfWindow window = read_rf_window(dem, rf_area(tx, grid.radius_km));
  RfResult result = compute_rf(window.grid, tx, resolve_grid(grid, dem.georef().dy * 3600.0), options);
  result.notes.insert(result.notes.end(), window.notes.begin(), window.notes.end());
  result.path_loss.attributes["dem"] = window.tiles;
  if (result.signal) result.signal->attributes["dem"] = window.tiles;
  return result;
}

}  // namespace terravol::volume
