// dsp::scoreBoundaries: an alignment's timing against reference labels, as `lipsync eval --align`
// and bench/align_accuracy report it.
#include <gtest/gtest.h>

#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {
namespace {

PhonemeSchedule schedule(std::initializer_list<std::pair<double, const char*>> starts, double end) {
    PhonemeSchedule s;
    for (const auto& [start, phoneme] : starts) {
        if (!s.empty()) s.back().end = start;
        s.push_back({start, end, phoneme, 1.0f});
    }
    return s;
}

void expectErrors(const BoundaryScore& b, std::initializer_list<double> seconds) {
    ASSERT_EQ(b.errors.size(), seconds.size());
    std::size_t i = 0;
    for (const double e : seconds) EXPECT_NEAR(b.errors[i++], e, 1e-9) << "boundary " << i;
}

TEST(BoundaryScore, ABoundaryPlacedLateCountsByHowLate) {
    const auto ref = schedule({{0, "sil"}, {0.2, "bmp"}, {0.3, "aa"}, {0.5, "sil"}}, 0.8);
    const auto hyp = schedule({{0, "sil"}, {0.215, "bmp"}, {0.3, "aa"}, {0.46, "sil"}}, 0.8);
    const auto b = scoreBoundaries(hyp, ref);
    expectErrors(b, {0.015, 0.0, 0.04});
    EXPECT_EQ(b.missed, 0u);
    EXPECT_NEAR(b.percentile(0.5), 0.015, 1e-9);
    EXPECT_NEAR(b.shareWithin(0.02), 2.0 / 3, 1e-9);
    EXPECT_NEAR(b.shareWithin(0.05), 1.0, 1e-9);
}

TEST(BoundaryScore, OnlyABoundaryBetweenTheSameTwoClassesWithinTheWindowCounts) {
    const auto ref = schedule({{0, "sil"}, {0.2, "d"}, {0.3, "ih"}, {0.5, "sil"}}, 0.8);
    // d→ah is not d→ih; ih→sil lies 150 ms off: both missed, at the window's 100 ms.
    const auto hyp =
        schedule({{0, "sil"}, {0.21, "d"}, {0.3, "ah"}, {0.35, "ih"}, {0.65, "sil"}}, 0.8);
    const auto b = scoreBoundaries(hyp, ref);
    expectErrors(b, {0.01, 0.1, 0.1});
    EXPECT_EQ(b.missed, 2u);
    EXPECT_NEAR(scoreBoundaries(hyp, ref, 0.2).errors[2], 0.15, 1e-9);
}

TEST(BoundaryScore, TheNearestOfTwoPartnersIsTaken) {
    const auto ref = schedule({{0, "sil"}, {1.0, "aa"}, {1.2, "sil"}}, 2.0);
    const auto hyp =
        schedule({{0, "sil"}, {0.95, "aa"}, {0.97, "sil"}, {1.02, "aa"}, {1.2, "sil"}}, 2.0);
    const auto b = scoreBoundaries(hyp, ref);
    expectErrors(b, {0.02, 0.0});
}

TEST(BoundaryScore, RepeatedSegmentsOfOneClassAreNoBoundaryAndScoresAddUp) {
    const auto ref = schedule({{0, "sil"}, {0.2, "d"}, {0.25, "d"}, {0.3, "aa"}}, 0.6);
    const auto hyp = schedule({{0, "sil"}, {0.2, "d"}, {0.33, "aa"}}, 0.6);
    auto total = scoreBoundaries(hyp, ref);
    EXPECT_EQ(total.errors.size(), 2u);
    total.add(scoreBoundaries(ref, ref));
    EXPECT_EQ(total.errors.size(), 4u);
    EXPECT_NEAR(total.percentile(1.0), 0.03, 1e-9);
    EXPECT_EQ(BoundaryScore{}.percentile(0.5), 0.0);
    EXPECT_EQ(BoundaryScore{}.shareWithin(0.02), 0.0);
}

}  // namespace
}  // namespace lipsyncd::dsp
