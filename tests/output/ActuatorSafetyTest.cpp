// The safety layer: whatever comes in, commands stay within limits and slew; NaN holds;
// switches do not chatter; the mouth rests on stop and on stalled input; idle servos relax.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

const std::vector<std::string> kPoses{"open", "pbm"};

output::Puppet jawPuppet(const std::string& extra = "") {
    return output::Puppet::load(writePuppet("jaw", R"(name = "jaw"
stall_timeout = 0.3
[[actuator]]
name = "jaw"
backend = "virtual"
gains = { open = 1.0, pbm = -0.5 }
min = 0.1
max = 0.8
slew = 4.0
rest = 0.2
deadband = 0.02
idle_after = 0.5
)" + extra));
}

struct Collect : output::CommandSink {
    std::vector<std::pair<double, output::ActuatorCommand>> seen;
    void write(double t, std::span<const output::ActuatorCommand> c) override {
        seen.emplace_back(t, c[0]);
    }
};

TEST(ActuatorSafety, CommandsStayWithinLimitsAndSlewWhateverComesIn) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    Collect sink;
    driver.addSink(sink);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> any(-1e6f, 1e6f);
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              1e30f,
                              -1e30f,
                              0,
                              1};
    for (int i = 0; i < 5000; ++i) {
        const float w[2] = {i % 7 == 0 ? specials[i % 7] : any(rng),
                            i % 11 == 0 ? specials[(i / 11) % 7] : any(rng)};
        driver.update(0.01 * i, w);
    }
    for (std::size_t i = 0; i < sink.seen.size(); ++i) {
        const auto v = sink.seen[i].second.value;
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.1);
        ASSERT_LE(v, 0.8);
        if (i > 0) {
            ASSERT_LE(std::abs(v - sink.seen[i - 1].second.value), 4.0 * 0.01 + 1e-9) << i;
        }
    }
}

TEST(ActuatorSafety, NonFiniteWeightsHoldTheLastGoodTarget) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    const float open[2] = {0.6f, 0};
    for (int i = 0; i < 50; ++i) driver.update(0.01 * i, open);
    const double before = driver.last()[0].value;
    EXPECT_NEAR(before, 0.6, 1e-9);
    const float nan[2] = {std::numeric_limits<float>::quiet_NaN(), 0};
    for (int i = 50; i < 100; ++i) driver.update(0.01 * i, nan);
    EXPECT_NEAR(driver.last()[0].value, before, 1e-9);
}

TEST(ActuatorSafety, RestIsReachedSlewLimitedOnStop) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    Collect sink;
    driver.addSink(sink);
    const float open[2] = {1, 0};
    for (int i = 0; i < 100; ++i) driver.update(0.01 * i, open);
    const double t = driver.rest(0.99);
    EXPECT_TRUE(driver.atRest());
    EXPECT_NEAR(driver.last()[0].value, 0.2, 1e-9);
    EXPECT_NEAR(t - 0.99, (0.8 - 0.2) / 4.0, 0.011);  // at the slew limit, no faster
}

TEST(ActuatorSafety, StalledInputSendsTheMouthToRest) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    const float open[2] = {1, 0};
    for (int i = 0; i < 50; ++i) driver.update(0.01 * i, open);
    for (int i = 50; i < 70; ++i) driver.tick(0.01 * i);  // 0.2 s: within the 0.3 s timeout
    EXPECT_NEAR(driver.last()[0].value, 0.8, 1e-9);
    for (int i = 70; i < 300; ++i) driver.tick(0.01 * i);
    EXPECT_TRUE(driver.atRest());
}

TEST(ActuatorSafety, AServoAtRestRelaxesAfterItsIdleTimeAndWakesOnMovement) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    const float closed[2] = {0.2f, 0};  // target = rest
    driver.update(0, closed);
    driver.update(0.3, closed);
    EXPECT_TRUE(driver.last()[0].active);
    driver.update(0.6, closed);
    EXPECT_FALSE(driver.last()[0].active);
    const float open[2] = {0.7f, 0};
    driver.update(0.61, open);
    EXPECT_TRUE(driver.last()[0].active);
}

TEST(ActuatorSafety, DeadbandKeepsSmallChangesFromTheActuator) {
    const auto puppet = jawPuppet();
    output::PuppetDriver driver(puppet, kPoses);
    const float a[2] = {0.5f, 0};
    for (int i = 0; i < 30; ++i) driver.update(0.01 * i, a);
    const double held = driver.last()[0].value;
    EXPECT_NEAR(held, 0.5, 0.02);  // within a deadband of the target
    // Jitter smaller than the deadband around where it stands: nothing moves.
    const float up[2] = {static_cast<float>(held + 0.009), 0},
                down[2] = {static_cast<float>(held - 0.009), 0};
    for (int i = 30; i < 60; ++i) driver.update(0.01 * i, i % 2 ? up : down);
    EXPECT_EQ(driver.last()[0].value, held);
    const float far[2] = {static_cast<float>(held + 0.1), 0};  // a real move goes through
    driver.update(0.6, far);
    EXPECT_GT(driver.last()[0].value, held);
}

TEST(SwitchLogic, HysteresisAndMinimumTimesPreventChatter) {
    output::ActuatorConfig c;
    c.backend = output::Backend::Switch;
    c.threshold = 0.5;
    c.hysteresis = 0.2;  // on above 0.6, off below 0.4
    c.minOnSeconds = 0.1;
    c.minOffSeconds = 0.05;
    output::SwitchLogic s(c);
    EXPECT_FALSE(s.update(0.00, 0.55));  // inside the band: stays off
    EXPECT_TRUE(s.update(0.01, 0.65));
    EXPECT_TRUE(s.update(0.02, 0.1));   // on for 10 ms only: min_on holds it
    EXPECT_TRUE(s.update(0.10, 0.45));  // inside the band
    EXPECT_FALSE(s.update(0.11, 0.3));  // 100 ms served: off
    EXPECT_FALSE(s.update(0.12, 0.9));  // off for 10 ms: min_off holds it
    EXPECT_TRUE(s.update(0.16, 0.9));
    // Random input: no state lasts less than its minimum.
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> any(0, 1);
    output::SwitchLogic r(c);
    bool state = false;
    double since = -1e9;
    for (int i = 1; i < 10000; ++i) {
        const double t = 0.005 * i;
        const bool now = r.update(t, any(rng));
        if (now != state) {
            ASSERT_GE(t - since, state ? c.minOnSeconds : c.minOffSeconds) << t;
            state = now;
            since = t;
        }
    }
}

}  // namespace
}  // namespace lipsyncd::test
