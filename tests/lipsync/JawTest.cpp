// The jaw a puppet shows: class order kept through the whole runtime, rest when speech stops,
// loudness that opens wider but never past a phoneme's opening, and the jaw scores of eval.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <random>

#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

struct Shipped {
    lipsync::PoseSet poses = lipsync::PoseSet::named("facefx");
    lipsync::BigramCurveSet curves = lipsync::BigramCurveSet::named("english", poses);
    std::size_t jaw = *poses.find("jaw");
};
const Shipped& shipped() {
    static const Shipped s;
    return s;
}

float jawHeight(const std::string& cls) {
    return *PhonemeSet::common()[*PhonemeSet::common().find(cls)].jaw;
}

float weightAt(const PoseTrack& track, double t, std::size_t pose) {
    const auto f = static_cast<std::size_t>(std::lround(t * 100));
    return track.frame(std::min(f, track.frames() - 1))[pose];
}

// `n` speech classes (no silence) held `hold` seconds each, in random order, appended to `s`.
void appendSpeech(std::mt19937& rng, std::size_t n, double hold, PhonemeSchedule& s) {
    const auto& set = PhonemeSet::common();
    std::uniform_int_distribution<std::size_t> pick(0, set.size() - 1);
    for (std::size_t i = 0; i < n; ++i) {
        std::size_t c;
        do c = pick(rng);
        while (c == set.silence());
        const double t = s.empty() ? 0 : s.back().end;
        s.push_back({t, t + hold, set[c].name, 1});
    }
}
void appendSilence(double length, PhonemeSchedule& s) {
    const double t = s.empty() ? 0 : s.back().end;
    s.push_back({t, t + length, "sil", 1});
}

TEST(Jaw, EveryClassHasAJawHeightAndTheOrderIsTheArticulatoryOne) {
    for (const auto& c : PhonemeSet::common().classes()) ASSERT_TRUE(c.jaw) << c.name;
    // Low vowels most open, then mid, then high; consonants lower; sibilants nearly closed;
    // bilabials at closure.
    EXPECT_GT(jawHeight("aa"), jawHeight("eh"));
    EXPECT_GT(jawHeight("eh"), jawHeight("ih"));
    EXPECT_GT(jawHeight("ih"), jawHeight("d"));
    EXPECT_GT(jawHeight("d"), jawHeight("z"));
    EXPECT_LT(jawHeight("z"), 0.1f);
    EXPECT_EQ(jawHeight("bmp"), 0.0f);
}

// Where a phoneme is held long enough for the jaw to reach its target, the jaw at its centre
// keeps the class order, whatever comes before and after.
TEST(Jaw, HeldPhonemesKeepTheClassOrderThroughTheWholeRuntime) {
    std::mt19937 rng(11);
    for (int trial = 0; trial < 20; ++trial) {
        PhonemeSchedule s;
        appendSilence(0.3, s);
        appendSpeech(rng, 30, 0.25, s);
        appendSilence(0.5, s);
        const auto track = lipsync::animate(s, shipped().curves, shipped().poses);
        for (std::size_t i = 1; i + 1 < s.size(); ++i) {
            const double centre = (s[i].start + s[i].end) / 2;
            EXPECT_NEAR(weightAt(track, centre, shipped().jaw), jawHeight(s[i].phoneme), 0.03)
                << s[i].phoneme << " at " << centre << " s (trial " << trial << ")";
            for (std::size_t k = 1; k + 1 < s.size(); ++k) {
                if (jawHeight(s[i].phoneme) < jawHeight(s[k].phoneme) + 0.1) continue;
                EXPECT_GT(weightAt(track, centre, shipped().jaw),
                          weightAt(track, (s[k].start + s[k].end) / 2, shipped().jaw))
                    << s[i].phoneme << " vs " << s[k].phoneme;
            }
        }
    }
}

