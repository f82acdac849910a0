#include <gtest/gtest.h>

#include <fstream>
#include <lipsyncd/dsp.hpp>

using namespace lipsyncd;

namespace {
// Runs frame classes (one per 10 ms hop) through a segmenter; returns the schedule.
PhonemeSchedule segment(const std::vector<std::string>& classes, dsp::SegmenterConfig config = {}) {
    const auto& set = PhonemeSet::common();
    dsp::Segmenter seg(set, 0.01, config);
    PhonemeSchedule out;
    for (std::size_t i = 0; i < classes.size(); ++i) {
        dsp::FrameLabel l;
        l.time = 0.005 + 0.01 * i;
        l.phoneme = static_cast<int>(*set.find(classes[i]));
        l.confidence = 0.5f;
        for (const auto& s : seg.push(l)) out.push_back(s);
    }
    for (const auto& s : seg.finish(0.01 * classes.size())) out.push_back(s);
    return out;
}

std::vector<std::string> repeat(const std::string& c, int n) {
    return std::vector<std::string>(n, c);
}

std::vector<std::string> concat(std::initializer_list<std::vector<std::string>> parts) {
    std::vector<std::string> out;
    for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
    return out;
}
}  // namespace

TEST(Segmenter, RunsBecomeSegmentsCoveringTheWholeTime) {
    const auto s =
        segment(concat({repeat("sil", 10), repeat("aa", 10), repeat("bmp", 5), repeat("sil", 10)}));
    ASSERT_EQ(s.size(), 4u);
    EXPECT_EQ(s[0].phoneme, "sil");
    EXPECT_DOUBLE_EQ(s[0].start, 0.0);
    EXPECT_NEAR(s[1].start, 0.10, 1e-9);
    EXPECT_EQ(s[1].phoneme, "aa");
    EXPECT_EQ(s[2].phoneme, "bmp");
    EXPECT_NEAR(s[3].end, 0.35, 1e-9);
    for (std::size_t i = 1; i < s.size(); ++i) EXPECT_DOUBLE_EQ(s[i].start, s[i - 1].end);
}

TEST(Segmenter, FlickerShorterThanTheMinimumMergesIntoItsNeighbours) {
    // One frame of 'ih' inside a vowel is flicker: the vowel continues.
    const auto s = segment(concat({repeat("aa", 10), repeat("ih", 1), repeat("aa", 10)}));
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].phoneme, "aa");
    EXPECT_NEAR(s[0].end, 0.21, 1e-9);
}

TEST(Segmenter, ConsonantsKeepTheirShorterMinimum) {
    dsp::SegmenterConfig c;
    c.minConsonantSeconds = 0.03;
    c.minVowelSeconds = 0.06;
    const auto kept = segment(concat({repeat("aa", 10), repeat("bmp", 3), repeat("aa", 10)}), c);
    ASSERT_EQ(kept.size(), 3u);
    EXPECT_EQ(kept[1].phoneme, "bmp");
    const auto vowelFlicker =
        segment(concat({repeat("aa", 10), repeat("ih", 4), repeat("aa", 10)}), c);
    EXPECT_EQ(vowelFlicker.size(), 1u);
}

TEST(Segmenter, EmitsEachSegmentWithinItsReportedDelay) {
    const auto& set = PhonemeSet::common();
    dsp::Segmenter seg(set, 0.01);
    const auto classes = concat({repeat("sil", 10), repeat("aa", 8), repeat("d", 4),
                                 repeat("ih", 9), repeat("z", 6), repeat("sil", 20)});
    double worst = 0;
    for (std::size_t i = 0; i < classes.size(); ++i) {
        dsp::FrameLabel l;
        l.time = 0.005 + 0.01 * i;
        l.phoneme = static_cast<int>(*set.find(classes[i]));
        for (const auto& s : seg.push(l)) worst = std::max(worst, (l.time + 0.005) - s.end);
    }
    EXPECT_GT(worst, 0.0);
    EXPECT_LE(worst, seg.delaySeconds() + 1e-9);
}

TEST(Segmenter, AShortSilenceInsideSpeechIsAStopClosureNotAPause) {
    // 60 ms of silence between two vowels is the closure of a stop (the t of "atta"): the
    // mouth holds a consonant there. 200 ms is a pause, and silence before the first sound
    // or after the last stays silence however short.
    const auto closure = segment(concat({repeat("sil", 5), repeat("aa", 10), repeat("sil", 6),
                                         repeat("aa", 10), repeat("sil", 5)}));
    ASSERT_EQ(closure.size(), 5u);
    EXPECT_EQ(closure[0].phoneme, "sil");
    EXPECT_EQ(closure[2].phoneme, "d");
    EXPECT_NEAR(closure[2].end - closure[2].start, 0.06, 1e-9);
    EXPECT_EQ(closure[4].phoneme, "sil");

    const auto pause = segment(concat({repeat("aa", 10), repeat("sil", 20), repeat("aa", 10)}));
    ASSERT_EQ(pause.size(), 3u);
    EXPECT_EQ(pause[1].phoneme, "sil");

    dsp::SegmenterConfig off;
    off.stopClosureSeconds = 0;
    EXPECT_EQ(
        segment(concat({repeat("aa", 10), repeat("sil", 6), repeat("aa", 10)}), off)[1].phoneme,
        "sil");
}

