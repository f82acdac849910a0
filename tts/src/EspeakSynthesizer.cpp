#include <espeak-ng/speak_lib.h>

#include <atomic>
#include <cctype>
#include <cstring>
#include <lipsyncd/tts.hpp>
#include <span>

namespace lipsyncd {

namespace {

std::atomic<bool> gInstanceAlive{false};

// Collects one synthesis: samples, and a phoneme event stream turned into segments.
struct Collector {
    std::vector<std::int16_t>* samples;
    std::size_t maxSamples = 0;  // 0: no limit
    bool truncated = false;
    std::vector<std::pair<double, std::string>> events;  // (time s, mnemonic)
    // Word starts: (character position in the text, 1-based; length in characters; the index
    // of the first phoneme event after it).
    struct Word {
        int position, length;
        std::size_t firstEvent;
    };
    std::vector<Word> words;
};

// espeak-ng hands over audio in chunks, each with the events inside it. A chunk may carry no
// events at all: its list is then only the terminator, which still carries our user_data, so
// the collector is found on every entry including the terminator (dropping such chunks loses
// audio and slides every later label).
int onSynth(short* wav, int count, espeak_EVENT* events) {
    Collector* collector = nullptr;
    for (espeak_EVENT* e = events; e; ++e) {
        if (e->user_data) collector = static_cast<Collector*>(e->user_data);
        if (collector && e->type == espeakEVENT_PHONEME) {
            char name[9] = {};
            std::memcpy(name, e->id.string, 8);
            collector->events.emplace_back(e->audio_position / 1000.0, name);
        }
        if (collector && e->type == espeakEVENT_WORD)
            collector->words.push_back({e->text_position, e->length, collector->events.size()});
        if (e->type == espeakEVENT_LIST_TERMINATED) break;
    }
    if (collector && wav && count > 0 && collector->samples) {
        auto& out = *collector->samples;
        auto n = static_cast<std::size_t>(count);
        if (collector->maxSamples && out.size() + n > collector->maxSamples) {
            n = collector->maxSamples - out.size();
            collector->truncated = true;
        }
        out.insert(out.end(), wav, wav + n);
        if (collector->truncated) return 1;  // stop synthesis: the limit is reached
    }
    return 0;  // continue synthesis
}

// espeak-ng's own pitch when none is asked for (espeak_SetParameter: 0..100).
constexpr int kDefaultPitch = 50;

// The voice file for a language code ("en-gb" -> "gmw/en"): espeak_SetVoiceByName knows voice
// names and file names, but users name voices by language, as the espeak-ng command does.
std::string voiceFileForLanguage(const std::string& language) {
    const espeak_VOICE** voices = espeak_ListVoices(nullptr);
    const espeak_VOICE* best = nullptr;
    int bestPriority = 1000;
    for (; voices && *voices; ++voices) {
        // `languages` is a list of (priority byte, NUL-terminated code), ended by a zero byte.
        for (const char* p = (*voices)->languages; p && *p; p += std::strlen(p + 1) + 2) {
            const int priority = static_cast<unsigned char>(*p);
            if (language == p + 1 && priority < bestPriority && (*voices)->identifier &&
                std::strncmp((*voices)->identifier, "mb/", 3) !=
                    0) {  // mbrola voices need extra data
                best = *voices;
                bestPriority = priority;
            }
        }
    }
    return best ? best->identifier : "";
}

bool selectVoice(const std::string& voice) {
    if (espeak_SetVoiceByName(voice.c_str()) == EE_OK) return true;
    const auto plus = voice.find('+');
    const std::string file = voiceFileForLanguage(voice.substr(0, plus));
    if (file.empty()) return false;
    const std::string withVariant = plus == std::string::npos ? file : file + voice.substr(plus);
    return espeak_SetVoiceByName(withVariant.c_str()) == EE_OK;
}

// Characters (espeak-ng counts code points from 1) to byte offsets in UTF-8 text.
std::size_t byteOffset(const std::string& text, int characters) {
    std::size_t i = 0;
    for (int c = 0; c < characters && i < text.size(); ++c) {
        ++i;
        while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
    }
    return i;
}

// A phoneme mnemonic that is a sound: not a pause (_, _:) nor a mark.
bool isSound(const std::string& name) {
    const auto first = static_cast<unsigned char>(name.empty() ? '_' : name[0]);
    return std::isalnum(first) != 0 || first == '@';
}

bool isWordByte(char c) {
    const auto b = static_cast<unsigned char>(c);
    return b >= 0x80 || std::isalnum(b) != 0;  // any byte of a non-ASCII letter counts
}

// The word at [from, to) of the text. Before a word set off by a dash ("a house - in the town")
// espeak-ng places the word's event on the dash; the word is the next one in the text.
std::string wordAt(const std::string& text, std::size_t from, std::size_t to) {
    if (from >= to || std::any_of(text.begin() + from, text.begin() + to, isWordByte))
        return text.substr(from, to - from);
    const auto isSpace = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
    const auto begin = std::find_if(text.begin() + to, text.end(), isWordByte);
    if (begin == text.end()) return text.substr(from, to - from);
    auto end = std::find_if(begin, text.end(), isSpace);
    while (!isWordByte(*(end - 1))) --end;  // "в," → "в"
    return std::string(begin, end);
}

// The words espeak-ng says as one ("tout le monde" is one entry of its French dictionary, one
// word event whose length covers "tout"): the word's text runs on to where the next word's event
// starts, so a name says every word its phonemes are (trailing spaces and marks left off).
std::string wordNamed(const std::string& text, std::size_t from, std::size_t to,
                      std::size_t nextFrom) {
    auto name = wordAt(text, from, to);
    // On a dash (marks only), wordAt has found the word after it: that is the name.
    const bool onADash =
        from < to && std::none_of(text.begin() + from, text.begin() + to, isWordByte);
    if (onADash || nextFrom <= to) return name;
    const auto rest = std::string_view(text).substr(to, nextFrom - to);
    const auto last = std::find_if(rest.rbegin(), rest.rend(), isWordByte);
    if (last != rest.rend()) name += rest.substr(0, static_cast<std::size_t>(rest.rend() - last));
    return name;
}

// Each word event owns the phoneme events from it to the next word event; pauses before the
// first word belong to none.
std::vector<SpokenWord> spokenWords(const std::string& text, const Collector& c, double total) {
    std::vector<SpokenWord> words;
    for (std::size_t w = 0; w < c.words.size(); ++w) {
        const auto& mark = c.words[w];
        const auto nextFrom =
            w + 1 < c.words.size() ? byteOffset(text, c.words[w + 1].position - 1) : text.size();
        SpokenWord word{wordNamed(text, byteOffset(text, mark.position - 1),
                                  byteOffset(text, mark.position - 1 + mark.length), nextFrom),
                        {}};
        const auto last = w + 1 < c.words.size() ? c.words[w + 1].firstEvent : c.events.size();
        std::size_t shareFrom = 0;  // the segment a run of zero-length phonemes shares
        for (std::size_t i = mark.firstEvent; i < last; ++i) {
            const double start = std::min(c.events[i].first, total);
            const double end =
                i + 1 < c.events.size() ? std::min(c.events[i + 1].first, total) : total;
            if (end > start) {
                shareFrom = word.phonemes.size();
                word.phonemes.push_back({start, end, c.events[i].second, 1.0f});
            } else if (!word.phonemes.empty() && isSound(c.events[i].second)) {
                // espeak-ng reports a coda /l/ at the same position as the event after it (its
                // sound is rendered inside the vowel before it: "well" is w, E over 245 ms, l at
                // 0 ms), so the word would lose it. It is said, so it stays, with an equal share
                // of the segment it is rendered in.
                word.phonemes.push_back({end, end, c.events[i].second, 1.0f});
                auto run = std::span(word.phonemes).subspan(shareFrom);
                const double from = run.front().start, step = (run.back().end - from) / run.size();
                for (std::size_t k = 0; k < run.size(); ++k) {
                    run[k].start = from + step * static_cast<double>(k);
                    run[k].end = k + 1 < run.size() ? from + step * static_cast<double>(k + 1)
                                                    : run.back().end;
                }
            }
        }
        words.push_back(std::move(word));
    }
    return words;
}

}  // namespace

namespace {
// espeak-ng is initialised once a process and never terminated: espeak_Terminate followed by
// espeak_Initialize hangs (espeak-ng 1.51), so a second synthesiser made after the first was
// destroyed (a test process, a service whose worker restarts) would wait for ever. The data
// folder is the first synthesiser's; another asked for later is an error.
struct Engine {
    std::string dataPath;
    int sampleRate = 0;
};
const Engine& engine(const std::string& dataPath) {
    static const Engine once = [&] {
        Engine e{dataPath,
                 espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 200,
                                   dataPath.empty() ? nullptr : dataPath.c_str(),
                                   espeakINITIALIZE_PHONEME_EVENTS | espeakINITIALIZE_DONT_EXIT)};
        if (e.sampleRate > 0) espeak_SetSynthCallback(onSynth);
        return e;
    }();
    return once;
}
}  // namespace