TEST(Jaw, ABilabialBetweenOpenVowelsClosesTheJaw) {
    const PhonemeSchedule s{{0, 0.2, "sil", 1},
                            {0.2, 0.4, "aa", 1},
                            {0.4, 0.47, "bmp", 1},
                            {0.47, 0.7, "aa", 1},
                            {0.7, 1.0, "sil", 1}};
    const auto track = lipsync::animate(s, shipped().curves, shipped().poses);
    float lowest = 1;
    for (double t = 0.4; t <= 0.47; t += 0.01)
        lowest = std::min(lowest, weightAt(track, t, shipped().jaw));
    EXPECT_LT(lowest, 0.1f);
    EXPECT_GT(weightAt(track, 0.3, shipped().jaw), 0.9f);
}

// Every pose, not only the jaw: a mouth half open in a pause or after the line reads as broken.
void expectRestBetween(const PoseTrack& track, double from, double to) {
    for (std::size_t f = 0; f < track.frames(); ++f) {
        if (track.times[f] < from - 1e-9 || track.times[f] > to + 1e-9) continue;
        for (std::size_t p = 0; p < track.poses.size(); ++p)
            ASSERT_LT(track.frame(f)[p], 1e-4f)
                << track.poses[p] << " at " << track.times[f] << " s";
    }
}

TEST(Jaw, TheMouthRestsWithin150MsOfTheEndOfSpeechAndInPausesOver250Ms) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        PhonemeSchedule s;
        appendSilence(0.3, s);
        appendSpeech(rng, 6, 0.12, s);
        const double pauseAt = s.back().end;
        appendSilence(0.3, s);
        appendSpeech(rng, 6, 0.12, s);
        appendSilence(0.5, s);
        const auto track = lipsync::animate(s, shipped().curves, shipped().poses);
        expectRestBetween(track, s.front().start, s.front().end - 0.1);
        expectRestBetween(track, pauseAt + 0.15, pauseAt + 0.3 - 0.1);
        expectRestBetween(track, s.back().start + 0.15, s.back().end);
    }
}

TEST(Jaw, TheCausalStreamRestsWithin150MsOfASilenceWithoutWaitingForWhatFollows) {
    const PhonemeSchedule s{{0, 0.3, "aa", 1}, {0.3, 0.4, "ah", 1}};
    lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, 0);
    PoseTrack out;
    for (const auto& seg : s) stream.push(seg, out);
    stream.preview("sil", 0.6, out);  // silence so far, its end unknown
    expectRestBetween(out, 0.55, 0.6);
}

TEST(Jaw, LouderSpeechOpensWiderButNeverPastThePhonemesOpening) {
    const PhonemeSchedule s{{0, 0.1, "sil", 1},
                            {0.1, 0.4, "aa", 1},
                            {0.4, 0.5, "bmp", 1},
                            {0.5, 0.8, "aa", 1},
                            {0.8, 1.0, "sil", 1}};
    const auto plain = lipsync::animate(s, shipped().curves, shipped().poses);
    LevelTrack levels;
    levels.db.assign(101, -20.0f);                                 // speaking level
    for (std::size_t f = 50; f <= 80; ++f) levels.db[f] = -38.0f;  // the second vowel quiet
    for (std::size_t f = 40; f < 50; ++f) levels.db[f] = 0.0f;     // a very loud m
    auto shaped = plain;
    lipsync::shapeByLoudness(shipped().poses, levels, s, PhonemeSet::common(), shaped);
    const auto jaw = shipped().jaw;
    for (std::size_t i = 0; i < plain.values.size(); ++i)
        ASSERT_LE(shaped.values[i], plain.values[i] + 1e-6f);
    EXPECT_NEAR(weightAt(shaped, 0.25, jaw), weightAt(plain, 0.25, jaw), 0.01);
    const double gain = shipped().poses[jaw].loudnessGain;
    EXPECT_NEAR(weightAt(shaped, 0.65, jaw), (1 - gain) * weightAt(plain, 0.65, jaw), 0.01);
    EXPECT_LT(weightAt(shaped, 0.45, jaw), 0.05f);  // the nasal stays closed however loud
}

