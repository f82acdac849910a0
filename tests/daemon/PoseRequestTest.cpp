// `pose`: a client sets the mouth's pose weights directly (the curve editor's preview on the
// puppet). They go through the puppet driver as a clip's do, so its limits and slew hold; a
// pose is held 0.25 s, after which the puppet's stall rule rests the mouth; a pose never
// fights a clip that plays. What is not a weight in [0, 1] of a pose the daemon knows is
// refused by name, and the daemon goes on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <lipsyncd/daemon.hpp>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

double jawAt(const DaemonProcess& d, double from, double to, bool peak) {
    double v = peak ? 0 : 1e9;
    for (const auto& [t, jaw] : d.recorded("jaw"))
        if (t >= from && t <= to) v = peak ? std::max(v, jaw) : std::min(v, jaw);
    return v;
}

// When the jaw first left rest (the daemon is idle and at rest until a pose arrives).
double firstMove(const DaemonProcess& d) {
    for (const auto& [t, jaw] : d.recorded("jaw"))
        if (jaw != 0.0) return t;
    return -1;
}

TEST(PoseRequest, APoseMovesTheJawWithinItsSlewAndRestsAfterTheHold) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto reply = c.request({{"cmd", "pose"}, {"weights", {{"jaw", 0.6}, {"w", 0.2}}}});
    ASSERT_EQ(reply["ok"], true) << reply;
    EXPECT_DOUBLE_EQ(reply["held"].get<double>(), 0.25);
    // Held 0.25 s, then the terminal puppet's stall timeout (0.5 s) and its slew back to rest.
    std::this_thread::sleep_for(1500ms);
    EXPECT_EQ(d.stop(), 0);
    const auto jaw = d.recorded("jaw");
    double peak = 0, fastest = 0, reached = -1, rested = -1;
    for (std::size_t i = 1; i < jaw.size(); ++i) {
        const auto& [t, v] = jaw[i];
        peak = std::max(peak, v);
        if (reached < 0 && v >= 0.6 - 1e-6) reached = t;
        if (reached >= 0 && rested < 0 && v == 0.0) rested = t;
        const double dt = t - jaw[i - 1].first;
        if (dt > 1e-6) fastest = std::max(fastest, std::abs(v - jaw[i - 1].second) / dt);
    }
    EXPECT_NEAR(peak, 0.6, 1e-6) << "the jaw's gain is 1 and nothing else moves it";
    EXPECT_LE(fastest, 15.0 * 1.05) << "the jaw's slew limit (terminal.toml: 15 a second)";
    ASSERT_GT(reached, 0) << "the jaw never reached the pose";
    ASSERT_GT(rested, 0) << "the jaw never went back to rest";
    // At the pose for the hold at least, at rest within hold + stall timeout + slew after it.
    EXPECT_GE(rested - reached, 0.25 - 0.05);
    EXPECT_LT(rested - reached, 0.25 + 0.5 + 0.2);
    EXPECT_EQ(jaw.back().second, 0.0);
}

TEST(PoseRequest, AStreamOfPosesHoldsTheMouthWithoutResting) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    auto longestGap = std::chrono::steady_clock::duration{};
    while (std::chrono::steady_clock::now() - start < 1500ms) {  // 3× the stall timeout
        ASSERT_EQ(c.request({{"cmd", "pose"}, {"weights", {{"jaw", 0.4}}}})["ok"], true);
        const auto now = std::chrono::steady_clock::now();
        longestGap = std::max(longestGap, now - last);
        last = now;
        std::this_thread::sleep_for(30ms);
    }
    EXPECT_EQ(d.stop(), 0);
    // A pose is held 0.25 s and the puppet rests 0.5 s (its stall timeout) after that: only a
    // client stalled that long by a busy machine makes resting right.
    if (longestGap > 700ms) GTEST_SKIP() << "the client stalled between two poses (machine busy)";
    const double t0 = firstMove(d);
    ASSERT_GT(t0, 0) << "the jaw never moved";
    // Up in 0.4 / 15 s. Checked until 1.1 s in: longer than hold + stall timeout (0.75 s), and
    // clear of the rest that stop() makes once the 1.5 s stream ends (a late first move on a busy
    // machine would otherwise put that rest inside the window).
    EXPECT_NEAR(jawAt(d, t0 + 0.1, t0 + 1.1, false), 0.4, 1e-6) << "rested mid-stream";
}

