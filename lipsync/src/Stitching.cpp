// Section 2.2.1, first half: phone bigrams (p_i, p_i+1) over (t_i, t_i+2), each bigram's curves
// time-warped onto its span, overlapping curves of one pose stitched with max() so that no
// bigram's motion is damped by its neighbours ("we choose the maximum value over linear
// blending or averaging ... so that the original information is preserved").
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

PoseCurves::PoseCurves(std::size_t poses, double rate_, double startTime_, std::size_t firstFrame_,
                       std::size_t frames_)
    : startTime(startTime_),
      firstFrame(firstFrame_),
      rate(rate_),
      frames(frames_),
      values(poses, std::vector<float>(frames_, 0.0f)) {}

namespace {
std::size_t classOf(const PhonemeSegment& s, const PhonemeSet& phonemes) {
    const auto idx = phonemes.find(s.phoneme);
    if (!idx)
        throw InputError("schedule: '" + s.phoneme + "' at " + std::to_string(s.start) +
                         " s is not a class of the phoneme set in use (map the schedule first; "
                         "--phonemes picks the set)");
    return *idx;
}

// The time-warp: normalised time 0..½ runs over the first phoneme and ½..1 over the second, so
// a curve authored for phonemes of equal length keeps its timing relative to each phoneme when
// their lengths differ (a long vowel after a short consonant holds its pose through its own
// middle instead of sagging where a uniform stretch would put the boundary).
double warp(double t, double t0, double boundary, double t1) {
    if (t < boundary) return boundary > t0 ? 0.5 * (t - t0) / (boundary - t0) : 0.5;
    return t1 > boundary ? 0.5 + 0.5 * (t - boundary) / (t1 - boundary) : 0.5;
}

// Warps one bigram's curves onto [t0, t1] and keeps the larger value per frame.
void stitchPair(const BigramCurveSet& set, std::size_t a, std::size_t b, double t0, double boundary,
                double t1, PoseCurves& curves) {
    if (!(t1 > t0) || curves.frames == 0) return;
    const double origin = curves.startTime + static_cast<double>(curves.firstFrame) / curves.rate;
    const double first = std::ceil((t0 - origin) * curves.rate - 1e-9);
    const double last = std::floor((t1 - origin) * curves.rate + 1e-9);
    if (last < 0 || first > static_cast<double>(curves.frames - 1)) return;
    const auto from = static_cast<std::size_t>(std::max(0.0, first));
    const auto to = std::min(static_cast<std::size_t>(last), curves.frames - 1);
    for (std::size_t p = 0; p < curves.values.size(); ++p) {
        const ControlCurve* c = set.curve(a, b, p);
        if (!c) continue;
        auto& v = curves.values[p];
        for (std::size_t f = from; f <= to; ++f)
            v[f] = std::max(v[f], c->at(warp(curves.timeOf(f), t0, boundary, t1)));
    }
}
}  // namespace

void stitchBigrams(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                   const PhonemeSet& phonemes, PoseCurves& curves, Bracket bracket) {
    if (schedule.empty()) return;
    const std::size_t sil = phonemes.silence();
    // Bracketing silence of zero length: the pair (sil, p_0) spans p_0 alone, (p_n, sil) p_n.
    if (bracket.start)
        stitchPair(set, sil, classOf(schedule.front(), phonemes), schedule.front().start,
                   schedule.front().start, schedule.front().end, curves);
    for (std::size_t i = 0; i + 1 < schedule.size(); ++i)
        stitchPair(set, classOf(schedule[i], phonemes), classOf(schedule[i + 1], phonemes),
                   schedule[i].start, schedule[i].end, schedule[i + 1].end, curves);
    if (bracket.end)
        stitchPair(set, classOf(schedule.back(), phonemes), sil, schedule.back().start,
                   schedule.back().end, schedule.back().end, curves);
}

}  // namespace lipsyncd::lipsync