// A word's sound fades before its pause while the mouth still holds the vowel: the fade must not
// shut the mouth early (the rest ramp closes it once the pause starts). The same fade inside
// speech, with no pause after it, is quieter speech and narrows the mouth as before.
TEST(Jaw, TheFadeBeforeAPauseDoesNotShutTheMouthButQuietSpeechStillNarrowsIt) {
    const PhonemeSchedule beforePause{
        {0, 0.1, "sil", 1}, {0.1, 0.5, "aa", 1}, {0.5, 0.8, "sil", 1}};
    const PhonemeSchedule inSpeech{
        {0, 0.1, "sil", 1}, {0.1, 0.5, "aa", 1}, {0.5, 0.8, "ah", 1}, {0.8, 1.0, "sil", 1}};
    LevelTrack levels;
    levels.db.assign(101, -20.0f);                                // speaking level
    for (std::size_t f = 44; f < 50; ++f) levels.db[f] = -45.0f;  // the last 60 ms fade out
    const auto jaw = shipped().jaw;
    const double gain = shipped().poses[jaw].loudnessGain;
    const auto shaped = [&](const PhonemeSchedule& s, double hold) {
        auto track = lipsync::animate(s, shipped().curves, shipped().poses);
        const auto plain = track;
        lipsync::LoudnessConfig config;
        config.fadeHoldSeconds = hold;
        lipsync::shapeByLoudness(shipped().poses, levels, s, PhonemeSet::common(), track, config);
        return std::pair(weightAt(plain, 0.47, jaw), weightAt(track, 0.47, jaw));
    };
    const auto [plain, held] = shaped(beforePause, 0.1);
    ASSERT_GT(plain, 0.3f);
    EXPECT_NEAR(held, plain, 1e-4);  // the vowel's last frames keep its opening
    const auto [plain0, faded] = shaped(beforePause, 0);
    EXPECT_NEAR(faded, (1 - gain) * plain0, 0.01);  // without the hold: shut by the fade
    const auto [plainInSpeech, quiet] = shaped(inSpeech, 0.1);
    EXPECT_NEAR(quiet, (1 - gain) * plainInSpeech, 0.01);  // no pause after it: quieter speech
    // The hold covers the last 0.1 s of speech whichever phonemes it holds: here 0.47 s lies in
    // the vowel before a short last one.
    const PhonemeSchedule shortLast{
        {0, 0.1, "sil", 1}, {0.1, 0.48, "aa", 1}, {0.48, 0.5, "ah", 1}, {0.5, 0.8, "sil", 1}};
    const auto [plainShort, heldShort] = shaped(shortLast, 0.1);
    EXPECT_NEAR(heldShort, plainShort, 1e-4);
}

// A jaw track of the shipped poses, 100 frames a second, the jaw at frame f `jaw(f)` and every
// other pose at 0.3.
template <class Jaw>
PoseTrack jawTrack(std::size_t frames, Jaw jaw) {
    PoseTrack track;
    for (const auto& p : shipped().poses.poses()) track.poses.push_back(p.name);
    std::vector<float> w(track.poses.size(), 0.3f);
    for (std::size_t f = 0; f < frames; ++f) {
        w[shipped().jaw] = jaw(f);
        track.append(double(f) / 100, w);
    }
    return track;
}

