#include "LpcSpectrum.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace lipsyncd::dsp {

namespace {
// |A|² below this would be a pole on the unit circle; keeps the log finite (+100 dB cap).
constexpr float kMinPower = 1e-10f;

float toDb(float re, float im) {
    return -10.0f * std::log10(std::max(re * re + im * im, kMinPower));
}
}  // namespace

DirectLpcSpectrum::DirectLpcSpectrum(int order, int bins, double warp)
    : order_(order), bins_(bins) {
    // Tables by coefficient, then bin: the loop over bins is the inner one and vectorises, and
    // each bin's sums are still taken in order of the coefficients.
    const auto n = static_cast<std::size_t>(bins) * static_cast<std::size_t>(order + 1);
    cos_.resize(n);
    sin_.resize(n);
    for (int m = 0; m < bins; ++m) {
        // Above π/warp (warp > 1) the grid stays at the band's top: nothing is heard there.
        const double w = std::min(std::numbers::pi, warp * std::numbers::pi * m / bins);
        for (int i = 0; i <= order; ++i) {
            cos_[i * bins + m] = static_cast<float>(std::cos(w * i));
            sin_[i * bins + m] = static_cast<float>(std::sin(w * i));
        }
    }
    re_.resize(static_cast<std::size_t>(bins));
    im_.resize(static_cast<std::size_t>(bins));
}

void DirectLpcSpectrum::evaluate(std::span<const float> a, std::span<float> outDb) {
    const int n = order_ + 1;
    std::fill(re_.begin(), re_.end(), 0.0f);
    std::fill(im_.begin(), im_.end(), 0.0f);
    float* re = re_.data();
    float* im = im_.data();
    for (int i = 0; i < n; ++i) {
        const float ai = a[i];
        const float* c = &cos_[i * bins_];
        const float* s = &sin_[i * bins_];
        for (int m = 0; m < bins_; ++m) {
            re[m] += ai * c[m];
            im[m] -= ai * s[m];
        }
    }
    for (int m = 0; m < bins_; ++m) outDb[m] = toDb(re[m], im[m]);
}

FftLpcSpectrum::FftLpcSpectrum(int bins) : bins_(bins), size_(2 * bins) {
    if (bins < 2 || (bins & (bins - 1)) != 0)
        throw std::invalid_argument("FFT spectrum: bins must be a power of two");
    re_.resize(size_);
    im_.resize(size_);
    twiddleRe_.resize(size_ / 2);
    twiddleIm_.resize(size_ / 2);
    for (int i = 0; i < size_ / 2; ++i) {
        twiddleRe_[i] = static_cast<float>(std::cos(2 * std::numbers::pi * i / size_));
        twiddleIm_[i] = static_cast<float>(-std::sin(2 * std::numbers::pi * i / size_));
    }
    int bits = 0;
    while ((1 << bits) < size_) ++bits;
    bitReverse_.resize(size_);
    for (int i = 0; i < size_; ++i) {
        int r = 0;
        for (int b = 0; b < bits; ++b) r |= ((i >> b) & 1) << (bits - 1 - b);
        bitReverse_[i] = r;
    }
}

void FftLpcSpectrum::evaluate(std::span<const float> a, std::span<float> outDb) {
    // Zero-extended coefficients in bit-reversed order, then iterative radix-2 butterflies.
    std::fill(re_.begin(), re_.end(), 0.0f);
    std::fill(im_.begin(), im_.end(), 0.0f);
    const int n = std::min<int>(static_cast<int>(a.size()), size_);
    for (int i = 0; i < n; ++i) re_[bitReverse_[i]] = a[i];
    for (int len = 2; len <= size_; len <<= 1) {
        const int half = len / 2, step = size_ / len;
        for (int start = 0; start < size_; start += len) {
            for (int j = 0; j < half; ++j) {
                const float wr = twiddleRe_[j * step], wi = twiddleIm_[j * step];
                const int p = start + j, q = p + half;
                const float tr = re_[q] * wr - im_[q] * wi;
                const float ti = re_[q] * wi + im_[q] * wr;
                re_[q] = re_[p] - tr;
                im_[q] = im_[p] - ti;
                re_[p] += tr;
                im_[p] += ti;
            }
        }
    }
    for (int m = 0; m < bins_; ++m) outDb[m] = toDb(re_[m], im_[m]);
}

}  // namespace lipsyncd::dsp
