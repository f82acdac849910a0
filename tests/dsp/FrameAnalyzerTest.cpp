#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <lipsyncd/dsp.hpp>
#include <numbers>
#include <random>

#include "../../dsp/src/LpcSpectrum.hpp"

using namespace lipsyncd::dsp;

namespace {
std::vector<float> sine(double hz, int rate, int n, float amplitude = 0.5f) {
    std::vector<float> x(n);
    for (int i = 0; i < n; ++i)
        x[i] = amplitude * static_cast<float>(std::sin(2 * M_PI * hz * i / rate));
    return x;
}
}  // namespace

TEST(FrameAnalyzer, SpectrumPeaksAtAToneFrequency) {
    AnalysisConfig c;
    FrameAnalyzer analyzer(c);
    auto f = analyzer.makeFeatures();
    std::mt19937 rng(1);
    std::normal_distribution<float> noise(0, 0.01f);
    auto x = sine(1500, c.analysisRate, c.windowSamples());
    for (auto& v : x) v += noise(rng);
    analyzer.analyze(x, f);
    ASSERT_TRUE(f.valid);
    const auto peak = std::max_element(f.spectrum.begin(), f.spectrum.end()) - f.spectrum.begin();
    const double peakHz = 5000.0 * peak / c.spectrumBins;
    EXPECT_NEAR(peakHz, 1500, 5000.0 / c.spectrumBins);
    EXPECT_NEAR(f.energyDb, 20 * std::log10(0.5 / std::sqrt(2.0)), 0.5);
}

TEST(FrameAnalyzer, SilenceAndClippingAreMarkedNotCrashed) {
    AnalysisConfig c;
    FrameAnalyzer analyzer(c);
    auto f = analyzer.makeFeatures();
    const std::vector<float> silence(c.windowSamples(), 0.0f);
    analyzer.analyze(silence, f);
    EXPECT_FALSE(f.valid);
    for (float v : f.spectrum) EXPECT_EQ(v, 0.0f);
    auto square = sine(200, c.analysisRate, c.windowSamples(), 4.0f);
    for (auto& v : square) v = std::clamp(v, -1.0f, 1.0f);
    analyzer.analyze(square, f);
    EXPECT_TRUE(f.clipped);
    for (float v : f.spectrum) EXPECT_TRUE(std::isfinite(v));
}

TEST(LpcSpectrum, DirectAndFftEvaluationAgree) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.5f, 0.5f);
    DirectLpcSpectrum direct(12, 32);
    FftLpcSpectrum fft(32);
    std::vector<float> a(13), d(32), f(32);
    for (int trial = 0; trial < 10; ++trial) {
        a[0] = 1;
        for (int i = 1; i < 13; ++i) a[i] = u(rng) / i;
        direct.evaluate(a, d);
        fft.evaluate(a, f);
        for (int m = 0; m < 32; ++m) EXPECT_NEAR(d[m], f[m], 1e-3) << m;
    }
}

// The envelope's levels are taken eight bins at a time by a series, not libm's log10f: they must
// still be −10·log10 |A(e^jω)|² to well under the spectra's own precision, in every bin of a grid
// that is not a multiple of eight, up to the +100 dB cap at a pole on the unit circle.
TEST(LpcSpectrum, LevelsAreTheEnvelopeInDbToAHundredthOfAMillibel) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-0.9f, 0.9f);
    for (const int bins : {32, 20}) {
        DirectLpcSpectrum direct(12, bins);
        std::vector<float> a(13), db(static_cast<std::size_t>(bins));
        for (int trial = 0; trial < 50; ++trial) {
            a[0] = 1;
            for (int i = 1; i < 13; ++i) a[i] = u(rng) * static_cast<float>(trial % 5 + 1) / i;
            direct.evaluate(a, db);
            for (int m = 0; m < bins; ++m) {
                std::complex<double> sum = 0;
                for (int i = 0; i < 13; ++i)
                    sum += static_cast<double>(a[i]) *
                           std::polar(1.0, -std::numbers::pi * m * i / bins);
                const double want = -10 * std::log10(std::max(std::norm(sum), 1e-10));
                EXPECT_NEAR(db[m], want, 1e-3 + 1e-5 * std::abs(want))
                    << bins << " bins, bin " << m;
            }
        }
    }
    // A zero of A on the grid (a = 1, −1: ω = 0) is the cap, not infinity.
    DirectLpcSpectrum two(1, 8);
    std::vector<float> db(8);
    two.evaluate(std::vector<float>{1.0f, -1.0f}, db);
    EXPECT_NEAR(db[0], 100.0f, 1e-3);
}

// A warp reads the envelope at warp times each bin's frequency: a resonance at f shows in the
// bin of f / warp, and warp 1 is the grid as it was.
TEST(LpcSpectrum, AWarpMovesAResonanceToItsWarpedBin) {
    const int bins = 32;
    const double f = 0.3;  // of the band: bin 9.6 unwarped
    const double r = 0.97, w = std::numbers::pi * f;
    const std::vector<float> a = {1.0f, static_cast<float>(-2 * r * std::cos(w)),
                                  static_cast<float>(r * r)};
    auto peakBin = [&](double warp) {
        DirectLpcSpectrum spectrum(2, bins, warp);
        std::vector<float> db(bins);
        spectrum.evaluate(a, db);
        return static_cast<int>(std::max_element(db.begin(), db.end()) - db.begin());
    };
    EXPECT_EQ(peakBin(1.0), 10);
    EXPECT_EQ(peakBin(0.8), 12);  // 9.6 / 0.8
    EXPECT_EQ(peakBin(1.2), 8);   // 9.6 / 1.2
    DirectLpcSpectrum plain(2, bins), none(2, bins, 1.0);
    std::vector<float> x(bins), y(bins);
    plain.evaluate(a, x);
    none.evaluate(a, y);
    EXPECT_EQ(x, y);
}

TEST(AnalysisConfig, AWarpIsBoundedAndNeedsDirectEvaluation) {
    auto errorOf = [](AnalysisConfig c) {
        try {
            c.validate();
        } catch (const lipsyncd::InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    AnalysisConfig c;
    c.warp = 0.9;
    EXPECT_EQ(errorOf(c), "");
    c.warp = 1.6;
    EXPECT_NE(errorOf(c).find("analysis.warp: must be 0.7..1.4"), std::string::npos);
    c.warp = std::nan("");
    EXPECT_NE(errorOf(c).find("analysis.warp"), std::string::npos);
    c.warp = 0.9;
    c.spectrumByFft = true;
    EXPECT_NE(errorOf(c).find("analysis.warp: needs direct evaluation"), std::string::npos);
}

TEST(AnalysisConfig, RejectsNonsenseNamingTheField) {
    AnalysisConfig c;
    c.order = 40;
    try {
        c.validate();
        FAIL();
    } catch (const lipsyncd::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("analysis.order"), std::string::npos);
    }
}
