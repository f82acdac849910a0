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

double sampleValue(float x) {
    return std::isfinite(x) ? x : 0.0;
}
double sampleValue(std::int16_t x) {
    return x / 32768.0;
}

// Float samples as they are, 16-bit ones scaled to full scale 1.
template <class Sample>
LevelTrack measure(std::span<const Sample> samples, int sampleRate, double frameRate,
                   double windowSeconds) {
    LevelTrack track;
    track.rate = frameRate;
    if (sampleRate <= 0 || samples.empty()) return track;
    const double hop = sampleRate / frameRate;
    const auto half = static_cast<std::ptrdiff_t>(windowSeconds * sampleRate / 2);
    const auto n = static_cast<std::ptrdiff_t>(samples.size());
    const auto frames = static_cast<std::size_t>(std::floor(static_cast<double>(n) / hop)) + 1;
    // Each frame sums its own window: no buffer the size of the audio (a 40 s `say` in the
    // service would otherwise hold 7 MB of running sums), and the windows are short.
    track.db.reserve(frames);
    for (std::size_t f = 0; f < frames; ++f) {
        const auto centre = static_cast<std::ptrdiff_t>(std::llround(static_cast<double>(f) * hop));
        const auto lo = std::clamp<std::ptrdiff_t>(centre - half, 0, n);
        const auto hi = std::clamp<std::ptrdiff_t>(centre + half, 0, n);
        double energy = 0;
        for (auto i = lo; i < hi; ++i) {
            const double x = sampleValue(samples[static_cast<std::size_t>(i)]);
            energy += x * x;
        }
        track.db.push_back(toDb(hi > lo ? energy / static_cast<double>(hi - lo) : 0.0));
    }
    return track;
}
}  // namespace

LevelTrack measureLevels(std::span<const float> samples, int sampleRate, double frameRate,
                         double windowSeconds) {
    return measure(samples, sampleRate, frameRate, windowSeconds);
}

LevelTrack measureLevels(std::span<const std::int16_t> samples, int sampleRate, double frameRate,
                         double windowSeconds) {
    return measure(samples, sampleRate, frameRate, windowSeconds);
}

std::vector<float> followEnvelope(const LevelTrack& levels, const EnvelopeFollowerConfig& c) {
    std::vector<float> out;
    if (levels.db.empty()) return out;
    // The gain knob, set once for the voice: full opening at the speaking level.
    const float peak = *std::max_element(levels.db.begin(), levels.db.end());
    const double full =
        std::pow(10.0, levels.speakingLevel(c.fullAtPercentile, c.gateBelowPeakDb) / 20);
    const double gate = std::pow(10.0, (peak - c.gateBelowPeakDb) / 20);
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
