// Several transmitters, best server, and the split over ranks (plan.h).
#include "volume/plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

#include "volume/text.h"

namespace terravol::volume {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

std::string label(const RfPlan& plan, std::size_t t) {
  const std::string& name = plan.transmitters[t].name;
  return name.empty() ? "tx" + std::to_string(t + 1) : name;
}

}  // namespace

RfPlan plan_rf(const DemExtent& dem, double dem_spacing_arcsec, std::vector<Transmitter> transmitters,
            const RfGrid& grid_in, const RfOptions& options) {
  if (transmitters.empty()) throw std::invalid_argument("no transmitter");
  RfPlan plan;
  plan.grid = resolve_grid(grid_in, dem_spacing_arcsec, options.model);
  plan.transmitters = std::move(transmitters);
  const Transmitter& anchor = plan.transmitters.front();
  const double s = plan.grid.spacing_arcsec / 3600.0;
  int i_lo = std::numeric_limits<int>::max(), j_lo = i_lo, i_hi = std::numeric_limits<int>::min(), j_hi = i_hi;
  std::vector<std::array<int, 2>> firsts;
  for (std::size_t t = 0; t < plan.transmitters.size(); ++t) {
    const Transmitter& tx = plan.transmitters[t];
    if (tx.lat < dem.south || tx.lat > dem.north || tx.lon < dem.west || tx.lon > dem.east) {
      throw std::invalid_argument("transmitter " + label(plan, t) + " at " + num(tx.lat) + ", " + num(tx.lon) +
                                  " lies outside the DEM (" + num(dem.south) + ".." + num(dem.north) + " N, " +
                                  num(dem.west) + ".." + num(dem.east) + " E)");
    }
    check_rf_parameters(tx, plan.grid, options);
    RfBox box = rf_box(dem, tx, plan.grid, anchor.lat, anchor.lon);
    if (box.clipped) plan.notes.push_back("the box of " + label(plan, t) + " was clipped to the DEM's extent");
    const int i0 = static_cast<int>(std::lround((box.lattice.origin[0] - anchor.lon) / s));
    const int j0 = static_cast<int>(std::lround((box.lattice.origin[1] - anchor.lat) / s));
    firsts.push_back({i0, j0});
    i_lo = std::min(i_lo, i0);
    j_lo = std::min(j_lo, j0);
    i_hi = std::max(i_hi, i0 + box.lattice.dims[0] - 1);
    j_hi = std::max(j_hi, j0 + box.lattice.dims[1] - 1);
    plan.boxes.push_back(box.lattice);
  }
  Lattice& l = plan.lattice;
  l = plan.boxes.front();
  l.dims[0] = i_hi - i_lo + 1;
  l.dims[1] = j_hi - j_lo + 1;
  l.origin[0] = anchor.lon + i_lo * s;
  l.origin[1] = anchor.lat + j_lo * s;
  if (static_cast<double>(l.dims[0]) * l.dims[1] * l.dims[2] > static_cast<double>(kMaxPoints)) {
    throw std::invalid_argument("the lattice of all transmitters, " + std::to_string(l.dims[0]) + " x " +
                                std::to_string(l.dims[1]) + " x " + std::to_string(l.dims[2]) +
                                ", is too large (at most 2^28 points): use a coarser spacing or fewer heights");
  }
  for (const auto& f : firsts) plan.offsets.push_back({f[0] - i_lo, f[1] - j_lo});
  return plan;
}

std::size_t RowShare::values(const RfPlan& plan) const {
  std::size_t n = 0;
  for (std::size_t t = 0; t < rows.size(); ++t) {
    const Lattice& b = plan.boxes[t];
    n += rows[t].size() * static_cast<std::size_t>(b.dims[0]) * static_cast<std::size_t>(b.dims[2]);
  }
  return n;
}

RowShare share_of(const RfPlan& plan, int rank, int ranks) {
  if (ranks < 1 || rank < 0 || rank >= ranks) {
    throw std::invalid_argument("share_of: rank " + std::to_string(rank) + " of " + std::to_string(ranks));
  }
  RowShare share;
  share.rows.resize(plan.boxes.size());
  std::size_t g = 0;
  for (std::size_t t = 0; t < plan.boxes.size(); ++t) {
    for (int j = 0; j < plan.boxes[t].dims[1]; ++j, ++g) {
      if (static_cast<int>(g % static_cast<std::size_t>(ranks)) == rank) share.rows[t].push_back(j);
    }
  }
  return share;
}

