// The viseme-space filter of paper 001, section 5, as a second runtime for comparison: one
// viseme vector a_i per 10 ms slot (the pose vector of the slot's phoneme), filtered as
//   a'_i = 0.1·a_i−1 + 0.5·a_i + 0.3·a_i+1 + 0.1·a_i+3
// ("a heavier weight on the succeeding frame ... the lips tend to aim at the next phoneme"),
// then averaged in groups of slots down to the output rate (their motion blur). It looks 30 ms
// ahead, where the bigram runtime needs the next phoneme's end: the lowest-latency option.
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
constexpr double kSlotRate = 100;  // one viseme per 10 ms, as the paper's aligner gives

// The viseme of each class: the pose its self-bigram (c, c) holds at the first phoneme's
// centre, i.e. what the curve set shows for that phoneme held (the paper's "average viseme").
std::vector<std::vector<float>> visemes(const BigramCurveSet& set, std::size_t classes,
                                        std::size_t poses) {
    std::vector<std::vector<float>> v(classes, std::vector<float>(poses, 0.0f));
    for (std::size_t c = 0; c < classes; ++c)
        for (std::size_t p = 0; p < poses; ++p)
            if (const auto* curve = set.curve(c, c, p)) v[c][p] = curve->at(0.25);
    return v;
}
}  // namespace

PoseTrack animateFilter(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                        const PoseSet& poses, const RuntimeConfig& config,
                        const PhonemeSet& phonemes) {
    PoseTrack track;
    track.poses = poses.names();
    if (schedule.empty()) return track;
    const auto table = visemes(set, phonemes.size(), poses.size());
    const double start = schedule.front().start, end = schedule.back().end;
    const auto slots = static_cast<std::size_t>(std::floor((end - start) * kSlotRate + 1e-9)) + 1;
    std::vector<std::size_t> cls(slots);
    for (std::size_t i = 0, seg = 0; i < slots; ++i) {
        const double t = start + static_cast<double>(i) / kSlotRate;
        while (seg + 1 < schedule.size() && t >= schedule[seg].end) ++seg;
        const auto c = phonemes.find(schedule[seg].phoneme);
        if (!c)
            throw InputError("schedule: '" + schedule[seg].phoneme + "' is not a phoneme class");
        cls[i] = *c;
    }
    // Beyond either end the mouth is at rest (silence).
    const auto at = [&](long long i, std::size_t p) {
        return i < 0 || i >= static_cast<long long>(slots)
                   ? 0.0f
                   : table[cls[static_cast<std::size_t>(i)]][p];
    };
    std::vector<std::vector<float>> filtered(slots, std::vector<float>(poses.size()));
    for (std::size_t i = 0; i < slots; ++i)
        for (std::size_t p = 0; p < poses.size(); ++p) {
            const auto k = static_cast<long long>(i);
            filtered[i][p] = std::clamp(
                0.1f * at(k - 1, p) + 0.5f * at(k, p) + 0.3f * at(k + 1, p) + 0.1f * at(k + 3, p),
                0.0f, 1.0f);
        }
    // Down to the output rate: each output frame averages the slots nearest to it.
    const auto frames =
        static_cast<std::size_t>(std::floor((end - start) * config.outputRate + 1e-9)) + 1;
    std::vector<float> row(poses.size());
    for (std::size_t f = 0; f < frames; ++f) {
        const double t = static_cast<double>(f) / config.outputRate;
        const auto from = static_cast<std::size_t>(
            std::max(0.0, std::round((t - 0.5 / config.outputRate) * kSlotRate)));
        auto to = static_cast<std::size_t>(std::round((t + 0.5 / config.outputRate) * kSlotRate));
        to = std::clamp(to, from + 1, slots);
        std::fill(row.begin(), row.end(), 0.0f);
        for (std::size_t i = std::min(from, slots - 1); i < to; ++i)
            for (std::size_t p = 0; p < poses.size(); ++p) row[p] += filtered[i][p];
        const auto n = static_cast<float>(to - std::min(from, slots - 1));
        for (auto& v : row) v /= n;
        track.append(start + t, row);
    }
    return track;
}

}  // namespace lipsyncd::lipsync
