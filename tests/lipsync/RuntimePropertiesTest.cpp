// The whole runtime over random schedules: what must hold whatever the input, and streaming
// against the offline pass.
#include <gtest/gtest.h>

#include <random>

#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

// Random classes and durations from 5 ms to 400 ms, starting at `start`.
PhonemeSchedule randomSchedule(std::mt19937& rng, std::size_t n, double start = 0) {
    const auto& set = PhonemeSet::common();
    std::uniform_int_distribution<std::size_t> pick(0, set.size() - 1);
    std::uniform_real_distribution<double> length(0.005, 0.4);
    PhonemeSchedule s;
    double t = start;
    for (std::size_t i = 0; i < n; ++i) {
        const double d = length(rng);
        s.push_back({t, t + d, set[pick(rng)].name, 1});
        t += d;
    }
    return s;
}

void expectBoundsSpeedAndConstraints(const PoseTrack& track, const lipsync::PoseSet& poses,
                                     double rate) {
    for (std::size_t f = 0; f < track.frames(); ++f) {
        const auto w = track.frame(f);
        for (std::size_t p = 0; p < poses.size(); ++p) {
            ASSERT_GE(w[p], 0.0f);
            ASSERT_LE(w[p], 1.0f);
            const float before = f == 0 ? 0.0f : track.frame(f - 1)[p];
            ASSERT_LE(std::abs(w[p] - before), poses[p].speedLimit / rate + 1e-5)
                << poses[p].name << " at " << f;
        }
        for (const auto& c : poses.constraints())
            ASSERT_LE(w[c.low], std::max(0.0f, static_cast<float>(c.threshold) - w[c.high]) + 1e-5f)
                << poses[c.high].name << "/" << poses[c.low].name << " at frame " << f;
    }
}

TEST(RuntimeProperties, BoundsSpeedLimitsAndConstraintsHoldAfterTheLastStep) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 30; ++trial) {
        const auto s = randomSchedule(rng, 40);
        const auto track = lipsync::animate(s, shipped().curves, shipped().poses);
        ASSERT_EQ(track.frames(),
                  static_cast<std::size_t>(std::floor(s.back().end * 100 + 1e-9)) + 1);
        expectBoundsSpeedAndConstraints(track, shipped().poses, 100);
    }
}

TEST(RuntimeProperties, MaxStitchNeverLowersACurve) {
    std::mt19937 rng(11);
    const auto s = randomSchedule(rng, 30);
    const auto frames = static_cast<std::size_t>(s.back().end * 100) + 1;
    lipsync::PoseCurves all(shipped().poses.size(), 100, 0, 0, frames);
    lipsync::stitchBigrams(s, shipped().curves, PhonemeSet::common(), all);
    // Each bigram alone (a two-phoneme schedule, not bracketed) is never above the stitched result.
    for (std::size_t i = 0; i + 1 < s.size(); ++i) {
        lipsync::PoseCurves one(shipped().poses.size(), 100, 0, 0, frames);
        lipsync::stitchBigrams(std::span(s).subspan(i, 2), shipped().curves, PhonemeSet::common(),
                               one, {false, false});
        for (std::size_t p = 0; p < one.values.size(); ++p)
            for (std::size_t f = 0; f < frames; ++f) ASSERT_GE(all.values[p][f], one.values[p][f]);
    }
}

TEST(RuntimeProperties, ShortLongAndSingleSchedulesBehave) {
    const auto& sh = shipped();
    for (const PhonemeSchedule& s :
         {PhonemeSchedule{{0, 0.004, "aa", 1}}, PhonemeSchedule{{0, 12.0, "ow", 1}},
          PhonemeSchedule{{0, 0.5, "sil", 1}, {0.5, 0.51, "bmp", 1}, {0.51, 1, "sil", 1}}}) {
        const auto track = lipsync::animate(s, sh.curves, sh.poses);
        ASSERT_GE(track.frames(), 1u);
        expectBoundsSpeedAndConstraints(track, sh.poses, 100);
        // Silence at the end lets the mouth come back to rest.
        if (s.back().phoneme == "sil") {
            for (float v : track.frame(track.frames() - 1)) EXPECT_LT(v, 0.05f);
        }
    }
    // A long vowel holds its pose rather than sagging in the middle.
    const auto held = lipsync::animate(
        PhonemeSchedule{{0, 0.3, "sil", 1}, {0.3, 3.3, "aa", 1}, {3.3, 3.6, "sil", 1}}, sh.curves,
        sh.poses);
    const auto open = *held.pose("open");
    EXPECT_GT(held.frame(180)[open], 0.45f);
}

TEST(StreamingRuntime, WithALongEnoughDelayEqualsTheOfflinePass) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 10; ++trial) {
        const auto s = randomSchedule(rng, 60);
        const auto offline = lipsync::animate(s, shipped().curves, shipped().poses);
        lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 1.2);
        PoseTrack streamed;
        for (const auto& seg : s) stream.push(seg, streamed);
        stream.finish(streamed);
        ASSERT_EQ(streamed.frames(), offline.frames());
        for (std::size_t i = 0; i < offline.values.size(); ++i)
            ASSERT_FLOAT_EQ(streamed.values[i], offline.values[i])
                << "frame " << i / offline.poses.size();
    }
}

