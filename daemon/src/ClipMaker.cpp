// Requests made ready to play: a file is decoded and analysed offline (ahead of playback, so a
// replayed file has no recognition latency); text is spoken by espeak-ng with its exact
// schedule. Either way the pose weights are computed before the first sample is heard.
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/tts.hpp>

namespace lipsyncd::daemon {

struct ClipMaker::Impl {
    DaemonConfig config;
    lipsync::PoseSet poses;
    lipsync::BigramCurveSet curves;
    dsp::TemplateSet templates;
    std::vector<std::string> poseNames;

    explicit Impl(const DaemonConfig& c)
        : config(c), poses(lipsync::PoseSet::named(c.poses)),
          curves(c.character.empty() ? lipsync::BigramCurveSet::named(c.curves, poses)
                                     : lipsync::BigramCurveSet::load(findDataFile(c.character), poses)),
          templates(c.templates.empty() ? dsp::TemplateSet::loadDefault() : dsp::TemplateSet::load(findDataFile(c.templates))),
          poseNames(poses.names()) {}

    PoseTrack animate(const PhonemeSchedule& s) const {
        lipsync::RuntimeConfig rc;
        rc.outputRate = config.outputRateHz;
        return config.runtime == "filter" ? lipsync::animateFilter(s, curves, poses, rc) : lipsync::animate(s, curves, poses, rc);
    }
};

ClipMaker::ClipMaker(const DaemonConfig& config) : impl_(std::make_unique<Impl>(config)) {}
ClipMaker::~ClipMaker() = default;

const std::vector<std::string>& ClipMaker::poseNames() const { return impl_->poseNames; }

Clip ClipMaker::fromFile(const std::filesystem::path& file, int channel) const {
    dsp::DecodeOptions decode;
    decode.channel = channel;
    Clip clip;
    clip.name = file.string();
    const auto audio = dsp::readAudioFile(file, decode);
    clip.samples = audio.samples;
    clip.rate = audio.sampleRate;
    const auto result = dsp::analyzeFile(file, impl_->templates, PhonemeSet::common(), {}, decode);
    clip.weights = impl_->animate(result.schedule);
    return clip;
}

Clip ClipMaker::fromText(EspeakSynthesizer& synth, const std::string& text, const std::string& voice) const {
    const auto v = voice.empty() ? impl_->config.voice : voice;
    const auto speech = synth.synthesize({text, v, 0, -1});
    Clip clip;
    clip.name = "say: " + text;
    clip.rate = speech.sampleRate;
    for (auto s : speech.samples) clip.samples.push_back(static_cast<float>(s) / 32768.0f);
    clip.weights = impl_->animate(mapSchedule(speech.phonemes, espeakMapForVoice(v), nullptr));
    return clip;
}

}  // namespace lipsyncd::daemon
