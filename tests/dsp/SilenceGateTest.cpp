// The energy gate on real recordings: room noise far below the voice is silence even before
// the adaptive noise floor has caught up with it.
#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <random>

using namespace lipsyncd;
using namespace lipsyncd::dsp;

TEST(FrameClassifier, RoomNoiseFarBelowTheVoiceIsSilenceBeforeTheFloorCatchesUp) {
    // A clip that starts with speech: the noise floor has nothing to start from, so the room
    // (36 dB under the voice, at -45 dBFS: above the absolute gate) only the peak-relative gate
    // calls silence.
    const auto& set = PhonemeSet::common();
    const auto templates = TemplateSet::loadDefault();
    auto run = [&](float belowPeakDb) {
        ClassifierConfig config;
        config.silenceBelowPeakDb = belowPeakDb;
        FrameClassifier classifier(templates, set, config);
        FrameAnalyzer analyzer(templates.analysis);
        auto features = analyzer.makeFeatures();
        std::mt19937 rng(5);
        std::normal_distribution<float> noise(0, 1);
        std::vector<float> x(static_cast<std::size_t>(templates.analysis.windowSamples()));
        int silent = 0;
        for (int i = 0; i < 60; ++i) {
            for (std::size_t k = 0; k < x.size(); ++k)  // a -9 dBFS vowel, then a -45 dBFS room
                x[k] = i < 30 ? 0.5f * static_cast<float>(std::sin(0.3 * k)) + 0.05f * noise(rng)
                              : 0.0056f * noise(rng);
            features.time = 0.0125 + 0.01 * i;
            analyzer.analyze(x, features);
            const auto label = classifier.classify(features);
            if (i >= 30) silent += label.silent;
        }
        return silent;
    };
    EXPECT_EQ(run(30), 30);
    EXPECT_EQ(run(0), 0);  // the floor alone (off): the room is taken for speech
}
