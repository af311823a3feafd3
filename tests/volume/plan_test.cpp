// Several transmitters: the plan's boxes against compute_rf's, any split over ranks giving the
// same bits as computing each transmitter alone, and the best server against a brute-force
// search over the transmitters in world coordinates.
#include "volume/plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

#include "volume_test_util.h"

namespace terravol::volume {
namespace {

// Smooth hills over 45..46 N, 6..7 E.
io::Grid hills() {
  return test::synthetic_dem([](double lat, double lon) { return 600.0 + 250.0 * std::sin(30.0 * lat) * std::cos(40.0 * lon); });
}

Transmitter tx(double lat, double lon, double erp, const std::string& name) {
  Transmitter t;
  t.lat = lat;
  t.lon = lon;
  t.height_agl = 25.0;
  t.erp_w = erp;
  t.name = name;
  return t;
}

RfGrid small_grid() {
  RfGrid g;
  g.radius_km = 3.0;
  g.spacing_arcsec = 12.0;
  g.heights_agl = {5.0, 55.0, 105.0};
  return g;
}

const DemExtent kExtent{45.0, 46.0, 6.0, 7.0};
constexpr double kStep = 12.0 / 3600.0;

// Transmitters on the first one's grid (so each one's own compute_rf lattice lines up).
std::vector<Transmitter> three() {
  return {tx(45.5, 6.5, 50.0, "a"), tx(45.5 + 6 * kStep, 6.5 + 8 * kStep, 20.0, "b"),
          tx(45.5 - 5 * kStep, 6.5 + 14 * kStep, 80.0, "c")};
}

TEST(RfPlan, BoxesAreEachTransmittersOwnOnOneGrid) {
  const io::Grid dem = hills();
  const RfPlan plan = plan_rf(kExtent, 3.0, three(), small_grid());
  ASSERT_EQ(plan.boxes.size(), 3u);
  for (std::size_t t = 0; t < 3; ++t) {
    const RfResult alone = compute_rf(dem, plan.transmitters[t], small_grid());
    EXPECT_EQ(plan.boxes[t].dims, alone.path_loss.lattice.dims) << t;
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(plan.boxes[t].origin[a], alone.path_loss.lattice.origin[a], 1e-9) << t;
    // The box's lattice points are the union's, at its offset.
    const auto [oi, oj] = plan.offsets[t];
    EXPECT_NEAR(plan.lattice.world(0, oi), plan.boxes[t].origin[0], 1e-9);
    EXPECT_NEAR(plan.lattice.world(1, oj), plan.boxes[t].origin[1], 1e-9);
    EXPECT_LE(oi + plan.boxes[t].dims[0], plan.lattice.dims[0]);
    EXPECT_LE(oj + plan.boxes[t].dims[1], plan.lattice.dims[1]);
  }
  EXPECT_TRUE(plan.boxes[0] == compute_rf(dem, plan.transmitters[0], small_grid()).path_loss.lattice);
  EXPECT_TRUE(plan.notes.empty());
}

TEST(RfPlan, RejectsWhatTheModelRejects) {
  EXPECT_THROW(plan_rf(kExtent, 3.0, {}, small_grid()), std::invalid_argument);
  auto bad = three();
  bad[1].lat = 50.0;
  EXPECT_THROW(plan_rf(kExtent, 3.0, bad, small_grid()), std::invalid_argument);
  bad = three();
  bad[2].frequency_mhz = -1.0;
  EXPECT_THROW(plan_rf(kExtent, 3.0, bad, small_grid()), std::invalid_argument);
  auto corner = three();
  corner[2].lat = 45.005;
  EXPECT_EQ(plan_rf(kExtent, 3.0, corner, small_grid()).notes.size(), 1u);
}

TEST(PlanShares, EveryRowOnceAndSplitsGiveTheBitsOfOneProcess) {
  const io::Grid dem = hills();
  const RfPlan plan = plan_rf(kExtent, 3.0, three(), small_grid());
  std::vector<std::vector<float>> alone;
  for (const Transmitter& t : plan.transmitters) alone.push_back(compute_rf(dem, t, small_grid()).path_loss.values);
  for (const int ranks : {1, 2, 3, 5}) {
    SCOPED_TRACE(ranks);
    PlanAssembler assembler(plan, {}, "");
    std::size_t values = 0;
    // Ranks in reverse: the assembler does not care about the order.
    for (int r = ranks - 1; r >= 0; --r) {
      const RowShare share = share_of(plan, r, ranks);
      const std::vector<float> v = compute_share(dem, plan, share, {});
      EXPECT_EQ(v.size(), share.values(plan));
      values += v.size();
      assembler.add(share, v);
    }
    const std::vector<Volume> got = assembler.take();
    std::size_t total = 0;
    for (std::size_t t = 0; t < 3; ++t) {
      total += plan.boxes[t].size();
      ASSERT_EQ(got[t].values.size(), alone[t].size());
      EXPECT_EQ(std::memcmp(got[t].values.data(), alone[t].data(), alone[t].size() * sizeof(float)), 0) << t;
      EXPECT_EQ(got[t].name, "path_loss_db");
      EXPECT_EQ(got[t].attributes.at("tx_name"), plan.transmitters[t].name);
    }
    EXPECT_EQ(values, total);
  }
}

// The same with the Longley-Rice model: a plan's shares over ranks are each transmitter's
// compute_rf with ITM, to the bit (NaN at the transmitters' own columns included).
TEST(PlanShares, ItmSplitsGiveTheBitsOfOneProcess) {
  const io::Grid dem = hills();
  RfOptions o;
  o.model = RfModel::kItm;
  const RfPlan plan = plan_rf(kExtent, 3.0, three(), small_grid(), o);
  for (const int ranks : {1, 3}) {
    SCOPED_TRACE(ranks);
    PlanAssembler assembler(plan, o, "");
    for (int r = 0; r < ranks; ++r) {
      const RowShare share = share_of(plan, r, ranks);
      assembler.add(share, compute_share(dem, plan, share, o));
    }
    const std::vector<Volume> got = assembler.take();
    for (std::size_t t = 0; t < 3; ++t) {
      const std::vector<float> alone = compute_rf(dem, plan.transmitters[t], small_grid(), o).path_loss.values;
      ASSERT_EQ(got[t].values.size(), alone.size());
      EXPECT_EQ(std::memcmp(got[t].values.data(), alone.data(), alone.size() * sizeof(float)), 0) << t;
      EXPECT_NE(got[t].attributes.at("model").find("Longley-Rice ITM"), std::string::npos);
    }
  }
}

TEST(PlanShares, AssemblerRefusesWrongOrMissingShares) {
  const io::Grid dem = hills();
  const RfPlan plan = plan_rf(kExtent, 3.0, three(), small_grid());
  PlanAssembler assembler(plan, {}, "");
  const RowShare share = share_of(plan, 0, 2);
  const std::vector<float> v = compute_share(dem, plan, share, {});
  EXPECT_THROW(assembler.add(share, std::span<const float>(v).first(v.size() - 1)), std::invalid_argument);
  assembler.add(share, v);
  EXPECT_THROW(assembler.add(share, v), std::invalid_argument);  // the same rows again
  EXPECT_THROW(assembler.take(), std::logic_error);
  EXPECT_THROW(share_of(plan, 2, 2), std::invalid_argument);
}

TEST(BestServer, IsTheStrongestCoveringTransmitterFoundByBruteForce) {
  const io::Grid dem = hills();
  const RfPlan plan = plan_rf(kExtent, 3.0, three(), small_grid());
  std::vector<Volume> signals;
  PlanAssembler assembler(plan, {}, "");
  const RowShare all = share_of(plan, 0, 1);
  assembler.add(all, compute_share(dem, plan, all, {}));
  std::vector<Volume> losses = assembler.take();
  for (std::size_t t = 0; t < 3; ++t) signals.push_back(signal_from_path_loss(losses[t], *plan.transmitters[t].erp_w));
  const BestServer best = best_server(plan, signals);
  const Lattice& u = plan.lattice;
  EXPECT_EQ(best.best_signal.lattice, u);
  std::size_t covered = 0, by[3] = {0, 0, 0};
  std::mt19937 rng(17);
  for (int k = 0; k < u.dims[2]; ++k) {
    for (int j = 0; j < u.dims[1]; ++j) {
      for (int i = 0; i < u.dims[0]; ++i) {
        // Brute force: every transmitter whose box holds the point's world coordinates.
        const double lon = u.world(0, i), lat = u.world(1, j);
        float want = NAN;
        int server = 0;
        for (std::size_t t = 0; t < 3; ++t) {
          const Lattice& b = signals[t].lattice;
          const double fi = (lon - b.origin[0]) / b.spacing[0], fj = (lat - b.origin[1]) / b.spacing[1];
          const int bi = static_cast<int>(std::lround(fi)), bj = static_cast<int>(std::lround(fj));
          if (bi < 0 || bj < 0 || bi >= b.dims[0] || bj >= b.dims[1]) continue;
          ASSERT_NEAR(fi, bi, 1e-6);
          const float s = signals[t].at(bi, bj, k);
          if (std::isnan(want) || s > want) {
            want = s;
            server = static_cast<int>(t) + 1;
          }
        }
        const float got = best.best_signal.at(i, j, k), got_server = best.best_server.at(i, j, k);
        if (server == 0) {
          EXPECT_TRUE(std::isnan(got) && std::isnan(got_server)) << i << " " << j << " " << k;
          continue;
        }
        ++covered;
        ++by[server - 1];
        ASSERT_EQ(got, want) << i << " " << j << " " << k;
        ASSERT_EQ(got_server, static_cast<float>(server)) << i << " " << j << " " << k;
      }
    }
  }
  EXPECT_LT(covered, u.size());  // the union has corners no box holds
  std::size_t overlap = 0;  // points two or more boxes hold: where the choice is made
  for (int j = 0; j < u.dims[1]; ++j) {
    for (int i = 0; i < u.dims[0]; ++i) {
      int holders = 0;
      for (std::size_t t = 0; t < 3; ++t) {
        const auto [oi, oj] = plan.offsets[t];
        holders += i >= oi && j >= oj && i < oi + plan.boxes[t].dims[0] && j < oj + plan.boxes[t].dims[1];
      }
      overlap += holders > 1;
    }
  }
  EXPECT_GT(overlap, 100u);
  for (const std::size_t n : by) EXPECT_GT(n, 100u);
  EXPECT_EQ(best.best_server.attributes.at("transmitters").substr(0, 12), "a,45.5,6.5,2");
}

TEST(RecordedTransmitters, ParsesTheAttributeInOrderAndNamesABadEntry) {
  Volume v;
  EXPECT_TRUE(recorded_transmitters(v).empty());
  v.attributes["transmitters"] = "slc,40.7608,-111.891,30;east peak,40.7,-111.75,12.5";
  const std::vector<RecordedTransmitter> t = recorded_transmitters(v);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].name, "slc");
  EXPECT_EQ(t[0].lat, 40.7608);
  EXPECT_EQ(t[0].lon, -111.891);
  EXPECT_EQ(t[0].height_agl, 30.0);
  EXPECT_EQ(t[1].name, "east peak");
  EXPECT_EQ(t[1].height_agl, 12.5);
  for (const char* bad : {"slc,40.7,-111.8", "slc,40.7,x,30", ",40.7,-111.8,30", "a,1,2,3;;b,1,2,3"}) {
    v.attributes["transmitters"] = bad;
    try {
      recorded_transmitters(v);
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("attribute transmitters: '", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace terravol::volume
