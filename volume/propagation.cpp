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
//
// With RfModel::kItm the same profile goes to the Longley-Rice model instead (volume/itm.h,
// whose effective Earth comes from the surface refractivity): the profile without the bulge,
// the antennas' heights above the ground at its ends, basic transmission loss out. The antenna
// pattern applies to it the same way (ColumnModel): ITM finds no knife edges, so its departure is
// the steepest line from the transmitter over the whole profile (k-factor Earth), the horizon
// ray of an obstructed path, the direct line of a clear one.
#include "volume/propagation.h"

#include <GeographicLib/Geodesic.hpp>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>
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

// Bilinear height of a geographic grid at (lat, lon), clamped to its edges; at() takes the
// position in the grid's (fractional) column and row instead.
class DemSampler {
 public:
  explicit DemSampler(const io::Grid& g) : g_(g) {}
  double column(double lon) const { return (lon - g_.georef.x0) / g_.georef.dx; }
  double row(double lat) const { return (g_.georef.y0 - lat) / g_.georef.dy; }
  double operator()(double lat, double lon) const { return at(column(lon), row(lat)); }
  double at(double column, double row) const {
    return inside(std::clamp(column, 0.0, static_cast<double>(g_.cols - 1)),
                  std::clamp(row, 0.0, static_cast<double>(g_.rows - 1)));
  }
  // Whether (column, row) lies within the grid, where at() needs no clamp.
  bool holds(double column, double row) const {
    return column >= 0.0 && column <= g_.cols - 1 && row >= 0.0 && row <= g_.rows - 1;
  }
  // at() for a position the grid holds.
  double inside(double c, double r) const {
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

constexpr double kItmMinHeight = 0.5, kItmMaxHeight = 3000.0;  // the Algorithm's antenna limits
// ITM has no value at zero distance; a lattice column placed on another transmitter's grid can
// land within rounding (nanometres) of its own transmitter, so "no path" is under a metre.
constexpr double kItmMinDistance = 1.0;

void bad(const std::string& what) { throw std::invalid_argument(what); }

// The transmitter and the model's options.
void check_model(const Transmitter& tx, const RfOptions& options) {
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
  if (!std::isfinite(options.k_factor) || options.k_factor <= 0.0) bad("k-factor " + num(options.k_factor) + ": must be > 0");
  if (options.edge_depth < 1 || options.edge_depth > 16) bad("edge depth " + std::to_string(options.edge_depth) + ": must be within [1, 16]");
  if (options.model == RfModel::kItm) {
    check_itm(tx.frequency_mhz, options.itm);
    if (tx.height_agl < kItmMinHeight || tx.height_agl > kItmMaxHeight) {
      bad("transmitter height " + num(tx.height_agl) + ": ITM takes antenna heights within [0.5, 3000] m above ground");
    }
  }
}

// The receiver lattice, for that model.
void check_grid(const RfGrid& grid, const RfOptions& options) {
  if (!std::isfinite(grid.radius_km) || grid.radius_km <= 0.0 || grid.radius_km > 500.0) {
    bad("radius " + num(grid.radius_km) + ": must be within (0, 500] km");
  }
  if (!std::isfinite(grid.spacing_arcsec) || grid.spacing_arcsec < 0.0 || grid.spacing_arcsec > 3600.0) {
    bad("spacing " + num(grid.spacing_arcsec) + ": must be within (0, 3600] arc seconds");
  }
  const auto& h = grid.heights_agl;
  for (std::size_t n = 0; n < h.size(); ++n) {
    if (!std::isfinite(h[n]) || h[n] < 0.0 || h[n] > 100000.0) bad("height " + num(h[n]) + ": must be within [0, 100000] m");
    if (options.model == RfModel::kItm && (h[n] < kItmMinHeight || h[n] > kItmMaxHeight)) {
      bad("height " + num(h[n]) + ": ITM takes antenna heights within [0.5, 3000] m above ground");
    }
    if (n > 0 && h[n] <= h[n - 1]) bad("heights must increase");
    if (n > 1 && std::abs((h[n] - h[n - 1]) - (h[1] - h[0])) > 1e-6) bad("heights must be evenly spaced");
  }
}

std::vector<double> default_heights(RfModel model) {
  const double first = model == RfModel::kItm ? 10.0 : 0.0;
  std::vector<double> h;
  for (int n = 0; n <= 40; ++n) h.push_back(first + 50.0 * n);
  return h;
}

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

// The profile step compute_rf uses for tx over this DEM: its finer spacing in metres at the
// transmitter.
double profile_step_m(const io::Grid& dem, const Transmitter& tx) {
  const io::SceneFrame frame(tx.lat, tx.lon);
  return std::min(dem.georef.dx * frame.metres_per_degree_lon(), dem.georef.dy * frame.metres_per_degree_lat());
}

}  // namespace

void check_rf_parameters(const Transmitter& tx, const RfGrid& grid, const RfOptions& options) {
  check_model(tx, options);
  check_grid(grid, options);
}

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

void sample_profile(const io::Grid& dem, double tx_lat, double tx_lon, double rx_lat, double rx_lon, double step_m,
                    TerrainProfile& out) {
  const DemSampler ground(dem);
  double distance = 0.0, azi1 = 0.0, azi2 = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(tx_lat, tx_lon, rx_lat, rx_lon, distance, azi1, azi2);
  const int segments = std::max(1, static_cast<int>(std::ceil(distance / step_m)));
  out.distance_m = distance;
  out.azimuth_deg = azi1 < 0.0 ? azi1 + 360.0 : azi1;
  out.ground_m.resize(static_cast<std::size_t>(segments) + 1);
  out.ground_m[0] = ground(tx_lat, tx_lon);
  // Along the line the grid position is affine in the sample index: stepped from the
  // transmitter's (the same points to rounding, without two divisions per sample).
  const double c_tx = ground.column(tx_lon), r_tx = ground.row(tx_lat);
  const double dc = (ground.column(rx_lon) - c_tx) / segments, dr = (ground.row(rx_lat) - r_tx) / segments;
  if (ground.holds(c_tx, r_tx) && ground.holds(c_tx + segments * dc, r_tx + segments * dr)) {
    // Both ends inside the grid, so every sample between: at() without its clamps.
    for (int m = 1; m < segments; ++m) {
      out.ground_m[static_cast<std::size_t>(m)] = ground.inside(c_tx + m * dc, r_tx + m * dr);
    }
  } else {
    for (int m = 1; m < segments; ++m) out.ground_m[static_cast<std::size_t>(m)] = ground.at(c_tx + m * dc, r_tx + m * dr);
  }
  out.ground_m[static_cast<std::size_t>(segments)] = ground(rx_lat, rx_lon);
}

struct ColumnModel::State {
  Transmitter tx;
  RfOptions options;
  double lambda = 0.0, two_ka = 0.0;
  // The column in the raised frame: distances, terrain heights raised by the bulge (k-factor
  // Earth); x[0] = 0 and y[0] the transmitter's top, y[last] the receiver's top (set per height).
  std::vector<double> x, y;
  std::vector<KnifeEdge> edges;
  std::optional<ItmPath> itm;
  std::vector<double> losses;  // ITM's losses of one column

