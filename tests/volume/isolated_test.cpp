// The child process that runs hostile-input parsers (volume/isolated.h): its answer comes back
// whole, a child that hangs is killed at the timeout and says so, and a crash is reported.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <string>
#include <thread>

#include "volume/isolated.h"

namespace terravol::volume::detail {
namespace {

TEST(RunIsolated, TheChildsAnswerComesBackWhole) {
  const std::string big(300000, 'x');  // more than a pipe holds at once
  const IsolatedRun run = run_isolated([&] { return big + "end"; }, std::size_t{1} << 30, 30.0);
  ASSERT_TRUE(run.ok) << run.failure;
  EXPECT_FALSE(run.timed_out);
  EXPECT_EQ(run.output, big + "end");
}

TEST(RunIsolated, AChildThatHangsIsKilledAtTheTimeoutAndSaysSo) {
  const auto t0 = std::chrono::steady_clock::now();
  const IsolatedRun run = run_isolated(
      [] {
        std::this_thread::sleep_for(std::chrono::seconds(20));
        return std::string("late");
      },
      std::size_t{1} << 30, 0.5);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(run.ok);
  EXPECT_TRUE(run.timed_out);
  EXPECT_EQ(run.failure, "took longer than 0.5 s");
  EXPECT_LT(s, 10.0);
}

TEST(RunIsolated, ACrashIsReportedWithItsSignal) {
  const IsolatedRun run = run_isolated(
      [] {
        std::raise(SIGSEGV);
        return std::string("never");
      },
      std::size_t{1} << 30, 30.0);
  EXPECT_FALSE(run.ok);
  EXPECT_FALSE(run.timed_out);
  EXPECT_NE(run.failure.find("crashed (signal 11"), std::string::npos) << run.failure;
}

}  // namespace
}  // namespace terravol::volume::detail
