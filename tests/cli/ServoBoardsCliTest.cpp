// The servo boards as a user meets them: `lipsync check` prints a linkage's angle table and
// refuses one that cannot reach; `lipsync drive --puppet maestro-jaw` with its port on a
// pseudo-terminal sends compact-protocol targets that stay within the jaw's pulses and end at
// rest; `lipsync devices` lists buses, ports and chips.
#include <fcntl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <lipsyncd/core.hpp>

#include "../support/PseudoTerminal.hpp"
#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

TEST(ServoBoardsCli, CheckPrintsTheLinkageTableAndRefusesAnUnreachableOne) {
    auto r = runLipsync({"check", "--puppet", "maestro-jaw"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("jaw [maestro Maestro on /dev/ttyACM0 channel 0"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("jaw opening   horn angle   pulse"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("25.0°"), std::string::npos) << r.out;
    for (const char* name : {"pca9685-jaw-lips", "pwm-jaw"})
        EXPECT_EQ(runLipsync({"check", "--puppet", name}).exitCode, 0) << name;

    const auto dir = scratchDir("check_linkage");
    auto text = slurp(findDataFile("puppets/maestro-jaw.toml"));
    text.replace(text.find("rod = 53.0"), 10, "rod = 20.0");  // cannot span the pivots
    std::ofstream(dir / "short-rod.toml") << text;
    r = runLipsync({"check", "--puppet", (dir / "short-rod.toml").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("short-rod.toml:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("cannot reach"), std::string::npos) << r.err;
}

TEST(ServoBoardsCli, DriveSendsMaestroTargetsToAPseudoTerminalEndingAtRest) {
    Pty pty;
    const std::string port = pty.slave();
    const int keep = ::open(port.c_str(), O_RDWR | O_NOCTTY);  // the pty outlives the run
    const auto dir = scratchDir("drive_maestro");
    auto text = slurp(findDataFile("puppets/maestro-jaw.toml"));
    text.replace(text.find("/dev/ttyACM0"), 12, port);
    std::ofstream(dir / "maestro.toml") << text;
    {
        std::ofstream w(dir / "w.csv");
        w << "time,jaw,open,wide,w,pbm,fv,shch,tongue_up,tongue_down,tongue_back\n";
        for (int f = 0; f <= 100; ++f)
            w << f * 0.01 << "," << (f < 50 ? 1.0 : 0.2) << ",0,0,0,0,0,0,0,0,0\n";
    }
    const auto r = runLipsync({"drive", "--weights", (dir / "w.csv").string(), "--puppet",
                               (dir / "maestro.toml").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto bytes = pty.drain(500);  // until quiet: some bytes arrive after lipsync has exited
    ::close(keep);
    ASSERT_GT(bytes.size(), 8u);
    ASSERT_EQ(bytes.size() % 4, 0u);  // compact protocol: 4 bytes a command, nothing else
    EXPECT_EQ(bytes[0], 0x87);        // speed limit first, then acceleration
    EXPECT_EQ(bytes[4], 0x89);
    std::vector<unsigned> targets;
    for (std::size_t i = 8; i < bytes.size(); i += 4) {
        ASSERT_EQ(bytes[i], 0x84);
        ASSERT_EQ(bytes[i + 1], 0);
        targets.push_back(bytes[i + 2] | (bytes[i + 3] << 7));
    }
    // The jaw's pulses through its linkage: 1326 µs closed, 1708 µs at 25° (`lipsync check`).
    for (const auto t : targets) {
        EXPECT_GE(t, 4 * 1325u);
        EXPECT_LE(t, 4 * 1709u);
    }
    EXPECT_GT(*std::max_element(targets.begin(), targets.end()), 4 * 1600u);  // it opened
    EXPECT_NEAR(targets.back(), 4 * 1326.0, 2);                               // rest last
}

TEST(ServoBoardsCli, DevicesListsBusesPortsAndChips) {
    const auto r = runLipsync({"devices"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* section : {"I2C buses", "Serial ports", "PWM chips"})
        EXPECT_NE(r.out.find(section), std::string::npos) << section << "\n" << r.out;
}

}  // namespace
}  // namespace lipsyncd::test
