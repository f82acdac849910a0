// Each step of the runtime (section 2.2) on hand-computed cases.
#include <gtest/gtest.h>

#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

using lipsync::ControlCurve;
using lipsync::PoseCurves;

TEST(ControlCurve, PassesThroughItsEndsAndHeldTargets) {
    const ControlCurve c({{0, 0}, {0.3f, 0.8f}, {0.4f, 0.8f}, {0.5f, 0.8f}, {1, 0}});
    EXPECT_FLOAT_EQ(c.at(0), 0);
    EXPECT_NEAR(c.at(1), 0, 1e-6);
    // Three equal vertices: the B-spline reaches the value at the middle one.
    EXPECT_NEAR(c.at(0.4), 0.8, 0.01);
    // A single vertex is only approached (the curve is smooth, not the polygon itself).
    const ControlCurve peak({{0, 0}, {0.5f, 1}, {1, 0}});
    EXPECT_LT(peak.at(0.5), 0.9);
    EXPECT_GT(peak.at(0.5), 0.5);
}

TEST(ControlCurve, StaysInsideTheControlValues) {
    const ControlCurve c({{0, 0.2f}, {0.1f, 1}, {0.2f, 0}, {0.3f, 1}, {1, 0.2f}});
    for (int i = 0; i <= 1000; ++i) {
        const float v = c.at(i / 1000.0);
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
    }
}

TEST(Stitching, PairsSpanTwoPhonemesAndOverlapsKeepTheMax) {
    const auto poses = twoPoses();
    lipsync::BigramCurveSet set("t", poses, PhonemeSet::common());
    set.setCurve(cls("sil"), cls("aa"), 0, flat(0.3f));   // covers aa
    set.setCurve(cls("aa"), cls("bmp"), 0, flat(0.6f));   // covers aa and bmp
    set.setCurve(cls("bmp"), cls("sil"), 0, flat(0.2f));  // covers bmp
    const PhonemeSchedule s{{0, 0.1, "aa", 1}, {0.1, 0.2, "bmp", 1}};
    PoseCurves curves(2, 100, 0, 0, 21);
    lipsync::stitchBigrams(s, set, PhonemeSet::common(), curves);
    for (std::size_t f = 0; f <= 20; ++f) EXPECT_FLOAT_EQ(curves.values[0][f], 0.6f) << f;
    EXPECT_FLOAT_EQ(curves.values[1][10], 0.0f);  // no pbm curve anywhere
}

TEST(Stitching, WarpsEachBigramOntoItsSpan) {
    const auto poses = twoPoses();
    lipsync::BigramCurveSet set("t", poses, PhonemeSet::common());
    set.setCurve(cls("aa"), cls("bmp"), 1, ControlCurve({{0, 0}, {1, 1}}));  // a ramp over the pair
    const PhonemeSchedule s{{0, 0.1, "aa", 1}, {0.1, 0.3, "bmp", 1}};
    PoseCurves curves(2, 100, 0, 0, 31);
    lipsync::stitchBigrams(s, set, PhonemeSet::common(), curves);
    // The pair spans 0 .. 0.3; normalised ½ falls on the boundary at 0.1 s, so the ramp (a
    // clamped B-spline of a line) is at ¼ mid-aa, ½ at the boundary, ¾ mid-bmp.
    EXPECT_NEAR(curves.values[1][5], 0.25, 0.01);
    EXPECT_NEAR(curves.values[1][10], 0.5, 0.01);
    EXPECT_NEAR(curves.values[1][20], 0.75, 0.01);
    EXPECT_NEAR(curves.values[1][30], 1.0, 1e-4);
}

TEST(Stitching, UnknownPhonemeIsNamed) {
    const auto poses = twoPoses();
    lipsync::BigramCurveSet set("t", poses, PhonemeSet::common());
    const PhonemeSchedule s{{0, 0.1, "AA1", 1}};
    PoseCurves curves(2, 100, 0, 0, 11);
    try {
        lipsync::stitchBigrams(s, set, PhonemeSet::common(), curves);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'AA1'"), std::string::npos) << e.what();
    }
}

