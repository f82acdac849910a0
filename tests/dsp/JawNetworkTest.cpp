// The jaw network (TemplateSet::jawNetwork): what it learns, that training is reproducible, its
// file form and validation, and that the classifier's heard jaw comes from it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <random>
#include <string>

#include "ExpectRejected.hpp"

using namespace lipsyncd;
using namespace lipsyncd::dsp;

namespace {
AnalysisConfig fourBins() {
    AnalysisConfig c;
    c.spectrumBins = 4;
    return c;
}

// Frames whose jaw height shows only in how bin 0 stands against bin 1 (as F1 against the bins
// above it), under a loudness that lifts every bin alike; a class per height, labelled in turn.
struct Utterance {
    std::vector<FrameFeatures> frames;
    PhonemeSchedule labels;
};

Utterance utterance(std::mt19937& rng) {
    // Classes of the common set and their jaw heights (config/phonemes/common.toml).
    const std::vector<std::pair<std::string, float>> classes = {
        {"aa", 1.0f}, {"eh", 0.6f}, {"ih", 0.35f}, {"z", 0.05f}, {"bmp", 0.0f}};
    std::normal_distribution<float> loud(0, 6), noise(0, 0.5f);
    Utterance u;
    double t = 0;
    for (int segment = 0; segment < 40; ++segment) {
        const auto& [name, jaw] = classes[static_cast<std::size_t>(segment) % classes.size()];
        u.labels.push_back({t, t + 0.2, name, 1});
        for (int i = 0; i < 20; ++i, t += 0.01) {
            FrameFeatures f;
            f.valid = true;
            f.energyDb = -20;
            f.time = t + 0.005;
            const float l = loud(rng);
            f.spectrum = {l + 12 * jaw + noise(rng), l + noise(rng), l + noise(rng), noise(rng)};
            u.frames.push_back(std::move(f));
        }
    }
    return u;
}

TemplateSet train(std::mt19937& rng, int hiddenUnits = 8) {
    TrainingOptions options;
    options.analysis = fourBins();
    options.clustersPerClass = 1;
    options.jawHiddenUnits = hiddenUnits;
    options.jawEpochs = 150;
    options.classHiddenUnits = 0;  // the distances stay the templates' (ClassNetworkTest)
    TemplateTrainer trainer(options, PhonemeSet::common());
    for (int i = 0; i < 4; ++i) {
        const auto u = utterance(rng);
        trainer.addUtterance(u.frames, u.labels);
    }
    return trainer.build("test");
}

double correlation(const std::vector<double>& x, const std::vector<double>& y) {
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    const double n = static_cast<double>(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        sx += x[i], sy += y[i], sxx += x[i] * x[i], syy += y[i] * y[i], sxy += x[i] * y[i];
    }
    return (n * sxy - sx * sy) / std::sqrt((n * sxx - sx * sx) * (n * syy - sy * sy));
}

// Pearson r of the classifier's heard jaw against each frame's labelled jaw height, on new
// frames of the same kind.
double heardJawR(const TemplateSet& t, std::mt19937& rng) {
    const auto& set = PhonemeSet::common();
    FrameClassifier classifier(t, set);
    const auto u = utterance(rng);
    std::vector<double> heard, truth;
    for (const auto& f : u.frames) {
        heard.push_back(classifier.classify(f).jaw);
        for (const auto& s : u.labels)
            if (f.time >= s.start && f.time < s.end)
                truth.push_back(*set[*set.find(s.phoneme)].jaw);
    }
    return correlation(heard, truth);
}
}  // namespace

TEST(JawNetwork, LearnsTheJawFromWhereItShowsUnderLoudness) {
    std::mt19937 rng(11);
    const auto withNetwork = train(rng);
    ASSERT_TRUE(withNetwork.jawNetwork.has_value());
    EXPECT_EQ(withNetwork.jawNetwork->hiddenUnits(), 8u);
    const auto withoutNetwork = train(rng, 0);
    EXPECT_FALSE(withoutNetwork.jawNetwork.has_value());
    // The loudness moves every bin 6 dB either way, the height only 12 dB across all classes:
    // the network learns bin 0 against bin 1; the class distances, thrown by the loudness, do
    // worse.
    const double network = heardJawR(withNetwork, rng), distances = heardJawR(withoutNetwork, rng);
    std::cout << "heard jaw r: " << network << " (network), " << distances
              << " (class distances)\n";
    EXPECT_GT(network, 0.95);
    EXPECT_GT(network, distances + 0.05);
}

