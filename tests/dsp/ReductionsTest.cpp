// Common reductions (config/reductions/en.toml): loaded and checked, turned into alternative
// pronunciations, and a reduced utterance aligns better with them than without.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "TestSpeech.hpp"
#include "TestSynth.hpp"

namespace lipsyncd {
namespace {

EspeakSynthesizer& synth() {
    return test::espeak();
}

std::string classes(const PhonemeSchedule& s) {
    std::string out;
    for (const auto& p : s) out += (out.empty() ? "" : " ") + p.phoneme;
    return out;
}

std::filesystem::path writeText(const std::string& name, const std::string& text) {
    const auto file = std::filesystem::temp_directory_path() / name;
    std::ofstream(file) << text;
    return file;
}

std::string errorOf(const std::filesystem::path& file) {
    try {
        Reductions::load(file, espeakMapForVoice("en-us"));
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(Reductions, TheShippedEnglishFileLoads) {
    const auto map = espeakMapForVoice("en-us");
    EXPECT_NO_THROW(Reductions::forVoice("en-gb+f2", map));
    // A language without a file has no reductions, not an error.
    const auto none = Reductions::forVoice("xx", map);
    SpokenWord word{"and", {{0, 0.05, "a", 1.0f}, {0.05, 0.1, "n", 1.0f}, {0.1, 0.15, "d", 1.0f}}};
    EXPECT_TRUE(none.alternatives(word, nullptr, map, PhonemeSet::common()).empty());
}

TEST(Reductions, BadFilesNameTheLineAndPhoneme) {
    auto e = errorOf(writeText("red_bad.toml", "name = \"en\"\n[words]\n\"and\" = [\"@ n QQ\"]\n"));
    EXPECT_NE(e.find("red_bad.toml:3"), std::string::npos) << e;
    EXPECT_NE(e.find("'QQ'"), std::string::npos) << e;
    e = errorOf(writeText("red_case.toml", "name = \"en\"\n[words]\n\"And\" = [\"@ n\"]\n"));
    EXPECT_NE(e.find("lower case"), std::string::npos) << e;
    e = errorOf(writeText("red_rule.toml", "name = \"en\"\n[rules]\ndrop_everything = [\"t\"]\n"));
    EXPECT_NE(e.find("drop_everything"), std::string::npos) << e;
    e = errorOf(writeText("red_empty.toml", "name = \"en\"\n[words]\n\"to\" = [\" \"]\n"));
    EXPECT_NE(e.find("empty"), std::string::npos) << e;
}

TEST(Reductions, WeakFormsAndRulesGiveAlternatives) {
    const auto map = espeakMapForVoice("en-us");
    const auto reductions = Reductions::forVoice("en-us", map);
    const auto script =
        scriptForText(synth(), "bread and butter, last night", "en-us", map, nullptr, &reductions);
    ASSERT_EQ(script.size(), 5u);
    std::vector<std::string> forms;
    for (const auto& a : script[1].alternatives) forms.push_back(classes(a));
    // "and": /ən/, /n/, and /æn/ with its d dropped before the b of "butter".
    EXPECT_NE(std::find(forms.begin(), forms.end(), "d"), forms.end());
    EXPECT_NE(std::find(forms.begin(), forms.end(), "ah d"), forms.end());
    // "last night": the t between s and n may go.
    forms.clear();
    for (const auto& a : script[3].alternatives) forms.push_back(classes(a));
    EXPECT_EQ(classes(script[3].phonemes), "l ah z d");
    EXPECT_NE(std::find(forms.begin(), forms.end(), "l ah z"), forms.end());
    // "night" ends the text: no word after it, no t/d deletion.
    EXPECT_TRUE(script[4].alternatives.empty());
    // Without reductions, only espeak-ng's reading.
    const auto plain = scriptForText(synth(), "bread and butter", "en-us", map, nullptr);
    EXPECT_TRUE(plain[1].alternatives.empty());
}

// Russian clitics said unstressed: espeak-ng reads "Со" as a stressed /so/; its weak form /sɐ/
// is offered whatever the case and the quotes around the written word.
TEST(Reductions, RussianCliticsGetTheirWeakFormsWrittenAnyWay) {
    const auto map = espeakMapForVoice("ru");
    const auto reductions = Reductions::forVoice("ru", map);
    const auto script =
        scriptForText(synth(), "«Со спокойным» к нему", "ru", map, nullptr, &reductions);
    ASSERT_EQ(script.size(), 4u);
    EXPECT_EQ(classes(script[0].phonemes), "z ao");
    ASSERT_EQ(script[0].alternatives.size(), 1u);
    EXPECT_EQ(classes(script[0].alternatives[0]), "z ah");
    // "к", read alone as its letter's name /ka/, is said as /k/ only.
    ASSERT_EQ(script[2].alternatives.size(), 1u);
    EXPECT_EQ(classes(script[2].alternatives[0]), "kg");
    EXPECT_TRUE(script[1].alternatives.empty());
}

// espeak-ng's speech of `text` with some of its sounds cut out (word index, mnemonic), and
// its labels with the same sounds cut: a speaker who reduces.
struct Reduced {
    std::vector<float> samples;
    int rate = 0;
    PhonemeSchedule labels;
};

Reduced speakReduced(const std::string& text, const std::vector<std::pair<int, std::string>>& cut) {
    const auto s = synth().synthesize({text, "en-us+m3", 160, -1});
    std::vector<std::pair<double, double>> gone;
    for (const auto& [w, phoneme] : cut)
        for (const auto& p : s.words.at(static_cast<std::size_t>(w)).phonemes)
            if (p.phoneme == phoneme) gone.emplace_back(p.start, p.end);
    const auto removedBefore = [&](double t) {
        double d = 0;
        for (const auto& [a, b] : gone)
            if (b <= t + 1e-9) d += b - a;
        return d;
    };
    const auto isGone = [&](double t) {
        return std::any_of(gone.begin(), gone.end(),
                           [&](const auto& g) { return t >= g.first && t < g.second; });
    };
    Reduced out;
    out.rate = s.sampleRate;
    for (std::size_t i = 0; i < s.samples.size(); ++i)
        if (!isGone(static_cast<double>(i) / s.sampleRate))
            out.samples.push_back(s.samples[i] / 32768.0f);
    PhonemeSchedule raw;
    for (const auto& p : s.phonemes)
        if (!isGone(p.start) || p.end - p.start < 1e-9)
            raw.push_back(
                {p.start - removedBefore(p.start), p.end - removedBefore(p.end), p.phoneme, 1.0f});
    out.labels = mapSchedule(raw, espeakMapForVoice("en-us"), nullptr);
    return out;
}

double meanBoundaryError(const PhonemeSchedule& hyp, const PhonemeSchedule& ref) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 1; i < ref.size(); ++i, ++n) {
        double best = 0.1;
        for (std::size_t j = 1; j < hyp.size(); ++j)
            if (hyp[j - 1].phoneme == ref[i - 1].phoneme && hyp[j].phoneme == ref[i].phoneme)
                best = std::min(best, std::abs(hyp[j].start - ref[i].start));
        sum += best;
    }
    return n ? sum / n : 0;
}

TEST(Reductions, AReducedUtteranceAlignsBetterWithThem) {
    const std::string text = "We ate bread and butter and jam last night, and then we went to bed.";
    // Every "and" said as a bare /n/, "las' night", "wen' to".
    const auto s = speakReduced(
        text, {{3, "a"}, {3, "d"}, {5, "a"}, {5, "d"}, {7, "t"}, {9, "a"}, {9, "d"}, {12, "t"}});
    const auto file =
        test::writeAudio("reduced.wav", s.samples, s.rate, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto with =
        alignText(synth(), file, text, "en-us", templates, {}, {}, {}, std::nullopt, true);
    const auto without =
        alignText(synth(), file, text, "en-us", templates, {}, {}, {}, std::nullopt, false);
    const double errWith = meanBoundaryError(with.alignment.schedule, s.labels);
    const double errWithout = meanBoundaryError(without.alignment.schedule, s.labels);
    EXPECT_LT(errWith, errWithout * 0.9) << "with " << errWith << " s, without " << errWithout;
}

}  // namespace
}  // namespace lipsyncd
