// A speaker's own class means (SpeakerAdaptation): the MAP estimate of each template from the
// frames of its class nearest to it, and what it must leave alone.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {
namespace {

// Two features; class "ah" with templates at (0, 0) and (10, 10), class "d" with one at (-5, 5).
TemplateSet twoClasses() {
    TemplateSet t;
    t.analysis.spectrumBins = 2;
    t.binWeights = {1, 1};
    t.classes = {{"ah", {{0, 0}, {10, 10}}, 100}, {"d", {{-5, 5}}, 100}};
    return t;
}

FrameFeatures frame(double time, float a, float b) {
    FrameFeatures f;
    f.time = time;
    f.valid = true;
    f.spectrum = {a, b};
    return f;
}

// Frames every 10 ms from 0.005 s, each at `value`.
std::vector<FrameFeatures> frames(int count, float a, float b) {
    std::vector<FrameFeatures> out;
    for (int i = 0; i < count; ++i) out.push_back(frame(0.005 + 0.01 * i, a, b));
    return out;
}

// `voice` refuses to load `file`, saying the file and `named` (the field at fault).
void expectRefused(SpeakerAdaptation& voice, const std::filesystem::path& file,
                   const std::string& named) {
    try {
        voice.load(file);
        ADD_FAILURE() << "loaded " << file << " despite its " << named;
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
}

TEST(SpeakerAdaptation, EachTemplateMovesTowardItsNearestFramesByTheirShareOfThePrior) {
    SpeakerAdaptation adaptation(twoClasses());
    // Six frames of "ah" near its second template; the first and last are edge frames.
    adaptation.add(frames(6, 12, 8), {{0.0, 0.06, "ah"}});
    EXPECT_EQ(adaptation.frames(), 4u);
    const auto moved = adaptation.adapted(4);
    // (τ·t + Σx) / (τ + n) with τ = 4, n = 4: halfway from (10, 10) to (12, 8).
    EXPECT_FLOAT_EQ(moved.classes[0].spectra[1][0], 11.0f);
    EXPECT_FLOAT_EQ(moved.classes[0].spectra[1][1], 9.0f);
    // The template no frame was nearest to, and the class not heard, stay.
    EXPECT_EQ(moved.classes[0].spectra[0], (std::vector<float>{0, 0}));
    EXPECT_EQ(moved.classes[1].spectra[0], (std::vector<float>{-5, 5}));
    // No prior: the frames' own mean. A prior far larger than the frames: the base.
    EXPECT_FLOAT_EQ(adaptation.adapted(0).classes[0].spectra[1][0], 12.0f);
    EXPECT_NEAR(adaptation.adapted(1e6f).classes[0].spectra[1][0], 10.0f, 1e-4);
}

TEST(SpeakerAdaptation, SilenceQuietFramesInvalidFramesAndShortSegmentsTeachNothing) {
    SpeakerAdaptation adaptation(twoClasses());
    auto f = frames(12, 12, 8);
    f[3].valid = false;  // digital silence
    const std::vector<std::uint8_t> silent = {0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0};  // a closure
    adaptation.add(f,
                   {{0.0, 0.06, "ah"},     // frames 0..5: 1..4 inside, 2 quiet, 3 invalid
                    {0.06, 0.08, "d"},     // two frames: both edges
                    {0.08, 0.12, "sil"}},  // silence is not a class to learn
                   silent);
    EXPECT_EQ(adaptation.frames(), 2u);  // frames 1 and 4
    EXPECT_EQ(adaptation.adapted(0).classes[1].spectra[0], (std::vector<float>{-5, 5}));
}

TEST(SpeakerAdaptation, FramesAreAssignedAgainstTheBaseSoOrderDoesNotMatter) {
    const auto a1 = frames(5, 6, 6), a2 = frames(5, 4, 4);  // nearer (10, 10), nearer (0, 0)
    SpeakerAdaptation one(twoClasses()), other(twoClasses());
    one.add(a1, {{0.0, 0.05, "ah"}});
    one.add(a2, {{0.0, 0.05, "ah"}});
    other.add(a2, {{0.0, 0.05, "ah"}});
    other.add(a1, {{0.0, 0.05, "ah"}});
    EXPECT_EQ(one.adapted(2).classes[0].spectra, other.adapted(2).classes[0].spectra);
    // Merging another's frames is the same as hearing them.
    SpeakerAdaptation first(twoClasses()), second(twoClasses());
    first.add(a1, {{0.0, 0.05, "ah"}});
    second.add(a2, {{0.0, 0.05, "ah"}});
    first.add(second);
    EXPECT_EQ(first.frames(), one.frames());
    EXPECT_EQ(first.adapted(2).classes[0].spectra, one.adapted(2).classes[0].spectra);
}

// lipsyncd's speaker_file: what was learnt comes back after a restart, but only onto the base
// set it was learnt on, and a broken file names its field and changes nothing.
TEST(SpeakerAdaptation, WhatWasLearntIsKeptInAFileAcrossRuns) {
    const auto file = std::filesystem::temp_directory_path() / "lipsyncd_speaker.json";
    SpeakerAdaptation learnt(twoClasses());
    learnt.add(frames(6, 12, 8), {{0.0, 0.06, "ah"}});
    learnt.add(frames(6, -4, 6), {{0.0, 0.06, "d"}});
    learnt.save(file);
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(file) += ".tmp"));
    SpeakerAdaptation restarted(twoClasses());
    restarted.load(file);
    EXPECT_EQ(restarted.frames(), learnt.frames());
    EXPECT_EQ(restarted.adapted(3).classes[0].spectra, learnt.adapted(3).classes[0].spectra);
    EXPECT_EQ(restarted.adapted(3).classes[1].spectra, learnt.adapted(3).classes[1].spectra);

