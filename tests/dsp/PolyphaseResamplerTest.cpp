// The polyphase FIR behind StreamResampler's usual ratios: its response, its timing, and that
// its output does not depend on how the input is cut into blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/dsp.hpp>

#include "../../dsp/src/PolyphaseResampler.hpp"

using namespace lipsyncd;

namespace {
constexpr dsp::LowPassSpec kMedium{70, 0.916, 1.0};

std::vector<float> tone(double hz, int rate, double seconds, double amplitude = 0.5) {
    std::vector<float> x(static_cast<std::size_t>(rate * seconds));
    for (std::size_t i = 0; i < x.size(); ++i)
        x[i] = static_cast<float>(amplitude * std::sin(2 * M_PI * hz * i / rate));
    return x;
}

std::vector<float> resample(dsp::PolyphaseResampler& r, const std::vector<float>& x,
                            std::size_t block) {
    std::vector<float> y;
    for (std::size_t i = 0; i < x.size(); i += block) {
        const auto n = std::min(block, x.size() - i);
        const auto o = r.process(std::span<const float>(x).subspan(i, n), false);
        y.insert(y.end(), o.begin(), o.end());
    }
    const auto o = r.process({}, true);
    y.insert(y.end(), o.begin(), o.end());
    return y;
}

std::vector<float> resample(int from, int to, const std::vector<float>& x,
                            std::size_t block = 4096) {
    auto r = dsp::PolyphaseResampler::create(from, to, kMedium, 4096);
    EXPECT_TRUE(r.has_value()) << from << " -> " << to;
    return r ? resample(*r, x, block) : std::vector<float>{};
}

// RMS level in dB of the middle of y (the ends hold the filter's start and finish).
double rmsDb(const std::vector<float>& y) {
    const std::size_t skip = y.size() / 10;
    double acc = 0;
    for (std::size_t i = skip; i < y.size() - skip; ++i) acc += double(y[i]) * y[i];
    return 10 * std::log10(acc / static_cast<double>(y.size() - 2 * skip) + 1e-30);
}
}  // namespace

TEST(PolyphaseResampler, KeepsTheBandAndItsLengthAtTheUsualRates) {
    const double level = 20 * std::log10(0.5 / std::sqrt(2.0));
    for (const int rate : {8000, 16000, 22050, 32000, 44100, 48000}) {
        SCOPED_TRACE(rate);
        for (const double hz : {200.0, 1000.0, 3500.0}) {
            const auto x = tone(hz, rate, 1.0);
            const auto y = resample(rate, 10000, x);
            // One output per 1/10000 s of input, the last before the input's end.
            EXPECT_EQ(y.size(), static_cast<std::size_t>(std::ceil(x.size() * 10000.0 / rate)));
            EXPECT_NEAR(rmsDb(y), level, 0.05) << hz << " Hz";
        }
    }
}

TEST(PolyphaseResampler, StopsWhatWouldFoldBack) {
    for (const int rate : {16000, 22050, 44100, 48000}) {
        for (const double hz : {5200.0, 5500.0, 7000.0}) {
            const auto y = resample(rate, 10000, tone(hz, rate, 1.0));
            EXPECT_LT(rmsDb(y) - 20 * std::log10(0.5 / std::sqrt(2.0)), -60.0)
                << rate << " Hz input, " << hz << " Hz tone";
        }
    }
}

TEST(PolyphaseResampler, PutsAnImpulseWhereItWas) {
    for (const int rate : {16000, 22050, 48000}) {
        std::vector<float> x(static_cast<std::size_t>(rate), 0.0f);
        const std::size_t at = static_cast<std::size_t>(rate) / 2 + 3;
        x[at] = 1.0f;
        const auto y = resample(rate, 10000, x, 160);
        const auto peak = std::max_element(y.begin(), y.end()) - y.begin();
        EXPECT_NEAR(static_cast<double>(peak) / 10000, static_cast<double>(at) / rate, 0.6 / 10000)
            << rate;
    }
}

// A live path cuts its input into 10 ms blocks, a file into 4096-sample ones, a network stream
// into whatever arrives: the output must be the same samples, bit for bit.
TEST(PolyphaseResampler, GivesTheSameSamplesWhateverTheBlocks) {
    for (const int rate : {16000, 22050}) {
        auto x = tone(440, rate, 0.7);
        for (std::size_t i = 0; i < x.size(); ++i) x[i] += 0.1f * std::sin(0.37f * i * i);
        const auto whole = resample(rate, 10000, x, 4096);
        for (const std::size_t block : {1, 7, 160, 1000}) {
            const auto cut = resample(rate, 10000, x, block);
            ASSERT_EQ(cut.size(), whole.size()) << rate << ", blocks of " << block;
            for (std::size_t i = 0; i < whole.size(); ++i)
                ASSERT_EQ(cut[i], whole[i]) << rate << ", blocks of " << block << ", sample " << i;
        }
    }
}

// A bad sample (a NaN from a broken source) spoils the outputs whose filter covers it, and no
// more: the stream recovers a few ms later.
TEST(PolyphaseResampler, ForgetsABadSampleOnceItsFilterHasPassed) {
    auto x = tone(300, 16000, 0.5);
    x[4000] = std::nanf("");
    const auto y = resample(16000, 10000, x, 160);
    std::size_t bad = 0;
    for (const float v : y) bad += !std::isfinite(v);
    EXPECT_GT(bad, 0u);
    EXPECT_LT(bad, 120u);  // the filter spans 168 input samples: about 105 outputs
    for (std::size_t i = 3000; i < y.size(); ++i) ASSERT_TRUE(std::isfinite(y[i])) << i;
}

TEST(PolyphaseResampler, LeavesOddRatiosToLibsoxr) {
    EXPECT_FALSE(dsp::PolyphaseResampler::create(11025.5, 10000, kMedium, 4096));  // not whole Hz
    EXPECT_FALSE(dsp::PolyphaseResampler::create(10007, 10000, kMedium, 4096));    // 10,000 phases
    // StreamResampler still converts them, through libsoxr.
    for (const double rate : {11025.5, 10007.0}) {
        dsp::StreamResampler r(rate, 10000, dsp::ResamplerQuality::Medium, 8192);
        const auto x = tone(1000, static_cast<int>(rate), 0.5);
        std::size_t made = r.process(x).size();
        for (auto o = r.process({}, true); !o.empty(); o = r.process({}, true)) made += o.size();
        EXPECT_NEAR(static_cast<double>(made), x.size() * 10000.0 / rate, 2) << rate;
    }
}
