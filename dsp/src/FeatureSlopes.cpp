// Least-squares slopes over the newest frames (Furui 1986: the regression coefficients of each
// feature over a few frames). Over positions j = 0..n, the newest at n, the slope is
// Σ (j − n/2)·x_j / Σ (j − n/2)².
#include <algorithm>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

FeatureSlopes::FeatureSlopes(int frames, std::size_t features)
    : frames_(static_cast<std::size_t>(std::max(1, frames))),
      features_(features),
      past_(frames_ * features) {}

void FeatureSlopes::push(std::span<const float> frame, std::span<float> out) {
    const double centre = 0.5 * static_cast<double>(frames_);
    double norm = 0;
    for (std::size_t j = 0; j <= frames_; ++j) norm += (double(j) - centre) * (double(j) - centre);
    for (std::size_t b = 0; b < features_; ++b) {
        out[b] = frame[b];
        out[features_ + b] = static_cast<float>((static_cast<double>(frames_) - centre) * frame[b]);
    }
    for (std::size_t age = 1; age <= frames_; ++age) {  // position frames_ − age
        const float w = static_cast<float>(static_cast<double>(frames_ - age) - centre);
        // Before the input's first frame: the first (still held, as fewer than frames_ came).
        const std::size_t at = std::min(age, seen_);
        const float* x = at == 0 ? frame.data() : &past_[((seen_ - at) % frames_) * features_];
        for (std::size_t b = 0; b < features_; ++b) out[features_ + b] += w * x[b];
    }
    const auto scale = static_cast<float>(1 / norm);
    for (std::size_t b = 0; b < features_; ++b) out[features_ + b] *= scale;
    std::copy(frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(features_),
              past_.begin() + static_cast<std::ptrdiff_t>((seen_ % frames_) * features_));
    ++seen_;
}

}  // namespace lipsyncd::dsp
