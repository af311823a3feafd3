// Wall-clock milliseconds, for the figures the commands report (render --stats, fly --stats,
// the viewer's overlay and status file, the volumes' merge figures).
#pragma once

#include <chrono>

namespace terravol::app::scene {

using Clock = std::chrono::steady_clock;

inline double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}
inline double ms_since(Clock::time_point from) { return ms_between(from, Clock::now()); }

}  // namespace terravol::app::scene