DemExtent plan_area(const RfPlan& plan) {
  DemExtent a = rf_area(plan.transmitters.front(), plan.grid.radius_km);
  for (const Transmitter& tx : plan.transmitters) {
    const DemExtent b = rf_area(tx, plan.grid.radius_km);
    a.south = std::min(a.south, b.south);
    a.north = std::max(a.north, b.north);
    a.west = std::min(a.west, b.west);
    a.east = std::max(a.east, b.east);
  }
  return a;
}

std::vector<float> compute_share(const io::Grid& dem, const RfPlan& plan, const RowShare& share,
                                 const RfOptions& options, RfStats* stats) {
  if (share.rows.size() != plan.boxes.size()) throw std::invalid_argument("compute_share: the share is of another plan");
  std::vector<float> out(share.values(plan));
  const double total = static_cast<double>(out.size());
  std::size_t offset = 0;
  RfStats sum;
  for (std::size_t t = 0; t < plan.boxes.size(); ++t) {
    const Lattice& b = plan.boxes[t];
    const std::size_t n = share.rows[t].size() * static_cast<std::size_t>(b.dims[0]) * static_cast<std::size_t>(b.dims[2]);
    if (n == 0) continue;
    RfOptions o = options;
    if (options.progress) {
      o.progress = [&options, offset, n, total](double f) {
        options.progress((static_cast<double>(offset) + f * static_cast<double>(n)) / total);
      };
    }
    const RfStats st = compute_rf_rows(dem, plan.transmitters[t], b, share.rows[t], o,
                                       std::span<float>(out).subspan(offset, n),
                                       plan.grid.disc ? plan.grid.radius_km : 0.0);
    sum.itm_warned += st.itm_warned;
    sum.columns += st.columns;
    sum.samples += st.samples;
    sum.seconds += st.seconds;
    offset += n;
  }
  if (stats) *stats = sum;
  return out;
}

PlanAssembler::PlanAssembler(const RfPlan& plan, const RfOptions& options, const std::string& vertical_datum)
    : plan_(plan) {
  for (std::size_t t = 0; t < plan.boxes.size(); ++t) {
    volumes_.push_back(path_loss_volume(plan.transmitters[t], plan.boxes[t], options, vertical_datum));
    if (plan.grid.disc) volumes_.back().attributes["disc_radius_km"] = num(plan.grid.radius_km);
    filled_.emplace_back(static_cast<std::size_t>(plan.boxes[t].dims[1]), 0);
    missing_ += static_cast<std::size_t>(plan.boxes[t].dims[1]);
  }
}

void PlanAssembler::add(const RowShare& share, std::span<const float> values) {
  if (share.rows.size() != plan_.boxes.size() || values.size() != share.values(plan_)) {
    throw std::invalid_argument("PlanAssembler::add: " + std::to_string(values.size()) +
                                " values for a share of " + std::to_string(share.values(plan_)));
  }
  std::size_t offset = 0;
  for (std::size_t t = 0; t < plan_.boxes.size(); ++t) {
    const Lattice& b = plan_.boxes[t];
    const auto& rows = share.rows[t];
    const std::size_t nx = static_cast<std::size_t>(b.dims[0]), nr = rows.size();
    for (const int j : rows) {
      if (j < 0 || j >= b.dims[1] || filled_[t][static_cast<std::size_t>(j)]) {
        throw std::invalid_argument("PlanAssembler::add: row " + std::to_string(j) + " of " + label(plan_, t) +
                                    " is outside the box or came twice");
      }
      filled_[t][static_cast<std::size_t>(j)] = 1;
      --missing_;
    }
    std::vector<float>& dst = volumes_[t].values;
    for (int k = 0; k < b.dims[2]; ++k) {
      for (std::size_t r = 0; r < nr; ++r) {
        const float* src = values.data() + offset + nx * (r + nr * static_cast<std::size_t>(k));
        std::copy(src, src + nx, dst.begin() + static_cast<std::ptrdiff_t>(b.index(0, rows[r], k)));
      }
    }
    offset += nx * nr * static_cast<std::size_t>(b.dims[2]);
  }
}