    auto other = twoClasses();
    other.classes[1].spectra[0] = {-6, 5};
    SpeakerAdaptation elsewhere(other);
    expectRefused(elsewhere, file, "'base'");  // a voice learnt on other templates
    EXPECT_EQ(elsewhere.frames(), 0u);

    std::string text;
    {
        std::ifstream in(file);
        std::getline(in, text);
    }
    text.replace(text.find("\"sum\":["), 7, "\"sum\":[1,");  // one number too many
    std::ofstream(file) << text;
    expectRefused(restarted, file, "heard[0].sum");
    EXPECT_EQ(restarted.frames(), learnt.frames());  // what it had stays
    std::filesystem::remove(file);
}

// Four features (the fewest an analysis has), "ah" and "d" one template each, and small
// networks over them: two hidden units, each seeing one of the first two features; the class
// network over "ah" and "d" calls the first feature high "ah", the second "d".
TemplateSet withNetworks() {
    TemplateSet t;
    t.analysis.spectrumBins = 4;
    t.binWeights = {1, 1, 1, 1};
    t.classes = {{"ah", {{10, 0, 0, 0}}, 100}, {"d", {{0, 10, 0, 0}}, 100}};
    ClassNetwork c;
    c.classes = {"ah", "d"};
    c.inputMean = {0, 0, 0, 0};
    c.inputScale = {0.1f, 0.1f, 1, 1};
    c.hiddenWeights = {{1, 0}, {0, 1}, {0, 0}, {0, 0}};
    c.hiddenBias = {0, 0};
    c.outputWeights = {{0.5f, -0.5f}, {-0.5f, 0.5f}};
    c.outputBias = {0, 0};
    c.logPrior = {-0.7f, -0.7f};
    t.classNetwork = c;
    JawNetwork j;
    j.inputMean = c.inputMean;
    j.inputScale = c.inputScale;
    j.hiddenWeights = c.hiddenWeights;
    j.hiddenBias = {0, 0};
    j.outputWeights = {0.2f, -0.2f};
    t.jawNetwork = j;
    return t;
}

// Frames every 10 ms from 0.005 s, each at (a, b, 0, 0).
std::vector<FrameFeatures> fourFeatureFrames(int count, float a, float b) {
    auto out = frames(count, a, b);
    for (auto& f : out) f.spectrum.insert(f.spectrum.end(), {0.0f, 0.0f});
    return out;
}

// ln p(ah | x) − ln p(d | x) from the class network of `t`.
float ahOverD(const TemplateSet& t, float a, float b) {
    std::vector<float> out(2), scratch(2);
    t.classNetwork->scaledLogLikelihoods(std::vector<float>{a, b, 0, 0}, out, scratch, 0.0f);
    return out[0] - out[1];
}

// A show's voice trains the networks further line by line (learnNetworks); adapted() carries
// them, the speaker file keeps them, and a file whose networks are not the base's is refused.
TEST(SpeakerAdaptation, LearningNetworksTrainsThemFurtherOnEachLineAndKeepsThemInTheFile) {
    const auto base = withNetworks();
    // "ah" heard where the base network leans to "d" (the second feature high).
    const auto line = fourFeatureFrames(60, 2, 12);
    const PhonemeSchedule labels = {{0.0, 0.6, "ah"}};
    SpeakerAdaptation templatesOnly(base);
    templatesOnly.add(line, labels);
    EXPECT_EQ(templatesOnly.adapted(3).classNetwork->outputWeights,
              base.classNetwork->outputWeights);

    SpeakerAdaptation voice(base);
    voice.learnNetworks(4, 0.01f);
    voice.add(line, labels);
    const auto once = voice.adapted(3);
    ASSERT_TRUE(once.classNetwork && once.jawNetwork);
    EXPECT_GT(ahOverD(once, 2, 12), ahOverD(base, 2, 12));
    EXPECT_NE(once.jawNetwork->outputWeights, base.jawNetwork->outputWeights);
    EXPECT_EQ(once.classNetwork->logPrior, base.classNetwork->logPrior);
    voice.add(line, labels);  // the next line goes on from there
    EXPECT_GT(ahOverD(voice.adapted(3), 2, 12), ahOverD(once, 2, 12));

    const auto file = std::filesystem::temp_directory_path() / "lipsyncd_speaker_networks.json";
    voice.save(file);
    SpeakerAdaptation restarted(base);
    restarted.load(file);
    EXPECT_NEAR(ahOverD(restarted.adapted(3), 2, 12), ahOverD(voice.adapted(3), 2, 12), 1e-3);
    // The same templates, but a class network of another shape: not this base's.
    auto other = base;
    other.classNetwork->hiddenWeights = {{1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 0, 0}};
    other.classNetwork->hiddenBias = {0, 0, 0};
    other.classNetwork->outputWeights.push_back({0, 0});
    SpeakerAdaptation elsewhere(other);
    expectRefused(elsewhere, file, "class_network");  // networks trained from another set's
    EXPECT_EQ(elsewhere.frames(), 0u);
    // A jaw network of the same shape that hears the slopes: not this file's either.
    auto sloped = base;
    auto& jaw = *sloped.jawNetwork;
    jaw.slopeFrames = 2;
    jaw.inputMean.resize(8, 0.0f);
    jaw.inputScale.resize(8, 1.0f);
    jaw.hiddenWeights.resize(8, {0.0f, 0.0f});
    SpeakerAdaptation slopedVoice(sloped);
    expectRefused(slopedVoice, file, "jaw_network");
    std::filesystem::remove(file);
}

}  // namespace
}  // namespace lipsyncd::dsp
