// The template set's class bias (TemplateSet::classBiasDb): dB added to a class's distance in
// what the decoder weighs, not in what the forced aligner weighs; it travels with the set and is
// validated.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <string>
#include <vector>

#include "ExpectRejected.hpp"

using namespace lipsyncd;
using namespace lipsyncd::dsp;

namespace {
// Two classes of four bins, one template each: "aa" high in the low bins, "ih" in the high ones.
TemplateSet twoClasses(bool withNetworks) {
    TrainingOptions options;
    options.analysis = AnalysisConfig{};
    options.analysis.spectrumBins = 4;
    options.clustersPerClass = 1;
    options.jawHiddenUnits = 0;
    options.classHiddenUnits = withNetworks ? 4 : 0;
    TemplateTrainer trainer(options, PhonemeSet::common());
    for (int u = 0; u < 8; ++u) {  // 3,200 frames: enough for a network
        std::vector<FrameFeatures> frames;
        PhonemeSchedule labels;
        double t = 0;
        for (int segment = 0; segment < 20; ++segment) {
            const bool aa = segment % 2 == 0;
            labels.push_back({t, t + 0.2, aa ? "aa" : "ih", 1});
            for (int i = 0; i < 20; ++i, t += 0.01) {
                FrameFeatures f;
                f.valid = true;
                f.energyDb = -20;
                f.time = t + 0.005;
                const float wobble = static_cast<float>((i * 7 + segment * 3 + u) % 5) - 2;
                f.spectrum = aa ? std::vector<float>{20 + wobble, 18, -10, -12}
                                : std::vector<float>{-12, -10, 18 - wobble, 20};
                frames.push_back(std::move(f));
            }
        }
        trainer.addUtterance(frames, labels);
    }
    return trainer.build("test");
}

// An "aa" frame a little way towards "ih".
FrameFeatures aaLeaningToIh() {
    FrameFeatures f;
    f.valid = true;
    f.energyDb = -20;
    f.time = 0.005;
    f.spectrum = {8, 6, 2, 0};
    return f;
}

std::size_t index(const char* name) {
    return *PhonemeSet::common().find(name);
}
}  // namespace

TEST(ClassBias, MovesTheDecodersDistancesAndLeavesTheAlignersAlone) {
    for (const bool withNetworks : {false, true}) {
        SCOPED_TRACE(withNetworks ? "with a class network" : "templates alone");
        const auto plain = twoClasses(withNetworks);
        ASSERT_EQ(plain.classNetwork.has_value(), withNetworks);
        auto biased = plain;
        biased.classBiasDb = {{"aa", 1.5f}, {"ih", -0.25f}};
        FrameClassifier a(plain, PhonemeSet::common()), b(biased, PhonemeSet::common());
        b.classify(aaLeaningToIh());
        EXPECT_EQ(a.classify(aaLeaningToIh()).phoneme, static_cast<int>(index("aa")));
        EXPECT_NEAR(b.distances()[index("aa")] - a.distances()[index("aa")], 1.5f, 1e-4);
        EXPECT_NEAR(b.distances()[index("ih")] - a.distances()[index("ih")], -0.25f, 1e-4);
        for (std::size_t c = 0; c < a.templateDistances().size(); ++c)
            EXPECT_EQ(a.templateDistances()[c], b.templateDistances()[c]) << c;
        // Enough bias decides the frame the other way.
        const float gap = a.distances()[index("ih")] - a.distances()[index("aa")];
        ASSERT_GT(gap, 0);
        biased.classBiasDb = {{"ih", -(gap + 0.5f)}};
        FrameClassifier c(biased, PhonemeSet::common());
        EXPECT_EQ(c.classify(aaLeaningToIh()).phoneme, static_cast<int>(index("ih")));
    }
}

TEST(ClassBias, TravelsWithTheTemplatesAndIsValidated) {
    auto t = twoClasses(false);
    t.classBiasDb = {{"aa", -0.3f}, {"bmp", 0.4567f}};
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_class_bias.json";
    t.save(path);
    const auto back = TemplateSet::load(path);
    ASSERT_EQ(back.classBiasDb.size(), 2u);
    EXPECT_FLOAT_EQ(back.classBiasDb.at("aa"), -0.3f);
    EXPECT_FLOAT_EQ(back.classBiasDb.at("bmp"), 0.457f);  // kept to a thousandth of a dB
    std::filesystem::remove(path);

    auto bad = t;
    bad.classBiasDb["xx"] = 1;
    test::expectRejected(bad, "class_bias_db.xx: 'xx' is not a phoneme class");
    bad = t;
    bad.classBiasDb["aa"] = std::numeric_limits<float>::quiet_NaN();
    test::expectRejected(bad, "class_bias_db.aa: must be a finite dB within ±20");
    bad = t;
    bad.classBiasDb["aa"] = 25;
    test::expectRejected(bad, "class_bias_db.aa: must be a finite dB within ±20");
}
