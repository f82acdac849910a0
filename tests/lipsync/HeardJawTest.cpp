// The jaw heard in the audio (lipsync::blendHeardJaw, dsp FrameLabel::jaw): its share of the jaw
// pose, the closure that holds it back, and the pose-set keys that set them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::test {
namespace {

std::filesystem::path poseFile(const std::string& body) {
    // One file per test: ctest runs the tests as separate processes, side by side.
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const auto file = std::filesystem::temp_directory_path() /
                      ("lipsyncd-heard-jaw-" + std::string(test->name()) + ".toml");
    std::ofstream(file) << "name = \"heard\"\n" << body;
    return file;
}

lipsync::PoseSet jawAndLips() {
    return lipsync::PoseSet::load(
        poseFile("[[pose]]\nname = \"jaw\"\nheard_jaw = 0.8\nheard_jaw_aligned = 0.4\n"
                 "heard_jaw_closed_by = \"pbm\"\n"
                 "[[pose]]\nname = \"pbm\"\n"));
}

// Frames at 0, 0.1, 0.2 s: the schedule's jaw and lips, and a heard jaw of `heard` throughout.
PoseTrack track(std::vector<std::pair<float, float>> jawAndPbm) {
    PoseTrack t;
    t.poses = {"jaw", "pbm"};
    for (std::size_t f = 0; f < jawAndPbm.size(); ++f) {
        const float row[] = {jawAndPbm[f].first, jawAndPbm[f].second};
        t.append(0.1 * static_cast<double>(f), row);
    }
    return t;
}

LevelTrack heardThroughout(float heard, std::size_t frames) {
    LevelTrack levels;
    for (std::size_t f = 0; f < frames; ++f) {
        levels.add(0.01 * static_cast<double>(f), -20);
        levels.jaw.push_back(heard);
    }
    levels.rate = 100;
    return levels;
}

TEST(HeardJaw, SetsItsShareOfTheJawAndLeavesTheLipsAlone) {
    const auto poses = jawAndLips();
    auto t = track({{0.5f, 0.0f}, {0.2f, 0.3f}});
    lipsync::blendHeardJaw(poses, heardThroughout(1.0f, 30), t);
    EXPECT_NEAR(t.frame(0)[0], 0.2 * 0.5 + 0.8 * 1.0, 1e-5);
    EXPECT_NEAR(t.frame(1)[0], 0.2 * 0.2 + 0.8 * 1.0 * 0.7, 1e-5);  // the lips partly closed
    EXPECT_FLOAT_EQ(t.frame(1)[1], 0.3f);
}

TEST(HeardJaw, SpeechAlignedOnItsWordsTakesTheAlignedShare) {
    const auto poses = jawAndLips();
    auto analysed = track({{0.5f, 0.0f}}), aligned = analysed;
    auto levels = heardThroughout(1.0f, 30);
    lipsync::blendHeardJaw(poses, levels, analysed);
    levels.aligned = true;  // the schedule's phonemes were aligned on known words: surer
    lipsync::blendHeardJaw(poses, levels, aligned);
    EXPECT_NEAR(analysed.frame(0)[0], 0.2 * 0.5 + 0.8 * 1.0, 1e-5);
    EXPECT_NEAR(aligned.frame(0)[0], 0.6 * 0.5 + 0.4 * 1.0, 1e-5);
    std::vector<float> live = {0.5f, 0.0f};
    lipsync::blendHeardJaw(poses, 1.0, live, lipsync::HeardSpeech::aligned);
    EXPECT_NEAR(live[0], 0.7f, 1e-6f);
}

TEST(HeardJaw, AClosureTheSchedulePlacesStaysClosed) {
    const auto poses = jawAndLips();
    auto t = track({{0.0f, 1.0f}});
    lipsync::blendHeardJaw(poses, heardThroughout(0.9f, 30), t);
    EXPECT_FLOAT_EQ(t.frame(0)[0], 0.0f);
}

TEST(HeardJaw, FromAudioAloneAClosureTheEarHearsOpenIsDoubtedButNotAlignedOrLive) {
    const auto poses = lipsync::PoseSet::load(
        poseFile("[[pose]]\nname = \"jaw\"\nheard_jaw = 0.8\nheard_jaw_aligned = 0.4\n"
                 "heard_jaw_closed_by = \"pbm\"\nheard_jaw_doubts_closure = [0.3, 0.4]\n"
                 "[[pose]]\nname = \"pbm\"\n"));
    const auto blended = [&](float heard, bool aligned) {
        auto t = track({{0.0f, 1.0f}});  // the schedule closes the lips
        auto levels = heardThroughout(heard, 30);
        levels.aligned = aligned;
        lipsync::blendHeardJaw(poses, levels, t);
        return t.frame(0)[0];
    };
    EXPECT_FLOAT_EQ(blended(0.2f, false), 0.0f);                 // heard nearly closed: held
    EXPECT_NEAR(blended(0.35f, false), 0.8 * 0.35 * 0.5, 1e-5);  // half doubted
    EXPECT_NEAR(blended(0.9f, false), 0.8 * 0.9, 1e-5);          // heard open: the ear decides
    EXPECT_FLOAT_EQ(blended(0.9f, true), 0.0f);                  // aligned: the closure is known
    std::vector<float> live = {0.0f, 1.0f};
    lipsync::blendHeardJaw(poses, 0.9, live);  // live: no dips to close the jaw instead
    EXPECT_FLOAT_EQ(live[0], 0.0f);
}

TEST(HeardJaw, NothingChangesWithoutAHeardJaw) {
    const auto poses = jawAndLips();
    auto t = track({{0.5f, 0.0f}, {0.7f, 0.1f}});
    const auto before = t.values;
    auto levels = heardThroughout(1.0f, 30);
    levels.jaw.clear();  // known phonemes (say, align): nothing was heard
    lipsync::blendHeardJaw(poses, levels, t);
    EXPECT_EQ(t.values, before);
}

TEST(HeardJaw, OneFrameOfALiveStreamBlendsAsTheOfflineTrackDoes) {
    const auto poses = jawAndLips();
    std::vector<float> open = {0.5f, 0.0f}, shut = {0.0f, 1.0f}, lost = {0.5f, 0.0f};
    lipsync::blendHeardJaw(poses, 1.0, open);
    lipsync::blendHeardJaw(poses, 1.0, shut);
    lipsync::blendHeardJaw(poses, std::nan(""), lost);  // nothing sensible heard: nothing added
    EXPECT_NEAR(open[0], 0.9f, 1e-6f);
    EXPECT_FLOAT_EQ(shut[0], 0.0f);
    EXPECT_NEAR(lost[0], 0.1f, 1e-6f);
    EXPECT_FLOAT_EQ(open[1], 0.0f);
}

TEST(HeardJaw, APoseSetRejectsABadShareOrAnUnknownClosingPose) {
    for (const std::string body :
         {"[[pose]]\nname = \"jaw\"\nheard_jaw = 1.5\n",
          "[[pose]]\nname = \"jaw\"\nheard_jaw_aligned = -0.1\n",
          "[[pose]]\nname = \"jaw\"\nheard_jaw_closed_by = \"lips\"\n",
          "[[pose]]\nname = \"jaw\"\nheard_jaw_doubts_closure = [0.4, 0.3]\n",
          "[[pose]]\nname = \"jaw\"\nheard_jaw_doubts_closure = [0.3]\n"}) {
        const auto file = poseFile(body);
        try {
            lipsync::PoseSet::load(file);
            ADD_FAILURE() << "accepted: " << body;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(file.string()), std::string::npos) << what;
            EXPECT_NE(what.find("heard_jaw"), std::string::npos) << what;
        }
    }
}