TEST(PoseRequest, BadWeightsAreRefusedByNameAndTheDaemonGoesOn) {
    // The table refuses what JSON cannot even carry over the socket (a NaN) the same way.
    const auto nan = std::numeric_limits<double>::quiet_NaN();
    for (const auto& bad : {json{{"jaw", nan}}, json{{"jaw", 1.5}}, json{{"jaw", -0.1}},
                            json{{"jaw", "0.5"}}, json{{"jaw", true}}, json{{"", 0.5}}}) {
        const auto why = daemon::checkControlRequest({{"cmd", "pose"}, {"weights", bad}});
        ASSERT_TRUE(why.has_value()) << bad;
        EXPECT_NE(why->find("weights"), std::string::npos) << *why;
    }
    EXPECT_FALSE(daemon::checkControlRequest({{"cmd", "pose"}, {"weights", {{"jaw", 1}}}}));
    EXPECT_TRUE(daemon::checkControlRequest({{"cmd", "pose"}}));

    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto range = c.request({{"cmd", "pose"}, {"weights", {{"jaw", 1.5}}}});
    EXPECT_EQ(range["ok"], false);
    EXPECT_NE(range.value("error", "").find("\"weights\".\"jaw\" must be a number within 0 .. 1"),
              std::string::npos)
        << range;
    const auto unknown = c.request({{"cmd", "pose"}, {"weights", {{"jaw", 0.5}, {"grin", 1}}}});
    EXPECT_EQ(unknown["ok"], false);
    EXPECT_NE(unknown.value("error", "").find("unknown pose 'grin'"), std::string::npos) << unknown;
    EXPECT_NE(unknown.value("error", "").find("jaw, open"), std::string::npos) << unknown;
    for (const auto* line :
         {R"({"cmd":"pose","weights":{"jaw":NaN}})", R"({"cmd":"pose","weights":{"jaw":1e999}})",
          R"({"cmd":"pose","weights":[0.5]})"}) {
        c.sendLine(line);
        const auto reply = json::parse(c.readLine(), nullptr, false);
        EXPECT_EQ(reply.value("ok", true), false) << line;
    }
    std::this_thread::sleep_for(300ms);
    EXPECT_TRUE(d.running());
    EXPECT_EQ(d.stop(), 0);
    EXPECT_EQ(jawAt(d, 0, 1e9, true), 0.0) << "a refused pose moved the jaw";
}

TEST(PoseRequest, APoseIsRefusedWhileAClipPlaysAndSaysSo) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    ASSERT_EQ(c.request({{"cmd", "say"}, {"text", "Hello hello hello hello hello."}})["ok"], true);
    bool playing = false;
    for (int i = 0; i < 400 && !playing; ++i) {
        playing = !c.request({{"cmd", "status"}})["playing"].is_null();
        if (!playing) std::this_thread::sleep_for(50ms);
    }
    ASSERT_TRUE(playing) << "the clip never started";
    const auto reply = c.request({{"cmd", "pose"}, {"weights", {{"jaw", 1}}}});
    EXPECT_EQ(reply["ok"], false);
    EXPECT_NE(reply.value("error", "").find("refused while a clip plays"), std::string::npos)
        << reply;
    // After `stop`, poses are taken again.
    ASSERT_EQ(c.request({{"cmd", "stop"}})["ok"], true);
    EXPECT_EQ(c.request({{"cmd", "pose"}, {"weights", {{"jaw", 1}}}})["ok"], true);
    EXPECT_EQ(d.stop(), 0);
}

TEST(PoseRequest, CtlTakesNameEqualsValueWords) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto ok = runLipsync({"ctl", "--socket", d.socket().string(), "pose", "jaw=0.5", "w=0"});
    EXPECT_EQ(ok.exitCode, 0) << ok.err;
    EXPECT_NE(ok.out.find("\"held\""), std::string::npos) << ok.out;
    const auto bad = runLipsync({"ctl", "--socket", d.socket().string(), "pose", "jaw:0.5"});
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.err.find("'jaw:0.5' is not NAME=VALUE"), std::string::npos) << bad.err;
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
