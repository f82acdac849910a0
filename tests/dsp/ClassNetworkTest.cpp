// The class network (TemplateSet::classNetwork): that it tells apart classes the templates
// cannot, that training is reproducible, that the aligner still weighs the templates alone, and
// its file form and validation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <random>
#include <string>
#include <utility>

#include "ExpectRejected.hpp"
#include "LabelledFrames.hpp"

using namespace lipsyncd;
using namespace lipsyncd::dsp;

namespace {
// Two classes, each heard two ways: "aa" with bins 0 and 1 both high or both low, "ih" with one
// high and the other low. Each class's mean (one template a class) is the same flat spectrum,
// so the templates cannot tell them apart; a network can (an exclusive or).
using Utterance = test::LabelledFrames;

// `shift` moves bins 0 and 1 apart by that much: another voice, whose frames of one class lie
// where the first voice's lay for the other.
Utterance utterance(std::mt19937& rng, int segments = 40, float shift = 0) {
    std::normal_distribution<float> noise(0, 1);
    std::bernoulli_distribution coin;
    return test::aaAndIhInTurn(segments, [&](bool aa, int) {
        const float a = coin(rng) ? 8.0f : -8.0f, b = aa ? a : -a;
        return std::vector<float>{a + shift + noise(rng), b - shift + noise(rng), noise(rng),
                                  noise(rng)};
    });
}

// The spectrum alone, 4 bins, one template a class; no networks until asked for.
TrainingOptions fourBins() {
    TrainingOptions options;
    options.analysis = AnalysisConfig{};
    options.analysis.spectrumBins = 4;
    options.clustersPerClass = 1;
    options.jawHiddenUnits = 0;
    options.classHiddenUnits = 0;
    return options;
}

TemplateSet train(std::mt19937& rng, int hiddenUnits = 8, int utterances = 4) {
    auto options = fourBins();
    options.classHiddenUnits = hiddenUnits;
    options.classEpochs = 20;
    TemplateTrainer trainer(options, PhonemeSet::common());
    for (int i = 0; i < utterances; ++i) {
        const auto u = utterance(rng);
        trainer.addUtterance(u.frames, u.labels);
    }
    return trainer.build("test");
}

// Share of new frames the classifier decides right.
double accuracy(const TemplateSet& t, std::mt19937& rng, float classNetworkDb, float shift = 0) {
    ClassifierConfig config;
    config.classNetworkDb = classNetworkDb;
    return test::shareDecidedRight(t, utterance(rng, 40, shift), config);
}
}  // namespace

TEST(ClassNetwork, TellsApartClassesTheTemplatesCannot) {
    std::mt19937 rng(4);
    const auto t = train(rng);
    ASSERT_TRUE(t.classNetwork.has_value());
    EXPECT_EQ(t.classNetwork->hiddenUnits(), 8u);
    EXPECT_EQ(t.classNetwork->classes, (std::vector<std::string>{"aa", "ih"}));
    const double withNetwork = accuracy(t, rng, 1.0f), templatesAlone = accuracy(t, rng, 0.0f);
    EXPECT_GT(withNetwork, 0.95);
    EXPECT_LT(templatesAlone, 0.75);  // a coin, near enough
}

TEST(ClassNetwork, TrainingIsReproducibleAndTooLittleSpeechTrainsNone) {
    std::mt19937 a(5), b(5), c(5);
    const auto first = train(a), second = train(b);
    ASSERT_TRUE(first.classNetwork && second.classNetwork);
    EXPECT_EQ(first.classNetwork->hiddenWeights, second.classNetwork->hiddenWeights);
    EXPECT_EQ(first.classNetwork->outputWeights, second.classNetwork->outputWeights);
    EXPECT_EQ(first.classNetwork->logPrior, second.classNetwork->logPrior);
    // 800 frames: one voice's quirks, not its classes.
    EXPECT_FALSE(train(c, 8, 1).classNetwork.has_value());
}