TEST(Jaw, ASyllablesDipClosesTheJawButAWobbleOrAFallIntoAPauseDoesNot) {
    const auto& jawPose = shipped().poses[shipped().jaw];
    ASSERT_GT(jawPose.dipDepth, 0);
    // Two vowels at 0.6 with a consonant between them: the heard jaw dips to 0.3 at 0.2 s.
    const auto dip = [](std::size_t f) {
        return 0.6f - 0.3f * std::max(0.0f, 1 - std::abs(float(f) - 20) / 4);
    };
    auto track = jawTrack(40, dip);
    lipsync::deepenDips(shipped().poses, track);
    EXPECT_NEAR(weightAt(track, 0.2, shipped().jaw), 0.3 * (1 - jawPose.dipDepth), 1e-5);
    EXPECT_LT(weightAt(track, 0.19, shipped().jaw), dip(19));  // less beside it
    EXPECT_GT(weightAt(track, 0.19, shipped().jaw), dip(19) * (1 - jawPose.dipDepth));
    EXPECT_FLOAT_EQ(weightAt(track, 0.23, shipped().jaw), dip(23));  // the vowels keep theirs
    for (std::size_t f = 0; f < track.frames(); ++f)                 // and the other poses theirs
        EXPECT_FLOAT_EQ(track.frame(f)[shipped().jaw == 0 ? 1 : 0], 0.3f);

    // A wobble smaller than dip_rise, and a fall into a pause (no rise after it), stay.
    const float wobble = float(jawPose.dipRise) * 0.6f;
    for (const auto& curve : std::vector<std::function<float(std::size_t)>>{
             [&](std::size_t f) { return 0.5f - (f == 20 ? wobble : 0.0f); },
             [](std::size_t f) { return f < 20 ? 0.6f : std::max(0.0f, 0.6f - 0.1f * (f - 20)); },
         }) {
        auto flat = jawTrack(40, curve);
        const auto before = flat.values;
        lipsync::deepenDips(shipped().poses, flat);
        EXPECT_EQ(flat.values, before);
    }
}

TEST(Jaw, OnlyTheJawHeardFromAudioAloneHasItsDipsDeepened) {
    const lipsync::Runtime runtime{lipsync::RuntimeSpec{}};
    const PhonemeSchedule s{{0, 0.1, "sil", 1},
                            {0.1, 0.3, "aa", 1},
                            {0.3, 0.34, "d", 1},
                            {0.34, 0.6, "aa", 1},
                            {0.6, 0.9, "sil", 1}};
    LevelTrack levels;
    levels.db.assign(91, -20.0f);
    for (std::size_t f = 0; f <= 90; ++f)  // heard: open, with a shallow dip at the /d/
        levels.jaw.push_back(f < 10 || f >= 60 ? 0.0f : (f >= 30 && f < 34 ? 0.45f : 0.7f));
    const auto jaw = shipped().jaw;
    // The runtime's steps before the dips, by hand.
    const auto undeepened = [&] {
        auto track = lipsync::animate(s, shipped().curves, shipped().poses);
        lipsync::blendHeardJaw(shipped().poses, levels, track);
        lipsync::shapeByLoudness(shipped().poses, levels, s, PhonemeSet::common(), track);
        return track;
    };
    const auto lowest = [&](const PoseTrack& t) {
        float m = 1;
        for (int f = 28; f <= 36; ++f) m = std::min(m, t.frame(std::size_t(f))[jaw]);
        return m;
    };
    const auto audio = runtime.animate(s, &levels);
    EXPECT_LT(lowest(audio), 0.8f * lowest(undeepened()));
    levels.aligned = true;
    EXPECT_EQ(runtime.animate(s, &levels).values, undeepened().values);
}

TEST(Jaw, TheStreamingShaperFollowsADecayingPeak) {
    lipsync::LoudnessShaper shaper(shipped().poses);
    std::vector<float> w(shipped().poses.size(), 1.0f);
    shaper.shape(-20, 0.01, w);
    EXPECT_FLOAT_EQ(w[shipped().jaw], 1.0f);  // at the peak so far
    std::fill(w.begin(), w.end(), 1.0f);
    shaper.shape(-50, 0.01, w);
    EXPECT_NEAR(w[shipped().jaw], 1 - shipped().poses[shipped().jaw].loudnessGain, 1e-6);
}

