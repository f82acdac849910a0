// A line followed as it is said (the service's live lines after a cue): a fixed-lag alignment
// on the words, decided a lag behind the newest frame, that beats the audio alone on speech the
// templates were not trained on, and stands aside where no word explains the sound.
#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "TestSpeech.hpp"
#include "TestSynth.hpp"

namespace lipsyncd {
namespace {

// Not in the training or dev corpus; a voice and a rate the templates were not trained on, and
// not espeak-ng's default rate: followed live, the speaking rate is not measured first.
const std::string kLine = "Seven puppets sang a song about the moon.";

struct Spoken {
    std::filesystem::path file;
    PhonemeSchedule labels;
    double seconds = 0;
};

Spoken speak(const std::string& text, const std::string& name, double silenceBefore = 0) {
    const auto s = test::speak(test::espeak(), text, "en-us+f3", 150);
    std::vector<float> samples(static_cast<std::size_t>(silenceBefore * s.rate), 0.0f);
    samples.insert(samples.end(), s.samples.begin(), s.samples.end());
    Spoken out;
    out.file = test::writeAudio(name, samples, s.rate, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
    for (auto p : s.labels) {
        p.start += silenceBefore;
        p.end += silenceBefore;
        out.labels.push_back(p);
    }
    out.seconds = static_cast<double>(samples.size()) / s.rate;
    return out;
}

double groups(const PhonemeSchedule& schedule, const PhonemeSchedule& labels) {
    return dsp::scoreSchedule(schedule, labels, PhonemeSet::common()).groupAccuracy();
}

TEST(LineFollower, FollowsTheWordsBetterThanTheAudioAlone) {
    const auto s = speak(kLine, "follow_line.wav", 0.4);
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto audioOnly = dsp::analyzeFile(s.file, templates, PhonemeSet::common());
    for (const double lag : {0.05, 0.1, 0.2}) {
        const auto f = followText(test::espeak(), s.file, kLine, "en-us", templates, lag);
        // The schedule covers the file without gaps, as a live mouth's input does.
        ASSERT_FALSE(f.schedule.empty());
        EXPECT_DOUBLE_EQ(f.schedule.front().start, 0.0);
        for (std::size_t i = 1; i < f.schedule.size(); ++i)
            EXPECT_NEAR(f.schedule[i].start, f.schedule[i - 1].end, 1e-9) << lag;
        EXPECT_NEAR(f.schedule.back().end, f.durationSeconds, 1e-9);
        // Measured 88-89 % at these lags against 75 % from the audio alone.
        EXPECT_GE(groups(f.schedule, s.labels), 0.85) << lag;
        EXPECT_GT(groups(f.schedule, s.labels), groups(audioOnly.schedule, s.labels) + 0.08) << lag;
    }
}

// Each frame is decided `lag` frames after it: the newest decided frame trails the newest
// heard by exactly the lag, and the line's end places the frames still held back.
TEST(LineFollower, DecidesEachFrameALagBehindTheNewest) {
    const auto s = speak(kLine, "follow_lag.wav");
    const auto templates = dsp::TemplateSet::loadDefault();
    std::vector<std::string> warnings;
    const auto script =
        scriptForVoice(test::espeak(), kLine, "en-us", espeakMapForVoice("en-us"), &warnings);
    const double hop = templates.analysis.hopSeconds;
    dsp::LineFollower follower(script, PhonemeSet::common(), hop, 0.1);
    EXPECT_EQ(follower.lagFrames(), static_cast<int>(std::lround(0.1 / hop)));
    auto decoder = dsp::AudioDecoder::open(s.file);
    dsp::StreamingAnalyzer analyzer(templates, PhonemeSet::common(), decoder.sampleRate());
    int frames = 0, upcoming = 0;
    double newest = 0;
    PhonemeSchedule out;
    follower.onSegment([&](const PhonemeSegment& seg) { out.push_back(seg); });
    analyzer.onFrame([&](const dsp::StreamingAnalyzer::Frame& f) {
        follower.push(f.label, analyzer.templateDistances(), analyzer.distances());
        ++frames;
        newest = f.label.time;
        if (frames <= follower.lagFrames()) {
            EXPECT_EQ(follower.openPhoneme(), -1);
        } else {
            EXPECT_NEAR(follower.openUntil(), newest - 0.1 + hop / 2, 1e-6);
        }
        // What the path goes on to, among the frames not decided yet: another phoneme, after
        // the decided ones, by the newest.
        if (follower.upcomingPhoneme() >= 0) {
            ++upcoming;
            EXPECT_NE(follower.upcomingPhoneme(), follower.openPhoneme());
            EXPECT_GE(follower.upcomingStart(), follower.openUntil() - 1e-9);
            EXPECT_LE(follower.upcomingStart(), newest);
        }
    });
    std::vector<float> block(4096);
    while (const auto n = decoder.read(block)) analyzer.push(std::span(block.data(), n));
    analyzer.finish();
    follower.finish();
    ASSERT_FALSE(out.empty());
    EXPECT_NEAR(out.back().end, newest + hop / 2, 1e-6);
    EXPECT_EQ(follower.openPhoneme(), -1);
    EXPECT_GT(upcoming, frames / 4);
}

// Words the performer adds to the line are not forced into the line's words: with only the
// last three words of five given, the follower still does at least as well as the audio alone
// (measured 87 % against 80 %; 88 % with every word given).
TEST(LineFollower, AddedWordsAreNotForcedIntoTheLine) {
    const auto s = speak("Bring me the red umbrella.", "follow_extra.wav");
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto some =
        followText(test::espeak(), s.file, "the red umbrella", "en-us", templates, 0.1);
    const auto all =
        followText(test::espeak(), s.file, "Bring me the red umbrella.", "en-us", templates, 0.1);
    const auto audioOnly = dsp::analyzeFile(s.file, templates, PhonemeSet::common());
    EXPECT_GE(groups(all.schedule, s.labels), 0.85);
    EXPECT_GE(groups(some.schedule, s.labels), groups(audioOnly.schedule, s.labels));
}

// A line said from the first frame by a voice the templates fit less well than the silence
// class: each phoneme 1.5 dB off its templates, silence only 0.5 dB off (a telephone prompt,
// said from its first sample). Offline every word must be placed by the end; a frame decided a
// lag behind the newest has no such end, and at the whole-file aligner's 0.25 a frame of silence
// the best partial path stayed in the lead-in: the words were followed as silence.
TEST(LineFollower, ALineSaidAtOnceIsFollowedNotTakenForTheLeadIn) {
    const auto& set = PhonemeSet::common();
    const double hop = 0.01;
    struct Run {
        std::string phoneme;
        int frames;
    };
    const std::vector<std::vector<Run>> words = {
        {{"z", 10}, {"ih", 8}, {"kg", 10}, {"w", 10}, {"d", 15}},
        {{"bmp", 8}, {"aa", 14}, {"l", 9}, {"ah", 12}}};
    std::vector<dsp::ScriptWord> script;
    std::vector<int> truth;  // each frame's class
    for (const auto& runs : words) {
        dsp::ScriptWord w{"w" + std::to_string(script.size()), {}};
        double t = 0;
        for (const auto& r : runs) {
            w.phonemes.push_back({t, t + r.frames * hop, r.phoneme, 1.0f});
            t += r.frames * hop;
            truth.insert(truth.end(), static_cast<std::size_t>(r.frames),
                         static_cast<int>(*set.find(r.phoneme)));
        }
        script.push_back(w);
    }
    const auto sil = static_cast<int>(set.silence());
    truth.insert(truth.end(), 30, sil);
    const auto followed = [&](const dsp::AlignerConfig& config) {
        dsp::LineFollower follower(script, set, hop, 0.1, config);
        std::vector<int> out;
        follower.onSegment([&](const PhonemeSegment& seg) {
            const auto c = static_cast<int>(*set.find(seg.phoneme));
            while (out.size() * hop + hop / 2 < seg.end) out.push_back(c);
        });
        for (std::size_t i = 0; i < truth.size(); ++i) {
            std::vector<float> d(set.size(), 10.0f);
            dsp::FrameLabel label;
            label.time = (static_cast<double>(i) + 0.5) * hop;
            label.silent = truth[i] == sil;
            if (!label.silent) {
                d[*set.find("th")] = 4.0f;  // the nearest: a class no word has
                d[static_cast<std::size_t>(sil)] = 4.5f;
                d[static_cast<std::size_t>(truth[i])] = 5.5f;
            } else {
                d[static_cast<std::size_t>(sil)] = 4.0f;
            }
            label.phoneme = label.silent ? sil : static_cast<int>(*set.find("th"));
            follower.push(label, d, d);
        }
        follower.finish();
        std::size_t speech = 0, right = 0;
        for (std::size_t i = 0; i < truth.size() && i < out.size(); ++i)
            if (truth[i] != sil) ++speech, right += out[i] == truth[i];
        return static_cast<double>(right) / static_cast<double>(speech);
    };
    EXPECT_GE(followed({}), 0.8);
    dsp::AlignerConfig asWholeFiles;
    asWholeFiles.followingSilenceInSpeechCost = asWholeFiles.silenceInSpeechCost;
    EXPECT_LT(followed(asWholeFiles), 0.5);
}

TEST(LineFollower, RejectsALagBeyondTheLookahead) {
    const std::vector<dsp::ScriptWord> none;
    EXPECT_THROW(dsp::LineFollower(none, PhonemeSet::common(), 0.01, 5.0), InputError);
    EXPECT_THROW(dsp::LineFollower(none, PhonemeSet::common(), 0.01, -0.1), InputError);
}

}  // namespace
}  // namespace lipsyncd
