// The per-frame loops of FrameAnalyzer, one function each, so that bench/frontend_profile can
// time them apart and tests can hold them to the formulas. None allocates.
#pragma once

#include <array>
#include <cstddef>
#include <lipsyncd/dsp.hpp>
#include <span>

namespace lipsyncd::dsp::kernels {

struct FrameLevel {
    float energyDb = -120;  // RMS over the whole window length (missing samples count as 0)
    bool clipped = false;   // more than kClippedShare of the window at full scale
};
// Energy and clipping of the raw frame (before pre-emphasis); `windowLength` samples expected.
FrameLevel measureLevel(std::span<const float> frame, std::size_t windowLength);

// y[i] = (x[i] − α·x[i−1])·w[i] (x[−1] taken as x[0]); y has window.size() samples, zero past
// the end of the frame.
void preEmphasizeAndWindow(std::span<const float> frame, std::span<const float> window, float alpha,
                           float* y);

// r[0..order] of y[0..n) (samples before y[0] count as zeros), lag window applied.
void autocorrelate(const float* y, std::size_t n, int order, std::span<const float> lagWindow,
                   std::array<float, kMaxOrder + 1>& r);

}  // namespace lipsyncd::dsp::kernels
