#include "FrameKernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp::kernels {

namespace {
// A frame with more than this share of samples at full scale is clipped; its spectrum is
// distorted (flattened), so the classifier trusts it less.
constexpr float kClipLevel = 0.999f;
constexpr float kClippedShare = 0.01f;

using Lanes8 = FloatLanes;
using Counts8 = IntLanes;
}  // namespace

// Eight partial sums (sample i into sum i mod 8), one vector of eight lanes.
LIPSYNCD_VECTOR_CLONES FrameLevel measureLevel(std::span<const float> frame, std::size_t n) {
    const std::size_t m = std::min(n, frame.size());
    Lanes8 squares = {};
    Counts8 clipped = {};
    std::size_t i = 0;
    for (; i + 8 <= m; i += 8) {
        Lanes8 x;
        std::memcpy(&x, frame.data() + i, sizeof x);
        squares += x * x;
        clipped -= (x >= kClipLevel) | (x <= -kClipLevel);  // true is −1
    }
    for (std::size_t k = 0; i < m; ++i, ++k) {
        squares[k] += frame[i] * frame[i];
        clipped[k] += std::abs(frame[i]) >= kClipLevel;
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
    if (m > 0) y[0] = (frame[0] - alpha * frame[0]) * window[0];
    for (std::size_t i = 1; i < m; ++i) y[i] = (frame[i] - alpha * frame[i - 1]) * window[i];
    std::fill(y + m, y + n, 0.0f);
}

namespace {
// The longest window the configuration allows: 0.1 s at 48 kHz.
constexpr std::size_t kMaxWindowSamples = 4800;

// Autocorrelation of x[0..n) at lags 0..8·Vectors−1, all lags at once: r[k] = Σ_i x[i]·x[i−k],
// each lag's sum taken in order of i (x[i] = 0 for i < 0). The samples are first copied in
// reverse, so that x[i], x[i−1], ..., x[i−7] is one forward load, not a shuffle; each lag's sum
// is one dependency chain, and the lags' chains run side by side.
template <int Vectors>
LIPSYNCD_VECTOR_CLONES void autocorrelateLags(const float* x, std::size_t n,
                                              std::array<float, kMaxOrder + 1>& r) {
    constexpr int kLags = 8 * Vectors;
    std::array<float, kMaxWindowSamples + kLags> reversed;  // reversed[j] = x[n − 1 − j]
    n = std::min(n, kMaxWindowSamples);
    for (std::size_t j = 0; j < n; ++j) reversed[j] = x[n - 1 - j];
    std::fill_n(reversed.begin() + static_cast<std::ptrdiff_t>(n), kLags, 0.0f);
    Lanes8 acc[Vectors] = {};
    for (std::size_t i = 0; i < n; ++i) {
        const float* past = reversed.data() + (n - 1 - i);  // past[k] == x[i − k]
        for (int v = 0; v < Vectors; ++v) {
            Lanes8 p;
            std::memcpy(&p, past + 8 * v, sizeof p);
            acc[v] += x[i] * p;
        }
    }
    for (int v = 0; v < Vectors; ++v)
        for (int k = 0; k < 8 && 8 * v + k <= kMaxOrder; ++k) r[8 * v + k] = acc[v][k];
}
}  // namespace

void autocorrelate(const float* y, std::size_t n, int order, std::span<const float> lagWindow,
                   std::array<float, kMaxOrder + 1>& r) {
    if (order < 16)
        autocorrelateLags<2>(y, n, r);
    else
        autocorrelateLags<5>(y, n, r);
    for (int lag = 0; lag <= order; ++lag) r[lag] *= lagWindow[lag];
}

}  // namespace lipsyncd::dsp::kernels
