// The Maestro backend against a real pseudo-terminal: the bytes that arrive are decoded
// (compact and Pololu protocol) and checked: speed and acceleration first, targets within
// the pulse limits that follow the jaw, rest last; the port closing and coming back (a USB
// cable pulled and plugged in again, /dev/serial/by-id pointing at the new tty); a port that
// is not a tty, one that is not there, one the user may not open.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "../support/PseudoTerminal.hpp"
#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

struct MaestroCommand {
    int device;  // -1: compact protocol
    int command, channel;
    unsigned value;
};

// Strict: any byte that is not part of a whole command fails the test (a tty that is not raw
// would add 0x0D before every 0x0A).
std::vector<MaestroCommand> decode(const std::vector<std::uint8_t>& bytes) {
    std::vector<MaestroCommand> out;
    for (std::size_t i = 0; i < bytes.size();) {
        MaestroCommand c{-1, 0, 0, 0};
        if (bytes[i] == 0xaa) {
            EXPECT_LE(i + 6, bytes.size());
            if (i + 6 > bytes.size()) break;
            c.device = bytes[i + 1];
            c.command = bytes[i + 2] | 0x80;
            i += 3;
        } else {
            c.command = bytes[i++];
        }
        EXPECT_TRUE(c.command == 0x84 || c.command == 0x87 || c.command == 0x89) << c.command;
        EXPECT_LE(i + 3, bytes.size());
        if (i + 3 > bytes.size()) break;
        for (int k = 0; k < 3; ++k) EXPECT_LT(bytes[i + k], 0x80) << "a data byte with bit 7 set";
        c.channel = bytes[i];
        c.value = bytes[i + 1] | (bytes[i + 2] << 7);
        i += 3;
        out.push_back(c);
    }
    return out;
}

std::string shippedMaestroJaw(const std::string& port) {
    std::ifstream in(findDataFile("puppets/maestro-jaw.toml"));
    std::stringstream text;
    text << in.rdbuf();
    auto s = text.str();
    const auto at = s.find("port = \"/dev/ttyACM0\"");
    EXPECT_NE(at, std::string::npos);
    return s.replace(at, 21, "port = \"" + port + "\"");
}

unsigned quarterUs(const output::ActuatorConfig& a, double value) {
    return static_cast<unsigned>(std::lround(4 * output::servoPulseUs(a, value)));
}

TEST(Maestro, TheShippedJawSendsCompactTargetsThatFollowItWithinLimitsAndEndAtRest) {
    Pty pty;
    const auto puppet =
        output::Puppet::load(writePuppet("maestro", shippedMaestroJaw(pty.slave())));
    const auto& jaw = puppet.actuators[0];
    output::PuppetDriver driver(puppet, std::vector<std::string>{"jaw", "wide", "pbm"});
    driver.addSink(std::make_unique<output::MaestroSink>(puppet, pty.slave()));
    std::vector<MaestroCommand> seen;
    std::vector<unsigned> expected;
    unsigned last = ~0u;
    const auto expect = [&](int quietMs = 0) {
        const auto target = driver.last()[0].active ? quarterUs(jaw, driver.last()[0].value) : 0;
        if (target != last) expected.push_back(target);
        last = target;
        const auto got = decode(pty.drain(quietMs));
        seen.insert(seen.end(), got.begin(), got.end());
    };
    for (int i = 0; i < 300; ++i) {
        const float w[3] = {float(0.5 + 0.6 * std::sin(i * 0.07)), i % 50 < 10 ? 1.0f : 0.0f,
                            i % 90 < 5 ? 1.0f : 0.0f};
        driver.update(0.01 * i, w);
        expect();
    }
    double t = 3;
    while (!driver.atRest()) {
        driver.rest(t, 100, [&](double) { expect(); });
        t += 0.01;
    }
    expect(200);
    ASSERT_GE(seen.size(), 3u);
    EXPECT_EQ(seen[0].command, 0x87);  // Set Speed from the slew, then Set Acceleration
    EXPECT_EQ(seen[0].value, output::MaestroSink::speed(jaw));
    EXPECT_EQ(seen[1].command, 0x89);
    EXPECT_EQ(seen[1].value, 0u);  // no ramp: acceleration unlimited
    std::vector<unsigned> targets;
    for (std::size_t i = 2; i < seen.size(); ++i) {
        EXPECT_EQ(seen[i].device, -1);
        EXPECT_EQ(seen[i].command, 0x84);
        EXPECT_EQ(seen[i].channel, 0);
        targets.push_back(seen[i].value);
    }
    EXPECT_EQ(targets, expected);  // every change of the jaw, in order, nothing else
    const unsigned lo = quarterUs(jaw, jaw.min), hi = quarterUs(jaw, jaw.max);
    for (const auto target : targets) {
        EXPECT_GE(target, lo);
        EXPECT_LE(target, hi);
    }
    EXPECT_GT(*std::max_element(targets.begin(), targets.end()), (lo + hi) / 2);  // it moved
    EXPECT_EQ(targets.back(), quarterUs(jaw, jaw.rest));                          // rest last
}