std::vector<Volume> PlanAssembler::take() {
  if (missing_ != 0) throw std::logic_error("PlanAssembler::take: " + std::to_string(missing_) + " rows missing");
  return std::move(volumes_);
}

BestServer best_server(const RfPlan& plan, const std::vector<Volume>& signals) {
  if (signals.size() != plan.boxes.size()) throw std::invalid_argument("best_server: one signal per transmitter");
  for (std::size_t t = 0; t < signals.size(); ++t) {
    if (!(signals[t].lattice == plan.boxes[t])) throw std::invalid_argument("best_server: a signal is not on its box");
  }
  BestServer b;
  std::string list;
  for (std::size_t t = 0; t < plan.transmitters.size(); ++t) {
    const Transmitter& tx = plan.transmitters[t];
    list += (t ? ";" : "") + label(plan, t) + "," + num(tx.lat) + "," + num(tx.lon) + "," + num(tx.height_agl);
  }
  for (Volume* v : {&b.best_signal, &b.best_server}) {
    v->frame = signals.front().frame;
    v->lattice = plan.lattice;
    v->values.assign(plan.lattice.size(), kNaN);
    v->background = kNaN;
    v->active_points = plan.lattice.size();
    v->attributes["transmitters"] = list;
    for (const char* key : {"frequency_mhz", "k_factor", "model", "vertical_datum", "dem"}) {
      const auto it = signals.front().attributes.find(key);
      if (it != signals.front().attributes.end()) v->attributes[key] = it->second;
    }
  }
  b.best_signal.name = "best_signal_dbm";
  b.best_signal.units = "dBm";
  b.best_signal.attributes["signal"] = "the strongest signal_dbm of the transmitters whose box holds the point";
  b.best_server.name = "best_server";
  b.best_server.units = "";
  b.best_server.attributes["values"] =
      "the position in 'transmitters' (from 1) of the transmitter giving best_signal_dbm; NaN: no transmitter's box";
  const Lattice& u = plan.lattice;
  for (std::size_t t = 0; t < signals.size(); ++t) {
    const Lattice& box = plan.boxes[t];
    const auto [oi, oj] = plan.offsets[t];
    const float server = static_cast<float>(t + 1);
    for (int k = 0; k < box.dims[2]; ++k) {
      for (int j = 0; j < box.dims[1]; ++j) {
        const float* src = &signals[t].values[box.index(0, j, k)];
        const std::size_t dst = u.index(oi, oj + j, k);
        for (int i = 0; i < box.dims[0]; ++i) {
          const float s = src[i];
          float& best = b.best_signal.values[dst + static_cast<std::size_t>(i)];
          if (std::isfinite(s) && !(best >= s)) {  // NaN best: not yet covered
            best = s;
            b.best_server.values[dst + static_cast<std::size_t>(i)] = server;
          }
        }
      }
    }
  }
  return b;
}

std::vector<RecordedTransmitter> recorded_transmitters(const Volume& volume) {
  std::vector<RecordedTransmitter> out;
  const auto it = volume.attributes.find("transmitters");
  if (it == volume.attributes.end() || text::trim(it->second).empty()) return out;
  for (std::string_view entry : text::split_on(it->second, ';')) {
    const std::vector<std::string_view> f = text::split_on(entry, ',');
    RecordedTransmitter t;
    std::optional<double> lat, lon, h;
    if (f.size() == 4) {
      t.name = std::string(text::trim(f[0]));
      lat = text::to_number(text::trim(f[1]));
      lon = text::to_number(text::trim(f[2]));
      h = text::to_number(text::trim(f[3]));
    }
    if (t.name.empty() || !lat || !lon || !h || !std::isfinite(*lat) || !std::isfinite(*lon) || !std::isfinite(*h)) {
      throw std::invalid_argument("attribute transmitters: '" + std::string(entry) + "' is not NAME,LAT,LON,HEIGHT_AGL");
    }
    t.lat = *lat;
    t.lon = *lon;
    t.height_agl = *h;
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace terravol::volume
