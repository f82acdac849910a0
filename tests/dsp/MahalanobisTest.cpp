// Matching under the full within-class covariance (TrainingOptions::fullCovariance,
// TemplateSet::whitening): what it tells apart that per-bin weights cannot, and its file form.
#include <gtest/gtest.h>

#include <filesystem>
#include <lipsyncd/dsp.hpp>
#include <random>
#include <string>

#include "ExpectRejected.hpp"

using namespace lipsyncd;
using namespace lipsyncd::dsp;

namespace {
AnalysisConfig twoBins() {
    AnalysisConfig c;
    c.spectrumBins = 4;
    return c;
}

// Frames of a class whose first two bins move together by a lot (a loud or soft voice lifts
// neighbouring bins at once) and apart only a little; `mean0` is where the class differs.
std::vector<FrameFeatures> correlatedFrames(float mean0, std::mt19937& rng, int count) {
    std::normal_distribution<float> common(0, 5), own(0, 0.5f);
    std::vector<FrameFeatures> frames;
    for (int i = 0; i < count; ++i) {
        FrameFeatures f;
        f.valid = true;
        f.energyDb = -20;
        f.time = 0.01 * i;
        const float u = common(rng);
        f.spectrum = {mean0 + u + own(rng), u + own(rng), own(rng), own(rng)};
        frames.push_back(std::move(f));
    }
    return frames;
}

TemplateSet train(bool full, std::mt19937& rng) {
    TrainingOptions options;
    options.analysis = twoBins();
    options.clustersPerClass = 1;
    options.fullCovariance = full;
    TemplateTrainer trainer(options, PhonemeSet::common());
    trainer.addSustained(correlatedFrames(0, rng, 2000), "aa");
    trainer.addSustained(correlatedFrames(3, rng, 2000), "ih");
    return trainer.build("test");
}

double accuracy(const TemplateSet& t, std::mt19937& rng) {
    const auto& set = PhonemeSet::common();
    FrameClassifier classifier(t, set);
    int right = 0, all = 0;
    for (const auto& [mean0, name] : {std::pair{0.0f, "aa"}, std::pair{3.0f, "ih"}})
        for (const auto& f : correlatedFrames(mean0, rng, 500)) {
            right += set[classifier.classify(f).phoneme].name == name;
            ++all;
        }
    return static_cast<double>(right) / all;
}
}  // namespace

TEST(Mahalanobis, TellsApartClassesThatDifferAcrossCorrelatedBins) {
    std::mt19937 rng(7);
    const auto diagonal = train(false, rng);
    const auto full = train(true, rng);
    EXPECT_TRUE(diagonal.whitening.empty());
    ASSERT_EQ(full.whitening.size(), 4u);
    // Per-bin weights see bin 0 spread by the shared movement and confuse the classes; the
    // covariance knows bin 0 minus bin 1 is steady and separates them.
    EXPECT_LT(accuracy(diagonal, rng), 0.75);
    EXPECT_GT(accuracy(full, rng), 0.95);
}

TEST(Mahalanobis, TheWhiteningTravelsWithTheTemplatesAndIsValidated) {
    std::mt19937 rng(3);
    const auto t = train(true, rng);
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_whitened_templates.json";
    t.save(path);
    const auto back = TemplateSet::load(path);
    ASSERT_EQ(back.whitening.size(), t.whitening.size());
    for (std::size_t r = 0; r < t.whitening.size(); ++r)
        for (std::size_t c = 0; c < t.whitening.size(); ++c)
            EXPECT_NEAR(back.whitening[r][c], t.whitening[r][c],
                        1e-4 * std::abs(t.whitening[r][c]));
    EXPECT_GT(accuracy(back, rng), 0.95);

    auto bad = t;
    bad.whitening.pop_back();
    test::expectRejected(bad, "whitening has 3 rows");
    bad = t;
    bad.whitening[1][3] = 0.5f;  // above the diagonal
    test::expectRejected(bad, "whitening[1][3]");
    bad = t;
    bad.whitening[2][2] = 0;
    test::expectRejected(bad, "whitening[2][2]");
    bad = t;
    bad.whitening[0].push_back(1);
    test::expectRejected(bad, "whitening[0] has 5 values");
}
