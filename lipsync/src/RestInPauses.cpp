// The mouth rests when speech stops. The bigram curves alone do not guarantee it: a pair
// (vowel, sil) is stretched over the whole pause, so its fall to rest takes half the pause, and
// valley smoothing can bridge a short pause altogether. A puppet whose jaw hangs half open in a
// pause, or after its line, reads as broken, so every pose is capped by a ramp to 0 at each
// pause (an addition of ours to paper 000's runtime; it only ever lowers a weight).
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
// The cap in a pause [a, b]: 1 at a, 0 from a + within to b − within, 1 again at b. A pause
// that opens the schedule has no fall; one that closes it has no rise.
float capAt(double t, double a, double b, double within, bool opens, bool closes) {
    const double fall = opens ? 0 : (a + within - t) / within;
    const double rise = closes ? 0 : (t - (b - within)) / within;
    return static_cast<float>(std::clamp(std::max(fall, rise), 0.0, 1.0));
}
// Scales every pose by the cap over the frames inside the pause [a, b] (from `fromFrame` on).
void capPause(double a, double b, bool opens, bool closes, const RestRule& rest, PoseCurves& curves,
              std::size_t fromFrame) {
    const auto frameAt = [&](double t) { return (t - curves.startTime) * curves.rate; };
    const double first = std::max(
        {std::ceil(frameAt(a) - 1e-9), static_cast<double>(curves.firstFrame + fromFrame)});
    const double last = std::min(std::floor(frameAt(b) + 1e-9),
                                 static_cast<double>(curves.firstFrame + curves.frames) - 1);
    for (double g = first; g <= last; ++g) {
        const auto f = static_cast<std::size_t>(g) - curves.firstFrame;
        const float cap = capAt(curves.timeOf(f), a, b, rest.within, opens, closes);
        for (auto& pose : curves.values) pose[f] *= cap;
    }
}
}  // namespace

void restInPauses(std::span<const PhonemeSegment> schedule, const PhonemeSet& phonemes,
                  const RestRule& rest, PoseCurves& curves, std::size_t fromFrame,
                  Bracket bracket) {
    const auto& silence = phonemes[phonemes.silence()].name;
    for (std::size_t i = 0; i < schedule.size(); ++i) {
        if (schedule[i].phoneme != silence) continue;
        std::size_t j = i;  // a run of silences is one pause
        while (j + 1 < schedule.size() && schedule[j + 1].phoneme == silence) ++j;
        const double a = schedule[i].start, b = schedule[j].end;
        const bool opens = bracket.start && i == 0;
        const bool closes = bracket.end && j + 1 == schedule.size();
        if (opens || closes || b - a >= rest.minPause)
            capPause(a, b, opens, closes, rest, curves, fromFrame);
        i = j;
    }
}

}  // namespace lipsyncd::lipsync