output::Puppet twoChannelPuppet(const std::string& port, const std::string& extra) {
    return output::Puppet::load(writePuppet("maestro2", R"(name = "m"
[[actuator]]
name = "jaw"
backend = "maestro"
port = ")" + port + R"("
channel = 0
)" + extra + R"(
pulse_min_us = 1000
pulse_max_us = 2000
gains = { open = 1.0 }
min = 0.0
max = 1.0
slew = 5.0
ramp = 0.1
[[actuator]]
name = "lip"
backend = "maestro"
port = ")" + port + R"("
channel = 5
)" + extra + R"(
gains = { open = 1.0 }
min = 0.0
max = 1.0
)" + kVirtualActuator));
}

TEST(Maestro, ThePololuProtocolNamesTheDevice) {
    Pty pty;
    const auto puppet = twoChannelPuppet(pty.slave(), "device = 12");
    output::MaestroSink sink(puppet, pty.slave());
    const output::ActuatorCommand c[3] = {{0.5, true, false}, {0.25, true, false}, {}};
    sink.write(0, c);
    const auto bytes = pty.drain(200);
    const std::vector<std::uint8_t> jawTarget{0xaa, 12, 0x04, 0, 6000 & 0x7f, 6000 >> 7};
    ASSERT_EQ(bytes.size(), 6u * 6);  // speed + acceleration for two channels, two targets
    EXPECT_TRUE(std::equal(jawTarget.begin(), jawTarget.end(), bytes.begin() + 24));
    const auto got = decode(bytes);
    ASSERT_EQ(got.size(), 6u);
    // Slew 5/s over 1000 µs = 5000 µs/s = 200 quarter-µs per 10 ms; reached in 0.1 s:
    // 200 · 0.08 / 0.1 = 160 per 80 ms.
    EXPECT_EQ(got[0].command, 0x87);
    EXPECT_EQ(got[0].value, 200u);
    EXPECT_EQ(got[1].command, 0x89);
    EXPECT_EQ(got[1].value, 160u);
    EXPECT_EQ(got[5].channel, 5);
    EXPECT_EQ(got[5].value, 5000u);  // 0.25 of 1000 .. 2000 µs (the default pulses)
    for (const auto& g : got) EXPECT_EQ(g.device, 12);
}

TEST(Maestro, APortThatClosesIsReopenedWhenItIsBackWhileTheOthersGoOn) {
    const auto link =
        std::filesystem::temp_directory_path() / ("lipsyncd_maestro_" + std::to_string(::getpid()));
    auto first = std::make_unique<Pty>();
    std::filesystem::remove(link);
    std::filesystem::create_symlink(first->slave(), link);
    const auto puppet = twoChannelPuppet(link.string(), "");
    std::vector<std::string> log;
    output::PuppetDriver driver(puppet, std::vector<std::string>{"open"});
    driver.addSink(std::make_unique<output::MaestroSink>(
        puppet, link.string(), [&](const std::string& m) { log.push_back(m); }));
    std::ostringstream recorded;
    output::RecorderSink recorder(recorded, puppet, output::RecorderSink::Format::Csv);
    driver.addSink(recorder);
    std::unique_ptr<Pty> second;
    std::vector<MaestroCommand> before, after;
    for (int i = 0; i < 400; ++i) {
        if (i == 100) first->close();  // unplugged
        if (i == 250) {                // plugged in again: a new tty behind the same link
            second = std::make_unique<Pty>();
            std::filesystem::remove(link);
            std::filesystem::create_symlink(second->slave(), link);
        }
        const float w[1] = {float(0.5 + 0.4 * std::sin(i * 0.05))};
        driver.update(0.01 * i, w);
        if (i < 100) {
            const auto got = decode(first->drain());
            before.insert(before.end(), got.begin(), got.end());
        }
        if (second) {
            const auto got = decode(second->drain());
            after.insert(after.end(), got.begin(), got.end());
        }
    }
    std::filesystem::remove(link);
    const auto text = recorded.str();
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 3 * 400);  // never missed a step
    EXPECT_GT(before.size(), 50u);
    ASSERT_GE(log.size(), 2u);
    EXPECT_NE(log[0].find("gone"), std::string::npos) << log[0];
    EXPECT_NE(log[0].find(puppet.source.string() + ":2:"), std::string::npos) << log[0];
    EXPECT_NE(log.back().find("connected"), std::string::npos) << log.back();
    // Back within the reopen interval, limits set again first, then both channels' targets.
    ASSERT_GT(after.size(), 60u);
    EXPECT_EQ(after[0].command, 0x87);
    EXPECT_EQ(after[4].command, 0x84);
    EXPECT_EQ(after[5].command, 0x84);
    EXPECT_NE(after[4].channel, after[5].channel);
}