  // x, y for a profile (both models: Deygout's terrain, and the departure's geometry).
  void raise(const TerrainProfile& profile) {
    const std::size_t n = profile.ground_m.size();
    const int segments = static_cast<int>(n) - 1;
    const double distance = profile.distance_m;
    x.resize(n);
    y.resize(n);
    x[0] = 0.0;
    y[0] = profile.ground_m[0] + tx.height_agl;
    for (int m = 1; m < segments; ++m) {
      const double t = static_cast<double>(m) / segments;
      const double d = t * distance;
      x[static_cast<std::size_t>(m)] = d;
      y[static_cast<std::size_t>(m)] = profile.ground_m[static_cast<std::size_t>(m)] + d * (distance - d) / two_ka;
    }
    x[static_cast<std::size_t>(segments)] = distance;
  }

  // The steepest slope from the transmitter to the terrain samples (ITM's departure), -inf
  // without samples. Precondition: raise(profile).
  double terrain_slope() const {
    double slope = -std::numeric_limits<double>::infinity();
    for (std::size_t m = 1; m + 1 < x.size(); ++m) slope = std::max(slope, (y[m] - y[0]) / x[m]);
    return slope;
  }

  // Departure elevation (degrees) of a path whose steepest line from the transmitter has
  // `slope` in the raised frame, less the tilt of the local horizontal there (the bulge's
  // slope at d = 0); and the pattern's gain there.
  void departure(double slope, double distance, double azimuth, RfPath& p) const {
    p.departure_deg = (std::atan(slope) - std::atan(distance / two_ka)) / kDegree;
    p.antenna_gain_db = tx.antenna ? tx.antenna->gain_db(azimuth, p.departure_deg) : 0.0;
  }