TEST(StreamingRuntime, CausalModeEmitsEveryFrameAtOnceWithinBounds) {
    std::mt19937 rng(5);
    const auto s = randomSchedule(rng, 50);
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
    PoseTrack out;
    for (const auto& seg : s) {
        stream.push(seg, out);
        // Every frame up to the closed boundary is out already: no waiting for the next phoneme.
        EXPECT_EQ(out.frames(), static_cast<std::size_t>(std::floor(seg.end * 100 + 1e-9)) + 1);
    }
    stream.finish(out);
    expectBoundsSpeedAndConstraints(out, shipped().poses, 100);
}

// Told what comes next (a followed line's words), the causal mode's guess of what follows the
// newest phoneme is that, not the phoneme going on: its frames come closer to the offline pass,
// which knows the whole schedule.
TEST(StreamingRuntime, AnExpectedNextPhonemeBringsTheCausalModeCloserToTheOfflinePass) {
    std::mt19937 rng(11);
    double told = 0, untold = 0;
    for (int trial = 0; trial < 10; ++trial) {
        const auto s = randomSchedule(rng, 40);
        const auto offline = lipsync::animate(s, shipped().curves, shipped().poses);
        for (const bool tell : {false, true}) {
            lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
            PoseTrack out;
            std::size_t next = 0;
            for (int tick = 1; next < s.size(); ++tick) {
                const double now = 0.01 * tick;
                while (next < s.size() && s[next].end <= now + 1e-9) {
                    if (tell && next + 1 < s.size())
                        stream.expect(s[next + 1].phoneme, s[next].end);
                    stream.push(s[next++], out);
                }
                if (next >= s.size()) break;
                if (tell && next + 1 < s.size() && s[next + 1].start < now + 0.1)
                    stream.expect(s[next + 1].phoneme, s[next + 1].start);
                stream.preview(s[next].phoneme, now, out);
            }
            double error = 0;
            for (std::size_t f = 0; f < out.frames() && f < offline.frames(); ++f)
                for (std::size_t p = 0; p < out.poses.size(); ++p)
                    error += std::abs(out.frame(f)[p] - offline.frame(f)[p]);
            (tell ? told : untold) += error;
        }
    }
    EXPECT_LT(told, untold * 0.5) << told << " against " << untold;  // measured 0.33
}

// The causal mode, ticked every 10 ms as the service's live mode runs it: the segments closed
// by each tick, then the phoneme still open.
PoseTrack tickedCausally(const PhonemeSchedule& s) {
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
    PoseTrack out;
    std::size_t next = 0;
    for (int tick = 1; next < s.size(); ++tick) {
        const double now = 0.01 * tick;
        while (next < s.size() && s[next].end <= now + 1e-9) stream.push(s[next++], out);
        if (next < s.size()) stream.preview(s[next].phoneme, now, out);
    }
    return out;
}

// How the live mouth says a line does not depend on how long the pause before it lasted: the
// guess of how long the open phoneme goes on comes from the phonemes heard, not from the pause
// (a minute's wait once stretched that guess over seconds, and the first phonemes after it
// barely moved the mouth).
TEST(StreamingRuntime, TheCausalModeSaysALineAlikeAfterAShortOrALongPause) {
    std::mt19937 rng(19);
    const auto before = randomSchedule(rng, 10), line = randomSchedule(rng, 12);
    const auto after = [&](double pause) {
        auto s = before;
        const double start = s.back().end + pause;
        s.push_back({s.back().end, start, "sil", 1});
        for (auto seg : line) s.push_back({seg.start + start, seg.end + start, seg.phoneme, 1});
        return std::pair{tickedCausally(s), start};
    };
    const auto [shortly, shortStart] = after(0.5);
    const auto [later, longStart] = after(30);
    double difference = 0, total = 0;
    const auto lineFrames = static_cast<std::size_t>(line.back().end * 100);
    for (std::size_t f = 0; f < lineFrames; ++f) {
        const auto a = shortly.frame(static_cast<std::size_t>(std::lround(shortStart * 100)) + f);
        const auto b = later.frame(static_cast<std::size_t>(std::lround(longStart * 100)) + f);
        for (std::size_t p = 0; p < a.size(); ++p)
            difference += std::abs(a[p] - b[p]), total += a[p];
    }
    EXPECT_LT(difference, 0.01 * total);  // measured 0; 5 % when the pause counted
}

TEST(StreamingRuntime, ASegmentThatLeavesAGapIsRefused) {
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0.5);
    PoseTrack out;
    stream.push({0, 0.1, "aa", 1}, out);
    EXPECT_THROW(stream.push({0.2, 0.3, "aa", 1}, out), InputError);
}

}  // namespace
}  // namespace lipsyncd::test
