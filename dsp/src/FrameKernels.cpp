#include "FrameKernels.hpp"

#include <algorithm>
#include <cmath>

namespace lipsyncd::dsp::kernels {

namespace {
// A frame with more than this share of samples at full scale is clipped; its spectrum is
// distorted (flattened), so the classifier trusts it less.
constexpr float kClipLevel = 0.999f;
constexpr float kClippedShare = 0.01f;
}  // namespace

// Eight partial sums let the compiler vectorise.
FrameLevel measureLevel(std::span<const float> frame, std::size_t n) {
    const std::size_t m = std::min(n, frame.size());
    std::array<float, 8> squares{};
    std::array<int, 8> clipped{};
    for (std::size_t i = 0; i < m; ++i) {
        squares[i % 8] += frame[i] * frame[i];
        clipped[i % 8] += std::abs(frame[i]) >= kClipLevel;
    }
    double sumSquares = 0;
    int clippedSamples = 0;
    for (int j = 0; j < 8; ++j) sumSquares += squares[j], clippedSamples += clipped[j];
    const double rms = std::sqrt(sumSquares / static_cast<double>(n));
    FrameLevel out;
    out.energyDb = rms > 0 ? std::max(static_cast<float>(20 * std::log10(rms)), -120.0f) : -120.0f;
    out.clipped = clippedSamples > kClippedShare * static_cast<float>(n);
    return out;
}

void preEmphasizeAndWindow(std::span<const float> frame, std::span<const float> window, float alpha,
                           float* y) {
    const std::size_t n = window.size();
    const std::size_t m = std::min(n, frame.size());
    float previous = frame.empty() ? 0.0f : frame[0];
    for (std::size_t i = 0; i < m; ++i) {
        y[i] = (frame[i] - alpha * previous) * window[i];
        previous = frame[i];
    }
    std::fill(y + m, y + n, 0.0f);
}

namespace {
// Autocorrelation of x[0..n) at lags 0..Lags-1, all lags at once: each sample is multiplied by
// the Lags samples before it, an inner loop with no dependency between lags and a fixed trip
// count, which the compiler unrolls and vectorises (x[-Lags+1..-1] must be zeros).
// On x86-64 the loop is also built for AVX2/FMA and picked at load time (8 lanes instead of 4);
// other targets (the ARM boards puppets run on) get their own default vectorisation.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define LIPSYNCD_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LIPSYNCD_VECTOR_CLONES
#endif

template <int Lags>
LIPSYNCD_VECTOR_CLONES void autocorrelateLags(const float* x, std::size_t n,
                                              std::array<float, kMaxOrder + 1>& r) {
    std::array<float, Lags> acc{};
    for (std::size_t i = 0; i < n; ++i) {
        const float* past = x + i - (Lags - 1);  // past[Lags - 1 - lag] == x[i - lag]
        for (int k = 0; k < Lags; ++k) acc[k] += x[i] * past[Lags - 1 - k];
    }
    std::copy(acc.begin(), acc.end(), r.begin());
}
}  // namespace

void autocorrelate(const float* y, std::size_t n, int order, std::span<const float> lagWindow,
                   std::array<float, kMaxOrder + 1>& r) {
    if (order < 16)
        autocorrelateLags<16>(y, n, r);
    else
        autocorrelateLags<kMaxOrder + 1>(y, n, r);
    for (int lag = 0; lag <= order; ++lag) r[lag] *= lagWindow[lag];
}

}  // namespace lipsyncd::dsp::kernels
