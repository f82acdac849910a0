// The streaming runtime is on the live path (a push or a preview every 10 ms), where nothing may
// allocate: once warmed up, seconds of speech go through it without a single allocation.
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "../support/AllocationCount.hpp"
#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

// Speech as the front end closes it: phonemes of 20 to 200 ms, now and then a pause.
PhonemeSchedule speech(double seconds) {
    std::mt19937 rng(17);
    const auto& set = PhonemeSet::common();
    std::uniform_int_distribution<std::size_t> pick(0, set.size() - 1);
    std::uniform_real_distribution<double> length(0.02, 0.2), pause(0.1, 0.5);
    PhonemeSchedule s;
    double t = 0;
    for (std::size_t i = 0; t < seconds; ++i) {
        const bool silent = i % 12 == 11;
        const double d = silent ? pause(rng) : length(rng);
        s.push_back({t, t + d, silent ? "sil" : set[pick(rng)].name, 1});
        t += d;
    }
    return s;
}

// Feeds `s` in 10 ms ticks as the service's live mode does: the segments closed by each tick,
// then the phoneme still open (now and then not the one that closes, as the newest audio frame
// may say). Returns the allocations made by the ticks after `warmUp` seconds.
long allocationsAfterWarmUp(lipsync::StreamingRuntime& stream, const PhonemeSchedule& s,
                            double warmUp) {
    PoseTrack out;  // the caller's track, emptied after each tick: its memory is the caller's
    out.poses = shipped().poses.names();
    out.times.reserve(1000);
    out.values.reserve(1000 * out.poses.size());
    const std::string other = "ah";
    long made = 0;
    std::size_t next = 0;
    for (int tick = 1; next < s.size(); ++tick) {
        const double now = 0.01 * tick;
        std::optional<AllocationCount> count;
        if (now > warmUp) count.emplace();
        while (next < s.size() && s[next].end <= now + 1e-9) stream.push(s[next++], out);
        if (next < s.size()) {
            const auto& open = tick % 7 == 0 ? other : s[next].phoneme;
            stream.preview(open, now, out);
        }
        if (count) made += count->made();
        out.times.clear();
        out.values.clear();
    }
    return made;
}

TEST(StreamingAllocations, TheCausalModeAllocatesNothingOnceWarmedUp) {
    const auto s = speech(8);
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
    EXPECT_EQ(allocationsAfterWarmUp(stream, s, 1.0), 0);
}

TEST(StreamingAllocations, TheDelayedModeAllocatesNothingOnceWarmedUp) {
    const auto s = speech(8);
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0.3);
    EXPECT_EQ(allocationsAfterWarmUp(stream, s, 1.0), 0);
}

// A live show waits minutes between lines: the pause is one segment held open all that time.
// Each tick's work and memory stay those of a short window (before, each tick reran the steps
// over the whole pause, and the buffers grew with it: a minute of pause cost 25 us a tick more).
PhonemeSchedule speechAroundAPause(double pauseSeconds) {
    auto s = speech(3);
    const double resume = s.back().end + pauseSeconds;
    s.push_back({s.back().end, resume, "sil", 1});
    for (auto seg : speech(3)) {
        seg.start += resume, seg.end += resume;
        s.push_back(seg);
    }
    return s;
}

TEST(StreamingAllocations, ALongPauseHeldOpenAllocatesNothing) {
    const auto s = speechAroundAPause(60);
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
    EXPECT_EQ(allocationsAfterWarmUp(stream, s, 1.0), 0);
}

}  // namespace
}  // namespace lipsyncd::test
