// The tick's frame event: valid JSON whatever the names and values, and written without a
// single allocation once the names are set (the real-time loop does not allocate).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <nlohmann/json.hpp>

#include "../../daemon/src/FrameEvent.hpp"
#include "../support/AllocationCount.hpp"

namespace lipsyncd::test {
namespace {

using nlohmann::json;

TEST(FrameEvent, IsTheJsonOfTheTicksValues) {
    daemon::FrameEventWriter w;
    const std::vector<std::string> poses{"jaw", "open"}, actuators{"servo \"a\"", "lips"};
    w.setNames(poses, actuators);
    const std::vector<float> weights{0.25f, NAN};
    std::vector<output::ActuatorCommand> commands(2);
    commands[0].value = 0.5;
    commands[1].value = -0.125;
    const auto line = std::string(w.format(1.5, weights, commands, 2.25));
    ASSERT_EQ(line.back(), '\n');
    const auto e = json::parse(line);
    EXPECT_EQ(e["event"], "frame");
    EXPECT_EQ(e["time"], 1.5);
    EXPECT_EQ(e["weights"]["jaw"], 0.25);
    EXPECT_TRUE(e["weights"]["open"].is_null()) << "not a number is null, never bad JSON";
    EXPECT_EQ(e["actuators"]["servo \"a\""], 0.5);
    EXPECT_EQ(e["actuators"]["lips"], -0.125);
    EXPECT_EQ(e["position"], 2.25);
    // Nothing playing: no weights, no position.
    const auto idle = json::parse(std::string(w.format(2, {}, commands, std::nullopt)));
    EXPECT_TRUE(idle["weights"].empty());
    EXPECT_FALSE(idle.contains("position"));
}

TEST(FrameEvent, FormattingAllocatesNothing) {
    daemon::FrameEventWriter w;
    std::vector<std::string> poses, actuators;
    for (int i = 0; i < 10; ++i) poses.push_back("pose_with_a_long_name_" + std::to_string(i));
    for (int i = 0; i < 6; ++i) actuators.push_back("actuator_" + std::to_string(i));
    w.setNames(poses, actuators);
    std::vector<float> weights(poses.size());
    std::vector<output::ActuatorCommand> commands(actuators.size());
    const AllocationCount count;
    std::size_t bytes = 0;
    for (int f = 0; f < 1000; ++f) {
        for (std::size_t i = 0; i < weights.size(); ++i)  // long, unround numbers
            weights[i] = -1.0f / static_cast<float>(f * 7 + static_cast<int>(i) + 3);
        for (auto& c : commands) c.value = -1e-300 * f - 12345.678901234567;
        bytes += w.format(1e9 + f / 3.0, weights, commands, -f / 7.0).size();
    }
    EXPECT_EQ(count.made(), 0);
    EXPECT_GT(bytes, 1000u * 200);
}

}  // namespace
}  // namespace lipsyncd::test
