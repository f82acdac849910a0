#include <gtest/gtest.h>

#include <cmath>

#include "TestSpeech.hpp"

using namespace lipsyncd;

namespace {
std::vector<float> tone(double hz, int rate, double seconds) {
    std::vector<float> x(static_cast<std::size_t>(rate * seconds));
    for (std::size_t i = 0; i < x.size(); ++i)
        x[i] = 0.5f * static_cast<float>(std::sin(2 * M_PI * hz * i / rate));
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

namespace {
// Feeds 10 ms blocks with one impulse at `impulse`; returns how much input had gone in past the
// impulse when its peak came out (that sample's latency), and the output's peak position.
std::pair<double, double> impulseLatency(dsp::ResamplerQuality quality, std::size_t impulse) {
    const int in = 16000, out = 10000;
    const std::size_t block = 160;
    dsp::StreamResampler r(in, out, quality, 4096);
    std::vector<float> x(in, 0.0f), y;
    x[impulse] = 1.0f;
    double measured = -1;
    for (std::size_t i = 0; i + block <= x.size(); i += block) {
        const auto o = r.process(std::span<const float>(x).subspan(i, block));
        y.insert(y.end(), o.begin(), o.end());
        const auto peak = std::max_element(y.begin(), y.end());
        if (measured < 0 && !y.empty() && *peak > 0.3f &&
            std::size_t(peak - y.begin()) + 4 < y.size())
            measured =
                static_cast<double>(i + block - impulse) / in;  // the peak is past, not at the edge
    }
    return {measured, static_cast<double>(std::max_element(y.begin(), y.end()) - y.begin()) / out};
}
}  // namespace

TEST(StreamResampler, ReportedDelayBoundsTheMeasuredOne) {
    // A sample's wait depends on where it falls in a block (the 10 ms one; for libsoxr, at High,
    // its own processing block too): sweep the impulse across a block and take the longest wait.
    // delaySeconds() must bound it, and not loosely.
    for (auto quality :
         {dsp::ResamplerQuality::Medium, dsp::ResamplerQuality::Low, dsp::ResamplerQuality::High}) {
        const double reported = dsp::StreamResampler(16000, 10000, quality, 4096).delaySeconds();
        double worst = 0;
        for (std::size_t impulse = 8000; impulse < 8000 + 1200; impulse += 37) {
            const auto [latency, peakAt] = impulseLatency(quality, impulse);
            ASSERT_GT(latency, 0);
            worst = std::max(worst, latency);
            if (quality == dsp::ResamplerQuality::Medium) {  // linear phase: output time-aligned
                EXPECT_NEAR(peakAt, impulse / 16000.0, 1.5 / 10000);
            }
        }
        EXPECT_LE(worst, reported + 0.001);
        EXPECT_GE(worst, reported - 0.012) << "reported " << reported;
    }
}

// A whole file may be resampled differently from live input, for speed: libsoxr in larger DFT
// blocks (from 22.05 kHz, or at High quality), the FIR as live (16 kHz, Medium). Either way its
// samples must be the live path's (to float rounding), in number and in time.
TEST(StreamResampler, AWholeFileGivesTheLiveSamples) {
    const auto& speech = test::testSpeech();
    const auto at16k = test::resampleOffline(speech.samples, speech.rate, 16000);
    struct Case {
        const std::vector<float>& x;
        int rate;
        dsp::ResamplerQuality quality;
    };
    for (const auto& [x, rate, quality] :
         {Case{speech.samples, speech.rate, dsp::ResamplerQuality::Medium},
          Case{speech.samples, speech.rate, dsp::ResamplerQuality::High},
          Case{at16k, 16000, dsp::ResamplerQuality::Medium}}) {
        auto run = [&](dsp::ResamplerUse use) {
            dsp::StreamResampler r(rate, 10000, quality, 4096, use);
            std::vector<float> y;
            for (std::size_t i = 0; i < x.size(); i += 4096) {
                const auto n = std::min<std::size_t>(4096, x.size() - i);
                const auto o = r.process(std::span<const float>(x).subspan(i, n));
                y.insert(y.end(), o.begin(), o.end());
            }
            for (auto o = r.process({}, true); !o.empty(); o = r.process({}, true))
                y.insert(y.end(), o.begin(), o.end());
            return std::make_pair(y, r.delaySeconds());
        };
        const auto [live, liveDelay] = run(dsp::ResamplerUse::Live);
        const auto [file, fileDelay] = run(dsp::ResamplerUse::WholeFile);
        SCOPED_TRACE(rate);
        ASSERT_NEAR(static_cast<double>(file.size()), static_cast<double>(live.size()), 1);
        const std::size_t n = std::min(live.size(), file.size());
        if (rate == 16000 || quality == dsp::ResamplerQuality::High) {
            for (std::size_t i = 0; i < n; ++i) ASSERT_NEAR(file[i], live[i], 1e-5f) << i;
        } else {
            // The FIR and libsoxr's medium quality share a passband and a stopband, not the shape
            // of the transition between: the same signal to within 40 dB.
            double signal = 0, error = 0;
            for (std::size_t i = 0; i < n; ++i)
                signal += live[i] * live[i], error += (file[i] - live[i]) * (file[i] - live[i]);
            EXPECT_GT(10 * std::log10(signal / error), 40.0);
        }
        if (rate == 16000)
            EXPECT_EQ(fileDelay, liveDelay);  // the same FIR
        else
            EXPECT_GT(fileDelay,
                      liveDelay);  // what the larger blocks hold back: why live keeps small ones
    }
}