TEST(Segmenter, AStopClosureClassTheSetLacksIsRefusedByName) {
    dsp::SegmenterConfig c;
    c.closureClass = "tt";
    try {
        dsp::Segmenter seg(PhonemeSet::common(), 0.01, c);
        FAIL() << "accepted a closure class the set lacks";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'tt'"), std::string::npos) << e.what();
    }
}

TEST(TemplateSet, MalformedFilesNameTheField) {
    const auto dir = std::filesystem::temp_directory_path();
    auto errorOf = [&](const std::string& text) {
        const auto path = dir / "lipsyncd_bad_templates.json";
        std::ofstream(path) << text;
        try {
            dsp::TemplateSet::load(path);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(errorOf("{").find("not valid JSON"), std::string::npos);
    EXPECT_NE(errorOf("{\"format\": \"x\", \"version\": 1}").find("format"), std::string::npos);
    const std::string analysis =
        R"("analysis": {"rate": 10000, "hop": 0.01, "window": 0.025, "order": 12, "pre_emphasis": 0.97,
            "lag_window_hz": 60, "white_noise_correction": 0.0001, "bins": 4})";
    const std::string head = R"({"format": "lipsyncd-templates", "version": 1, )" + analysis;
    EXPECT_NE(
        errorOf(head + R"(, "bin_weights": [1,1,1], "classes": []})").find("bin_weights has 3"),
        std::string::npos);
    EXPECT_NE(
        errorOf(
            head +
            R"(, "bin_weights": [1,1,1,1], "classes": [{"phoneme": "xx", "spectra": [[0,0,0,0]]}]})")
            .find("'xx' is not a phoneme class"),
        std::string::npos);
    EXPECT_NE(
        errorOf(
            head +
            R"(, "bin_weights": [1,1,1,1], "classes": [{"phoneme": "aa", "spectra": [[0,0,0]]}]})")
            .find("classes[0] ('aa').spectra[0] has 3 values"),
        std::string::npos);
    EXPECT_NE(
        errorOf(head +
                R"(, "bin_weights": [1,1,1,1], "classes": [{"phoneme": "aa", "spectra": "no"}]})")
            .find("classes[0].spectra"),
        std::string::npos);
    // A speaker's warp (lipsync calibrate) is kept, and one out of range named.
    EXPECT_NE(errorOf(R"({"format": "lipsyncd-templates", "version": 1, "analysis": {"rate": 10000,
        "hop": 0.01, "window": 0.025, "order": 12, "pre_emphasis": 0.97, "lag_window_hz": 60,
        "white_noise_correction": 0.0001, "bins": 4, "warp": 3}, "bin_weights": [1,1,1,1],
        "classes": []})")
                  .find("analysis.warp: must be 0.7..1.4"),
              std::string::npos);
    // Extra features: unknown names are refused; known ones widen every vector.
    const std::string extra =
        R"({"format": "lipsyncd-templates", "version": 1, "analysis": {"rate": 10000,
        "hop": 0.01, "window": 0.025, "order": 12, "pre_emphasis": 0.97, "lag_window_hz": 60,
        "white_noise_correction": 0.0001, "bins": 4, "extra_features": )";
    EXPECT_NE(errorOf(extra + R"(["pitch"]}, "bin_weights": [1,1,1,1], "classes": []})")
                  .find("unknown feature 'pitch'"),
              std::string::npos);
    EXPECT_NE(errorOf(extra + R"(["log_error"]}, "bin_weights": [1,1,1,1], "classes": []})")
                  .find("bin_weights has 4 values, the analysis has 5 features"),
              std::string::npos);
}

TEST(TemplateSet, ShippedDefaultLoadsAndCoversTheCommonSet) {
    const auto t = dsp::TemplateSet::loadDefault();
    EXPECT_GE(t.classes.size(), 21u);
    EXPECT_EQ(t.analysis.analysisRate, 10000);
    EXPECT_EQ(t.analysis.order, 12);
}

TEST(Segmenter, TheScheduleStartsAtZeroWhateverTheFirstFrameTime) {
    // The first analysis frame is centred half a window in (12.5 ms), not at half a hop.
    const auto& set = PhonemeSet::common();
    dsp::Segmenter seg(set, 0.01);
    PhonemeSchedule out;
    for (int i = 0; i < 20; ++i) {
        dsp::FrameLabel l;
        l.time = 0.0125 + 0.01 * i;
        l.phoneme = static_cast<int>(*set.find(i < 10 ? "aa" : "sil"));
        for (const auto& s : seg.push(l)) out.push_back(s);
    }
    for (const auto& s : seg.finish(0.22)) out.push_back(s);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].start, 0.0);
    EXPECT_EQ(out[1].start, out[0].end);
    EXPECT_DOUBLE_EQ(out[1].end, 0.22);
}
