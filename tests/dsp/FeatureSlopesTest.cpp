// The networks hearing each feature's slope (ClassNetwork::slopeFrames, JawNetwork::slopeFrames,
// FeatureSlopes): the slopes themselves, that training and the classifier take them alike
// (classes, and their jaw heights, told apart only by which way the spectrum moves), and their
// file form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <lipsyncd/dsp.hpp>
#include <random>
#include <string>
#include <vector>

#include "ExpectRejected.hpp"
#include "LabelledFrames.hpp"

using namespace lipsyncd;
using namespace lipsyncd::dsp;

TEST(FeatureSlopes, ARampRisesByItsStepOnceItsFramesHaveCome) {
    FeatureSlopes slopes(4, 3);
    std::vector<float> out(6);
    for (int t = 0; t < 10; ++t) {
        const float x = static_cast<float>(t);
        slopes.push(std::vector<float>{x, 2 * x + 5, -x}, out);
        EXPECT_FLOAT_EQ(out[0], x);  // the frame itself first
        EXPECT_FLOAT_EQ(out[1], 2 * x + 5);
        if (t == 0) {
            EXPECT_FLOAT_EQ(out[3], 0.0f);  // before the first frame: the first
        }
        if (t >= 4) {
            EXPECT_NEAR(out[3], 1.0f, 1e-5);
            EXPECT_NEAR(out[4], 2.0f, 1e-5);
            EXPECT_NEAR(out[5], -1.0f, 1e-5);
        }
    }
    slopes.reset();  // a new input: nothing of the old one's frames
    slopes.push(std::vector<float>{100, 0, 0}, out);
    EXPECT_FLOAT_EQ(out[3], 0.0f);
    // Before the first frame the input holds it: a fall from it is a fall.
    slopes.push(std::vector<float>{90, 0, 0}, out);
    EXPECT_NEAR(out[3], -2.0f, 1e-5);  // positions 0..3 at 100, 4 at 90: (−200 + 180) / 10
}

TEST(FeatureSlopes, ANetworkInputPassesAFrameOfAnotherSizeOnAsItIs) {
    NetworkInput heard(2, 3);
    const std::vector<float> frame{1, 2, 3}, short_{7, 8};
    EXPECT_EQ(heard.push(frame).size(), 6u);  // the frame and its slopes
    const auto passed = heard.push(short_);   // never read past its end
    ASSERT_EQ(passed.size(), 2u);
    EXPECT_EQ(passed.data(), short_.data());
    const auto alone = NetworkInput(0, 3).push(frame);  // no slopes: the frame itself
    EXPECT_EQ(alone.data(), frame.data());
}

