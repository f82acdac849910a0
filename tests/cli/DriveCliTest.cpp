// `lipsync drive`, `check` and `devices` as a user runs them.
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <sstream>
#include <thread>

#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

fs::path weightsFile(const fs::path& dir, double seconds = 1.0) {
    const auto path = dir / "w.csv";
    std::ofstream out(path);
    out << "time,jaw,open,wide,w,pbm,fv,shch,tongue_up,tongue_down,tongue_back\n";
    for (int f = 0; f * 0.01 <= seconds + 1e-9; ++f)
        out << f * 0.01 << ",0.8,0.8,0.2,0,0,0,0,0.3,0,0\n";
    return path;
}

TEST(DriveCli, RecordsEveryCommandAndEndsAtRest) {
    const auto dir = scratchDir("drive");
    const auto rec = dir / "rec.csv";
    const auto r = runLipsync({"drive", "--weights", weightsFile(dir).string(), "--puppet",
                               "terminal", "--no-hardware", "--record", rec.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream in(rec);
    std::string line, last;
    std::getline(in, line);
    EXPECT_EQ(line, "time,actuator,value,active,on");
    std::size_t rows = 0;
    while (std::getline(in, line)) ++rows, last = line;
    EXPECT_GE(rows, 4u * 101);
    // The last command puts the last actuator (tongue) back at its rest value, 0.
    EXPECT_NE(last.find(",tongue,0.00000,"), std::string::npos) << last;
}

TEST(DriveCli, AMissingGpioChipIsAClearErrorAndJsonLinesWork) {
    const auto dir = scratchDir("drive_gpio");
    auto r = runLipsync({"drive", "--weights", weightsFile(dir).string(), "--puppet", "jaw-servo"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("GPIO chip 'gpiochip0'"), std::string::npos) << r.err;
    r = runLipsync({"drive", "--weights", weightsFile(dir).string(), "--puppet", "jaw-servo",
                    "--no-hardware", "--record", "-"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out.rfind("time,actuator", 0), 0u);
    r = runLipsync({"drive", "--weights", weightsFile(dir).string(), "--puppet", "hid-board",
                    "--record", (dir / "rec.jsonl").string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;  // an absent HID board is waited for, not fatal
    EXPECT_NE(r.err.find("not present"), std::string::npos) << r.err;
    std::ifstream in(dir / "rec.jsonl");
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first.rfind("{\"time\":", 0), 0u) << first;
}

TEST(DriveCli, SigtermMovesTheMouthToRestAndSaysSo) {
    const auto dir = scratchDir("drive_signal");
    const auto rec = dir / "rec.csv";
    const auto weights = weightsFile(dir, 30.0);  // 30 s at real time: stopped long before
    std::thread killer([] {
        std::this_thread::sleep_for(std::chrono::milliseconds(700));
        std::system("pkill -TERM -f 'lipsync drive.*drive_signal' >/dev/null 2>&1");
    });
    const auto r = runLipsync({"drive", "--weights", weights.string(), "--puppet", "terminal",
                               "--no-hardware", "--realtime", "--record", rec.string()});
    killer.join();
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("interrupted: moving to rest"), std::string::npos) << r.err;
    std::ifstream in(rec);
    std::string line, last;
    while (std::getline(in, line)) last = line;
    EXPECT_NE(last.find(",tongue,0.00000,"), std::string::npos) << last;
    EXPECT_LT(std::stod(last.substr(0, last.find(','))), 5.0);  // stopped early, not played out
}

TEST(CheckCli, ExplainsAPuppetAndNamesTheLineOfAMistake) {
    auto r = runLipsync({"check", "--puppet", "jaw-and-lips"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("jaw [servo gpiochip0 line 18]"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("inverted"), std::string::npos);
    const auto dir = scratchDir("check");
    std::ofstream(dir / "bad.toml")
        << "name = \"x\"\n[[actuator]]\nname = \"j\"\nbackend = \"servo\"\nline = 3\n"
           "gains = { open = 1 }\nmin = 1\nmax = 0\n";
    r = runLipsync({"check", "--puppet", (dir / "bad.toml").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("bad.toml:8"), std::string::npos) << r.err;
    r = runLipsync({"devices"});
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find("GPIO chips"), std::string::npos);
}

}  // namespace
}  // namespace lipsyncd::test
