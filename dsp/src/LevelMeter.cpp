// Speech level over time: the frame RMS Lewis's analysis reports beside each spectrum, measured
// on whole audio in memory (for TTS output and evaluation), and the loudness envelope follower
// that inexpensive jaw boards drive a servo with (the baseline `lipsync eval` compares with).
#include <algorithm>
#include <cmath>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
float toDb(double meanSquare) {
    return static_cast<float>(10 * std::log10(std::max(meanSquare, 1e-12)));
}
}  // namespace

LevelTrack measureLevels(std::span<const float> samples, int sampleRate, double frameRate,
                         double windowSeconds) {
    LevelTrack track;
    track.rate = frameRate;
    if (sampleRate <= 0 || samples.empty()) return track;
    const double hop = sampleRate / frameRate;
    const auto half = static_cast<std::ptrdiff_t>(windowSeconds * sampleRate / 2);
    const auto n = static_cast<std::ptrdiff_t>(samples.size());
    const auto frames = static_cast<std::size_t>(std::floor(static_cast<double>(n) / hop)) + 1;
    // Running sums of squares make each frame O(1) whatever the window.
    std::vector<double> cumulative(samples.size() + 1, 0.0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double x = std::isfinite(samples[i]) ? samples[i] : 0.0;
        cumulative[i + 1] = cumulative[i] + x * x;
    }
    track.db.reserve(frames);
    for (std::size_t f = 0; f < frames; ++f) {
        const auto centre = static_cast<std::ptrdiff_t>(std::llround(static_cast<double>(f) * hop));
        const auto lo = std::clamp<std::ptrdiff_t>(centre - half, 0, n);
        const auto hi = std::clamp<std::ptrdiff_t>(centre + half, 0, n);
        const double energy = hi > lo ? (cumulative[hi] - cumulative[lo]) / (hi - lo) : 0.0;
        track.db.push_back(toDb(energy));
    }
    return track;
}

std::vector<float> followEnvelope(const LevelTrack& levels, const EnvelopeFollowerConfig& c) {
    std::vector<float> out;
    if (levels.db.empty()) return out;
    // The gain knob, set once for the voice: full opening at the speaking level.
    std::vector<float> sorted(levels.db);
    const float peak = *std::max_element(sorted.begin(), sorted.end());
    std::erase_if(sorted, [&](float v) { return v < peak - c.gateBelowPeakDb; });
    const auto k = static_cast<std::size_t>(c.fullAtPercentile * (sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
    const double full = std::pow(10.0, sorted[k] / 20),
                 gate = std::pow(10.0, (peak - c.gateBelowPeakDb) / 20);
    const double dt = 1 / levels.rate;
    const double attack = 1 - std::exp(-dt / c.attackSeconds);
    const double release = 1 - std::exp(-dt / c.releaseSeconds);
    double envelope = 0;
    for (float db : levels.db) {
        const double amplitude = std::pow(10.0, db / 20);
        envelope += (amplitude > envelope ? attack : release) * (amplitude - envelope);
        out.push_back(static_cast<float>(std::clamp((envelope - gate) / (full - gate), 0.0, 1.0)));
    }
    return out;
}

}  // namespace lipsyncd::dsp
