// Channel normalisation (dsp::SpectrumNormaliser): what the front end can do so a new
// microphone, room or voice looks like the ones it was trained on.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lipsyncd/dsp.hpp>
#include <random>

using namespace lipsyncd;
using namespace lipsyncd::dsp;

namespace {
AnalysisConfig normalised(int bins = 8) {
    AnalysisConfig c;
    c.spectrumBins = bins;
    c.spectrumMean.assign(static_cast<std::size_t>(bins), 0.0f);
    c.meanPriorSeconds = 1;
    c.meanMemorySeconds = 5;
    return c;
}

FrameFeatures frame(std::vector<float> spectrum, float energyDb = -20) {
    FrameFeatures f;
    f.valid = true;
    f.energyDb = energyDb;
    f.spectrum = std::move(spectrum);
    return f;
}

std::vector<float> randomSpectrum(std::mt19937& rng, std::size_t bins) {
    std::normal_distribution<float> n(0, 6);
    std::vector<float> s(bins);
    for (auto& v : s) v = n(rng);
    return s;
}
}  // namespace

TEST(SpectrumNormaliser, TwoChannelsOfTheSameSpeechConvergeOnTheSameSpectra) {
    // The same frames through a plain channel and through one with a steep tilt and a notch:
    // after a few seconds of speech the normalised spectra agree to a fraction of a dB.
    const auto c = normalised();
    SpectrumNormaliser plain(c), coloured(c);
    std::mt19937 rng(3);
    float lastDifference = 0, firstDifference = 0;
    for (int i = 0; i < 2000; ++i) {
        auto a = frame(randomSpectrum(rng, 8));
        auto b = a;
        for (std::size_t k = 0; k < 8; ++k) b.spectrum[k] += -2.0f * k + (k == 5 ? -9.0f : 0.0f);
        plain.apply(a);
        coloured.apply(b);
        float d = 0;
        for (std::size_t k = 0; k < 8; ++k)
            d = std::max(d, std::abs(a.spectrum[k] - b.spectrum[k]));
        if (i == 0) firstDifference = d;
        lastDifference = d;
    }
    EXPECT_GT(firstDifference, 5.0f);
    EXPECT_LT(lastDifference, 0.5f);
}

TEST(SpectrumNormaliser, AShortClipStaysNearThePriorAndPausesDoNotMoveIt) {
    auto c = normalised(4);
    c.spectrumMean = {1, 2, 3, 4};
    c.meanPriorSeconds = 2;
    SpectrumNormaliser n(c);
    // Ten frames of one loud vowel: the prior (200 frames' worth) barely moves.
    for (int i = 0; i < 10; ++i) {
        auto f = frame({11, 12, 13, 14}, -10);
        n.apply(f);
    }
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(n.mean()[k], k + 1.0f, 0.6f);
    // A long pause far below the speech peak is not speech: the mean stays put.
    const std::vector<float> before(n.mean().begin(), n.mean().end());
    for (int i = 0; i < 300; ++i) {
        auto f = frame({-30, -30, -30, -30}, -60);
        n.apply(f);
        EXPECT_FLOAT_EQ(f.spectrum[0], -30 - before[0]);
    }
    for (std::size_t k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(n.mean()[k], before[k]);
}

TEST(SpectrumNormaliser, TheMeanTravelsWithTheTemplatesAndIsValidated) {
    const auto dir = std::filesystem::temp_directory_path();
    TemplateSet t;
    t.analysis = normalised(4);
    t.analysis.spectrumMean = {0.5f, -1.25f, 2, 0};
    t.binWeights = {1, 1, 1, 1};
    t.classes.push_back({"aa", {{0, 0, 0, 0}}, 40});
    const auto path = dir / "lipsyncd_normalised_templates.json";
    t.save(path);
    const auto back = TemplateSet::load(path);
    EXPECT_EQ(back.analysis.spectrumMean, t.analysis.spectrumMean);
    EXPECT_DOUBLE_EQ(back.analysis.meanPriorSeconds, 1);
    EXPECT_DOUBLE_EQ(back.analysis.meanMemorySeconds, 5);

    auto bad = t.analysis;
    bad.spectrumMean = {1, 2, 3};
    try {
        bad.validate();
        FAIL() << "a mean of the wrong length was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("analysis.spectrum_mean"), std::string::npos);
    }
    bad = t.analysis;
    bad.meanMemorySeconds = 0.5;  // less than the prior
    EXPECT_THROW(bad.validate(), InputError);
}
