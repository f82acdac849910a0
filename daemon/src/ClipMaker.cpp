// Requests made ready to play: a file is decoded and analysed offline (ahead of playback, so a
// replayed file has no recognition latency); text is spoken by espeak-ng with its exact
// schedule. Either way the pose weights are computed before the first sample is heard.
#include <algorithm>
#include <array>
#include <cmath>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/tts.hpp>
#include <optional>

#include "LiveMode.hpp"
#include "MemoryWav.hpp"
#include "ShowSpeaker.hpp"
#include "StreamingLive.hpp"

namespace lipsyncd::daemon {

namespace {
constexpr int kMaxPlaybackRate = 48000;  // what any sound card plays; above is resampled
}  // namespace

struct ClipMaker::Impl {
    DaemonConfig config;
    lipsync::Runtime runtime;  // built as `lipsync animate` builds it
    dsp::TemplateSet templates;
    dsp::FrontEndConfig frontEnd;  // the defaults, unless `lipsync eval --live` set its own
    std::vector<std::string> poseNames;
    std::shared_ptr<ShowSpeaker> speaker;  // null: adapt_speaker = false

    explicit Impl(const DaemonConfig& c)
        : config(c),
          runtime(c.runtime),
          templates(c.templateSet ? *c.templateSet : dsp::TemplateSet::named(c.templates)),
          frontEnd(c.frontEnd ? *c.frontEnd : dsp::FrontEndConfig{}),
          poseNames(runtime.poses().names()) {}
};

ClipMaker::ClipMaker(const DaemonConfig& config, const ClipMaker* previous,
                     const std::function<void(const std::string&)>& log) {
    try {
        impl_ = std::make_unique<Impl>(config);
    } catch (const InputError& e) {  // which key of the config named what failed to load
        throw InputError(config.source.string() + ": [mouth] " + e.what());
    }
    if (!config.adaptSpeaker) return;
    // A reload goes on with the voice learnt so far, unless what it adapts or keeps it changed.
    const auto* before = previous ? previous->impl_.get() : nullptr;
    if (before && before->speaker && before->config.templates == config.templates &&
        before->config.speakerFile == config.speakerFile)
        impl_->speaker = before->speaker;
    else
        impl_->speaker = std::make_shared<ShowSpeaker>(
            impl_->templates, config.speakerFile, log ? log : [](const std::string&) {});
}
ClipMaker::~ClipMaker() = default;

ShowSpeaker* ClipMaker::speaker() const {
    return impl_->speaker.get();
}

const std::vector<std::string>& ClipMaker::poseNames() const {
    return impl_->poseNames;
}

namespace {
// The sound to play, decoded a block at a time straight into 16-bit samples: no float copy
// of the whole file is ever held (memory with a full queue of long clips). Above 48 kHz it is
// resampled to 48 kHz: what one clip may hold is then bounded by max_clip_seconds alone.
std::vector<std::int16_t> decodeForPlayback(const std::filesystem::path& file,
                                            const dsp::DecodeOptions& options, int& rate) {
    auto decoder = dsp::AudioDecoder::open(file, options);
    rate = std::min(decoder.sampleRate(), kMaxPlaybackRate);
    std::optional<dsp::StreamResampler> resampler;
    if (rate != decoder.sampleRate()) resampler.emplace(decoder.sampleRate(), rate);
    std::vector<std::int16_t> out;
    out.reserve(static_cast<std::size_t>(static_cast<double>(decoder.frames().value_or(0)) * rate /
                                         decoder.sampleRate()) +
                1);
    const auto append = [&](std::span<const float> block) {
        for (const float v : block)
            out.push_back(
                static_cast<std::int16_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f)));
    };
    std::array<float, 4096> block{};
    while (const auto n = decoder.read(block)) {
        const auto in = std::span<const float>(block).first(n);
        resampler ? append(resampler->process(in)) : append(in);
    }
    if (resampler) append(resampler->process({}, true));
    return out;
}
}  // namespace

namespace {
// What a line taught the show's voice, kept (and written to its file), and said. False when it
// taught nothing (no frame placed, or a reset came in between).
bool learnFrom(ShowSpeaker& speaker, const std::string& name, ShowSpeaker::Lesson lesson,
               const std::function<void(const std::string&)>& log) {
    const auto done = speaker.finish(std::move(lesson));
    if (!done.saveProblem.empty())
        log("the show's voice is not kept for a restart: " + done.saveProblem);
    if (!done.learnt) return false;
    const auto heard = speaker.heard();
    log(name + ": the show's voice learnt from " + std::to_string(heard.lines) + " line(s), " +
        std::to_string(heard.frames) + " frames");
    return true;
}
}  // namespace