TEST(ClassNetwork, FineTuningOnOneVoiceTeachesTheNetworkThatVoice) {
    std::mt19937 rng(6);
    const auto base = train(rng);
    constexpr float kVoice = 10;
    const double before = accuracy(base, rng, 1.0f, kVoice);
    EXPECT_LT(before, 0.75);
    auto options = fourBins();
    options.classHiddenUnits = 8;  // the frames the networks learn from are kept
    TemplateTrainer voice(options, PhonemeSet::common());
    for (int i = 0; i < 2; ++i) {
        const auto u = utterance(rng, 40, kVoice);
        voice.addUtterance(u.frames, u.labels);
    }
    EXPECT_EQ(voice.networkFrames(), 1600u);
    const auto tuned = voice.fineTuneNetworks(base, 20, 3e-3f);
    ASSERT_TRUE(tuned.classNetwork.has_value());
    EXPECT_GT(accuracy(tuned, rng, 1.0f, kVoice), 0.9);
    // From the base's weights, through its standardisation, divided by its priors; the
    // templates as they were.
    EXPECT_EQ(tuned.classNetwork->inputMean, base.classNetwork->inputMean);
    EXPECT_EQ(tuned.classNetwork->logPrior, base.classNetwork->logPrior);
    EXPECT_NE(tuned.classNetwork->outputWeights, base.classNetwork->outputWeights);
    ASSERT_EQ(tuned.classes.size(), base.classes.size());
    for (std::size_t c = 0; c < base.classes.size(); ++c)
        EXPECT_EQ(tuned.classes[c].spectra, base.classes[c].spectra);
    // No pass, no change.
    const auto same = voice.fineTuneNetworks(base, 0, 3e-3f);
    EXPECT_EQ(same.classNetwork->outputWeights, base.classNetwork->outputWeights);
    EXPECT_EQ(same.classNetwork->hiddenWeights, base.classNetwork->hiddenWeights);
}

TEST(ClassNetwork, TheAlignerStillWeighsTheTemplatesAlone) {
    std::mt19937 rng(6);
    const auto t = train(rng);
    ClassifierConfig off;
    off.classNetworkDb = 0;
    FrameClassifier with(t, PhonemeSet::common()), without(t, PhonemeSet::common(), off);
    const auto u = utterance(rng, 4);
    bool differs = false;
    for (const auto& f : u.frames) {
        with.classify(f);
        without.classify(f);
        const auto d = with.distances(), alone = with.templateDistances(),
                   ref = without.distances();
        ASSERT_EQ(d.size(), ref.size());
        for (std::size_t c = 0; c < d.size(); ++c) {
            EXPECT_EQ(alone[c], ref[c]);
            if (std::isfinite(d[c])) {
                EXPECT_GE(d[c], ref[c]);  // the network only ever adds
                differs |= d[c] > ref[c];
            }
        }
    }
    EXPECT_TRUE(differs);
    auto silent = u.frames[3];  // digital silence after speech: nothing to compare, as alone
    silent.valid = false;
    with.classify(silent);
    without.classify(silent);
    for (std::size_t c = 0; c < with.templateDistances().size(); ++c)
        EXPECT_EQ(with.templateDistances()[c], without.distances()[c]) << c;
    auto broken = u.frames[3];  // a NaN in the features reaches no distance through the network
    broken.spectrum[1] = std::nanf("");
    with.classify(broken);
    without.classify(broken);
    for (std::size_t c = 0; c < with.distances().size(); ++c)
        if (std::isfinite(without.distances()[c])) {
            EXPECT_FALSE(std::isnan(with.distances()[c]));
        }
}

