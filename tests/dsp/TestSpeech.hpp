// Speech for tests, made by espeak-ng in-process (no recordings from elsewhere), and small
// helpers to write it in any format libsndfile knows.
#pragma once

#include <sndfile.h>

#include <filesystem>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>
#include <string>
#include <vector>

#include "TestSynth.hpp"

namespace lipsyncd::test {

struct Speech {
    std::vector<float> samples;
    int rate = 0;
    PhonemeSchedule labels;  // common set
};

// `text` said by espeak-ng's `voice` at `wpm` words a minute (0: the voice's own rate), with
// espeak-ng's own timings as its labels.
inline Speech speak(EspeakSynthesizer& synth, const std::string& text, const std::string& voice,
                    int wpm = 0) {
    const auto s = synth.synthesize({text, voice, wpm, -1});
    Speech out;
    out.rate = s.sampleRate;
    out.samples.reserve(s.samples.size());
    for (auto v : s.samples) out.samples.push_back(v / 32768.0f);
    out.labels = mapSchedule(s.phonemes, espeakMapForVoice(voice), nullptr);
    return out;
}

inline const Speech& testSpeech() {
    static const Speech speech = speak(
        espeak(), "Hello puppet, please open your mouth wide and say something funny.", "en-us");
    return speech;
}

inline std::vector<float> resampleOffline(const std::vector<float>& in, int from, int to) {
    dsp::StreamResampler r(from, to, dsp::ResamplerQuality::High, 4096);
    std::vector<float> out;
    for (std::size_t i = 0; i < in.size(); i += 4096) {
        const auto block =
            std::span<const float>(in).subspan(i, std::min<std::size_t>(4096, in.size() - i));
        const auto o = r.process(block);
        out.insert(out.end(), o.begin(), o.end());
    }
    for (;;) {
        const auto o = r.process({}, true);
        if (o.empty()) break;
        out.insert(out.end(), o.begin(), o.end());
    }
    return out;
}

// Writes interleaved `channels` copies (channel c scaled by gains[c]) in `format` (SF_FORMAT_*).
inline std::filesystem::path writeAudio(const std::string& name, const std::vector<float>& mono,
                                        int rate, int format, std::vector<float> gains = {1.0f}) {
    const auto path = std::filesystem::temp_directory_path() / ("lipsyncd_test_" + name);
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = static_cast<int>(gains.size());
    info.format = format;
    SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
    if (!f)
        throw std::runtime_error(std::string("test: cannot write ") + path.string() + ": " +
                                 sf_strerror(nullptr));
    std::vector<float> interleaved;
    for (float v : mono)
        for (float g : gains) interleaved.push_back(v * g);
    sf_writef_float(f, interleaved.data(), static_cast<sf_count_t>(mono.size()));
    sf_close(f);
    return path;
}

}  // namespace lipsyncd::test