namespace {
// "aa" while bin 0 rises from −8 to 8 over 0.2 s, "ih" while it falls back: both classes hold the
// same values, so neither a frame's spectrum nor the templates can tell them apart; which way
// the spectrum moves can.
using Utterance = test::LabelledFrames;

Utterance risingAndFalling(std::mt19937& rng, int segments = 40) {
    std::normal_distribution<float> noise(0, 1);
    return test::aaAndIhInTurn(segments, [&](bool aa, int i) {
        const float ramp = -8.0f + 16.0f * static_cast<float>(i) / 19.0f;
        return std::vector<float>{(aa ? ramp : -ramp) + noise(rng), noise(rng), noise(rng),
                                  noise(rng)};
    });
}

TemplateSet train(std::mt19937& rng, int slopeFrames, int jawSlopeFrames = -1) {
    TrainingOptions options;
    options.analysis = AnalysisConfig{};  // the spectrum alone, 4 bins
    options.analysis.spectrumBins = 4;
    options.clustersPerClass = 1;
    options.jawHiddenUnits = jawSlopeFrames < 0 ? 0 : 8;  // -1: no jaw network
    options.jawEpochs = 60;
    options.jawSlopeFrames = std::max(0, jawSlopeFrames);
    options.classHiddenUnits = 8;
    options.classEpochs = 20;
    options.classSlopeFrames = slopeFrames;
    TemplateTrainer trainer(options, PhonemeSet::common());
    for (int i = 0; i < 4; ++i) {
        const auto u = risingAndFalling(rng);
        trainer.addUtterance(u.frames, u.labels);
    }
    return trainer.build("test");
}

double accuracy(const TemplateSet& t, std::mt19937& rng) {
    return test::shareDecidedRight(t, risingAndFalling(rng));
}

// `t` written to a file of that name and read back.
TemplateSet savedAndLoaded(const TemplateSet& t, const std::string& name) {
    const auto path = std::filesystem::temp_directory_path() / name;
    t.save(path);
    auto back = TemplateSet::load(path);
    std::filesystem::remove(path);
    return back;
}

// How much further the jaw opens for aa than for ih.
float aaAboveIh() {
    const auto& set = PhonemeSet::common();
    return *set[*set.find("aa")].jaw - *set[*set.find("ih")].jaw;
}

// The mean distance of the classifier's jaw from the labelled class's jaw height, over the
// frames of the last 15 of each segment (the first few still hear the turn before them).
double jawError(const TemplateSet& t, std::mt19937& rng) {
    const auto& set = PhonemeSet::common();
    FrameClassifier classifier(t, set);
    const auto u = risingAndFalling(rng);
    double sum = 0;
    int counted = 0;
    for (std::size_t i = 0; i < u.frames.size(); ++i) {
        const float jaw = classifier.classify(u.frames[i]).jaw;
        if (i % 20 < 5) continue;
        const auto& label = u.labels[i / 20];
        sum += std::abs(jaw - *set[*set.find(label.phoneme)].jaw);
        ++counted;
    }
    return sum / counted;
}
}  // namespace

TEST(FeatureSlopes, TheClassNetworkHearsWhichWayTheSpectrumMoves) {
    std::mt19937 rng(7);
    const auto withSlopes = train(rng, 4), frameAlone = train(rng, 0);
    ASSERT_TRUE(withSlopes.classNetwork && frameAlone.classNetwork);
    EXPECT_EQ(withSlopes.classNetwork->slopeFrames, 4);
    EXPECT_EQ(withSlopes.classNetwork->inputMean.size(), 8u);  // the frame and its slopes
    EXPECT_EQ(frameAlone.classNetwork->inputMean.size(), 4u);
    // Past frames only: the first frames after each turn still hear the slope before it.
    EXPECT_GT(accuracy(withSlopes, rng), 0.85);
    EXPECT_LT(accuracy(frameAlone, rng), 0.75);  // a coin, near enough
}

TEST(FeatureSlopes, TravelWithTheNetworkAndAreValidated) {
    std::mt19937 rng(8);
    const auto t = train(rng, 4);
    const auto back = savedAndLoaded(t, "lipsyncd_feature_slopes.json");
    ASSERT_TRUE(back.classNetwork.has_value());
    EXPECT_EQ(back.classNetwork->slopeFrames, 4);
    EXPECT_EQ(fineTuningOptions(back).classSlopeFrames, 4);

    auto bad = t;
    bad.classNetwork->slopeFrames = kMaxSlopeFrames + 1;
    test::expectRejected(bad, "class_network.slope_frames: must be 0 to 16 (17)");
    bad = t;
    bad.classNetwork->slopeFrames = 0;  // its inputs are the slopes' too
    test::expectRejected(bad, "class_network.input_mean has 8 values, expected 4");
}

TEST(FeatureSlopes, FineTuningKeepsTheSlopes) {
    std::mt19937 rng(9);
    const auto t = train(rng, 4);
    TemplateTrainer trainer(fineTuningOptions(t), PhonemeSet::common());
    const auto u = risingAndFalling(rng, 20);
    trainer.addUtterance(u.frames, u.labels);
    const auto tuned = trainer.fineTuneNetworks(t, 2, 1e-3f);
    ASSERT_TRUE(tuned.classNetwork.has_value());
    EXPECT_EQ(tuned.classNetwork->slopeFrames, 4);
    EXPECT_EQ(tuned.classNetwork->inputMean.size(), 8u);
    EXPECT_GT(accuracy(tuned, rng), 0.85);
}