TEST(Maestro, APortThatIsNotATtyOrNotThereIsNamedWithThePuppetLine) {
    const auto file =
        std::filesystem::temp_directory_path() / ("lipsyncd_notatty_" + std::to_string(::getpid()));
    std::ofstream(file) << "";
    for (const auto& [port, why] :
         {std::pair<std::string, std::string>{file.string(), "not a serial port (a tty)"},
          {"/dev/ttyACM97", "no such port"}}) {
        const auto puppet = twoChannelPuppet(port, "");
        std::vector<std::string> log;
        output::MaestroSink sink(puppet, port, [&](const std::string& m) { log.push_back(m); });
        const output::ActuatorCommand c[3] = {{0.5, true, false}, {0.25, true, false}, {}};
        sink.write(0, c);
        EXPECT_FALSE(sink.connected());
        ASSERT_EQ(log.size(), 1u);
        EXPECT_NE(log[0].find(puppet.source.string() + ":2: Maestro on " + port), std::string::npos)
            << log[0];
        EXPECT_NE(log[0].find(why), std::string::npos) << log[0];
    }
    std::filesystem::remove(file);
}

// In the death-test child: open the port as an ordinary user, say what happened, exit.
[[noreturn]] void openAsNobody(const output::Puppet& puppet, const std::string& port) {
    dropPrivileges();
    output::MaestroSink sink(puppet, port,
                             [](const std::string& m) { std::fprintf(stderr, "%s\n", m.c_str()); });
    const output::ActuatorCommand c[3] = {{0.5, true, false}, {0.25, true, false}, {}};
    sink.write(0, c);
    std::_Exit(sink.connected() ? 1 : 0);
}

TEST(MaestroDeathTest, APortTheUserMayNotOpenSaysWhichGroup) {
    const auto file =
        std::filesystem::temp_directory_path() / ("lipsyncd_noperm_" + std::to_string(::getpid()));
    std::ofstream(file) << "";
    std::filesystem::permissions(file, std::filesystem::perms::none);
    const auto puppet = twoChannelPuppet(file.string(), "");
    EXPECT_EXIT(openAsNobody(puppet, file.string()), ::testing::ExitedWithCode(0),
                "permission denied \\(add the user to group dialout\\)");
    std::filesystem::remove(file);
}

}  // namespace
}  // namespace lipsyncd::test
