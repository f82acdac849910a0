// Scoring a schedule's phoneme boundaries against reference labels (the timing of an alignment).
#include <algorithm>
#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <string_view>
#include <vector>

namespace lipsyncd::dsp {

namespace {
struct Boundary {
    double time;
    std::string_view left, right;
};

std::vector<Boundary> boundariesOf(const PhonemeSchedule& s) {
    std::vector<Boundary> out;
    for (std::size_t i = 1; i < s.size(); ++i)
        if (s[i].phoneme != s[i - 1].phoneme)
            out.push_back({s[i].start, s[i - 1].phoneme, s[i].phoneme});
    return out;  // in time order, as the schedule is
}
}  // namespace

void BoundaryScore::add(const BoundaryScore& other) {
    errors.insert(errors.end(), other.errors.begin(), other.errors.end());
    missed += other.missed;
}

double BoundaryScore::percentile(double p) const {
    if (errors.empty()) return 0;
    auto sorted = errors;
    const auto last = static_cast<double>(sorted.size() - 1);
    const auto at = static_cast<std::size_t>(std::min(last, std::clamp(p, 0.0, 1.0) * last + 0.5));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(at),
                     sorted.end());
    return sorted[at];
}

double BoundaryScore::shareWithin(double seconds) const {
    if (errors.empty()) return 0;
    const auto n =
        std::count_if(errors.begin(), errors.end(), [&](double e) { return e <= seconds + 1e-9; });
    return static_cast<double>(n) / static_cast<double>(errors.size());
}

BoundaryScore scoreBoundaries(const PhonemeSchedule& hypothesis, const PhonemeSchedule& reference,
                              double missedAfter) {
    const auto hyp = boundariesOf(hypothesis);
    BoundaryScore score;
    std::size_t from = 0;  // the first hypothesis boundary not before (reference − missedAfter)
    for (const auto& r : boundariesOf(reference)) {
        while (from < hyp.size() && hyp[from].time < r.time - missedAfter) ++from;
        double best = missedAfter;
        bool found = false;
        for (std::size_t k = from; k < hyp.size() && hyp[k].time <= r.time + missedAfter; ++k)
            if (hyp[k].left == r.left && hyp[k].right == r.right) {
                best = std::min(best, std::abs(hyp[k].time - r.time));
                found = true;
            }
        score.missed += !found;
        score.errors.push_back(best);
    }
    return score;
}

}  // namespace lipsyncd::dsp
