// Whether the 10 ms loop keeps up: what `status` reports and when the log warns.
#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "../../daemon/src/LoopHealth.hpp"
#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

using namespace std::chrono_literals;

TEST(LoopHealth, CountsTicksMissedPeriodsAndTheBusiestTurn) {
    daemon::LoopHealth loop;
    loop.tick(0.001, 0);
    loop.tick(0.003, 2);
    loop.turn(0.004);
    loop.turn(0.020);
    const auto r = loop.reply();
    EXPECT_EQ(r["ticks"], 2);
    EXPECT_EQ(r["missed"], 2);
    EXPECT_NEAR(r["tick_cpu_ms_mean"].get<double>(), 2.0, 1e-9);
    EXPECT_NEAR(r["tick_cpu_ms_max"].get<double>(), 3.0, 1e-9);
    EXPECT_NEAR(r["busiest_cpu_ms"].get<double>(), 20.0, 1e-9);
}

TEST(LoopHealth, WarnsWhilePeriodsAreMissedAtMostOnceAMinute) {
    daemon::LoopHealth loop;
    loop.tick(0.001, 0);
    EXPECT_FALSE(loop.warning(0)) << "it kept up";
    loop.tick(0.001, 3);
    loop.turn(0.035);
    const auto first = loop.warning(1);
    ASSERT_TRUE(first);
    EXPECT_NE(first->find("3 ticks"), std::string::npos) << *first;
    EXPECT_NE(first->find("35 ms"), std::string::npos) << *first;
    loop.tick(0.001, 1);
    EXPECT_FALSE(loop.warning(30)) << "a minute has not passed";
    const auto second = loop.warning(61.5);
    ASSERT_TRUE(second) << "the tick missed since is still said";
    EXPECT_NE(second->find("1 ticks"), std::string::npos) << *second;
    EXPECT_FALSE(loop.warning(200)) << "nothing missed since";
}

// A daemon held back (stopped for a quarter of a second, as a board too busy to run it would
// hold it) misses ticks: status counts them and the log says the mouth may lag.
TEST(LoopHealth, ADaemonHeldBackSaysSoInStatusAndTheLog) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    // The socket answers as soon as the daemon listens; its loop may not have ticked yet on a
    // busy machine: wait (up to 5 s) until it has.
    const auto ticked = [](const json& s) { return s["loop"]["ticks"].get<int>() > 0; };
    const auto before = statusWhen(c, ticked, 5s)["loop"];
    ASSERT_GT(before["ticks"].get<int>(), 0) << before;
    ::kill(d.pid, SIGSTOP);
    std::this_thread::sleep_for(250ms);
    ::kill(d.pid, SIGCONT);
    std::this_thread::sleep_for(100ms);
    const auto after = c.request({{"cmd", "status"}})["loop"];
    EXPECT_GE(after["missed"].get<int>(), 15) << after;
    EXPECT_GT(after["ticks"].get<int>(), before["ticks"].get<int>()) << after;
    EXPECT_EQ(d.stop(), 0);
    EXPECT_NE(d.log().find("the loop fell behind"), std::string::npos) << d.log();
}

}  // namespace
}  // namespace lipsyncd::test
