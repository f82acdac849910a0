// Forced alignment on synthetic per-frame distances with known boundaries: the aligner must
// find them, survive words the speaker skipped or sounds nobody scripted, and hold only a
// bounded window of frames however long the input.
#include <gtest/gtest.h>

#include <limits>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {
namespace {

constexpr double kHop = 0.01;

struct Run {
    std::string phoneme;
    int frames;
};

// Frames whose nearest class is the run's (4 dB) and every other class far (10 dB); silence
// runs are below the energy gate.
struct Frames {
    std::vector<std::vector<float>> distances;
    std::vector<bool> silent;
    std::vector<double> boundaries;  // truth: where each run after the first starts

    void add(const std::vector<Run>& runs) {
        const auto& set = PhonemeSet::common();
        for (const auto& r : runs) {
            if (!distances.empty()) boundaries.push_back(distances.size() * kHop);
            std::vector<float> d(set.size(), 10.0f);
            d[*set.find(r.phoneme)] = 4.0f;
            for (int i = 0; i < r.frames; ++i) {
                distances.push_back(d);
                silent.push_back(r.phoneme == "sil");
            }
        }
    }
    Alignment align(std::span<const ScriptWord> script, ForcedAligner* keep = nullptr) const {
        ForcedAligner local(script, PhonemeSet::common(), kHop);
        ForcedAligner& a = keep ? *keep : local;
        for (std::size_t i = 0; i < distances.size(); ++i)
            a.push((i + 0.5) * kHop, distances[i], silent[i]);
        return a.finish();
    }
};

// A word whose expected durations are 80 % of the true ones (the speaker is slower than the
// synthesiser): the emissions, not the duration model, must place the boundaries.
ScriptWord word(const std::string& text, const std::vector<Run>& runs) {
    ScriptWord w{text, {}};
    double t = 0;
    for (const auto& r : runs) {
        const double d = 0.8 * r.frames * kHop;
        w.phonemes.push_back({t, t + d, r.phoneme, 1.0f});
        t += d;
    }
    return w;
}

const std::vector<Run> kMama = {{"bmp", 6}, {"ah", 12}, {"bmp", 5}, {"ah", 10}};
const std::vector<Run> kSee = {{"z", 8}, {"ih", 14}};
const std::vector<Run> kWow = {{"w", 6}, {"aw", 15}, {"w", 7}};

std::vector<ScriptWord> mamaSeeWow() {
    return {word("mama", kMama), word("see", kSee), word("wow", kWow)};
}

void expectBoundariesAt(const PhonemeSchedule& s, const std::vector<double>& truth) {
    ASSERT_EQ(s.size(), truth.size() + 1);
    for (std::size_t i = 0; i < truth.size(); ++i)
        EXPECT_NEAR(s[i + 1].start, truth[i], 1e-6)
            << "boundary " << i << " (" << s[i].phoneme << " | " << s[i + 1].phoneme << ")";
}

TEST(ForcedAligner, FindsKnownBoundariesExactly) {
    Frames f;
    f.add({{"sil", 20}});
    f.add(kMama);
    f.add({{"sil", 15}});  // a pause between words
    f.add(kSee);
    f.add(kWow);
    f.add({{"sil", 20}});
    const auto script = mamaSeeWow();
    const auto a = f.align(script);
    EXPECT_TRUE(a.complete);
    expectBoundariesAt(a.schedule, f.boundaries);
    ASSERT_EQ(a.words.size(), 3u);
    for (const auto& w : a.words) {
        EXPECT_TRUE(w.placed) << w.text;
        EXPECT_GT(w.confidence, 0.5f) << w.text;
    }
    EXPECT_NEAR(a.words[0].start, 0.20, 1e-6);
    EXPECT_NEAR(a.words[1].start, 0.20 + 0.33 + 0.15, 1e-6);
    EXPECT_TRUE(a.unexplained.empty());
}

// Frames of the runs, each `excessDb` further from its own class than from `nearest` (by
// default a class no word has: a voice the templates fit less well).
void addOffTemplate(Frames& f, const std::vector<Run>& runs, float excessDb,
                    const std::string& nearest = "th") {
    const auto& set = PhonemeSet::common();
    for (const auto& r : runs) {
        std::vector<float> d(set.size(), 10.0f);
        d[*set.find(nearest)] = 4.0f;
        d[*set.find(r.phoneme)] = 4.0f + excessDb;
        for (int i = 0; i < r.frames; ++i) {
            f.distances.push_back(d);
            f.silent.push_back(false);
        }
    }
}

// A word's confidence is judged against its line: where every word lies 1.2 dB off (a real
// voice), a word 2 dB off is still the word; where the others fit, it is not; a one-word line
// has only a low floor.
TEST(ForcedAligner, AWordsConfidenceIsJudgedAgainstItsLine) {
    auto seeIn = [](float othersDb) {
        Frames f;
        f.add({{"sil", 20}});
        addOffTemplate(f, kMama, othersDb);
        addOffTemplate(f, kSee, 2.0f);
        addOffTemplate(f, kWow, othersDb);
        f.add({{"sil", 20}});
        return f.align(mamaSeeWow()).words[1];
    };
    const auto offLine = seeIn(1.2f), fittingLine = seeIn(0.0f);
    EXPECT_LT(offLine.confidence, AlignerConfig{}.minWordConfidence);
    EXPECT_TRUE(offLine.placed);
    EXPECT_NEAR(offLine.confidence, fittingLine.confidence, 0.05);
    EXPECT_FALSE(fittingLine.placed);

    Frames alone;
    alone.add({{"sil", 20}});
    addOffTemplate(alone, kSee, 2.0f);
    alone.add({{"sil", 20}});
    const std::vector<ScriptWord> see = {word("see", kSee)};
    EXPECT_TRUE(alone.align(see).words[0].placed);
}

// A word said alone often ends in a long vowel or fricative that the templates fit less well:
// straight after the last phoneme it is that phoneme held on. After a pause, sound like it is
// something else (music after the line) and is left unexplained.
TEST(ForcedAligner, ALastPhonemeHeldLongStaysWithTheWordButSoundAfterAPauseDoesNot) {
    auto align = [&](const std::vector<ScriptWord>& script, const Frames& f,
                     const AlignerConfig& config) {
        ForcedAligner a(script, PhonemeSet::common(), kHop, 1.0, config);
        for (std::size_t i = 0; i < f.distances.size(); ++i)
            a.push((i + 0.5) * kHop, f.distances[i], f.silent[i]);
        return a.finish();
    };
    // 2.3 dB off with the nearest 4 dB away: 0.7 a frame at the default distance weight,
    // between the two edge fillers' costs.
    Frames held;
    held.add({{"sil", 20}});
    held.add(kSee);
    addOffTemplate(held, {{"ih", 15}}, 2.3f);
    const double heldEnd = held.distances.size() * kHop;
    held.add({{"sil", 3}});  // the clip cut close
    const std::vector<ScriptWord> see = {word("see", kSee)};
    const auto a = align(see, held, {});
    ASSERT_TRUE(a.words[0].placed);
    EXPECT_NEAR(a.words[0].end, heldEnd, 0.0101);
    EXPECT_TRUE(a.unexplained.empty());
    AlignerConfig oneCost;  // one cheap filler after the line, pause or not: the tail is lost
    oneCost.edgeFillerCostPerFrame = oneCost.fillerAfterPauseCostPerFrame;
    EXPECT_LT(align(see, held, oneCost).words[0].end, heldEnd - 0.1);

    // A consonant may run on through a pause (a stop's closure is silent), so without the
    // filler after a pause the music would be the word's last /z/.
    const std::vector<dsp::Run> is = {{"ih", 10}, {"z", 10}};
    Frames paused;
    paused.add({{"sil", 20}});
    paused.add(is);
    const double isEnd = paused.distances.size() * kHop;
    for (int i = 0; i < 10; ++i) {  // digital silence between the line and the music
        paused.distances.emplace_back(PhonemeSet::common().size(),
                                      std::numeric_limits<float>::infinity());
        paused.silent.push_back(true);
    }
    const double musicFrom = paused.distances.size() * kHop;
    addOffTemplate(paused, {{"z", 60}}, 2.3f);
    paused.add({{"sil", 20}});
    const std::vector<ScriptWord> script = {word("is", is)};
    const auto b = align(script, paused, {});
    ASSERT_TRUE(b.words[0].placed);
    EXPECT_NEAR(b.words[0].end, isEnd, 0.0101);
    ASSERT_EQ(b.unexplained.size(), 1u);  // from within the pause, on to the end
    EXPECT_GE(b.unexplained[0].first, isEnd);
    EXPECT_LE(b.unexplained[0].first, musicFrom);
    EXPECT_GE(b.unexplained[0].second, musicFrom + 0.6);
    AlignerConfig noPause;  // one dear filler after the line: the word takes the music in
    noPause.fillerAfterPauseCostPerFrame = noPause.edgeFillerCostPerFrame;
    EXPECT_GT(align(script, paused, noPause).words[0].end, musicFrom + 0.3);
}

TEST(ForcedAligner, AWordTheSpeakerSkippedIsNotPlaced) {
    Frames f;
    f.add({{"sil", 20}});
    f.add(kMama);
    f.add(kWow);  // "see" left out
    f.add({{"sil", 20}});
    const auto script = mamaSeeWow();
    const auto a = f.align(script);
    EXPECT_TRUE(a.complete);
    EXPECT_TRUE(a.words[0].placed);
    EXPECT_FALSE(a.words[1].placed);
    EXPECT_TRUE(a.words[2].placed);
    expectBoundariesAt(a.schedule, f.boundaries);
}

const std::vector<Run> kLong = {{"bmp", 6}, {"ah", 8}, {"kg", 6}, {"ah", 8}, {"l", 6},
                                {"ih", 8},  {"f", 6},  {"ah", 8}, {"l", 6},  {"ah", 10}};

// A long word the voice fits poorly is aligned and judged by its confidence, not taken for one
// the speaker left out: leaving it out costs by its phonemes (AlignerConfig::skipPhonemeCost). At
// one price a word, however long, it was skipped (festvox-ru's "Покалывало" at a line's start).
TEST(ForcedAligner, ALongWordTheVoiceFitsPoorlyIsAlignedNotSkipped) {
    Frames f;
    f.add({{"sil", 20}});
    addOffTemplate(f, kLong, 5.0f);
    addOffTemplate(f, kSee, 1.2f);
    addOffTemplate(f, kWow, 1.2f);
    f.add({{"sil", 20}});
    const std::vector<ScriptWord> script = {word("pokalyvalo", kLong), word("see", kSee),
                                            word("wow", kWow)};
    const auto firstWord = [&](const AlignerConfig& c) {
        ForcedAligner a(script, PhonemeSet::common(), kHop, 1.0, c);
        return f.align(script, &a).words[0];
    };
    const auto said = firstWord({});
    EXPECT_GT(said.confidence, 0.0f);
    EXPECT_GE(said.start, 0.2 - 1e-9);  // within its own stretch, 0.2 .. 0.92 s
    EXPECT_LE(said.end, 0.92 + 1e-9);
    EXPECT_GT(said.end - said.start, 0.3);
    AlignerConfig perWord;
    perWord.skipPhonemeCost = 0;
    const auto skipped = firstWord(perWord);
    EXPECT_EQ(skipped.confidence, 0.0f);
    EXPECT_EQ(skipped.end, skipped.start);
}

// A one-word line's word is never skipped, however poorly the voice fits it: it is aligned, and
// its confidence says whether it was said. (Skipped, the line was all filler and its word had no
// confidence at all: a child's "spectacles" in ktuberling.) In a longer line a word still may be.
TEST(ForcedAligner, AOneWordLinesWordIsAlignedAndJudgedNotSkipped) {
    Frames f;
    f.add({{"sil", 20}});
    f.add({{"kg", 22}});
    f.add({{"sil", 20}});
    for (auto& frame : f.distances)  // 10 dB further from every class than from /kg/
        for (auto& d : frame) d = d > 4.0f ? 14.0f : d;
    const std::vector<ScriptWord> script = {word("see", kSee)};
    const auto a = f.align(script);
    ASSERT_TRUE(a.complete);
    ASSERT_EQ(a.words.size(), 1u);
    EXPECT_GT(a.words[0].end - a.words[0].start, 0.1);
    EXPECT_GT(a.words[0].confidence, 0.0f);
    EXPECT_EQ(a.words[0].placed, a.words[0].confidence >= AlignerConfig{}.minSingleWordConfidence);
}

TEST(ForcedAligner, SoundsNobodyScriptedAreReportedAndTheWordsStillPlaced) {
    Frames f;
    f.add({{"sil", 20}});
    f.add(kMama);
    const double coughFrom = f.distances.size() * kHop;
    f.add({{"kg", 6}, {"oy", 8}, {"f", 6}, {"th", 7}, {"kg", 5}, {"oy", 8}});  // not in the script
    const double coughTo = f.distances.size() * kHop;
    f.add(kSee);
    f.add(kWow);
    f.add({{"sil", 20}});
    const auto script = mamaSeeWow();
    const auto a = f.align(script);
    for (const auto& w : a.words) EXPECT_TRUE(w.placed) << w.text;
    EXPECT_NEAR(a.words[1].start, coughTo, 0.0101);
    double covered = 0;
    for (const auto& [from, to] : a.unexplained)
        covered += std::max(0.0, std::min(to, coughTo) - std::max(from, coughFrom));
    EXPECT_GT(covered, 0.8 * (coughTo - coughFrom));
}

TEST(ForcedAligner, LongInputIsAlignedInABoundedWindow) {
    // 11 minutes of "mama see wow", 600 times over.
    Frames f;
    std::vector<ScriptWord> script;
    for (int i = 0; i < 600; ++i) {
        f.add({{"sil", 30}});
        f.add(kMama);
        f.add(kSee);
        f.add(kWow);
        for (auto& w : mamaSeeWow()) script.push_back(w);
    }
    f.add({{"sil", 30}});
    AlignerConfig config;
    ForcedAligner aligner(script, PhonemeSet::common(), kHop, 1.0, config);
    const auto a = f.align(script, &aligner);
    EXPECT_GT(f.distances.size(), 60000u);
    EXPECT_LE(
        aligner.peakFramesHeld(),
        static_cast<std::size_t>((config.commitSeconds + config.lookaheadSeconds) / kHop) + 1);
    EXPECT_TRUE(a.complete);
    expectBoundariesAt(a.schedule, f.boundaries);
    for (const auto& w : a.words) ASSERT_TRUE(w.placed) << w.text;
}

// A slow speaker whose last words sound more like the vowel before them than like themselves
// (a real voice against templates): before the end, holding that vowel scores best.
Frames slowSpeakerHoldingAVowel() {
    Frames f;
    f.add({{"sil", 20}});
    f.add(kMama);
    std::vector<dsp::Run> slowSeeWow;  // twice as long as the script's "see wow"
    for (const auto& runs : {kSee, kWow})
        for (const auto& r : runs) slowSeeWow.push_back({r.phoneme, 2 * r.frames});
    addOffTemplate(f, slowSeeWow, 0.5f, "ah");
    f.add({{"sil", 10}});
    return f;
}

// Whether the aligner reaches the end through every word, its last two placed.
bool placesTheLastWords(const Frames& f, const AlignerConfig& config, bool knowLength) {
    const auto script = mamaSeeWow();
    ForcedAligner aligner(script, PhonemeSet::common(), kHop, 1.0, config);
    if (knowLength) aligner.expectFrames(static_cast<std::int64_t>(f.distances.size()));
    const auto a = f.align(script, &aligner);
    return a.complete && a.words[1].end > a.words[1].start && a.words[2].end > a.words[2].start;
}

// Committed to the path holding the vowel, the aligner cannot fit the last words in the frames
// left, and skips them.
TEST(ForcedAligner, KnowingTheInputsLengthCommitsToAPathThatCanStillSayEveryWord) {
    const auto f = slowSpeakerHoldingAVowel();
    AlignerConfig config;
    config.commitSeconds = 1.4;
    config.lookaheadSeconds = 0.1;
    EXPECT_TRUE(placesTheLastWords(f, config, true));
    // The case this guards against still arises without it.
    EXPECT_FALSE(placesTheLastWords(f, config, false));
    config.commitSeconds = 100;  // no commit before the end: the whole input's best path
    EXPECT_TRUE(placesTheLastWords(f, config, false));
}

// Without a commit, in a narrow beam, the paths still saying the words on time lie too far
// behind the one holding the vowel and are dropped; then nothing reaches the end through the
// words. Knowing the input's length, the beam weighs what a path behind the words owes (the
// words it could no longer say at the line's rate) and keeps them.
TEST(ForcedAligner, KnowingTheInputsLengthKeepsPathsOnTimeInTheBeam) {
    const auto f = slowSpeakerHoldingAVowel();
    AlignerConfig config;
    config.commitSeconds = 100;
    config.beam = 6;  // the paths on time lie 12 to 16 behind the vowel's here
    EXPECT_TRUE(placesTheLastWords(f, config, true));
    EXPECT_FALSE(placesTheLastWords(f, config, false));
}

TEST(ForcedAligner, NoFramesMeansNoWordPlacedAndNoCrash) {
    const auto script = mamaSeeWow();
    ForcedAligner aligner(script, PhonemeSet::common(), kHop);
    const auto a = aligner.finish();
    EXPECT_FALSE(a.complete);
    for (const auto& w : a.words) EXPECT_FALSE(w.placed);
}

TEST(ForcedAligner, TooFewFramesForTheWordsDoesNotCrash) {
    Frames f;
    f.add({{"bmp", 3}, {"ah", 3}});
    std::vector<ScriptWord> script;
    for (int i = 0; i < 20; ++i)
        for (auto& w : mamaSeeWow()) script.push_back(w);
    ForcedAligner aligner(script, PhonemeSet::common(), kHop);
    EXPECT_GT(aligner.minimumSeconds(), 10 * f.distances.size() * kHop);
    const auto a = f.align(script, &aligner);
    EXPECT_FALSE(a.complete);
    EXPECT_FALSE(a.words.back().placed);
}

TEST(ForcedAligner, FramesWithoutSpectraAreSilence) {
    Frames f;
    f.add(kMama);
    f.distances.insert(
        f.distances.begin(), 10,
        std::vector<float>(PhonemeSet::common().size(), std::numeric_limits<float>::infinity()));
    f.silent.insert(f.silent.begin(), 10, true);
    const std::vector<ScriptWord> script = {word("mama", kMama)};
    const auto a = f.align(script);
    EXPECT_TRUE(a.words[0].placed);
    EXPECT_NEAR(a.words[0].start, 0.10, 1e-6);
}

// A word's weak end (an offglide, a final nasal) lies far from every template, silence
// included, but above the energy gate: it is still the word, not the pause after it.
TEST(ForcedAligner, SpeechAboveTheGateStaysWithTheWordNotThePause) {
    Frames f;
    f.add({{"sil", 20}});
    f.add({{"z", 8}, {"ih", 10}});
    const double wordEnd = (20 + 8 + 10 + 12) * kHop;
    const auto& set = PhonemeSet::common();
    for (int i = 0; i < 12; ++i) {  // the tail: nearest class ih, silence hardly further
        std::vector<float> d(set.size(), 12.0f);
        d[*set.find("ih")] = 7.0f;
        d[set.silence()] = 7.3f;
        f.distances.push_back(d);
        f.silent.push_back(false);
    }
    f.add({{"sil", 20}});
    const std::vector<ScriptWord> script = {word("see", {{"z", 8}, {"ih", 10}})};
    const auto a = f.align(script);
    ASSERT_TRUE(a.words[0].placed);
    EXPECT_NEAR(a.words[0].end, wordEnd, 0.0101);
    AlignerConfig free;
    free.silenceInSpeechCost = 0;
    ForcedAligner without(script, set, kHop, 1.0, free);
    EXPECT_LT(f.align(script, &without).words[0].end, wordEnd - 0.05)
        << "without the cost the pause takes the tail (the test no longer tests it)";
}

TEST(ForcedAligner, BadScriptsAreInputErrors) {
    const auto& set = PhonemeSet::common();
    EXPECT_THROW(ForcedAligner({}, set, kHop), InputError);
    const std::vector<ScriptWord> unknown = {{"xyz", {{0, 0.1, "nope", 1.0f}}}};
    EXPECT_THROW(ForcedAligner(unknown, set, kHop), InputError);
    const std::vector<ScriptWord> silentWord = {{"...", {{0, 0.1, "sil", 1.0f}}}};
    EXPECT_THROW(ForcedAligner(silentWord, set, kHop), InputError);
    const auto script = mamaSeeWow();
    EXPECT_THROW(ForcedAligner(script, set, kHop, 0.0), InputError);
}

}  // namespace
}  // namespace lipsyncd::dsp