TEST(FeatureSlopes, TheJawNetworkHearsThemToo) {
    std::mt19937 rng(10);
    const float apart = aaAboveIh();
    ASSERT_GT(apart, 0.2f);
    // Alone, as the class network hears them, and as the class network hears the frame alone.
    for (const int classSlopes : {4, 0}) {
        const auto withSlopes = train(rng, classSlopes, 4), frameAlone = train(rng, classSlopes, 0);
        ASSERT_TRUE(withSlopes.jawNetwork && frameAlone.jawNetwork);
        EXPECT_EQ(withSlopes.jawNetwork->slopeFrames, 4);
        EXPECT_EQ(withSlopes.jawNetwork->inputMean.size(), 8u);
        EXPECT_EQ(frameAlone.jawNetwork->inputMean.size(), 4u);
        // The frame alone cannot tell aa's height from ih's: it settles between them.
        EXPECT_LT(jawError(withSlopes, rng), 0.25 * apart) << classSlopes;
        EXPECT_GT(jawError(frameAlone, rng), 0.4 * apart) << classSlopes;
    }
}

TEST(FeatureSlopes, TheClassifiersJawIsTheNetworksOnWhatItHears) {
    std::mt19937 rng(11);
    for (const int classSlopes : {4, 2}) {  // one NetworkInput for both, and one each
        const auto t = train(rng, classSlopes, 4);
        FrameClassifier classifier(t, PhonemeSet::common());
        NetworkInput heard(4, 4);
        const auto u = risingAndFalling(rng, 4);
        for (const auto& f : u.frames)
            EXPECT_FLOAT_EQ(classifier.classify(f).jaw, (*t.jawNetwork)(heard.push(f.spectrum)));
    }
}

TEST(FeatureSlopes, TheJawsTravelWithItAndAreValidated) {
    std::mt19937 rng(12);
    const auto t = train(rng, 0, 4);
    const auto back = savedAndLoaded(t, "lipsyncd_jaw_slopes.json");
    ASSERT_TRUE(back.jawNetwork.has_value());
    EXPECT_EQ(back.jawNetwork->slopeFrames, 4);
    EXPECT_EQ(back.classNetwork->slopeFrames, 0);
    EXPECT_EQ(fineTuningOptions(back).jawSlopeFrames, 4);

    auto bad = t;
    bad.jawNetwork->slopeFrames = -1;
    test::expectRejected(bad, "jaw_network.slope_frames: must be 0 to 16 (-1)");
    bad = t;
    bad.jawNetwork->slopeFrames = 0;
    test::expectRejected(bad, "jaw_network.input_mean has 8 values, expected 4");
}

TEST(FeatureSlopes, FineTuningKeepsTheJawsSlopes) {
    std::mt19937 rng(13);
    const auto t = train(rng, 2, 4);
    TemplateTrainer trainer(fineTuningOptions(t), PhonemeSet::common());
    const auto u = risingAndFalling(rng, 20);
    trainer.addUtterance(u.frames, u.labels);
    const auto tuned = trainer.fineTuneNetworks(t, 2, 1e-3f);
    ASSERT_TRUE(tuned.jawNetwork && tuned.classNetwork);
    EXPECT_EQ(tuned.jawNetwork->slopeFrames, 4);
    EXPECT_EQ(tuned.classNetwork->slopeFrames, 2);
    EXPECT_NE(tuned.jawNetwork->outputWeights, t.jawNetwork->outputWeights);
    EXPECT_LT(jawError(tuned, rng), 0.25 * aaAboveIh());

    // A trainer keeping frames for other networks says so instead of training on the wrong rows.
    auto options = fineTuningOptions(t);
    options.jawSlopeFrames = 0;
    TemplateTrainer other(options, PhonemeSet::common());
    other.addUtterance(u.frames, u.labels);
    EXPECT_THROW(other.fineTuneNetworks(t, 1, 1e-3f), InputError);
}
