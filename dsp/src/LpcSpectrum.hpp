// The LPC log-magnitude envelope, −10·log10 |A(e^jω)|² in dB, on a uniform grid
// ω_m = π·m / bins (Lewis: "evaluating the magnitude of 1/A(z) at points on the upper half of
// the unit circle ... effectively a DFT of the zero-extended coefficient sequence").
// Two ways: direct evaluation with cached cos/sin tables, or a zero-padded FFT; bench/ measures
// which is faster at a given order. Direct evaluation can also read the envelope on a warped grid,
// ω_m = min(π, warp·π·m / bins): a vocal-tract-length warp (AnalysisConfig::warp; Lee & Rose
// 1996).
#pragma once

#include <span>
#include <vector>

namespace lipsyncd::dsp {

class DirectLpcSpectrum {
  public:
    DirectLpcSpectrum(int order, int bins, double warp = 1.0);
    void evaluate(std::span<const float> a, std::span<float> outDb);

  private:
    int order_, bins_;
    std::vector<float> cos_, sin_;  // [i * bins + m]
    std::vector<float> re_, im_;    // per bin, reused
};

class FftLpcSpectrum {
  public:
    explicit FftLpcSpectrum(int bins);  // bins must be a power of two
    void evaluate(std::span<const float> a, std::span<float> outDb);

  private:
    int bins_, size_;
    std::vector<float> re_, im_, twiddleRe_, twiddleIm_;
    std::vector<int> bitReverse_;
};

}  // namespace lipsyncd::dsp
