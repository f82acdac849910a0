// How well a puppet's jaw follows speech: against a reference made from the labelled phonemes'
// jaw heights (config/phonemes/common.toml), Pearson's r over time, the bilabial closures it
// shows, and the frames where it shows a closed mouth that is clearly open.
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
std::vector<float> movingAverage(std::span<const float> x, std::size_t half) {
    std::vector<double> cumulative(x.size() + 1, 0.0);
    for (std::size_t i = 0; i < x.size(); ++i) cumulative[i + 1] = cumulative[i] + x[i];
    std::vector<float> out(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        const std::size_t lo = i > half ? i - half : 0, hi = std::min(x.size(), i + half + 1);
        out[i] = static_cast<float>((cumulative[hi] - cumulative[lo]) / double(hi - lo));
    }
    return out;
}

std::size_t frameAt(double t, double rate, std::size_t frames) {
    return static_cast<std::size_t>(std::clamp(std::round(t * rate), 0.0, double(frames)));
}

bool isClosure(std::span<const PhonemeSegment> labels, std::size_t i, const PhonemeSet& set) {
    const auto c = set.find(labels[i].phoneme);
    if (!c || set[*c].group != "closed" || i == 0 || i + 1 == labels.size()) return false;
    const auto& silence = set[set.silence()].name;
    return labels[i - 1].phoneme != silence && labels[i + 1].phoneme != silence;
}
}  // namespace

std::vector<float> jawReference(std::span<const PhonemeSegment> labels, const PhonemeSet& set,
                                double rate, std::size_t frames, const JawScoreConfig& config) {
    std::vector<float> raw(frames, 0.0f);
    for (const auto& s : labels) {
        const auto c = set.find(s.phoneme);
        if (!c) throw InputError("jaw reference: '" + s.phoneme + "' is not a phoneme class");
        if (!set[*c].jaw)
            throw InputError("jaw reference: phoneme class '" + s.phoneme + "' has no jaw height");
        std::fill(raw.begin() + static_cast<std::ptrdiff_t>(frameAt(s.start, rate, frames)),
                  raw.begin() + static_cast<std::ptrdiff_t>(frameAt(s.end, rate, frames)),
                  *set[*c].jaw);
    }
    const auto half = static_cast<std::size_t>(std::round(config.smoothingSeconds * rate / 2));
    return movingAverage(raw, half);
}

double JawScore::r() const {
    const double vx = n * sxx - sx * sx, vy = n * syy - sy * sy;
    if (!(vx > 0 && vy > 0)) return 0;
    return (n * sxy - sx * sy) / std::sqrt(vx * vy);
}

void JawScore::add(const JawScore& o) {
    n += o.n, sx += o.sx, sy += o.sy, sxx += o.sxx, syy += o.syy, sxy += o.sxy;
    if (classJaw.size() < o.classJaw.size()) {
        classJaw.resize(o.classJaw.size(), 0.0);
        classFrames.resize(o.classJaw.size(), 0);
    }
    for (std::size_t c = 0; c < o.classJaw.size(); ++c)
        classJaw[c] += o.classJaw[c], classFrames[c] += o.classFrames[c];
    closures += o.closures, closuresCaught += o.closuresCaught;
    openFrames += o.openFrames, falseClosures += o.falseClosures, openJaw += o.openJaw;
}

JawScore scoreJaw(std::span<const float> jaw, std::span<const float> reference,
                  std::span<const PhonemeSegment> labels, const PhonemeSet& set, double rate,
                  const JawScoreConfig& config) {
    JawScore s;
    const std::size_t frames = std::min(jaw.size(), reference.size());
    for (std::size_t f = 0; f < frames; ++f) {
        const double x = jaw[f], y = reference[f];
        s.n += 1, s.sx += x, s.sy += y, s.sxx += x * x, s.syy += y * y, s.sxy += x * y;
        if (y > config.clearlyOpenAbove) {
            ++s.openFrames;
            s.openJaw += x;
            if (x < config.closedBelow) ++s.falseClosures;
        }
    }
    s.classJaw.assign(set.size(), 0.0);
    s.classFrames.assign(set.size(), 0);
    for (const auto& label : labels) {
        const auto c = set.find(label.phoneme);
        if (!c) continue;
        for (auto f = frameAt(label.start, rate, frames); f < frameAt(label.end, rate, frames); ++f)
            s.classJaw[*c] += jaw[f], ++s.classFrames[*c];
    }
    for (std::size_t i = 0; i < labels.size(); ++i) {
        if (!isClosure(labels, i, set)) continue;
        const auto lo = frameAt(labels[i].start - config.closureMarginSeconds, rate, frames);
        const auto hi = frameAt(labels[i].end + config.closureMarginSeconds, rate, frames);
        if (lo >= hi) continue;  // beyond the jaw's frames
        ++s.closures;
        const auto lowest = *std::min_element(jaw.begin() + static_cast<std::ptrdiff_t>(lo),
                                              jaw.begin() + static_cast<std::ptrdiff_t>(hi));
        if (lowest < config.closedBelow) ++s.closuresCaught;
    }
    return s;
}

}  // namespace lipsyncd::lipsync
