// espeak-ng synthesis: the audio and the phoneme events must agree, since every label in the
// training and dev corpora comes from these events.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <lipsyncd/tts.hpp>
#include <thread>

namespace lipsyncd {
namespace {

double rmsDbfs(const SynthesizedSpeech& s, double from, double to) {
    const auto a = static_cast<std::size_t>(from * s.sampleRate);
    const auto b = std::min(s.samples.size(), static_cast<std::size_t>(to * s.sampleRate));
    double sum = 0;
    for (std::size_t i = a; i < b; ++i) sum += double(s.samples[i]) * s.samples[i];
    return 10 * std::log10(sum / std::max<std::size_t>(1, b - a) / (32768.0 * 32768.0) + 1e-12);
}

EspeakSynthesizer& synthesizer() {
    static EspeakSynthesizer synth;  // espeak-ng allows one at a time
    return synth;
}

SynthesizedSpeech speak(const std::string& text, int rate = 165) {
    return synthesizer().synthesize({text, "en-us", rate, -1});
}

// A synthesiser made after another was destroyed speaks too (espeak-ng is initialised once a
// process: terminating and initialising it again used to hang the second, for ever). Run in a
// thread with a deadline, so a hang fails the test instead of the run. (ctest runs each test in
// its own process; in one run of the whole binary the shared synthesiser above may be alive.)
TEST(EspeakSynthesizer, ASecondSynthesiserAfterTheFirstSpeaksToo) {
    try {
        EspeakSynthesizer first;
        ASSERT_FALSE(first.synthesize({"One.", "en-us", 165, -1}).samples.empty());
    } catch (const std::runtime_error& e) {
        GTEST_SKIP() << "another synthesiser is alive in this process: " << e.what();
    }
    std::promise<std::size_t> spoken;
    auto second = spoken.get_future();
    std::thread([done = std::move(spoken)]() mutable {
        EspeakSynthesizer again;
        done.set_value(again.synthesize({"Two.", "en-us", 165, -1}).samples.size());
    }).detach();  // left behind if it hangs: the process ends with the test run
    ASSERT_EQ(second.wait_for(std::chrono::seconds(30)), std::future_status::ready)
        << "the second synthesiser hangs";
    EXPECT_GT(second.get(), 1000u);
    EXPECT_THROW(EspeakSynthesizer("/nonexistent/espeak-ng-data"), std::runtime_error);
}

TEST(EspeakSynthesizer, EveryPhonemeEventFallsInsideTheAudio) {
    // Several sentences: espeak-ng then delivers audio chunks that carry no events.
    const auto s = speak("Hello there! I am a puppet. Watch my mouth move, and wave back at me.");
    const double total = static_cast<double>(s.samples.size()) / s.sampleRate;
    ASSERT_FALSE(s.phonemes.empty());
    // The final phoneme is the closing pause; the word before it ("me") must be in the schedule.
    bool sawLastVowel = false;
    for (const auto& p : s.phonemes) sawLastVowel |= p.phoneme == "i:";
    EXPECT_TRUE(sawLastVowel);
    EXPECT_NEAR(s.phonemes.back().end, total, 0.001);
}

TEST(EspeakSynthesizer, PausesInTheEventsAreQuietInTheAudio) {
    const auto s = speak("Hello there! I am a puppet. Watch my mouth move.");
    const double speech = rmsDbfs(s, 0, static_cast<double>(s.samples.size()) / s.sampleRate);
    int pauses = 0;
    for (const auto& p : s.phonemes) {
        if (p.phoneme.rfind('_', 0) != 0 || p.end - p.start < 0.08) continue;
        ++pauses;
        EXPECT_LT(rmsDbfs(s, p.start + 0.02, p.end - 0.02), speech - 30)
            << "pause at " << p.start << "-" << p.end << " s is not quiet";
    }
    EXPECT_GE(pauses, 2);
}

// espeak-ng reports a coda /l/ before a pause at the same position as the pause ("well" is w,
// E over the whole vowel-and-l, l at 0 ms): the words the aligner follows must keep it, with
// a share of the vowel's time, or every "ball", "hotel" and "girl" loses its /l/.
TEST(EspeakSynthesizer, AWordKeepsTheCodaLEspeakReportsAtZeroLength) {
    for (const std::string text : {"well", "ball", "girl"}) {
        const auto s = speak(text);
        ASSERT_EQ(s.words.size(), 1u) << text;
        const auto& p = s.words[0].phonemes;
        const auto l = std::find_if(p.begin(), p.end(),
                                    [](const PhonemeSegment& x) { return x.phoneme == "l"; });
        ASSERT_NE(l, p.end()) << text << ": no l";
        EXPECT_GT(l->duration(), 0.03) << text;
        ASSERT_NE(l, p.begin());
        EXPECT_DOUBLE_EQ((l - 1)->end, l->start) << text;  // it shares, nothing overlaps
        EXPECT_GT((l - 1)->duration(), 0.03) << text;
    }
}

// espeak-ng voices a Russian consonant + /r/ cluster with a short vowel ("пр" is p @- r); a
// speaker says none (festvox-ru's own labels have none), so the words the aligner follows
// must not open the jaw there.
TEST(EspeakSynthesizer, RussianClustersWithRGetNoVowelInTheAlignersWords) {
    const auto map = espeakMapForVoice("ru");
    const auto script = scriptForText(synthesizer(), "Прямо, утро, книга.", "ru", map, nullptr);
    ASSERT_EQ(script.size(), 3u);
    const auto& pryamo = script[0].phonemes;  // p r ja m V
    ASSERT_GE(pryamo.size(), 2u);
    EXPECT_EQ(pryamo[0].phoneme, "bmp");
    EXPECT_EQ(pryamo[1].phoneme, "r");
    const auto& utro = script[1].phonemes;  // u t r V
    ASSERT_GE(utro.size(), 3u);
    EXPECT_EQ(utro[1].phoneme, "d");
    EXPECT_EQ(utro[2].phoneme, "r");
}

// Before a word set off by a dash espeak-ng places the word's event on the dash: the word
// list of an alignment named it "-" (festvox-ru's "а он - в направлении").
TEST(EspeakSynthesizer, AWordAfterADashIsNamedNotTheDash) {
    const auto en = scriptForText(synthesizer(), "a house - in, the town", "en-us",
                                  espeakMapForVoice("en-us"), nullptr);
    std::vector<std::string> words;
    for (const auto& w : en) words.push_back(w.text);
    EXPECT_EQ(words, (std::vector<std::string>{"a", "house", "in", "the", "town"}));
    const auto ru = scriptForText(synthesizer(), "а он - в направлении", "ru",
                                  espeakMapForVoice("ru"), nullptr);
    ASSERT_EQ(ru.size(), 4u);
    EXPECT_EQ(ru[2].text, "в");
}

// The mouth classes of a word in another language, as the aligner sees them (pauses are the
// gaps' job, not the word's).
std::vector<std::string> classesOf(const std::string& text, const std::string& voice,
                                   std::size_t word) {
    const auto script =
        scriptForText(synthesizer(), text, voice, espeakMapForVoice(voice), nullptr);
    std::vector<std::string> out;
    if (word < script.size())
        for (const auto& p : script[word].phonemes)
            if (p.phoneme != "sil") out.push_back(p.phoneme);
    return out;
}

// French, Spanish, Bulgarian, Romanian, Czech, Dutch, Catalan, Belarusian, Greek and Danish lines
// are said and aligned through their own maps (config/phonemes/espeak-fr.toml, -es, -bg, -ro,
// -cs, -nl, -ca, -be, -el, -da): the lips close for m, b and p, meet the teeth for f and v, round
// for ou and u, and the jaw opens for a, whatever the language's own letters.
TEST(EspeakSynthesizer, WordsInOtherLanguagesTakeTheMouthTheirSoundsNeed) {
    EXPECT_EQ(classesOf("Bonjour, ma petite fille.", "fr", 1),
              (std::vector<std::string>{"bmp", "ah"}));
    EXPECT_EQ(classesOf("du fromage", "fr", 1),  // f R o m a Z
              (std::vector<std::string>{"f", "r", "ow", "bmp", "aa", "sh"}));
    EXPECT_EQ(classesOf("vous", "fr", 0), (std::vector<std::string>{"f", "w"}));
    EXPECT_EQ(classesOf("Buenos días, mamá.", "es", 2),
              (std::vector<std::string>{"bmp", "aa", "bmp", "aa"}));
    EXPECT_EQ(classesOf("fruta", "es", 0), (std::vector<std::string>{"f", "r", "w", "d", "aa"}));
    EXPECT_EQ(classesOf("Мама, обичам плодове.", "bg", 0),
              (std::vector<std::string>{"bmp", "ah", "bmp", "ah"}));
    EXPECT_EQ(classesOf("плодове", "bg", 0),  // p l o d o v e
              (std::vector<std::string>{"bmp", "l", "ao", "d", "ao", "f", "eh"}));
    EXPECT_EQ(classesOf("Mama mănâncă fructe bune.", "ro", 3),
              (std::vector<std::string>{"bmp", "w", "d", "eh"}));
    EXPECT_EQ(classesOf("Máma vaří.", "cs", 0),
              (std::vector<std::string>{"bmp", "aa", "bmp", "aa"}));
    EXPECT_EQ(classesOf("řeka", "cs", 0), (std::vector<std::string>{"r", "eh", "kg", "aa"}));
    EXPECT_EQ(classesOf("krk", "cs", 0),
              (std::vector<std::string>{"kg", "r", "kg"}));  // syllabic r
    EXPECT_EQ(classesOf("těch dalších", "cs", 0),            // ch voiced before d (Q)
              (std::vector<std::string>{"d", "eh", "kg"}));
    EXPECT_EQ(classesOf("Hallo pop.", "nl", 1), (std::vector<std::string>{"bmp", "ao", "bmp"}));
    EXPECT_EQ(classesOf("wang", "nl", 0),  // w: the lower lip to the teeth
              (std::vector<std::string>{"f", "aa", "d"}));
    EXPECT_EQ(classesOf("goed", "nl", 0), (std::vector<std::string>{"kg", "w", "d"}));
    EXPECT_EQ(classesOf("La mare menja pa.", "ca", 1),  // m a ** @
              (std::vector<std::string>{"bmp", "aa", "r", "er"}));
    EXPECT_EQ(classesOf("vaca", "ca", 0),  // v: the lower lip to the teeth
              (std::vector<std::string>{"f", "aa", "kg", "ah"}));
    EXPECT_EQ(classesOf("lluna", "ca", 0), (std::vector<std::string>{"sh", "w", "d", "ah"}));
    EXPECT_EQ(classesOf("Мама п'е малако.", "be", 0),
              (std::vector<std::string>{"bmp", "ah", "bmp", "ah"}));
    EXPECT_EQ(classesOf("вуха", "be", 0), (std::vector<std::string>{"f", "w", "kg", "ah"}));
    EXPECT_EQ(classesOf("Ο μπαμπάς μου.", "el", 1),  // μπ is b
              (std::vector<std::string>{"bmp", "aa", "bmp", "aa", "z"}));
    EXPECT_EQ(classesOf("βουνό", "el", 0), (std::vector<std::string>{"f", "w", "d", "ow"}));
    EXPECT_EQ(classesOf("θέλω", "el", 0),  // θ: the tongue at the teeth, not the lips
              (std::vector<std::string>{"th", "eh", "l", "ow"}));
    EXPECT_EQ(classesOf("Mor og far.", "da", 2), (std::vector<std::string>{"f", "aa"}));
    EXPECT_EQ(classesOf("blå bøf", "da", 1),  // ø: the lips round
              (std::vector<std::string>{"bmp", "ow", "f"}));
    EXPECT_EQ(classesOf("hus", "da", 0), (std::vector<std::string>{"h", "w", "z"}));
    // Russian numbers: espeak-ng's r of три and четыре (R;) and the tap of сорок (*).
    EXPECT_EQ(classesOf("3", "ru", 0), (std::vector<std::string>{"d", "r", "ih"}));
    EXPECT_EQ(classesOf("сорок", "ru", 0),  // s V r o k
              (std::vector<std::string>{"z", "ah", "r", "ao", "kg"}));
}

// German, Italian, Portuguese, Polish and 34 more languages have maps made from espeak-ng's
// own IPA (scripts/make-phoneme-maps.py): the same mouth rules hold through them, whatever the
// language's letters.
TEST(EspeakSynthesizer, LanguagesWithGeneratedMapsTakeTheMouthTheirSoundsNeed) {
    const std::vector<std::string> mama{"bmp", "aa", "bmp", "aa"};
    for (const auto& [voice, word] :
         std::vector<std::pair<std::string, std::string>>{{"de", "mama"},
                                                          {"it", "mama"},
                                                          {"pl", "mama"},
                                                          {"uk", "мама"},
                                                          {"hi", "मामा"},
                                                          {"ka", "მამა"},
                                                          {"id", "mama"},
                                                          {"sw", "mama"}})
        EXPECT_EQ(classesOf(word, voice, 0), mama) << voice;
    EXPECT_EQ(classesOf("mamma", "is", 0),  // a long m: two of them, as espeak-ng says it
              (std::vector<std::string>{"bmp", "aa", "bmp", "bmp", "aa"}));
    EXPECT_EQ(classesOf("엄마", "ko", 0), (std::vector<std::string>{"ah", "bmp", "bmp", "ah"}));
    EXPECT_EQ(classesOf("mẹ", "vi", 0), (std::vector<std::string>{"bmp", "eh"}));
    EXPECT_EQ(classesOf("Pferd", "de", 0), (std::vector<std::string>{"bmp", "eh", "r", "d"}));
    EXPECT_EQ(classesOf("Fuß", "de", 0), (std::vector<std::string>{"f", "w", "z"}));
    EXPECT_EQ(classesOf("schön", "de", 0), (std::vector<std::string>{"sh", "ow", "d"}));
    EXPECT_EQ(classesOf("fuoco", "it", 0), (std::vector<std::string>{"f", "w", "ao", "kg", "ow"}));
    EXPECT_EQ(classesOf("obrigado", "pt", 0),  // O b r i g a d u
              (std::vector<std::string>{"ao", "bmp", "r", "ih", "kg", "aa", "d", "w"}));
    EXPECT_EQ(classesOf("obrigado", "pt-br", 0).front(), "ow");  // Brazil: a closer o
    EXPECT_EQ(classesOf("wąż", "pl", 0), (std::vector<std::string>{"f", "ao", "sh"}));
    EXPECT_EQ(classesOf("mjölk", "sv", 0),
              (std::vector<std::string>{"bmp", "sh", "ow", "l", "kg"}));
    EXPECT_EQ(classesOf("hus", "nb", 0), (std::vector<std::string>{"h", "w", "z"}));
    EXPECT_EQ(classesOf("köszönöm", "hu", 0).back(), "bmp");
    EXPECT_EQ(classesOf("hvala", "hr", 0), (std::vector<std::string>{"kg", "f", "aa", "l", "ah"}));
    for (const auto& [voice, text] : std::vector<std::pair<std::string, std::string>>{
             {"fi", "Hyvää päivää, kiitos paljon."},
             {"tr", "Günaydın çocuklar, nasılsınız?"},
             {"sk", "Ďakujem, dovidenia, mäso a kôra."}}) {
        std::vector<std::string> warnings;
        const auto script =
            scriptForText(synthesizer(), text, voice, espeakMapForVoice(voice), &warnings);
        EXPECT_GE(script.size(), 3u) << voice;
        EXPECT_TRUE(warnings.empty()) << voice << ": " << warnings.front();
    }
}

// A voice whose language has no map is an error that names the maps there are.
TEST(EspeakSynthesizer, AVoiceWithoutAMapNamesTheLanguagesThatHaveOne) {
    try {
        espeakMapForVoice("ja");
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("espeak-ja.toml"), std::string::npos) << what;
        EXPECT_NE(what.find("de, el, en"), std::string::npos) << what;
    }
}

// French espeak-ng says "tout le monde" as one dictionary entry, one word event whose length
// covers "tout": the word list named "tout" for all three words' sounds.
TEST(EspeakSynthesizer, WordsEspeakSaysAsOneAreNamedTogether) {
    const auto fr = scriptForText(synthesizer(), "Bonjour tout le monde.", "fr",
                                  espeakMapForVoice("fr"), nullptr);
    std::vector<std::string> words;
    for (const auto& w : fr) words.push_back(w.text);
    EXPECT_EQ(words, (std::vector<std::string>{"Bonjour", "tout le monde"}));
}

// When the first `phoneme` begins (-1: never).
double startOf(const SynthesizedSpeech& s, const std::string& phoneme) {
    for (const auto& p : s.phonemes)
        if (p.phoneme == phoneme) return p.start;
    return -1;
}

// A reading depends on its own request: the service reads lines in many voices and rates one
// after another, and the aligner times each line by espeak-ng's reading of it. A request
// without a rate or pitch once kept the last request's, and after a Russian line an English one
// read 6 % slower (the voice had changed the rate). espeak-ng still carries a little from one
// reading to the next (a coda /l/ before a pause reported 12 ms long instead of at no length,
// a last vowel held longer), hence the tolerance: "yellow" starts 1.4 s into the line.
TEST(EspeakSynthesizer, ARequestWithoutARateReadsAtTheDefaultWhateverCameBefore) {
    const SynthesisRequest line{"Ball. The red ball is yellow.", "en-us", 0, -1};
    const auto alone = synthesizer().synthesize(line);
    ASSERT_GT(startOf(alone, "j"), 1.0);
    synthesizer().synthesize({"Slowly, and high.", "en-us", 90, 90});
    EXPECT_NEAR(startOf(synthesizer().synthesize(line), "j"), startOf(alone, "j"), 0.025);
    synthesizer().synthesize({"Корреспондент американской газеты, проходя мимо.", "ru", 0, -1});
    EXPECT_NEAR(startOf(synthesizer().synthesize(line), "j"), startOf(alone, "j"), 0.025);
}

TEST(EspeakSynthesizer, UnknownVoiceIsAnInputErrorNamingIt) {
    try {
        synthesizer().synthesize({"hello", "xx-nowhere", 0, -1});
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("xx-nowhere"), std::string::npos) << e.what();
    }
}

TEST(EspeakSynthesizer, SpeechStopsAtTheRequestsLimitAndSaysSo) {
    const std::string text = "One two three four five six seven eight nine ten eleven twelve.";
    auto& synth = synthesizer();
    const auto whole = synth.synthesize({text, "en-us", 0, -1});
    ASSERT_GT(whole.samples.size(), static_cast<std::size_t>(2 * synth.sampleRate()));
    EXPECT_FALSE(whole.truncated);
    const auto cut = synth.synthesize({text, "en-us", 0, -1, 1.0});
    EXPECT_TRUE(cut.truncated);
    EXPECT_LE(cut.samples.size(), static_cast<std::size_t>(synth.sampleRate()) + 1);
    EXPECT_LE(cut.samples.capacity(), static_cast<std::size_t>(synth.sampleRate()) + 1)
        << "held more than the limit";
    // The next request starts afresh: nothing of the cut text is left in espeak-ng.
    const auto next = synth.synthesize({"Hello.", "en-us", 0, -1});
    EXPECT_FALSE(next.truncated);
    EXPECT_LT(next.samples.size(), whole.samples.size() / 3);
}

}  // namespace
}  // namespace lipsyncd
