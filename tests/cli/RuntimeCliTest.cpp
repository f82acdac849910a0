// `lipsync animate`, `say --weights`, `analyze --weights` and `curves generate` as a user runs
// them, and the golden replays (tests/golden, regenerated only by scripts/regen-golden.sh).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <lipsyncd/core.hpp>

#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

void expectSameTrack(const PoseTrack& a, const PoseTrack& b, float tolerance,
                     const std::string& what) {
    ASSERT_EQ(a.poses, b.poses) << what;
    ASSERT_EQ(a.frames(), b.frames()) << what;
    for (std::size_t i = 0; i < a.values.size(); ++i)
        ASSERT_NEAR(a.values[i], b.values[i], tolerance)
            << what << ": frame " << i / a.poses.size();
}

TEST(GoldenReplay, SayProducesTheCommittedWeights) {
    std::ifstream list(fs::path(LIPSYNCD_TEST_DATA_DIR).parent_path() / "golden" /
                       "utterances.txt");
    ASSERT_TRUE(list) << "tests/golden/utterances.txt missing";
    const auto dir = scratchDir("golden");
    int replays = 0;
    for (std::string line; std::getline(list, line);) {
        if (line.empty() || line[0] == '#') continue;
        const auto a = line.find('|'), b = line.find('|', a + 1);
        const auto name = line.substr(0, a);
        const auto out = dir / (name + ".csv");
        const auto r = runLipsync({"say", line.substr(b + 1), "--voice",
                                   line.substr(a + 1, b - a - 1), "--weights", out.string()});
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const auto golden =
            fs::path(LIPSYNCD_TEST_DATA_DIR).parent_path() / "golden" / (name + ".csv");
        expectSameTrack(readPoseTrackCsvFile(out), readPoseTrackCsvFile(golden), 2e-4f,
                        name + " (if the change is meant, run scripts/regen-golden.sh)");
        ++replays;
    }
    EXPECT_GE(replays, 3);
}

TEST(AnimateCli, ArpabetLabelsAndStreamingMatchTheOfflinePass) {
    const auto dir = scratchDir("animate");
    std::ofstream(dir / "hi.lab")
        << "0 0.2 sil\n0.2 0.3 HH\n0.3 0.5 AY1\n0.5 0.62 B\n0.62 0.9 AA1\n0.9 1.2 sil\n";
    const auto offline = dir / "offline.csv", streamed = dir / "streamed.csv";
    auto r = runLipsync(
        {"animate", "--schedule", (dir / "hi.lab").string(), "--weights", offline.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runLipsync({"animate", "--schedule", (dir / "hi.lab").string(), "--weights",
                    streamed.string(), "--delay", "1.5"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto track = readPoseTrackCsvFile(offline);
    expectSameTrack(track, readPoseTrackCsvFile(streamed), 0, "streaming with a long delay");
    EXPECT_EQ(track.frames(), 121u);  // 1.2 s at 100 Hz, both ends
    // The lips close for the B.
    EXPECT_GT(track.frame(56)[*track.pose("pbm")], 0.5f);
}

TEST(AnimateCli, BadSchedulesNameTheLineOrSymbol) {
    const auto dir = scratchDir("animate_bad");
    std::ofstream(dir / "overlap.tsv") << "0\t0.2\tsil\n0.1\t0.3\taa\n";
    auto r =
        runLipsync({"animate", "--schedule", (dir / "overlap.tsv").string(), "--weights", "-"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("overlap.tsv:2"), std::string::npos) << r.err;
    std::ofstream(dir / "unknown.tsv") << "0\t0.2\tsil\n0.2\t0.3\tqq\n";
    // An unknown symbol is a warning naming it and the line; the rest still animates.
    r = runLipsync({"animate", "--schedule", (dir / "unknown.tsv").string(), "--labels", "common",
                    "--weights", "-"});
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.err.find("unknown.tsv:2: unknown phoneme 'qq'"), std::string::npos) << r.err;
    r = runLipsync({"animate", "--schedule", (dir / "unknown.tsv").string(), "--weights", "-",
                    "--curves", "/nonexistent.json"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("/nonexistent.json"), std::string::npos) << r.err;
}

TEST(AnimateCli, AnalyzeGoesStraightFromAudioToWeights) {
    const auto dir = scratchDir("analyze_weights");
    const auto wav = dir / "ah.wav", weights = dir / "ah.csv";
    ASSERT_EQ(runLipsync({"say", "Mama, open wide.", "--wav", wav.string()}).exitCode, 0);
    const auto r = runLipsync({"analyze", wav.string(), "--weights", weights.string(), "-q"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto track = readPoseTrackCsvFile(weights);
    ASSERT_GT(track.frames(), 50u);
    float maxOpen = 0;
    for (std::size_t f = 0; f < track.frames(); ++f)
        maxOpen = std::max(maxOpen, track.frame(f)[*track.pose("open")]);
    EXPECT_GT(maxOpen, 0.3f);
    EXPECT_EQ(runLipsync({"analyze", wav.string()}).exitCode, 2);  // nothing to write
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(PlotCli, DrawsACurvePerPoseAndThePhonemesUnderThem) {
    const auto dir = scratchDir("plot");
    const auto weights = dir / "w.csv", schedule = dir / "s.tsv", svg = dir / "w.svg";
    ASSERT_EQ(runLipsync({"say", "Bob & me", "--weights", weights.string(), "--schedule",
                          schedule.string()})
                  .exitCode,
              0);
    const auto r = runLipsync({"plot", "--weights", weights.string(), "--schedule",
                               schedule.string(), "-o", svg.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto text = slurp(svg);
    EXPECT_EQ(text.rfind("<?xml", 0), 0u);
    EXPECT_NE(text.find("</svg>"), std::string::npos);
    EXPECT_EQ(count(text, "<polyline class=\"pose\""), 10u);  // the FaceFX-style poses + jaw
    EXPECT_NE(text.find("data-pose=\"pbm\""), std::string::npos);
    EXPECT_EQ(
        count(text, "<text x=") - count(text, " s</text>") - 3 /* axis values */ - 10 /* legend */,
        readScheduleFile(schedule).size());
    // Bad input names the file.
    std::ofstream(dir / "bad.csv") << "time,open\n0,0.1\n0.01\n";
    const auto bad = runLipsync({"plot", "--weights", (dir / "bad.csv").string(), "-o", "-"});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("bad.csv:3"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace lipsyncd::test
