// What a play or say request must be before it is queued (checked at once, in the request's
// reply), and how the worker makes it ready. Bounded input: regular files only (a FIFO or a
// device would block the worker for ever), clips no longer than the config allows, text no
// longer than the config allows.
#include <sndfile.h>
#include <sys/stat.h>

#include <lipsyncd/tts.hpp>

#include "ClipQueue.hpp"
#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

double checkAudioFile(const std::filesystem::path& file, double maxSeconds) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) throw InputError(file.string() + ": no such file");
    if (!S_ISREG(st.st_mode)) throw InputError(file.string() + ": not a regular file");
    SF_INFO info{};
    SNDFILE* f = sf_open(file.c_str(), SFM_READ, &info);  // reads the header only
    if (!f) throw InputError(file.string() + ": not audio (" + sf_strerror(nullptr) + ")");
    sf_close(f);
    if (info.samplerate <= 0) throw InputError(file.string() + ": no sample rate");
    const double seconds = static_cast<double>(info.frames) / info.samplerate;
    if (seconds > maxSeconds)
        throw InputError(file.string() + ": " + std::to_string(seconds) +
                         " s is longer than max_clip_seconds (" + std::to_string(maxSeconds) +
                         " s in the config)");
    return seconds;
}

void checkText(const std::string& text, std::size_t maxBytes, const std::string& command) {
    if (text.size() > maxBytes)
        throw InputError(command + ": " + std::to_string(text.size()) +
                         " bytes of text is more than max_text_bytes (" + std::to_string(maxBytes) +
                         " in the config)");
}

Clip prepareClip(const ClipRequest& request, std::unique_ptr<EspeakSynthesizer>& synth) {
    Clip clip;
    if (!synth) synth = std::make_unique<EspeakSynthesizer>();  // one a process (espeak-ng)
    if (!request.file.empty()) {
        checkAudioFile(request.file, request.maxSeconds);  // again: it may have changed since
        // Known words (the request's, or FILE.txt beside it) are aligned, not recognised.
        clip = request.maker->fromFile(request.file, request.channel, *synth, request.knownText,
                                       logInfo);
    } else {
        clip = request.maker->fromText(*synth, request.text, request.voice, request.maxSeconds);
    }
    const double seconds = static_cast<double>(clip.samples.size()) / clip.rate;
    if (seconds > request.maxSeconds)
        throw InputError(std::to_string(seconds) + " s is longer than max_clip_seconds");
    clip.name = request.name;
    // Held until played: no spare capacity (the weights grew frame by frame). Shrinking
    // copies, so a buffer within 2 % of its size (the audio, reserved ahead) is left as it is.
    const auto compact = [](auto& v) {
        if (v.capacity() - v.size() > v.size() / 50) v.shrink_to_fit();
    };
    compact(clip.samples);
    compact(clip.weights.times);
    compact(clip.weights.values);
    return clip;
}

}  // namespace lipsyncd::daemon
