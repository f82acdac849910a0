// Known words aligned on espeak-ng speech (its own phoneme timings are the truth), with words
// skipped, wrong words, music around the line, and bad input: never a crash, always either a
// clear error or a flagged audio-only fallback.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "TestSpeech.hpp"
#include "TestSynth.hpp"

namespace lipsyncd {
namespace {

// Not in the training or dev corpus; a voice and rate the templates were not trained on.
const std::string kLine = "Seven puppets sang a song about the moon.";

using Spoken = test::Speech;

EspeakSynthesizer& synth() {
    return test::espeak();
}

Spoken speak(const std::string& text, const std::string& voice = "en-us+f3", int wpm = 150) {
    return test::speak(synth(), text, voice, wpm);
}

dsp::AlignFileResult align(const std::filesystem::path& file, const std::string& text) {
    return alignText(synth(), file, text, "en-us", dsp::TemplateSet::loadDefault());
}

std::filesystem::path wav(const std::string& name, const std::vector<float>& samples, int rate) {
    return test::writeAudio(name, samples, rate, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
}

// Per reference boundary: the distance to the nearest aligned boundary between the same
// classes (0.1 s when there is none).
std::vector<double> boundaryErrors(const PhonemeSchedule& hyp, const PhonemeSchedule& ref) {
    std::vector<double> errors;
    for (std::size_t i = 1; i < ref.size(); ++i) {
        double best = 0.1;
        for (std::size_t j = 1; j < hyp.size(); ++j)
            if (hyp[j - 1].phoneme == ref[i - 1].phoneme && hyp[j].phoneme == ref[i].phoneme)
                best = std::min(best, std::abs(hyp[j].start - ref[i].start));
        errors.push_back(best);
    }
    std::sort(errors.begin(), errors.end());
    return errors;
}

std::size_t placed(const dsp::AlignFileResult& r) {
    return std::count_if(r.alignment.words.begin(), r.alignment.words.end(),
                         [](const dsp::AlignedWord& w) { return w.placed; });
}

TEST(AlignText, EspeakSpeechBoundariesMatchItsOwnTimings) {
    const auto s = speak(kLine);
    const auto r = align(wav("align_line.wav", s.samples, s.rate), kLine);
    EXPECT_FALSE(r.fellBack);
    EXPECT_GE(placed(r), 7u);
    // The aligner's own boundaries (before words it is unsure of get audio-only analysis).
    const auto errors = boundaryErrors(r.alignment.schedule, s.labels);
    ASSERT_GT(errors.size(), 20u);
    EXPECT_LE(errors[errors.size() / 2], 0.015);  // median
    // Issue 11 asks for 95 % within 50 ms over a corpus (replay.dev_corpus_alignment checks
    // 72 files); in one line of 27 boundaries, no more than three beyond it. (The second pass
    // on the voice's own templates moves one here, /p/ to /ɪ/ in "puppets", from 3 to 54 ms,
    // while over the corpus it lowers the 95th percentile from 42.5 to 41.5 ms.)
    EXPECT_LE(std::count_if(errors.begin(), errors.end(), [](double e) { return e > 0.050; }), 3);
    // The schedule covers the file without gaps.
    EXPECT_DOUBLE_EQ(r.schedule.front().start, 0.0);
    for (std::size_t i = 1; i < r.schedule.size(); ++i)
        EXPECT_NEAR(r.schedule[i].start, r.schedule[i - 1].end, 1e-9);
    EXPECT_NEAR(r.schedule.back().end, r.durationSeconds, 1e-9);
    // The jaw heard in every frame travels with the levels, marked as aligned speech's (the
    // pose set's heard_jaw_aligned share).
    EXPECT_TRUE(r.levels.aligned);
    ASSERT_EQ(r.levels.jaw.size(), r.levels.db.size());
    EXPECT_GT(*std::max_element(r.levels.jaw.begin(), r.levels.jaw.end()), 0.5f);
}

// A puppet's lines in French, Spanish, Bulgarian or Romanian are aligned on the phonemes espeak-ng
// reads in that language (config/phonemes/espeak-LANG.toml), as Russian and English are: the
// words placed, and the boundaries where espeak-ng's own timings put them, although no French,
// Bulgarian or Romanian speech trained the templates.
TEST(AlignText, LinesInOtherLanguagesAreAlignedOnTheirOwnPhonemes) {
    const std::vector<std::pair<std::string, std::string>> lines = {
        {"fr", "Bonjour les enfants, voulez-vous voir mon spectacle?"},
        {"es", "Buenos días, amigos, bienvenidos al teatro de marionetas."},
        {"bg", "Добър ден, деца, елате да гледате представлението."},
        {"ro", "Bună ziua, copii, veniți să vedeți spectacolul nostru."}};
    for (const auto& [voice, text] : lines) {
        const auto s = speak(text, voice);
        const auto r = alignText(synth(), wav("align_" + voice + ".wav", s.samples, s.rate), text,
                                 voice, dsp::TemplateSet::loadDefault());
        EXPECT_FALSE(r.fellBack) << voice;
        // At most one short word left to audio-only analysis (Spanish "al" lies at the
        // confidence floor, placed or not by what espeak-ng synthesised before).
        EXPECT_GE(placed(r) + 1, r.alignment.words.size()) << voice;
        const auto errors = boundaryErrors(r.alignment.schedule, s.labels);
        ASSERT_GT(errors.size(), 20u) << voice;
        // Issue 11's goal for espeak-ng speech, median within 15 ms, holds in every language
        // (measured 6.5-9.5 ms; 90th percentile 30-43 ms).
        EXPECT_LE(errors[errors.size() / 2], 0.015) << voice;
        EXPECT_LE(errors[errors.size() * 9 / 10], 0.050) << voice;
    }
}

// Voices the templates were not trained on: aligned a second time on templates moved toward the
// voice's own frames (AlignerConfig::fileAdaptationPriorFrames), the boundaries come closer.
TEST(AlignText, ASecondPassOnTheVoiceItselfBringsBoundariesCloser) {
    const std::vector<std::pair<std::string, std::string>> lines = {
        {"The old lighthouse keeper waved at every passing ship.", "en-gb+f4"},
        {"The old lighthouse keeper waved at every passing ship.", "en-us+klatt3"},
        {"Bring me the red umbrella before the storm arrives.", "en-us+klatt3"}};
    const auto templates = dsp::TemplateSet::loadDefault();
    double onePass = 0, twoPasses = 0;
    for (const auto& [text, voice] : lines) {
        const auto s = speak(text, voice, 170);
        const auto file = wav("align_second_pass.wav", s.samples, s.rate);
        auto meanError = [&](float prior) {
            dsp::AlignerConfig config;
            config.fileAdaptationPriorFrames = prior;
            const auto r = alignText(synth(), file, text, "en-us", templates, {}, config);
            EXPECT_FALSE(r.fellBack) << voice << ": " << text;
            const auto e = boundaryErrors(r.alignment.schedule, s.labels);
            double sum = 0;
            for (double x : e) sum += x;
            return e.empty() ? 1.0 : sum / static_cast<double>(e.size());
        };
        onePass += meanError(0);
        twoPasses += meanError(dsp::AlignerConfig{}.fileAdaptationPriorFrames);
    }
    // Measured 14.8 → 14.3 ms (mean boundary error). Since the minimum durations grew
    // (AlignerConfig::minFractionOfExpected) the first pass comes closer on its own, and the
    // second's gain on these lines fell from 5 % to 3 %; on the espeak-ng dev corpus it still
    // takes p95 from 37.5 to 35.5 ms (bench/align_accuracy).
    EXPECT_LT(twoPasses, onePass * 0.98)
        << "one pass " << onePass / 3 << " s, two " << twoPasses / 3;
}

// The aligner weighs a share of what the class network and the set's class bias add to the
// templates' distances (AlignerConfig::classNetworkShare), in both passes: a class biased far
// against gets fewer frames with the share and the same as without the bias at none.
TEST(AlignText, TheClassNetworksShareReachesBothPasses) {
    const auto s = speak(kLine);
    const auto file = wav("align_network_share.wav", s.samples, s.rate);
    auto against = dsp::TemplateSet::loadDefault();
    against.classBiasDb["z"] = 20;  // "puppets", "sang", "song"
    const auto seconds = [&](const dsp::TemplateSet& t, float share, float prior) {
        dsp::AlignerConfig config;
        config.classNetworkShare = share;
        config.fileAdaptationPriorFrames = prior;
        const auto r = alignText(synth(), file, kLine, "en-us", t, {}, config);
        EXPECT_FALSE(r.fellBack);
        double z = 0;
        for (const auto& seg : r.alignment.schedule)
            if (seg.phoneme == "z") z += seg.end - seg.start;
        return z;
    };
    const auto plain = dsp::TemplateSet::loadDefault();
    const float share = dsp::AlignerConfig{}.classNetworkShare;
    ASSERT_GT(share, 0);
    for (const float prior : {0.0f, 3.0f}) {
        EXPECT_DOUBLE_EQ(seconds(against, 0, prior), seconds(plain, 0, prior)) << prior;
        EXPECT_LT(seconds(against, share, prior), 0.8 * seconds(plain, share, prior)) << prior;
    }
}

// The voice through a dull microphone (a one-pole low-pass, 12 dB down by 3 kHz): a channel the
// templates never heard.
Spoken dull(Spoken s) {
    float y = 0;
    for (auto& x : s.samples) x = y = 0.25f * x + 0.75f * y;
    return s;
}

// A show's lines by one voice: each line starts from templates moved toward what the earlier
// lines placed (dsp::SpeakerAdaptation carried by alignFile), and a later line comes closer.
TEST(AlignText, ASpeakersEarlierLinesBringALaterLineCloser) {
    const std::string voice = "en-us+klatt3";
    const auto templates = dsp::TemplateSet::loadDefault();
    dsp::SpeakerAdaptation speaker(templates);
    for (const std::string text : {"The old lighthouse keeper waved at every passing ship.",
                                   "Nobody knew why the clock stopped at midnight."}) {
        const auto s = dull(speak(text, voice, 170));
        alignText(synth(), wav("align_earlier.wav", s.samples, s.rate), text, "en-us", templates,
                  {}, {}, {}, std::nullopt, true, &speaker);
    }
    ASSERT_GT(speaker.frames(), 100u);
    const std::string later = "Bring me the red umbrella before the storm arrives.";
    const auto s = dull(speak(later, voice, 170));
    const auto file = wav("align_later.wav", s.samples, s.rate);
    auto meanError = [&](dsp::SpeakerAdaptation* carried) {
        // The speaker's effect alone, without the file's own pass or the class network's share
        // (with it, on these two short lines of espeak-ng, the later line comes out at 17.1 ms
        // cold and 21.5 ms after them; on the six voices held out for decisions, aligned, the
        // carried voice adds 11.8 points of visual groups with the share, 15.2 without:
        // AlignerConfig::classNetworkShare).
        dsp::AlignerConfig onePass;
        onePass.fileAdaptationPriorFrames = 0;
        onePass.classNetworkShare = 0;
        const auto r = alignText(synth(), file, later, "en-us", templates, {}, onePass, {},
                                 std::nullopt, true, carried);
        EXPECT_FALSE(r.fellBack);
        const auto e = boundaryErrors(r.alignment.schedule, s.labels);
        double sum = 0;
        for (double x : e) sum += x;
        return sum / static_cast<double>(std::max<std::size_t>(1, e.size()));
    };
    const double cold = meanError(nullptr);
    const auto before = speaker.frames();
    const double warm = meanError(&speaker);
    // Measured 26.2 → 25.7 ms: two short lines move the templates a little (a prior of 30
    // frames); on the real dev speakers, over many lines, the gain is larger (README).
    EXPECT_LT(warm, cold) << "cold " << cold << " s, after two lines " << warm << " s";
    EXPECT_GT(speaker.frames(), before);  // the later line is learnt too
}

TEST(AlignText, WordsTheSpeakerSkippedAreNotPlacedAndSaid) {
    const auto s = speak(kLine);
    const auto r = align(wav("align_skip.wav", s.samples, s.rate),
                         "Seven puppets sang a happy little song about the moon.");
    EXPECT_FALSE(r.fellBack);
    ASSERT_EQ(r.alignment.words.size(), 10u);
    EXPECT_FALSE(r.alignment.words[4].placed);  // happy
    EXPECT_FALSE(r.alignment.words[5].placed);  // little
    EXPECT_GE(placed(r), 6u);
    bool named = false;
    for (const auto& w : r.warnings) named |= w.find("'happy'") != std::string::npos;
    EXPECT_TRUE(named);
}

TEST(AlignText, MusicBeforeAndAfterTheLineIsLeftToAudioOnlyAnalysis) {
    const auto s = speak(kLine);
    std::vector<float> music;
    auto addChord = [&](double seconds) {
        for (int i = 0; i < static_cast<int>(seconds * s.rate); ++i) {
            const double t = static_cast<double>(i) / s.rate;
            music.push_back(static_cast<float>(
                0.1 * (std::sin(2 * M_PI * 220 * t) + std::sin(2 * M_PI * 277 * t) +
                       std::sin(2 * M_PI * 330 * t) + std::sin(2 * M_PI * 880 * t))));
        }
    };
    addChord(1.0);
    music.insert(music.end(), s.samples.begin(), s.samples.end());
    addChord(1.0);
    const auto r = align(wav("align_music.wav", music, s.rate), kLine);
    EXPECT_FALSE(r.fellBack);
    EXPECT_GE(placed(r), 6u);
    EXPECT_GT(r.alignment.words.front().start, 0.9);
    EXPECT_LT(r.alignment.words.back().end, r.durationSeconds - 0.9);
}

TEST(AlignText, TheWrongTextIsFlaggedNotForced) {
    const auto s = speak(kLine);
    const auto r =
        align(wav("align_wrong.wav", s.samples, s.rate), "Fish chips vinegar sauce, which wish?");
    EXPECT_LE(placed(r), 3u);  // of 6
    EXPECT_FALSE(r.warnings.empty());
    EXPECT_FALSE(r.schedule.empty());  // audio-only analysis stands in
}

TEST(AlignText, NumbersAreReadAsEspeakReadsThem) {
    const auto script =
        scriptForText(synth(), "I have 3 puppets", "en-us", espeakMapForVoice("en-us"), nullptr);
    ASSERT_EQ(script.size(), 4u);
    EXPECT_EQ(script[2].text, "3");
    std::string phonemes;
    for (const auto& p : script[2].phonemes) phonemes += p.phoneme + " ";
    EXPECT_EQ(phonemes, "th r ih ");
}

TEST(AlignText, EmptyTextIsAnError) {
    const auto s = speak(kLine);
    const auto file = wav("align_empty.wav", s.samples, s.rate);
    EXPECT_THROW(align(file, ""), InputError);
    EXPECT_THROW(align(file, "  \n\t "), InputError);
}

TEST(AlignText, TextInAScriptTheVoiceCannotReadIsAnError) {
    const auto s = speak(kLine);
    const auto file = wav("align_script.wav", s.samples, s.rate);
    try {
        align(file, "日本語 Привет");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no words"), std::string::npos) << e.what();
    }
    // A paragraph is quoted on one line, and cut short.
    try {
        align(file,
              "Покалывало грудь,\nстучала кровь в виски, но дышалось легко, - воздух был "
              "тонок и сух.\n");
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_NE(what.find("'Покалывало грудь, стучала"), std::string::npos) << what;
        EXPECT_NE(what.find("…'"), std::string::npos) << what;
        EXPECT_EQ(what.find("сух"), std::string::npos) << what;
    }
    // Mixed: the readable words are aligned, the others left to audio-only analysis.
    const auto r = align(file, "Seven puppets Привет sang a song about the moon.");
    EXPECT_GE(placed(r), 6u);
    bool warned = false;
    for (const auto& w : r.warnings) warned |= w.find("cannot read") != std::string::npos;
    EXPECT_TRUE(warned);
}

// Accents written as combining marks (decomposed text: "e" + U+0301) are the Latin letter's own:
// such words are read, not left out as another script.
TEST(AlignText, DecomposedAccentsAreReadAsTheirLetters) {
    const auto s = speak(kLine);
    const auto file = wav("align_nfd.wav", s.samples, s.rate);
    const auto r = align(file, "Seven puppets sang a song about the moon, cafe\u0301.");
    for (const auto& w : r.warnings) EXPECT_EQ(w.find("cannot read"), std::string::npos) << w;
    const auto vi = scriptForText(synth(), "Chie\u0302\u0301c die\u0302\u0300u.", "vi",
                                  espeakMapForVoice("vi"), nullptr);
    EXPECT_EQ(vi.size(), 2u);
}

// A short clip in a noisy room (the room 34 dB under the word, within the 35 dB the speech
// lies under its peak): the room is not speech, so the speaking rate is the word's own.
TEST(AlignText, TheRoomOfAShortClipDoesNotCountAsSpeech) {
    const auto s = speak("Moon.");
    std::vector<float> clip(static_cast<std::size_t>(s.rate), 0.0f);  // 0.5 s room each side
    clip.insert(clip.begin() + s.rate / 2, s.samples.begin(), s.samples.end());
    double peak = 0;
    for (auto v : s.samples) peak = std::max(peak, double(std::abs(v)));
    std::uint32_t seed = 1;
    // Uniform noise 40 dB under the word's peak sample: about 32 dB under its loudest 10 ms.
    for (auto& v : clip) {
        seed = seed * 1664525u + 1013904223u;
        v += static_cast<float>(peak * 0.017 * ((seed >> 8) / double(1 << 24) * 2 - 1));
    }
    const auto quiet = align(wav("align_room_quiet.wav", s.samples, s.rate), "Moon.");
    const auto noisy = align(wav("align_room_noisy.wav", clip, s.rate), "Moon.");
    EXPECT_NEAR(noisy.timeScale, quiet.timeScale, 0.25 * quiet.timeScale)
        << "the room was taken for speech";
}

TEST(AlignText, SilenceOnlyFallsBackWithAWarning) {
    const auto r = align(wav("align_silence.wav", std::vector<float>(44100, 0.0f), 22050), kLine);
    EXPECT_TRUE(r.fellBack);
    EXPECT_EQ(placed(r), 0u);
    ASSERT_FALSE(r.warnings.empty());
    EXPECT_NE(r.warnings.front().find("no speech"), std::string::npos) << r.warnings.front();
}

TEST(AlignText, AudioFarShorterThanTheWordsFallsBackWithAWarning) {
    const auto s = speak("Moon.");
    const auto r = align(wav("align_short.wav", s.samples, s.rate),
                         "Seven puppets sang a song about the moon, and then another song about "
                         "the sun, the stars and the sea, and then they went to bed.");
    EXPECT_TRUE(r.fellBack);
    bool said = false;
    for (const auto& w : r.warnings) said |= w.find("far shorter") != std::string::npos;
    EXPECT_TRUE(said);
    EXPECT_FALSE(r.schedule.empty());
    EXPECT_FALSE(r.levels.aligned);  // audio-only analysis: the audio-only share of the jaw
}

// The service's path: a FILE.txt beside FILE.wav is used, and said so; without one, or with
// words that cannot be used, the audio-only analysis.
TEST(AlignText, WordsBesideAPlayedFileAreUsedAndLogged) {
    const auto s = speak(kLine);
    const auto file = wav("align_clip.wav", s.samples, s.rate);
    auto words = file;
    words.replace_extension(".txt");
    std::filesystem::remove(words);
    std::vector<std::string> log;
    auto logger = [&](const std::string& line) { log.push_back(line); };
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto audioOnly =
        scheduleForClip(synth(), file, std::nullopt, "en-us", templates, {}, logger);
    EXPECT_TRUE(log.empty());
    EXPECT_EQ(audioOnly, dsp::analyzeFile(file, templates, PhonemeSet::common()).schedule);

    std::ofstream(words) << kLine << '\n';
    const auto aligned =
        scheduleForClip(synth(), file, std::nullopt, "en-us", templates, {}, logger);
    ASSERT_FALSE(log.empty());
    EXPECT_NE(log.front().find(words.string()), std::string::npos) << log.front();
    const auto errors = boundaryErrors(aligned, s.labels);
    EXPECT_LE(errors[errors.size() / 2], 0.015);

    log.clear();
    std::ofstream(words) << "  \n";  // empty words: said, and audio-only analysis
    EXPECT_EQ(scheduleForClip(synth(), file, std::nullopt, "en-us", templates, {}, logger),
              audioOnly);
    ASSERT_FALSE(log.empty());
    EXPECT_NE(log.front().find("not used"), std::string::npos) << log.front();
    std::filesystem::remove(words);

    // A file cut short is played as far as it goes, and the log says so, aligned or not.
    std::filesystem::resize_file(file, std::filesystem::file_size(file) / 2);
    for (const auto& text : {std::optional<std::string>(), std::optional<std::string>(kLine)}) {
        log.clear();
        EXPECT_FALSE(scheduleForClip(synth(), file, text, "en-us", templates, {}, logger).empty());
        EXPECT_TRUE(std::any_of(log.begin(), log.end(), [&](const std::string& line) {
            return line.find(file.string() + ": truncated") != std::string::npos;
        })) << (text ? "aligned" : "audio only");
    }
}

// The service's show voice (lipsyncd's adapt_speaker): lines played with their words teach the
// speaker, and a later file played without words is recognised on what they taught.
TEST(AlignText, AFileWithoutWordsIsRecognisedOnTheVoiceTheLinesBeforeTaught) {
    const std::string voice = "en-us+klatt3";
    const auto templates = dsp::TemplateSet::loadDefault();
    dsp::SpeakerAdaptation speaker(templates);
    const auto quiet = [](const std::string&) {};
    for (const std::string text : {"The old lighthouse keeper waved at every passing ship.",
                                   "Nobody knew why the clock stopped at midnight.",
                                   "Bring me the red umbrella before the storm arrives."}) {
        const auto s = dull(speak(text, voice, 170));
        scheduleForClip(synth(), wav("show_line.wav", s.samples, s.rate), text, "en-us", templates,
                        {}, quiet, nullptr, &speaker);
    }
    ASSERT_GT(speaker.frames(), 150u);
    const auto s = dull(speak(kLine, voice, 170));
    const auto file = wav("show_unscripted.wav", s.samples, s.rate);
    std::filesystem::remove(std::filesystem::path(file).replace_extension(".txt"));
    auto groups = [&](dsp::SpeakerAdaptation* carried) {
        const auto schedule = scheduleForClip(synth(), file, std::nullopt, "en-us", templates, {},
                                              quiet, nullptr, carried);
        return dsp::scoreSchedule(schedule, s.labels, PhonemeSet::common()).groupAccuracy();
    };
    const auto learnt = speaker.frames();
    const double cold = groups(nullptr);
    const double warm = groups(&speaker);
    // Measured 60.9 → 65.7 %.
    EXPECT_GT(warm, cold) << "visual groups " << cold << " on the shipped templates, " << warm
                          << " on the voice the lines taught";
    EXPECT_EQ(speaker.frames(), learnt);  // without words nothing is learnt
}

}  // namespace
}  // namespace lipsyncd