TEST(ValleySmoothing, FillsAValleyBetweenNearPeaks) {
    std::vector<float> c{0, 1, 0.2f, 0.2f, 0.8f, 0};
    lipsync::smoothValleys(c, 100, 0.05);     // peaks 3 frames apart, window 5 frames
    EXPECT_FLOAT_EQ(c[2], 1 - 0.2f / 3 * 1);  // on the line from 1 (frame 1) to 0.8 (frame 4)
    EXPECT_FLOAT_EQ(c[3], 1 - 0.2f / 3 * 2);
    EXPECT_FLOAT_EQ(c[5], 0);
}

TEST(ValleySmoothing, LeavesFarPeaksAndNeverLowers) {
    std::vector<float> c{0, 1, 0.2f, 0.2f, 0.8f, 0};
    const auto before = c;
    lipsync::smoothValleys(c, 100, 0.02);  // window of 2 frames: the peaks are 3 apart
    EXPECT_EQ(c, before);
    std::vector<float> rest{0, 0, 0, 0.5f, 0, 0, 0};
    lipsync::smoothValleys(rest, 100, 1.0);  // a single bump: nothing to join
    EXPECT_EQ(rest, (std::vector<float>{0, 0, 0, 0.5f, 0, 0, 0}));
}

TEST(PoseConstraints, TheLowerPriorityPoseGivesWay) {
    const auto poses = twoPoses();
    PoseCurves c(2, 100, 0, 0, 3);
    c.values[0] = {0.5f, 0.4f, 0.9f};  // open
    c.values[1] = {0.8f, 0.1f, 0.3f};  // pbm (higher priority)
    lipsync::applyConstraints(poses, c);
    EXPECT_FLOAT_EQ(c.values[0][0], 0.0f);  // 0.8 + 0.5 > 0.5: open = max(0, 0.5 − 0.8)
    EXPECT_FLOAT_EQ(c.values[0][1], 0.4f);  // 0.1 + 0.4 ≤ 0.5: untouched
    EXPECT_FLOAT_EQ(c.values[0][2], 0.2f);  // open = 0.5 − 0.3
    EXPECT_EQ(c.values[1], (std::vector<float>{0.8f, 0.1f, 0.3f}));  // pbm never changes
}

TEST(SpeedLimits, ARampNoSteeperThanTheLimit) {
    const auto poses = twoPoses(6.0);
    PoseCurves c(2, 100, 0, 0, 30);
    std::fill(c.values[0].begin(), c.values[0].end(), 1.0f);
    lipsync::limitSpeed(poses, false, std::vector<float>{0, 0}, c);
    for (std::size_t f = 0; f < 16; ++f) EXPECT_NEAR(c.values[0][f], 0.06 * (f + 1), 1e-5) << f;
    EXPECT_FLOAT_EQ(c.values[0][20], 1.0f);
}

TEST(SpeedLimits, ARisingHighPoseWaitsForItsPartnerToFall) {
    // open at 0.5 must fall to let pbm close the lips; pbm may not jump past C − open.
    const auto poses = twoPoses(6.0);
    PoseCurves c(2, 100, 0, 0, 20);
    std::fill(c.values[1].begin(), c.values[1].end(), 1.0f);  // pbm wants 1, open wants 0
    lipsync::limitSpeed(poses, true, std::vector<float>{0.5f, 0}, c);
    for (std::size_t f = 0; f < 20; ++f) {
        const float open = c.values[0][f], pbm = c.values[1][f];
        EXPECT_LE(open, std::max(0.0f, 0.5f - pbm) + 1e-6f) << f;
    }
    EXPECT_NEAR(c.values[0][0], 0.44, 1e-5);  // open falls at its limit
    EXPECT_GT(c.values[1][19], 0.9f);         // and pbm gets there
}

}  // namespace
}  // namespace lipsyncd::test