// ClassifierConfig::classPriorScale: the posteriors are divided by that power of each class's
// share of the training frames, so at 0 a common class gains on a rare one by the whole ratio of
// their shares and at 1 by nothing, in the distances the decoder weighs.
TEST(ClassNetwork, ThePriorScaleDividesOutThatMuchOfEachClassShare) {
    std::mt19937 rng(5);
    auto t = train(rng);
    const auto aa = PhonemeSet::common().find("aa"), ih = PhonemeSet::common().find("ih");
    ASSERT_TRUE(aa && ih);
    const std::size_t aaOut = t.classNetwork->classes[0] == "aa" ? 0 : 1;
    t.classNetwork->logPrior[aaOut] = std::log(0.9f);  // aa common, ih rare
    t.classNetwork->logPrior[1 - aaOut] = std::log(0.1f);
    const float ratio = std::log(0.9f / 0.1f);
    // How much further off ih lies than aa, in dB, on one frame, at a given prior scale.
    const auto u = utterance(rng, 2);
    auto ihOverAa = [&](float scale) {
        ClassifierConfig config;
        config.classNetworkDb = 1;
        config.classPriorScale = scale;
        FrameClassifier c(t, PhonemeSet::common(), config);
        c.classify(u.frames[3]);
        return c.distances()[*ih] - c.distances()[*aa];
    };
    EXPECT_NEAR(ihOverAa(0) - ihOverAa(1), ratio, 1e-3);
    EXPECT_NEAR(ihOverAa(0.5f) - ihOverAa(1), ratio / 2, 1e-3);
}

TEST(ClassNetwork, TravelsWithTheTemplatesAndIsValidated) {
    std::mt19937 rng(3);
    const auto t = train(rng);
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_class_network.json";
    t.save(path);
    const auto back = TemplateSet::load(path);
    ASSERT_TRUE(back.classNetwork.has_value());
    EXPECT_EQ(back.classNetwork->classes, t.classNetwork->classes);
    const auto u = utterance(rng, 2);
    std::vector<float> a(2), b(2), scratch(8);
    for (std::size_t i = 0; i < u.frames.size(); i += 7) {
        back.classNetwork->scaledLogLikelihoods(u.frames[i].spectrum, a, scratch, 1.0f);
        t.classNetwork->scaledLogLikelihoods(u.frames[i].spectrum, b, scratch, 1.0f);
        EXPECT_NEAR(a[0] - a[1], b[0] - b[1], 1e-2);
    }

    auto bad = t;
    bad.classNetwork->outputWeights[1].pop_back();
    test::expectRejected(bad, "class_network.output_weights[1] has 1 values, expected 2");
    bad = t;
    bad.classNetwork->outputWeights.pop_back();
    test::expectRejected(bad, "class_network.output_weights has 7 values, expected 8");
    bad = t;
    bad.classNetwork->logPrior.pop_back();
    test::expectRejected(bad, "class_network.log_prior has 1 values, expected 2");
    bad = t;
    bad.classNetwork->hiddenWeights[0].push_back(1);
    test::expectRejected(bad, "class_network.hidden_weights[0] has 9 values, expected 8");
    bad = t;
    bad.classNetwork->outputBias[0] = std::numeric_limits<float>::quiet_NaN();
    test::expectRejected(bad, "class_network.output_bias[0]");
    bad = t;
    bad.classNetwork->classes[1] = "xx";
    test::expectRejected(bad, "class_network.classes[1]: 'xx' is not a phoneme class");
    bad = t;
    bad.classNetwork->classes[1] = "aa";
    test::expectRejected(bad, "class_network.classes[1]: 'aa' listed twice");
}

