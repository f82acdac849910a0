// A file's second pass takes the distances of templates that did not move from the first pass's
// record (AdaptedDistances): what it gives must be, bit for bit, what a classifier on the moved
// set gives, or the second pass would align differently for being quicker.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <lipsyncd/dsp.hpp>

#include "../../dsp/src/AdaptedDistances.hpp"

namespace lipsyncd::dsp {
namespace {

// Frames near the templates of the set's first classes, each off by a different few dB.
std::vector<FrameFeatures> framesNear(const TemplateSet& set, int count) {
    std::vector<FrameFeatures> out;
    for (int i = 0; i < count; ++i) {
        const auto& cls = set.classes[static_cast<std::size_t>(i) % 4];
        FrameFeatures f;
        f.time = 0.005 + 0.01 * i;
        f.valid = true;
        f.energyDb = -20;
        f.spectrum = cls.spectra[static_cast<std::size_t>(i) % cls.spectra.size()];
        for (std::size_t k = 0; k < f.spectrum.size(); ++k)
            f.spectrum[k] += static_cast<float>((i * 7 + static_cast<int>(k) * 3) % 11) - 5.0f;
        out.push_back(f);
    }
    return out;
}

TEST(AdaptedDistances, TakingUnmovedTemplatesFromTheFirstPassChangesNoDistance) {
    const auto& set = PhonemeSet::common();
    const auto base = TemplateSet::loadDefault();
    const auto frames = framesNear(base, 40);
    // Only the classes of the frames' segments move: most blocks are taken from the record.
    SpeakerAdaptation own(base);
    own.add(frames, {{0.0, 0.2, base.classes[1].phoneme}, {0.2, 0.4, base.classes[2].phoneme}});
    ASSERT_GT(own.frames(), 0u);
    const auto adapted = own.adapted(3);

    FrameClassifier first(base, set), second(adapted, set);
    first.recordBlockDistances();
    AdaptedDistances distances(adapted, base, set);
    for (const auto& frame : frames) {
        first.classify(frame);
        second.classify(frame);
        const auto want = second.templateDistances();
        const auto got = distances(frame, first.blockDistances());
        ASSERT_EQ(got.size(), want.size());
        for (std::size_t c = 0; c < got.size(); ++c)
            EXPECT_EQ(got[c], want[c]) << "class " << c << " at " << frame.time << " s";
    }
}

TEST(AdaptedDistances, SomeBlocksAreTakenAndSomeMeasuredAgain) {
    const auto& set = PhonemeSet::common();
    const auto base = TemplateSet::loadDefault();
    SpeakerAdaptation own(base);
    own.add(framesNear(base, 40), {{0.0, 0.4, base.classes[1].phoneme}});
    const auto same = TemplateMatrix(own.adapted(3), set).sameBlocks(TemplateMatrix(base, set));
    const auto taken = std::count(same.begin(), same.end(), 1);
    EXPECT_GT(taken, 0);
    EXPECT_LT(taken, static_cast<std::ptrdiff_t>(same.size()));
}

TEST(AdaptedDistances, AFrameWithoutASpectrumIsFarFromEveryClass) {
    const auto& set = PhonemeSet::common();
    const auto base = TemplateSet::loadDefault();
    AdaptedDistances distances(base, base, set);
    FrameFeatures silent;  // not valid: digital silence
    const std::vector<float> record(TemplateMatrix(base, set).blocks(), 0.0f);
    for (const float d : distances(silent, record))
        EXPECT_EQ(d, std::numeric_limits<float>::infinity());
}

}  // namespace
}  // namespace lipsyncd::dsp