  // One height's loss and its parts into p (not the profile); `want_edges`: Deygout's edges in
  // p.edges (found anyway with a pattern). Precondition: raise(profile); for ITM the profile
  // set on itm. `terrain` is terrain_slope() (ITM with a pattern only).
  void evaluate(const TerrainProfile& profile, double rx_height_agl, double terrain, bool want_edges, RfPath& p) {
    const std::size_t last = x.size() - 1;
    const double distance = profile.distance_m;
    const double rx_top = profile.ground_m[last] + rx_height_agl;
    y[last] = rx_top;
    const double dh = rx_top - y[0];
    const double slant = std::max(1.0, std::sqrt(distance * distance + dh * dh));
    const double direct = distance > 0.0 ? dh / distance : 0.0;
    p.free_space_db = free_space_loss_db(slant, tx.frequency_mhz);
    p.edges.clear();
    p.itm_warning = 0;
    if (itm) {
      const ItmLoss r = itm->loss(rx_height_agl);
      p.diffraction_db = r.loss_db - p.free_space_db;
      p.itm_warning = static_cast<std::size_t>(r.warning);
      if (tx.antenna || want_edges) departure(std::max(direct, terrain), distance, profile.azimuth_deg, p);
      p.path_loss_db = r.loss_db - p.antenna_gain_db;
      return;
    }
    const bool edges_needed = want_edges || tx.antenna.has_value();
    p.diffraction_db = deygout(x.data(), y.data(), 0, static_cast<int>(last), false, false, lambda, options.edge_depth,
                               edges_needed ? &p.edges : nullptr);
    p.antenna_gain_db = 0.0;
    if (edges_needed) {
      // The first leg of the string over the edges: the steepest line to them or the receiver.
      double slope = direct;
      for (const KnifeEdge& e : p.edges) slope = std::max(slope, (y[e.sample] - y[0]) / x[e.sample]);
      departure(slope, distance, profile.azimuth_deg, p);
    }
    p.path_loss_db = p.free_space_db + p.diffraction_db - p.antenna_gain_db;
  }
};

ColumnModel::ColumnModel(const Transmitter& tx, const RfOptions& options) : s_(std::make_unique<State>()) {
  check_model(tx, options);
  s_->tx = tx;
  s_->options = options;
  s_->options.progress = nullptr;
  s_->lambda = wavelength(tx.frequency_mhz);
  s_->two_ka = 2.0 * options.k_factor * kEarthRadius;
  if (options.model == RfModel::kItm) s_->itm.emplace(tx.frequency_mhz, options.itm);
}

ColumnModel::~ColumnModel() = default;
ColumnModel::ColumnModel(ColumnModel&&) noexcept = default;
ColumnModel& ColumnModel::operator=(ColumnModel&&) noexcept = default;

std::size_t ColumnModel::path_loss(const TerrainProfile& profile, std::span<const double> heights, std::span<float> out) {
  State& s = *s_;
  const std::size_t n = profile.ground_m.size();
  const double distance = profile.distance_m;
  std::size_t warned = 0;
  if (s.itm) {
    if (!(distance >= kItmMinDistance)) {
      for (float& v : out) v = std::numeric_limits<float>::quiet_NaN();
      return 0;
    }
    s.itm->set_profile(profile.ground_m, distance / static_cast<double>(n - 1), s.tx.height_agl);
    if (!s.tx.antenna) {
      // ITM's own loss, all heights at once; the pattern's geometry is not needed.
      s.losses.resize(heights.size());
      warned = s.itm->losses(heights, s.losses);
      for (std::size_t k = 0; k < heights.size(); ++k) out[k] = static_cast<float>(s.losses[k]);
      return warned;
    }
  }
  s.raise(profile);
  const double terrain = s.itm && s.tx.antenna ? s.terrain_slope() : 0.0;
  RfPath p;
  for (std::size_t k = 0; k < heights.size(); ++k) {
    s.evaluate(profile, heights[k], terrain, false, p);
    out[k] = static_cast<float>(p.path_loss_db);
    if (p.itm_warning >= 3) ++warned;
  }
  return warned;
}

void ColumnModel::path(const TerrainProfile& profile, double rx_height_agl, RfPath& out) {
  State& s = *s_;
  if (s.itm) {
    if (!(profile.distance_m >= kItmMinDistance)) {
      out = RfPath{};
      out.free_space_db = out.diffraction_db = out.path_loss_db = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    s.itm->set_profile(profile.ground_m, profile.distance_m / static_cast<double>(profile.ground_m.size() - 1),
                       s.tx.height_agl);
  }
  s.raise(profile);
  s.evaluate(profile, rx_height_agl, s.itm ? s.terrain_slope() : 0.0, true, out);
}

std::string ColumnModel::description() const {
  const RfOptions& o = s_->options;
  if (o.model == RfModel::kItm) {
    const ItmParameters& p = o.itm;
    return "Longley-Rice ITM 1.2.2 point-to-point (Hufford's Algorithm): " +
           std::string(p.polarization == ItmPolarization::kVertical ? "vertical" : "horizontal") +
           " polarization, ground permittivity " + num(p.permittivity) + ", conductivity " + num(p.conductivity) +
           " S/m, N_0 " + num(p.refractivity) + " N-units, " + itm_climate_name(p.climate) + " climate, time " +
           num(p.time) + ", location " + num(p.location) + ", situation " + num(p.situation) + ", MDVAR " +
           std::to_string(p.mdvar());
  }
  return "free space + Deygout knife-edge diffraction (ITU-R P.526 J(v)), " + std::to_string(o.edge_depth) +
         " levels, earth bulge with k = " + num(o.k_factor);
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

RfGrid resolve_grid(const RfGrid& grid, double dem_spacing_arcsec, RfModel model) {
  RfGrid r = grid;
  if (r.heights_agl.empty()) r.heights_agl = default_heights(model);
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
  ColumnModel model(tx, options);
  TerrainProfile profile;
  sample_profile(dem, tx.lat, tx.lon, rx_lat, rx_lon, profile_step_m(dem, tx), profile);
  RfPath path;
  model.path(profile, rx_height_agl, path);
  std::sort(path.edges.begin(), path.edges.end(), [](const KnifeEdge& a, const KnifeEdge& b) { return a.sample < b.sample; });
  for (KnifeEdge& edge : path.edges) --edge.sample;  // sample 0 of the column is the transmitter
  const std::size_t segments = profile.ground_m.size() - 1;
  PathProfile& p = path.profile;
  p.distance_m = profile.distance_m;
  p.tx_height_m = profile.ground_m[0] + tx.height_agl;
  p.rx_height_m = profile.ground_m[segments] + rx_height_agl;
  for (std::size_t m = 1; m < segments; ++m) {
    p.d_m.push_back(static_cast<double>(m) / static_cast<double>(segments) * profile.distance_m);
    p.z_m.push_back(profile.ground_m[m]);
  }
  path.azimuth_deg = profile.azimuth_deg;
  return path;
}

RfStats compute_rf_rows(const io::Grid& dem, const Transmitter& tx, const Lattice& l, std::span<const int> rows,
                        const RfOptions& options, std::span<float> out, double disc_radius_km) {
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
  const ColumnModel prototype(tx, options);  // checks the model's parameters once, here
  const double step_m = profile_step_m(dem, tx);
  const std::size_t n_columns = nx * nr;
  const std::size_t layer = n_columns;
  const std::vector<double>& heights_m = grid.heights_agl;

  // The disc: decided from the flat distance in the transmitter's frame where that is clearly
  // inside or outside (it is within 0.5% of the geodesic one over 500 km), by the geodesic
  // near the rim.
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double mlat = frame.metres_per_degree_lat(), mlon = frame.metres_per_degree_lon();
  const double radius_m = disc_radius_km * 1000.0;
  auto outside_disc = [&](double lat, double lon) {
    if (!(disc_radius_km > 0.0)) return false;
    const double flat = std::hypot((lon - tx.lon) * mlon, (lat - tx.lat) * mlat);
    if (flat < 0.99 * radius_m) return false;
    if (flat > 1.01 * radius_m) return true;
    double distance = 0.0;
    GeographicLib::Geodesic::WGS84().Inverse(tx.lat, tx.lon, lat, lon, distance);
    return distance > radius_m;
  };

  RfStats stats;
  std::atomic<std::size_t> done{0}, samples{0}, warned{0}, computed{0};
  std::mutex progress_mutex;
  int reported = -1;
  const auto t0 = std::chrono::steady_clock::now();
  // Each thread's model (with its scratch space and Delta h's guesses, which only decide speed),
  // profile and column, kept from one range of columns to the next.
  struct Worker {
    ColumnModel model;
    TerrainProfile profile;
    std::vector<float> column;
  };
  tbb::enumerable_thread_specific<Worker> workers(
      [&] { return Worker{ColumnModel(tx, options), {}, std::vector<float>(static_cast<std::size_t>(nh))}; });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_columns, 64), [&](const tbb::blocked_range<std::size_t>& r) {
    auto& [model, profile, column] = workers.local();
    std::size_t local_samples = 0, local_warned = 0, local_computed = 0;
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const int i = static_cast<int>(c % nx);
      const int j = rows[c / nx];
      if (outside_disc(l.world(1, j), l.world(0, i))) {
        for (int k = 0; k < nh; ++k) out[c + layer * static_cast<std::size_t>(k)] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      ++local_computed;
      sample_profile(dem, tx.lat, tx.lon, l.world(1, j), l.world(0, i), step_m, profile);
      local_samples += profile.ground_m.size() - 2;
      local_warned += model.path_loss(profile, heights_m, column);
      for (int k = 0; k < nh; ++k) out[c + layer * static_cast<std::size_t>(k)] = column[static_cast<std::size_t>(k)];
    }
    samples += local_samples;
    warned += local_warned;
    computed += local_computed;
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
  stats.columns = computed.load();
  stats.samples = samples.load();
  stats.itm_warned = warned.load();
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
      {"model", ColumnModel(tx, options).description()},
      {"vertical_datum", vertical_datum},
  };
  if (options.model == RfModel::kDeygout) loss.attributes["k_factor"] = num(options.k_factor);
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

std::vector<std::string> rf_notes(const RfStats& stats, std::size_t box_columns, std::size_t points, const RfGrid& grid,
                                  const RfOptions& options) {
  std::vector<std::string> notes;
  if (grid.disc) {
    notes.push_back("the " + std::to_string(box_columns - stats.columns) + " columns farther than " +
                    num(grid.radius_km) + " km from the transmitter are NaN (disc)");
  }
  if (options.model == RfModel::kItm) {
    notes.push_back("ITM has no value at the transmitter's own column (NaN)");
    if (stats.itm_warned > 0) {
      notes.push_back(std::to_string(stats.itm_warned) + " of " + std::to_string(points) +
                      " points carry ITM warning 3 or 4: parameters outside the model's range (paths under 1 km, "
                      "N_s under 250 N-units over high ground, steep horizons); computed anyway");
    }
  }
  return notes;
}

RfResult compute_rf(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid_in, const RfOptions& options) {
  check_rf_parameters(tx, grid_in, options);
  check_dem(dem);
  const DemExtent e = dem_extent(dem.georef, dem.rows, dem.cols);
  check_inside(e, tx.lat, tx.lon, "transmitter");
  const RfGrid grid = resolve_grid(grid_in, dem.georef.dy * 3600.0, options.model);
  const RfBox box = rf_box(e, tx, grid, tx.lat, tx.lon);
  RfResult result;
  if (box.clipped) result.notes.push_back("the box was clipped to the DEM's extent");
  result.path_loss = path_loss_volume(tx, box.lattice, options, dem.vertical_datum);
  std::vector<int> rows(static_cast<std::size_t>(box.lattice.dims[1]));
  for (std::size_t j = 0; j < rows.size(); ++j) rows[j] = static_cast<int>(j);
  const RfStats stats = compute_rf_rows(dem, tx, box.lattice, rows, options, result.path_loss.values,
                                        grid.disc ? grid.radius_km : 0.0);
  result.seconds = stats.seconds;
  result.columns = stats.columns;
  result.mean_profile_samples =
      static_cast<double>(stats.samples) / static_cast<double>(std::max<std::size_t>(1, stats.columns));
  const std::size_t box_columns = static_cast<std::size_t>(box.lattice.dims[0]) * static_cast<std::size_t>(box.lattice.dims[1]);
  for (auto& note : rf_notes(stats, box_columns, box.lattice.size(), grid, options)) result.notes.push_back(note);
  if (grid.disc) result.path_loss.attributes["disc_radius_km"] = num(grid.radius_km);
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
  RfResult result = compute_rf(window.grid, tx, resolve_grid(grid, dem.georef().dy * 3600.0, options.model), options);
  result.notes.insert(result.notes.end(), window.notes.begin(), window.notes.end());
  result.path_loss.attributes["dem"] = window.tiles;
  if (result.signal) result.signal->attributes["dem"] = window.tiles;
  return result;
}

}  // namespace terravol::volume