TEST(JawScore, TheReferenceAgainstItselfIsPerfectAndAFrozenJawIsNot) {
    const auto& set = PhonemeSet::common();
    const PhonemeSchedule s{{0, 0.2, "sil", 1},
                            {0.2, 0.4, "aa", 1},
                            {0.4, 0.45, "bmp", 1},
                            {0.45, 0.7, "eh", 1},
                            {0.7, 0.9, "sil", 1}};
    const auto ref = lipsync::jawReference(s, set, 100, 91);
    EXPECT_NEAR(ref[30], 1.0f, 1e-6);
    EXPECT_NEAR(ref[10], 0.0f, 1e-6);
    const auto self = lipsync::scoreJaw(ref, ref, s, set, 100);
    EXPECT_NEAR(self.r(), 1.0, 1e-9);
    EXPECT_EQ(self.closures, 1u);
    EXPECT_EQ(self.closuresCaught, 1u);
    EXPECT_EQ(self.falseClosures, 0u);
    const std::vector<float> open(91, 0.6f), shut(91, 0.0f);
    EXPECT_EQ(lipsync::scoreJaw(open, ref, s, set, 100).closuresCaught, 0u);
    EXPECT_EQ(lipsync::scoreJaw(open, ref, s, set, 100).r(), 0.0);
    EXPECT_NEAR(lipsync::scoreJaw(open, ref, s, set, 100).openingWhereOpen(), 0.6, 1e-6);
    EXPECT_GT(self.openingWhereOpen(), 0.5);  // the reference itself, where it is above 0.5
    const auto closed = lipsync::scoreJaw(shut, ref, s, set, 100);
    EXPECT_GT(closed.openFrames, 10u);
    EXPECT_EQ(closed.falseClosureRate(), 1.0);
    auto twice = self;
    twice.add(closed);
    EXPECT_EQ(twice.closures, 2u);
    EXPECT_EQ(twice.n, 2 * self.n);
}

// `lipsync eval`'s per-class jaw column: where a mouth opens too little shows per phoneme.
TEST(JawScore, EachClassKeepsTheMeanJawOverItsLabelledFrames) {
    const auto& set = PhonemeSet::common();
    const PhonemeSchedule s{{0, 0.2, "sil", 1}, {0.2, 0.4, "aa", 1}, {0.4, 0.7, "eh", 1}};
    const auto ref = lipsync::jawReference(s, set, 100, 71);
    std::vector<float> jaw(71, 0.0f);
    std::fill(jaw.begin() + 20, jaw.begin() + 30, 1.0f);  // the first half of aa only
    std::fill(jaw.begin() + 40, jaw.begin() + 70, 0.3f);  // eh
    const auto score = lipsync::scoreJaw(jaw, ref, s, set, 100);
    const auto aa = *set.find("aa"), eh = *set.find("eh"), sil = set.silence();
    EXPECT_EQ(score.classFrames[aa], 20u);
    EXPECT_NEAR(score.meanJawOf(aa), 0.5, 1e-6);
    EXPECT_NEAR(score.meanJawOf(eh), 0.3, 1e-6);
    EXPECT_NEAR(score.meanJawOf(sil), 0.0, 1e-6);
    EXPECT_EQ(score.meanJawOf(*set.find("ao")), 0.0);  // never labelled
    auto sum = score;
    sum.add(lipsync::scoreJaw(std::vector<float>(71, 1.0f), ref, s, set, 100));
    EXPECT_EQ(sum.classFrames[aa], 40u);
    EXPECT_NEAR(sum.meanJawOf(aa), 0.75, 1e-6);
    lipsync::JawScore none;  // a speaker before any file: its sums grow to the set's classes
    none.add(score);
    EXPECT_NEAR(none.meanJawOf(eh), 0.3, 1e-6);
}

TEST(Jaw, APoseSetRejectsABadLoudnessGainRestRuleOrDipNamingTheLine) {
    const auto file = std::filesystem::temp_directory_path() / "lipsyncd-bad-poses.toml";
    for (const std::string body : {"[[pose]]\nname = \"jaw\"\nloudness_gain = 1.5\n",
                                   "[[pose]]\nname = \"jaw\"\n[rest]\nwithin = -1\n",
                                   "[[pose]]\nname = \"jaw\"\ndip_depth = 1.5\n",
                                   "[[pose]]\nname = \"jaw\"\ndip_rise = 0\n"}) {
        std::ofstream(file) << "name = \"bad\"\n" << body;
        try {
            lipsync::PoseSet::load(file);
            FAIL() << "accepted: " << body;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(file.string() + ":"), std::string::npos)
                << e.what();
        }
    }
    std::filesystem::remove(file);
}

}  // namespace
}  // namespace lipsyncd::test
