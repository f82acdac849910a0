#include "LpcSpectrum.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
// |A|² below this would be a pole on the unit circle; keeps the log finite (+100 dB cap).
constexpr float kMinPower = 1e-10f;

float toDb(float re, float im) {
    return -10.0f * std::log10(std::max(re * re + im * im, kMinPower));
}

// −10·log10 p for finite p ≥ kMinPower, eight bins at a time (libm's log10f is a call per bin,
// and was most of this stage's time). p = m·2^e with m in [√½, √2), and ln m = 2·atanh(s),
// s = (m − 1)/(m + 1), |s| ≤ 0.172: the series to s⁹ leaves under 1e-9, so the result matches
// log10f to float rounding (a few 1e-6 dB). Every lane is computed alike, so a bin's level does
// not depend on its position.
[[gnu::always_inline]] inline void powerToDb(const FloatLanes& p, FloatLanes& db) {
    IntLanes bits;
    std::memcpy(&bits, &p, sizeof bits);
    IntLanes e = (bits >> 23) - 127;  // p > 0: the sign bit is clear
    const IntLanes mantissa = (bits & 0x007fffff) | 0x3f800000;
    FloatLanes m;
    std::memcpy(&m, &mantissa, sizeof m);
    const IntLanes high = m > std::numbers::sqrt2_v<float>;  // −1 where true
    m = high ? 0.5f * m : m;
    e -= high;
    const FloatLanes s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
    const FloatLanes lnM =
        2.0f * s * (1.0f + s2 * (1.0f / 3 + s2 * (1.0f / 5 + s2 * (1.0f / 7 + s2 * (1.0f / 9)))));
    const FloatLanes ln = __builtin_convertvector(e, FloatLanes) * std::numbers::ln2_v<float> + lnM;
    db = (-10.0f / std::numbers::ln10_v<float>)*ln;
}

// The bins' levels in dB: the vector form, but libm's for a bin whose power is not finite (NaN or
// overflow), as it treats those.
LIPSYNCD_VECTOR_CLONES void binsToDb(const float* re, const float* im, int bins, float* outDb) {
    const auto n = static_cast<std::size_t>(bins);
    for (std::size_t first = 0; first < n; first += kVectorLanes) {
        FloatLanes power, p;
        for (std::size_t l = 0; l < kVectorLanes; ++l) {
            const std::size_t m = std::min(first + l, n - 1);
            power[l] = re[m] * re[m] + im[m] * im[m];
            p[l] = std::min(std::max(power[l], kMinPower), std::numeric_limits<float>::max());
        }
        FloatLanes db;
        powerToDb(p, db);
        for (std::size_t l = 0; l < kVectorLanes && first + l < n; ++l) {
            const std::size_t m = first + l;
            outDb[m] = std::isfinite(power[l]) ? db[l] : toDb(re[m], im[m]);
        }
    }
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
    binsToDb(re, im, bins_, outDb.data());
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
    binsToDb(re_.data(), im_.data(), bins_, outDb.data());
}

}  // namespace lipsyncd::dsp
