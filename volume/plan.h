// Several transmitters over one DEM (`terravol rf --tx A --tx B ...`): each transmitter's path
// loss on its own box, the best server over all of them, and the split of the work over the
// ranks of an MPI run. The per-transmitter computation is propagation.h's (compute_rf_rows);
// this is the loop around it.
//
// Determinism: every value depends only on its transmitter, its lattice point and the DEM
// window, never on which rank or thread computed it, so a run split over any number of ranks
// gives the same bits as one process.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "io/grid.h"
#include "volume/propagation.h"
#include "volume/volume.h"

namespace terravol::volume {

// The lattices of a plan. Every box is compute_rf's box for its transmitter (rf_box) on the grid
// of the first transmitter (longitudes tx0.lon + i s, latitudes tx0.lat + j s), so boxes of
// different transmitters share their lattice points and the first transmitter's box is exactly
// the one `terravol rf` gives it alone.
struct RfPlan {
  std::vector<Transmitter> transmitters;  // at least one
  RfGrid grid;                            // resolved (resolve_grid)
  std::vector<Lattice> boxes;             // one per transmitter
  std::vector<std::array<int, 2>> offsets;  // each box's first column (i, j) in `lattice`
  Lattice lattice;                        // the smallest lattice holding every box
  std::vector<std::string> notes;         // "the box of tx2 was clipped to the DEM's extent"
};

// Throws std::invalid_argument for bad parameters (propagation.h's checks), no transmitter, a
// transmitter outside the DEM, and a union lattice of more than kMaxPoints points.
RfPlan plan_rf(const DemExtent& dem, double dem_spacing_arcsec, std::vector<Transmitter> transmitters,
            const RfGrid& grid, const RfOptions& options = {});

// One rank's share of the work: rows (t, j) of the boxes, numbered transmitter by transmitter
// and row by row from 0; row number g belongs to rank g mod ranks. Interleaving rows keeps the
// shares even: a box's near rows (short paths) and far rows (long ones) are dealt out alike.
struct RowShare {
  std::vector<std::vector<int>> rows;  // per transmitter, increasing
  // How many values compute_share returns for this share under `plan`.
  std::size_t values(const RfPlan& plan) const;
};
// Precondition: 0 <= rank < ranks (std::invalid_argument).
RowShare share_of(const RfPlan& plan, int rank, int ranks);

// The path loss of a share: for each transmitter in order, compute_rf_rows over its rows
// (that function's layout), concatenated. `progress` in options is told the fraction of the
// share done. `dem` must hold every box (read_rf_window(plan_area(plan))).
std::vector<float> compute_share(const io::Grid& dem, const RfPlan& plan, const RowShare& share,
                                 const RfOptions& options, RfStats* stats = nullptr);

// The area every box of the plan may cover (the union of rf_area over its transmitters).
DemExtent plan_area(const RfPlan& plan);

// Puts shares together into one path-loss volume per transmitter (path_loss_volume).
class PlanAssembler {
 public:
  PlanAssembler(const RfPlan& plan, const RfOptions& options, const std::string& vertical_datum);
  // Adds a share's values (compute_share's). Throws std::invalid_argument when the count is
  // wrong or a row was added before.
  void add(const RowShare& share, std::span<const float> values);
  // The volumes, in the plan's order. Throws std::logic_error unless every row was added.
  std::vector<Volume> take();

 private:
  const RfPlan& plan_;
  std::vector<Volume> volumes_;
  std::vector<std::vector<char>> filled_;
  std::size_t missing_ = 0;
};

// The strongest signal at each point of the plan's lattice over the transmitters whose box holds
// the point, and which transmitter gives it:
// - "best_signal_dbm", dBm: the largest finite signal there (signals[t] on boxes[t]);
// - "best_server": the transmitter's position in the plan, from 1 (ties: the first);
// both NaN where no box holds the point. Both carry the attribute "transmitters",
// "NAME,LAT,LON,HEIGHT_AGL;..." in plan order, and the frame of the signals.
// Precondition: one signal per transmitter on its box (std::invalid_argument).
struct BestServer {
  Volume best_signal, best_server;
};
BestServer best_server(const RfPlan& plan, const std::vector<Volume>& signals);

// A transmitter as a volume records it in its attribute "transmitters" (best_server above).
struct RecordedTransmitter {
  std::string name;
  double lat = 0, lon = 0;  // degrees
  double height_agl = 0;    // metres above the ground
};
// The volume's "transmitters", in their order (best_server's values count from 1 in it); empty
// when it has no such attribute. Throws std::invalid_argument("attribute transmitters: ...")
// naming the entry that is not NAME,LAT,LON,HEIGHT_AGL with finite numbers.
std::vector<RecordedTransmitter> recorded_transmitters(const Volume& volume);

}  // namespace terravol::volume
