#include "TestSpeech.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace lipsyncd;

namespace {
std::vector<float> tone(double hz, int rate, double seconds) {
    std::vector<float> x(static_cast<std::size_t>(rate * seconds));
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.5f * static_cast<float>(std::sin(2 * M_PI * hz * i / rate));
    return x;
}

double rmsDb(const std::vector<float>& x, std::size_t skip) {
    double acc = 0;
    for (std::size_t i = skip; i < x.size() - skip; ++i) acc += x[i] * x[i];
    return 10 * std::log10(acc / (x.size() - 2 * skip) + 1e-30);
}
}  // namespace

TEST(StreamResampler, KeepsAToneInBand) {
    const auto out = test::resampleOffline(tone(1000, 48000, 1.0), 48000, 10000);
    EXPECT_NEAR(static_cast<double>(out.size()), 10000, 5);
    EXPECT_NEAR(rmsDb(out, 500), 20 * std::log10(0.5 / std::sqrt(2.0)), 0.5);
}

TEST(StreamResampler, RemovesAToneAboveTheNewNyquist) {
    const auto out = test::resampleOffline(tone(7000, 48000, 1.0), 48000, 10000);
    EXPECT_LT(rmsDb(out, 500) - 20 * std::log10(0.5 / std::sqrt(2.0)), -40.0);
}

TEST(StreamResampler, ReportedDelayMatchesTheMeasuredOne) {
    // Feed 1 ms blocks with an impulse at 0.1 s; note how much input had gone in when the
    // impulse's peak came out. That lag is the resampler's latency, which delaySeconds() reports.
    const int in = 16000, out = 10000;
    dsp::StreamResampler r(in, out, dsp::ResamplerQuality::Medium, 4096);
    std::vector<float> x(in, 0.0f);
    const std::size_t impulse = in / 10;
    x[impulse] = 1.0f;
    std::vector<float> y;
    double measured = -1;
    for (std::size_t i = 0; i < x.size(); i += 16) {
        const auto o = r.process(std::span<const float>(x).subspan(i, 16));
        y.insert(y.end(), o.begin(), o.end());
        const auto peak = std::max_element(y.begin(), y.end(), [](float a, float b) { return std::abs(a) < std::abs(b); });
        if (measured < 0 && !y.empty() && std::abs(*peak) > 0.3f &&
            std::size_t(peak - y.begin()) + 4 < y.size())  // the peak is past, not at the edge
            measured = static_cast<double>(i + 16 - impulse) / in;
    }
    ASSERT_GT(measured, 0);
    // Output is time-aligned with input: the peak sits where the impulse was.
    const auto peakAt = std::max_element(y.begin(), y.end()) - y.begin();
    EXPECT_NEAR(static_cast<double>(peakAt) / out, 0.1, 1.5 / out);
    // The bound holds, and is not loose: within 15 ms of what the impulse shows (one 10 ms probe block
    // plus detection granularity).
    EXPECT_LE(measured, r.delaySeconds() + 0.002) << "reported " << r.delaySeconds();
    EXPECT_GE(measured, r.delaySeconds() - 0.015) << "reported " << r.delaySeconds();
}