// The front end's side: a frame's heard jaw is its near classes' heights, 0 when silent.
TEST(HeardJaw, TheClassifierHearsTheHeightOfTheNearClasses) {
    const auto& set = PhonemeSet::common();
    dsp::TemplateSet t;
    t.analysis.spectrumBins = 4;
    t.binWeights = {1, 1, 1, 1};
    t.classes.push_back({"aa", {{10, 0, 0, 0}}, 40});   // jaw 1.0
    t.classes.push_back({"bmp", {{0, 10, 0, 0}}, 40});  // jaw 0
    dsp::ClassifierConfig config;
    config.jawSpreadDb = 0.5f;
    dsp::FrameClassifier classifier(t, set, config);
    const auto frame = [](std::vector<float> spectrum, float db) {
        dsp::FrameFeatures f;
        f.valid = true;
        f.energyDb = db;
        f.spectrum = std::move(spectrum);
        return f;
    };
    EXPECT_NEAR(classifier.classify(frame({10, 0, 0, 0}, -20)).jaw, 1.0f, 1e-3f);
    EXPECT_NEAR(classifier.classify(frame({0, 10, 0, 0}, -20)).jaw, 0.0f, 1e-3f);
    EXPECT_NEAR(classifier.classify(frame({5, 5, 0, 0}, -20)).jaw, 0.5f, 1e-3f);  // torn
    EXPECT_EQ(classifier.classify(frame({10, 0, 0, 0}, -90)).jaw, 0.0f);          // silent
}

}  // namespace
}  // namespace lipsyncd::test
