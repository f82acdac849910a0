// The viseme-space filter runtime (paper 001, section 5).
#include <gtest/gtest.h>

#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

TEST(VisemeFilter, WeightsFollowTheEquationOnAStep) {
    const auto poses = twoPoses();
    lipsync::BigramCurveSet set("t", poses, PhonemeSet::common());
    set.setCurve(cls("aa"), cls("aa"), 0, flat(0.8f));  // aa's viseme: open 0.8
    const PhonemeSchedule s{{0, 0.1, "sil", 1}, {0.1, 0.3, "aa", 1}, {0.3, 0.4, "sil", 1}};
    const auto track = lipsync::animateFilter(s, set, poses);
    ASSERT_EQ(track.frames(), 41u);
    const auto open = [&](std::size_t f) { return track.frame(f)[0]; };
    EXPECT_FLOAT_EQ(open(6), 0.0f);         // slots 5..9 all silence
    EXPECT_NEAR(open(7), 0.1 * 0.8, 1e-6);  // only a_{i+3} is aa: anticipation
    EXPECT_NEAR(open(9), (0.3 + 0.1) * 0.8, 1e-6);
    EXPECT_NEAR(open(10), (0.5 + 0.3 + 0.1) * 0.8, 1e-6);
    EXPECT_NEAR(open(15), 0.8, 1e-6);        // inside: all weights on aa
    EXPECT_NEAR(open(30), 0.1 * 0.8, 1e-6);  // the step down: only a_{i-1} is aa
}

TEST(VisemeFilter, AveragesSlotsDownToTheOutputRate) {
    const auto poses = twoPoses();
    lipsync::BigramCurveSet set("t", poses, PhonemeSet::common());
    set.setCurve(cls("aa"), cls("aa"), 0, flat(1.0f));
    const PhonemeSchedule s{{0, 0.5, "aa", 1}, {0.5, 1.0, "sil", 1}};
    lipsync::RuntimeConfig config;
    config.outputRate = 25;  // the paper's 25 fps: four slots a frame
    const auto track = lipsync::animateFilter(s, set, poses, config);
    ASSERT_EQ(track.frames(), 26u);
    for (std::size_t f = 0; f < track.frames(); ++f) {
        EXPECT_GE(track.frame(f)[0], 0.0f);
        EXPECT_LE(track.frame(f)[0], 1.0f);
    }
    EXPECT_NEAR(track.frame(5)[0], 1.0, 1e-6);
    EXPECT_NEAR(track.frame(20)[0], 0.0, 1e-6);
}

}  // namespace
}  // namespace lipsyncd::test
