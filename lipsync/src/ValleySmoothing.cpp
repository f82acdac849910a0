// Section 2.2.1, second half: a window of 2·t_w slides along each curve; where two local maxima
// c(t_a), c(t_b) fall inside it, the values between them are replaced by the line between the
// maxima, which "smoothes out the valley between two maxima and therefore helps reduce high
// frequency lip movements". Only valleys are filled: a value above the line stays.
#include <algorithm>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
// A rise followed by no fall: the start of a peak or plateau. Curve ends count when the curve
// falls away from them; zero is never a peak (a resting pose has no valley to fill).
bool isPeak(std::span<const float> c, std::size_t i) {
    if (c[i] <= 0) return false;
    const bool rises = i == 0 ? c.size() > 1 && c[0] > c[1] : c[i] > c[i - 1];
    const bool holds = i + 1 == c.size() || c[i] >= c[i + 1];
    return rises && holds;
}
}  // namespace

void smoothValleys(std::span<float> curve, double rate, double window) {
    const auto span = static_cast<std::size_t>(window * rate + 1e-9);  // 2·t_w in frames
    std::size_t previous = curve.size();  // the last peak seen, none yet
    for (std::size_t i = 0; i < curve.size(); ++i) {
        if (!isPeak(curve, i)) continue;
        if (previous < curve.size() && i - previous <= span) {
            const float a = curve[previous], b = curve[i];
            const auto n = static_cast<float>(i - previous);
            for (std::size_t k = previous + 1; k < i; ++k)
                curve[k] = std::max(curve[k], a + (b - a) * static_cast<float>(k - previous) / n);
        }
        previous = i;
    }
}

}  // namespace lipsyncd::lipsync
