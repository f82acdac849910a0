// Least-squares slopes over the newest frames (Furui 1986: the regression coefficients of each
// feature over a few frames). Over positions j = 0..n, the newest at n, the slope is
// Σ (j − n/2)·x_j / Σ (j − n/2)².
#include <algorithm>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

FeatureSlopes::FeatureSlopes(int frames, std::size_t features)
    : frames_(static_cast<std::size_t>(std::max(1, frames))),
      features_(features),
      past_(frames_ * features) {
    const double centre = 0.5 * static_cast<double>(frames_);
    double norm = 0;
    for (std::size_t j = 0; j <= frames_; ++j) {
        weights_.push_back(static_cast<float>(static_cast<double>(j) - centre));
        norm += (static_cast<double>(j) - centre) * (static_cast<double>(j) - centre);
    }
    for (auto& w : weights_) w = static_cast<float>(w / norm);
}

void FeatureSlopes::push(std::span<const float> frame, std::span<float> out) {
    for (std::size_t b = 0; b < features_; ++b) {
        out[b] = frame[b];
        out[features_ + b] = weights_[frames_] * frame[b];
    }
    for (std::size_t age = 1; age <= frames_; ++age) {  // position frames_ − age
        const float w = weights_[frames_ - age];
        // Before the input's first frame: the first (still held, as fewer than frames_ came).
        const std::size_t at = std::min(age, seen_);
        const float* x = at == 0 ? frame.data() : &past_[((seen_ - at) % frames_) * features_];
        for (std::size_t b = 0; b < features_; ++b) out[features_ + b] += w * x[b];
    }
    std::copy(frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(features_),
              past_.begin() + static_cast<std::ptrdiff_t>((seen_ % frames_) * features_));
    ++seen_;
}

NetworkInput::NetworkInput(int slopeFrames, std::size_t features) {
    if (slopeFrames <= 0) return;
    slopes_ = FeatureSlopes(slopeFrames, features);
    input_.assign(networkInputs(features, slopeFrames), 0.0f);
}

std::span<const float> NetworkInput::push(std::span<const float> frame) {
    // A frame of another size (not the analysis's) is passed on as it is, never read past its
    // end; the network reads no further than its shorter input (network::hiddenSums).
    if (input_.empty() || 2 * frame.size() != input_.size()) return frame;
    slopes_.push(frame, input_);
    return input_;
}

}  // namespace lipsyncd::dsp
