// Files are checked where they come in: times and values finite and in their documented
// ranges, names safe for the command record. A bad file is an error naming the file and
// line (exit 1), never a run that does not end or eats the machine.
#include <gtest/gtest.h>

#include <fstream>

#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

fs::path write(const fs::path& path, const std::string& text) {
    std::ofstream(path) << text;
    return path;
}

// The timeout turns a run that never ends into a failure (exit 124), not a hung test.
RunResult runBounded(const std::vector<std::string>& args) {
    std::vector<std::string> all{"20", LIPSYNCD_LIPSYNC_BIN};
    all.insert(all.end(), args.begin(), args.end());
    return runProgram("/usr/bin/timeout", all);
}

TEST(FileBounds, AnimateRefusesASegmentEndingFarInTheFuture) {
    const auto dir = scratchDir("bounds_animate");
    for (const std::string end : {"1e7", "1e300"}) {
        const auto schedule = write(dir / "far.tsv", "0 0.1 sil\n0.1 " + end + " aa\n");
        const auto r = runBounded(
            {"animate", "--schedule", schedule.string(), "--weights", (dir / "w.csv").string()});
        EXPECT_EQ(r.exitCode, 1) << end << ": " << r.err;
        EXPECT_NE(r.err.find("far.tsv:2"), std::string::npos) << r.err;
    }
}

TEST(FileBounds, DriveRefusesAFarFutureRowInsteadOfLooping) {
    const auto dir = scratchDir("bounds_drive");
    const auto weights = write(dir / "far.csv", "time,open\n0,0.5\n1e300,0.5\n");
    const auto r = runBounded(
        {"drive", "--weights", weights.string(), "--puppet", "terminal", "--no-hardware"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("far.csv:3"), std::string::npos) << r.err;
}

TEST(FileBounds, CheckWeightsRejectsNanAndInf) {
    const auto dir = scratchDir("bounds_check");
    for (const std::string bad : {"nan", "inf", "-inf"}) {
        const auto weights = write(dir / "w.csv", "time,open\n0,0.5\n0.01," + bad + "\n");
        const auto r = runBounded({"check", "--puppet", "terminal", "--weights", weights.string()});
        EXPECT_EQ(r.exitCode, 1) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("w.csv:3"), std::string::npos) << r.err;
    }
}

// A one-actuator puppet with `line` in its actuator table.
std::string puppetWith(const std::string& line, const std::string& name = "jaw") {
    return "name = \"p\"\n[[actuator]]\nname = \"" + name +
           "\"\nbackend = \"virtual\"\ngains = { open = 1.0 }\nmin = 0.0\nmax = 1.0\n" + line +
           "\n";
}

TEST(FileBounds, PuppetFilesRefuseNonFiniteAndHugeNumbers) {
    const auto dir = scratchDir("bounds_puppet");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"gains = { open = nan }", "gains"},
        {"trim = nan", "trim"},
        {"neutral = inf", "neutral"},
        {"max = inf", "max"},
        {"min = -1e308", "min"},
    };
    for (const auto& [line, key] : cases) {
        auto text = puppetWith(line);
        // A key given twice is its own error: drop the default of the one under test.
        for (const auto* k : {"gains = { open = 1.0 }\n", "min = 0.0\n", "max = 1.0\n"})
            if (line.rfind(std::string(k).substr(0, 4), 0) == 0)
                text.erase(text.find(k), std::string(k).size());
        const auto puppet = write(dir / "p.toml", text);
        const auto r = runBounded({"check", "--puppet", puppet.string()});
        EXPECT_EQ(r.exitCode, 1) << line << ": " << r.err;
        EXPECT_NE(r.err.find("p.toml:"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(key), std::string::npos) << line << ": " << r.err;
    }
}

TEST(FileBounds, ActuatorNamesThatWouldBreakTheRecordAreRefused) {
    const auto dir = scratchDir("bounds_names");
    for (const std::string name : {"jaw,open", "jaw\\nx", "jaw\\\"q", ""}) {
        const auto puppet = write(dir / "p.toml", puppetWith("", name));
        const auto r = runBounded({"check", "--puppet", puppet.string()});
        EXPECT_EQ(r.exitCode, 1) << name << ": " << r.err;
        EXPECT_NE(r.err.find("name"), std::string::npos) << r.err;
    }
}

}  // namespace
}  // namespace lipsyncd::test
