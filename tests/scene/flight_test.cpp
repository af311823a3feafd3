// app/scene/flight.h: the viewer's flight controls, without a window.
#include <gtest/gtest.h>

#include <cmath>

#include "app/scene/flight.h"
#include "io/scene_frame.h"

namespace terravol::app::scene {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// Metres east and north of `from` to `to`, at the frame's scale.
struct Offset {
  double east, north, up;
};
Offset offset(const io::SceneFrame& f, const CameraPose& from, const CameraPose& to) {
  return {(to.lon - from.lon) * f.metres_per_degree_lon(), (to.lat - from.lat) * f.metres_per_degree_lat(),
          to.alt - from.alt};
}

const io::SceneFrame kFrame(45.5, 6.5);
const auto kFlat = [](double, double) { return 0.0; };

TEST(Flight, SpeedIsTheHeightAboveGroundPerSecondWithinLimits) {
  FlightSettings s;
  EXPECT_DOUBLE_EQ(flight_speed(1000.0, s, false), 1000.0);
  EXPECT_DOUBLE_EQ(flight_speed(1000.0, s, true), 4000.0);
  EXPECT_DOUBLE_EQ(flight_speed(1.0, s, false), s.min_speed);
  EXPECT_DOUBLE_EQ(flight_speed(1e9, s, false), s.max_speed);
  s.speed_factor = 3.0;
  EXPECT_DOUBLE_EQ(flight_speed(1000.0, s, false), 3000.0);
}

TEST(Flight, ForwardAtLevelPitchMovesAlongTheHeadingAtConstantAltitude) {
  const CameraPose start{45.5, 6.5, 1000.0, 30.0, 0.0};
  FlightInput in;
  in.forward = 1;
  const CameraPose end = fly(start, in, 0.5, kFrame, kFlat, FlightSettings{});
  const Offset d = offset(kFrame, start, end);
  EXPECT_NEAR(std::hypot(d.east, d.north), 500.0, 1e-6);  // 1000 m/s for half a second
  EXPECT_NEAR(std::atan2(d.east, d.north) / kDegree, 30.0, 1e-9);
  EXPECT_NEAR(d.up, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(end.heading_deg, 30.0);
  EXPECT_DOUBLE_EQ(end.pitch_deg, 0.0);
}

TEST(Flight, ForwardLookingDownDescendsAlongTheView) {
  const CameraPose start{45.5, 6.5, 3000.0, 200.0, -30.0};
  FlightInput in;
  in.forward = 1;
  const CameraPose end = fly(start, in, 0.1, kFrame, kFlat, FlightSettings{});
  const Offset d = offset(kFrame, start, end);
  const double horizontal = std::hypot(d.east, d.north);
  EXPECT_NEAR(std::hypot(horizontal, d.up), 300.0, 1e-6);
  EXPECT_NEAR(std::atan2(d.up, horizontal) / kDegree, -30.0, 1e-9);
  EXPECT_NEAR(std::atan2(d.east, d.north) / kDegree, 200.0 - 360.0, 1e-9);
}

TEST(Flight, BackStrafeAndVerticalMoves) {
  const CameraPose start{45.5, 6.5, 1000.0, 90.0, -10.0};
  FlightInput back;
  back.forward = -1;
  Offset d = offset(kFrame, start, fly(start, back, 0.1, kFrame, kFlat, FlightSettings{}));
  EXPECT_LT(d.east, -90.0);  // west, and up: back along a downward view
  EXPECT_GT(d.up, 0.0);

  FlightInput right;
  right.right = 1;  // heading east: strafing right goes south, horizontally
  d = offset(kFrame, start, fly(start, right, 0.1, kFrame, kFlat, FlightSettings{}));
  EXPECT_NEAR(d.north, -100.0, 1e-6);
  EXPECT_NEAR(d.east, 0.0, 1e-6);
  EXPECT_NEAR(d.up, 0.0, 1e-9);

  FlightInput up;
  up.up = 1;
  d = offset(kFrame, start, fly(start, up, 0.1, kFrame, kFlat, FlightSettings{}));
  EXPECT_NEAR(d.up, 100.0, 1e-9);
  EXPECT_NEAR(std::hypot(d.east, d.north), 0.0, 1e-9);
}

TEST(Flight, NeverGoesBelowTheClearanceOverTheGround) {
  const auto hill = [](double, double) { return 800.0; };
  const CameraPose start{45.5, 6.5, 1000.0, 0.0, -90.0};
  FlightInput down;
  down.forward = 1;
  FlightSettings s;
  const CameraPose end = fly(start, down, 10.0, kFrame, hill, s);
  EXPECT_DOUBLE_EQ(end.alt, 800.0 + s.min_clearance);
}

TEST(Flight, TurningWrapsTheHeadingAndTiltingStopsShortOfVertical) {
  FlightSettings s;
  const CameraPose start{45.5, 6.5, 1000.0, 350.0, 80.0};
  FlightInput in;
  in.turn = 1;
  in.tilt = 1;
  const CameraPose end = fly(start, in, 0.5, kFrame, kFlat, s);
  EXPECT_NEAR(end.heading_deg, 20.0, 1e-9);  // 350 + 30
  EXPECT_DOUBLE_EQ(end.pitch_deg, s.max_pitch);
  EXPECT_DOUBLE_EQ(end.lat, start.lat);
  in.turn = -1;
  EXPECT_NEAR(fly(start, in, 0.5, kFrame, kFlat, s).heading_deg, 320.0, 1e-9);
}

TEST(Flight, MouseDragRightTurnsRightAndUpLooksUp) {
  FlightSettings s;
  const CameraPose start{45.5, 6.5, 1000.0, 10.0, -20.0};
  const CameraPose p = look(start, 100.0, 40.0, s);
  EXPECT_NEAR(p.heading_deg, 10.0 + 100.0 * s.look_deg_per_px, 1e-9);
  EXPECT_NEAR(p.pitch_deg, -20.0 + 40.0 * s.look_deg_per_px, 1e-9);
  EXPECT_NEAR(look(start, -100.0, 0.0, s).heading_deg, 360.0 + 10.0 - 100.0 * s.look_deg_per_px, 1e-9);
  EXPECT_DOUBLE_EQ(look(start, 0.0, -1e6, s).pitch_deg, -s.max_pitch);
}

}  // namespace
}  // namespace terravol::app::scene
