// The daemon builds its runtime as `lipsync animate` does (lipsync::Runtime): every key the
// tool has reaches the service, and a wrong one stops start-up naming the key.
#include <gtest/gtest.h>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

TEST(DaemonRuntime, ThePhonemesKeyLetsTheDaemonRunTheMandarinCurves) {
    // The Mandarin curves speak the Mandarin set (common + ü): with `phonemes` the daemon runs
    // them and the mouth moves; without it they cannot be read and start-up says why.
    DaemonProcess d("phonemes = \"mandarin\"\ncurves = \"mandarin\"\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected()) << d.log();
    ASSERT_TRUE(c.request({{"cmd", "say"}, {"text", "Open wide."}})["ok"]);
    waitUntilIdle(c);
    EXPECT_EQ(d.stop(), 0);
    double peak = 0;
    for (const auto& [t, v] : d.recorded("jaw")) peak = std::max(peak, v);
    EXPECT_GT(peak, 0.2) << "the jaw never moved";

    DaemonProcess without("curves = \"mandarin\"\n");
    const auto r =
        runProgram(LIPSYNCD_DAEMON_BIN, {"--config", (without.dir / "lipsyncd.toml").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("lipsyncd.toml: [mouth] curves 'mandarin' (phonemes 'common')"),
              std::string::npos)
        << r.err;
}

TEST(DaemonRuntime, AWrongRuntimeValueNamesItsKeyAndLine) {
    const std::pair<std::string, std::string> cases[] = {
        {"phonemes = \"klingon\"\n", "phonemes"},
        {"phonemes = \"pinyin\"\n", "phonemes"},  // a map onto a set, not a set
        {"curves = \"klingon\"\n", "curves"},
        {"poses = \"nowhere.toml\"\n", "poses"},
        {"templates = \"klingon\"\n", "templates"},
        {"loudness = \"yes\"\n", "loudness"},
    };
    for (const auto& [line, key] : cases) {
        DaemonProcess d(line);
        const auto r =
            runProgram(LIPSYNCD_DAEMON_BIN, {"--config", (d.dir / "lipsyncd.toml").string()});
        EXPECT_EQ(r.exitCode, 1) << line;
        // The [mouth] line that holds it: line 7 of the file DaemonProcess writes.
        EXPECT_NE(r.err.find("lipsyncd.toml:7"), std::string::npos) << line << r.err;
        EXPECT_NE(r.err.find(key), std::string::npos) << line << r.err;
    }
}

TEST(DaemonRuntime, TheConfigFillsTheSameSpecAsTheTool) {
    const auto dir = scratchDir("daemon_runtime_spec");
    std::ofstream(dir / "l.toml") << "[mouth]\nphonemes = \"mandarin\"\ncurves = \"mandarin\"\n"
                                     "runtime = \"filter\"\nloudness = false\noutput_rate = 50\n";
    const auto c = daemon::DaemonConfig::load(dir / "l.toml");
    EXPECT_EQ(c.runtime.phonemes, "mandarin");
    EXPECT_EQ(c.runtime.curves, "mandarin");
    EXPECT_EQ(c.runtime.kind, "filter");
    EXPECT_FALSE(c.runtime.loudness);
    EXPECT_EQ(c.runtime.config.outputRate, 50);
    const lipsync::Runtime runtime(c.runtime);
    EXPECT_TRUE(runtime.phonemes().find("yu"));
    // The tool with the same names makes the same weights.
    PhonemeSchedule s = {{0, 0.2, "sil"}, {0.2, 0.5, "yu"}, {0.5, 0.8, "sil"}};
    const auto track = runtime.animate(s);
    EXPECT_GE(track.frames(), 40u);  // 0.8 s at 50 Hz
    std::size_t w = track.poses.size();
    for (std::size_t i = 0; i < track.poses.size(); ++i)
        if (track.poses[i] == "w") w = i;
    ASSERT_LT(w, track.poses.size());
    EXPECT_GT(track.frame(17)[w], 0.3f) << "ü rounds the lips";
}

}  // namespace
}  // namespace lipsyncd::test