TEST(JawNetwork, TrainingIsReproducible) {
    std::mt19937 a(5), b(5);
    const auto first = train(a), second = train(b);
    ASSERT_TRUE(first.jawNetwork && second.jawNetwork);
    EXPECT_EQ(first.jawNetwork->hiddenWeights, second.jawNetwork->hiddenWeights);
    EXPECT_EQ(first.jawNetwork->outputWeights, second.jawNetwork->outputWeights);
    EXPECT_EQ(first.jawNetwork->outputBias, second.jawNetwork->outputBias);
}

TEST(JawNetwork, TooLittleSpeechTrainsNone) {
    TrainingOptions options;
    options.analysis = fourBins();
    TemplateTrainer trainer(options, PhonemeSet::common());
    std::mt19937 rng(2);
    const auto u = utterance(rng);  // 800 frames: one voice's quirks, not a jaw
    trainer.addUtterance(u.frames, u.labels);
    EXPECT_FALSE(trainer.build("test").jawNetwork.has_value());
}

TEST(JawNetwork, TheClassifierHearsTheJawFromItAndNothingInSilence) {
    std::mt19937 rng(9);
    const auto t = train(rng);
    FrameClassifier classifier(t, PhonemeSet::common());
    const auto u = utterance(rng);
    for (std::size_t i = 0; i < 50; ++i) {
        const auto label = classifier.classify(u.frames[i]);
        ASSERT_FALSE(label.silent);
        EXPECT_FLOAT_EQ(label.jaw, (*t.jawNetwork)(u.frames[i].spectrum));
        EXPECT_GE(label.jaw, 0.0f);
        EXPECT_LE(label.jaw, 1.0f);
    }
    auto quiet = u.frames[50];
    quiet.energyDb = -90;
    EXPECT_EQ(classifier.classify(quiet).jaw, 0.0f);
    auto broken = u.frames[51];  // a NaN in the features never reaches the jaw
    broken.spectrum[0] = std::nanf("");
    const float jaw = classifier.classify(broken).jaw;
    EXPECT_TRUE(std::isfinite(jaw));
}

TEST(JawNetwork, TravelsWithTheTemplatesAndIsValidated) {
    std::mt19937 rng(3);
    const auto t = train(rng);
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_jaw_network.json";
    t.save(path);
    const auto back = TemplateSet::load(path);
    ASSERT_TRUE(back.jawNetwork.has_value());
    const auto u = utterance(rng);
    for (std::size_t i = 0; i < u.frames.size(); i += 37)
        EXPECT_NEAR((*back.jawNetwork)(u.frames[i].spectrum), (*t.jawNetwork)(u.frames[i].spectrum),
                    1e-3);

    auto bad = t;
    bad.jawNetwork->inputMean.pop_back();
    test::expectRejected(bad, "jaw_network.input_mean has 3 values, expected 4");
    bad = t;
    bad.jawNetwork->hiddenWeights[2].push_back(1);
    test::expectRejected(bad, "jaw_network.hidden_weights[2] has 9 values, expected 8");
    bad = t;
    bad.jawNetwork->hiddenWeights.pop_back();
    test::expectRejected(bad, "jaw_network.hidden_weights has 3 values, expected 4");
    bad = t;
    bad.jawNetwork->outputWeights.pop_back();
    test::expectRejected(bad, "jaw_network.output_weights has 7 values, expected 8");
    bad = t;
    bad.jawNetwork->hiddenBias[1] = std::numeric_limits<float>::infinity();
    test::expectRejected(bad, "jaw_network.hidden_bias[1]");
    bad = t;
    bad.jawNetwork->hiddenBias.clear();
    test::expectRejected(bad, "1 to 256 hidden units");
}