// Both layers are summed eight units or classes at a time: every class's scaled likelihood must
// be exactly the plain sums in order, feature by feature into each unit and unit by unit into
// each class, silent (rectified) units adding nothing and a unit that is not a number counting
// as silent, whatever the numbers of units and classes (fewer than a block, a whole block, and
// blocks that overlap at the end).
TEST(ClassNetwork, EachClassIsTheSumOverItsUnitsWhateverTheBlocks) {
    std::mt19937 rng(11);
    std::normal_distribution<float> value(0, 1);
    const std::size_t features = 5;
    for (const auto& [units, count] :
         {std::pair<std::size_t, std::size_t>{13, 3}, {13, 8}, {13, 22}, {5, 22}, {16, 9}}) {
        ClassNetwork net;
        net.inputMean.assign(features, 0.5f);
        net.inputScale.assign(features, 2.0f);
        net.hiddenWeights.assign(features, std::vector<float>(units));
        for (auto& row : net.hiddenWeights)
            for (auto& w : row) w = value(rng);
        for (std::size_t h = 0; h < units; ++h) net.hiddenBias.push_back(value(rng));
        net.outputWeights.assign(units, std::vector<float>(count));
        for (auto& row : net.outputWeights)
            for (auto& w : row) w = value(rng);
        for (std::size_t c = 0; c < count; ++c) {
            net.outputBias.push_back(value(rng));
            net.logPrior.push_back(-std::abs(value(rng)));
        }
        for (int frame = 0; frame < 20; ++frame) {
            std::vector<float> x(features);
            for (auto& v : x) v = value(rng);
            if (frame == 7) x[2] = std::numeric_limits<float>::quiet_NaN();  // NaN units
            std::vector<float> hidden(units), expected(count), out(count), scratch(units);
            int silent = 0;
            for (std::size_t h = 0; h < units; ++h) {
                hidden[h] = net.hiddenBias[h];
                for (std::size_t i = 0; i < features; ++i)
                    hidden[h] +=
                        net.hiddenWeights[i][h] * ((x[i] - net.inputMean[i]) * net.inputScale[i]);
                silent += !(hidden[h] > 0);
            }
            for (std::size_t c = 0; c < count; ++c) {
                expected[c] = net.outputBias[c] - 0.5f * net.logPrior[c];
                for (std::size_t h = 0; h < units; ++h)
                    if (hidden[h] > 0) expected[c] += net.outputWeights[h][c] * hidden[h];
            }
            net.scaledLogLikelihoods(x, out, scratch, 0.5f);
            for (std::size_t c = 0; c < count; ++c)
                EXPECT_EQ(out[c], expected[c])
                    << count << " classes, frame " << frame << ", class " << c;
            if (frame == 0) {
                EXPECT_GT(silent, 0);  // the rectifier is exercised
            }
        }
    }
}

// A labeller marks what it doubts with confidence 0 (scripts: a class its aligner places badly in
// some recordings); those frames teach neither the templates nor the networks, and everything
// else is learnt as before.
TEST(TemplateTrainer, ASegmentLabelledWithConfidenceZeroTeachesNothing) {
    const auto trainWithBilabials = [](float confidence) {
        std::mt19937 rng(7);
        auto options = fourBins();
        options.jawHiddenUnits = 8;
        options.classHiddenUnits = 8;
        TemplateTrainer trainer(options, PhonemeSet::common());
        for (int i = 0; i < 4; ++i) {
            auto u = utterance(rng);
            double t = u.labels.back().end;
            for (int segment = 0; segment < 10; ++segment, t += 0.2) {
                u.labels.push_back({t, t + 0.2, "bmp", confidence});
                for (int k = 0; k < 20; ++k) {
                    FrameFeatures f = u.frames.back();
                    f.time = t + 0.005 + 0.01 * k;
                    f.spectrum = {20, 20, -20, -20};
                    u.frames.push_back(std::move(f));
                }
            }
            trainer.addUtterance(u.frames, u.labels);
        }
        return trainer.build("test");
    };
    const auto classesOf = [](const TemplateSet& t) {
        std::vector<std::string> names;
        for (const auto& c : t.classes) names.push_back(c.phoneme);
        return names;
    };
    const auto taught = trainWithBilabials(1.0f), doubted = trainWithBilabials(0.0f);
    EXPECT_EQ(classesOf(taught), (std::vector<std::string>{"aa", "ih", "bmp"}));
    ASSERT_TRUE(taught.classNetwork.has_value());
    EXPECT_EQ(taught.classNetwork->classes, (std::vector<std::string>{"aa", "ih", "bmp"}));
    EXPECT_EQ(classesOf(doubted), (std::vector<std::string>{"aa", "ih"}));
    ASSERT_TRUE(doubted.classNetwork.has_value());
    EXPECT_EQ(doubted.classNetwork->classes, (std::vector<std::string>{"aa", "ih"}));
    EXPECT_TRUE(doubted.jawNetwork.has_value());
}