EspeakSynthesizer::EspeakSynthesizer(const std::string& dataPath) {
    if (gInstanceAlive.exchange(true))
        throw std::runtime_error("espeak-ng: only one synthesiser can exist at a time");
    const auto& e = engine(dataPath);
    if (e.sampleRate <= 0) {
        gInstanceAlive = false;
        throw std::runtime_error("espeak-ng: initialisation failed (is espeak-ng-data installed?)");
    }
    if (e.dataPath != dataPath) {
        gInstanceAlive = false;
        throw std::runtime_error("espeak-ng: already initialised on '" + e.dataPath +
                                 "' in this process, not '" + dataPath + "'");
    }
    sampleRate_ = e.sampleRate;
}

EspeakSynthesizer::~EspeakSynthesizer() {
    gInstanceAlive = false;
}

SynthesizedSpeech EspeakSynthesizer::synthesize(const SynthesisRequest& request) {
    if (!selectVoice(request.voice))
        throw InputError("espeak-ng: unknown voice '" + request.voice +
                         "' (list them with: espeak-ng --voices)");
    // Always set: espeak-ng keeps the last request's rate and pitch (and a voice may change
    // them), so a request without them would otherwise read as the one before did.
    espeak_SetParameter(espeakRATE,
                        request.wordsPerMinute > 0 ? request.wordsPerMinute : espeakRATE_NORMAL, 0);
    espeak_SetParameter(espeakPITCH, request.pitch >= 0 ? request.pitch : kDefaultPitch, 0);

    SynthesizedSpeech out;
    out.sampleRate = sampleRate_;
    Collector collector{&out.samples};
    if (request.maxSeconds > 0) {
        collector.maxSamples = static_cast<std::size_t>(request.maxSeconds * sampleRate_) + 1;
        out.samples.reserve(collector.maxSamples);  // held at most: no growth, no copies
    }
    const auto rc = espeak_Synth(request.text.c_str(), request.text.size() + 1, 0, POS_CHARACTER, 0,
                                 espeakCHARS_UTF8, nullptr, &collector);
    if (rc != EE_OK) throw std::runtime_error("espeak-ng: synthesis failed");
    espeak_Synchronize();

    const double total = static_cast<double>(out.samples.size()) / sampleRate_;
    auto& ev = collector.events;
    for (std::size_t i = 0; i < ev.size(); ++i) {
        const double start = std::min(ev[i].first, total);
        const double end = i + 1 < ev.size() ? std::min(ev[i + 1].first, total) : total;
        if (end > start) out.phonemes.push_back({start, end, ev[i].second, 1.0f});
    }
    out.words = spokenWords(request.text, collector, total);
    out.truncated = collector.truncated;
    return out;
}

}  // namespace lipsyncd