Clip ClipMaker::fromFile(const std::filesystem::path& file, int channel, EspeakSynthesizer& synth,
                         const std::optional<std::string>& knownText,
                         const std::function<void(const std::string&)>& log) const {
    dsp::DecodeOptions decode;
    decode.channel = channel;
    Clip clip;
    clip.name = file.string();
    // Analysed on `channel` (the voice), played on the others (what the audience hears); the
    // analysis first, so its buffers are gone before the sound's is made. The mouth opens as
    // wide as the voice is loud: the analysis's own levels (as `lipsync analyze --weights`).
    // The show's voice (adapt_speaker) is learnt on a copy and kept once the schedule is made.
    LevelTrack levels;
    const auto say = log ? log : [](const std::string&) {};
    auto lesson = impl_->speaker ? std::optional(impl_->speaker->startLesson()) : std::nullopt;
    const auto schedule =
        scheduleForClip(synth, file, knownText, impl_->config.voice, impl_->templates, decode, say,
                        &levels, lesson ? &lesson->voice : nullptr);
    if (lesson) learnFrom(*impl_->speaker, file.string(), std::move(*lesson), say);
    clip.weights = impl_->runtime.animate(schedule, &levels);
    dsp::DecodeOptions play;
    play.skipChannel = channel;
    clip.samples = decodeForPlayback(file, play, clip.rate);
    return clip;
}

Clip ClipMaker::fromText(EspeakSynthesizer& synth, const std::string& text,
                         const std::string& voice, double maxSeconds) const {
    const auto v = voice.empty() ? impl_->config.voice : voice;
    auto speech = synth.synthesize({text, v, 0, -1, maxSeconds});
    if (speech.truncated)
        throw InputError("the speech is longer than max_clip_seconds (" +
                         std::to_string(maxSeconds) + " s in the config)");
    Clip clip;
    clip.name = "say: " + text;
    clip.rate = speech.sampleRate;
    const auto levels = dsp::measureLevels(speech.samples, speech.sampleRate);
    clip.samples = std::move(speech.samples);
    clip.weights = impl_->runtime.animate(
        mapSchedule(speech.phonemes, espeakMapForVoice(v), nullptr), &levels);
    return clip;
}

// As a played file with its words teaches the voice (fromFile), from samples kept in memory.
ClipMaker::LineLesson ClipMaker::learnFromLine(
    std::span<const float> samples, int rate, const std::string& text, EspeakSynthesizer& synth,
    const std::function<void(const std::string&)>& log) const {
    if (!impl_->speaker) return {false, "adapt_speaker is off in the config"};
    const auto say = log ? log : [](const std::string&) {};
    const auto name = "live line " + shownLine(text);
    const MemoryWav wav(samples, rate);
    auto lesson = impl_->speaker->startLesson();
    dsp::AlignFileResult r;
    try {
        r = alignText(synth, wav.path(), text, impl_->config.voice, impl_->templates,
                      impl_->frontEnd, {}, {}, std::nullopt, true, &lesson.voice);
    } catch (const InputError& e) {
        return {false, wav.named(e.what(), name)};
    }
    for (const auto& w : r.warnings) say(wav.named(w, name));
    const auto placed = std::count_if(r.alignment.words.begin(), r.alignment.words.end(),
                                      [](const dsp::AlignedWord& w) { return w.placed; });
    const auto words = std::to_string(placed) + " of " + std::to_string(r.alignment.words.size()) +
                       " words placed";
    if (r.fellBack || placed == 0) return {false, words + ": nothing learnt"};
    if (!learnFrom(*impl_->speaker, name, std::move(lesson), say))
        return {false, words + ", but nothing learnt (no frame kept, or a reset came in between)"};
    return {true, words};
}

}  // namespace lipsyncd::daemon

namespace lipsyncd::daemon {

std::unique_ptr<ClipMaker::Live> ClipMaker::startLive(int rate) const {
    // Live input follows the show's voice as the lines with words before it taught it.
    const auto& templates = impl_->speaker ? impl_->speaker->templates() : impl_->templates;
    return std::make_unique<StreamingLive>(templates, impl_->runtime, rate,
                                           impl_->config.followLagSeconds, impl_->frontEnd);
}

std::vector<dsp::ScriptWord> ClipMaker::readLine(const std::string& text,
                                                 EspeakSynthesizer& synth) const {
    const auto& voice = impl_->config.voice;
    const auto map = espeakMapForVoice(voice);
    // Live input is analysed in the common set (StreamingLive).
    if (&PhonemeSet::named(map.phonemeSet()) != &PhonemeSet::common())
        throw InputError("voice '" + voice + "' reads words in the '" + map.phonemeSet() +
                         "' phoneme set; live input is heard in the common set");
    std::vector<std::string> warnings;
    return scriptForVoice(synth, text, voice, map, &warnings);
}

}  // namespace lipsyncd::daemon
