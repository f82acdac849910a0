// Decoding with libsndfile: files by content, raw PCM by description, stdin for pipes.
#include <sndfile.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <optional>
#include <string_view>

namespace lipsyncd::dsp {

namespace {
constexpr std::size_t kBlockFrames = 4096;

int rawSubtype(const std::string& f) {
    if (f == "s8") return SF_FORMAT_PCM_S8;
    if (f == "u8") return SF_FORMAT_PCM_U8;
    if (f == "s16") return SF_FORMAT_PCM_16;
    if (f == "s24") return SF_FORMAT_PCM_24;
    if (f == "s32") return SF_FORMAT_PCM_32;
    if (f == "f32") return SF_FORMAT_FLOAT;
    if (f == "f64") return SF_FORMAT_DOUBLE;
    return 0;
}

// One channel: AudioDecoder::read's loop without the mixing, in a form that vectorises (the
// common case, and most of the decoding time of a long mono file). The same values as the mix
// of one channel: 0 + x (which turns −0 into +0) when mixing, x itself when it is chosen.
// Returns the number of non-finite samples (read as 0).
std::int64_t copyMono(const float* in, std::span<float> out, bool chosen) {
    const float zero = chosen ? -0.0f : 0.0f;  // −0 + x == x for every x
    std::int64_t nonFinite = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float v = zero + in[i];
        const bool finite = std::abs(v) <= std::numeric_limits<float>::max();
        nonFinite += !finite;
        out[i] = finite ? std::clamp(v, -1.0f, 1.0f) : 0.0f;
    }
    return nonFinite;
}

// 16-bit PCM as libsndfile's own float reading gives it (pcm.c: (float) s * (1 / 0x8000f), a
// product by a power of two, so exact): read as shorts and scaled here, in a loop that
// vectorises, instead of libsndfile's conversion loop and copyMono's pass after it. The same
// values bit for bit (tests/dsp/FrontEndTest.cpp checks all 65 536), a third of the decoding
// time of a 16-bit mono file (bench/frontend_profile).
void shortsToFloats(const short* in, std::span<float> out) {
    constexpr float kScale = 1.0f / 32768.0f;
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(in[i]) * kScale;
}

struct SndfileCloser {
    void operator()(SNDFILE* f) const { sf_close(f); }
};

// Header sizes a recorder writes before it knows the length (a WAV streamed to a pipe): not a
// promise of that much audio.
constexpr long long kStreamedLength = 0x7FFF0000;

// libsndfile reads a file whose header promises more audio than the file holds as far as it
// goes, and says so only in its log, as "data : 230036 (should be 2956)" (the WAV data chunk;
// AIFF's is SSND). The promised and held byte counts, when that is so.
std::optional<std::pair<long long, long long>> cutShort(SNDFILE* f) {
    std::string log(8192, '\0');
    sf_command(f, SFC_GET_LOG_INFO, log.data(), static_cast<int>(log.size()));
    for (std::size_t at = 0; at < log.size() && log[at];) {
        const auto end = std::min(log.find('\n', at), log.size());
        const auto line = std::string_view(log).substr(at, end - at);
        at = end + 1;
        const auto first = line.find_first_not_of(' ');
        if (first == std::string_view::npos) continue;
        const auto chunk = line.substr(first);
        const auto should = chunk.find("(should be ");
        if (!(chunk.starts_with("data") || chunk.starts_with("SSND")) ||
            should == std::string_view::npos || chunk.find(':') == std::string_view::npos)
            continue;
        const long long promised = std::atoll(chunk.data() + chunk.find(':') + 1);
        const long long held = std::atoll(chunk.data() + should + 11);
        if (promised > held && held >= 0 && promised < kStreamedLength)
            return std::pair(promised, held);
    }
    return std::nullopt;
}

std::string seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f s", s);
    return text;
}

// AudioDecoder::warnings()'s word for a file cut short; `why`: the decoder's reason, if any.
std::string truncated(const std::string& name, const std::string& promised, double held,
                      const std::string& why = "") {
    return name + ": truncated: its header promises " + promised + " of audio, the file holds " +
           seconds(held) + (why.empty() ? "" : " (" + why + ")") + "; read as far as it goes";
}
}  // namespace

RawFormat RawFormat::parse(const std::string& spec) {
    RawFormat f;
    const auto a = spec.find(':');
    const auto b = a == std::string::npos ? a : spec.find(':', a + 1);
    if (b == std::string::npos)
        throw InputError("--raw '" + spec + "': expected RATE:FORMAT:CHANNELS, e.g. 16000:s16:1");
    try {
        f.sampleRate = std::stoi(spec.substr(0, a));
        f.channels = std::stoi(spec.substr(b + 1));
    } catch (const std::exception&) {
        throw InputError("--raw '" + spec + "': RATE and CHANNELS must be whole numbers");
    }
    f.sampleFormat = spec.substr(a + 1, b - a - 1);
    if (f.sampleRate < 1000 || f.sampleRate > 384000)
        throw InputError("--raw '" + spec + "': rate must be 1000..384000 Hz");
    if (f.channels < 1 || f.channels > 64)
        throw InputError("--raw '" + spec + "': channels must be 1..64");
    if (!rawSubtype(f.sampleFormat))
        throw InputError("--raw '" + spec + "': format must be one of s8 u8 s16 s24 s32 f32 f64");
    return f;
}

struct AudioDecoder::State {
    std::unique_ptr<SNDFILE, SndfileCloser> file;
    SF_INFO info{};
    std::string name;
    int channel = -1;
    int skipChannel = -1;
    std::vector<float> interleaved;
    std::vector<short> shorts;  // 16-bit PCM is read as shorts (shortsToFloats)
    std::int64_t nonFinite = 0;
    std::int64_t framesRead = 0;
    std::vector<std::string> warnings;
};

AudioDecoder::AudioDecoder(std::unique_ptr<State> state) : state_(std::move(state)) {}
AudioDecoder::AudioDecoder(AudioDecoder&&) noexcept = default;
AudioDecoder& AudioDecoder::operator=(AudioDecoder&&) noexcept = default;
AudioDecoder::~AudioDecoder() = default;

AudioDecoder AudioDecoder::open(const std::filesystem::path& file, const DecodeOptions& options,
                                const std::optional<RawFormat>& raw) {
    auto s = std::make_unique<State>();
    s->name = file == "-" ? std::string("<stdin>") : file.string();
    if (raw) {
        s->info.samplerate = raw->sampleRate;
        s->info.channels = raw->channels;
        s->info.format = SF_FORMAT_RAW | rawSubtype(raw->sampleFormat) | SF_ENDIAN_LITTLE;
    }
    SNDFILE* f = nullptr;
    if (file == "-") {
        f = sf_open_fd(STDIN_FILENO, SFM_READ, &s->info, /*close_desc=*/0);
    } else {
        if (!std::filesystem::exists(file)) throw InputError(s->name + ": no such file");
        if (std::filesystem::is_directory(file)) throw InputError(s->name + ": is a directory");
        f = sf_open(file.c_str(), SFM_READ, &s->info);
    }
    if (!f)
        throw InputError(s->name + ": cannot decode audio (" + sf_strerror(nullptr) + ")" +
                         (raw ? "" : "; for headerless PCM give --raw RATE:FORMAT:CHANNELS"));
    s->file.reset(f);
    if (s->info.samplerate <= 0 || s->info.channels <= 0)
        throw InputError(s->name + ": no sample rate or no channels in the header");
    // Outside this range a header is broken or hostile, not speech (a 1 Hz "WAV" would
    // resample every byte into 10 000 analysis samples).
    if (s->info.samplerate < 1000 || s->info.samplerate > 384000)
        throw InputError(s->name + ": sample rate " + std::to_string(s->info.samplerate) +
                         " Hz in the header is outside 1000..384000 Hz");
    if (options.channel >= s->info.channels)
        throw InputError(s->name + ": has " + std::to_string(s->info.channels) +
                         " channel(s); --channel " + std::to_string(options.channel) +
                         " does not exist (channels count from 0)");
    s->channel = options.channel;
    // Skipping the only channel would leave nothing: then it is simply played.
    s->skipChannel = s->info.channels > 1 ? options.skipChannel : -1;
    s->interleaved.resize(kBlockFrames * static_cast<std::size_t>(s->info.channels));
    if ((s->info.format & SF_FORMAT_SUBMASK) == SF_FORMAT_PCM_16)
        s->shorts.resize(s->interleaved.size());
    if (const auto cut = raw || file == "-" ? std::nullopt : cutShort(f)) {
        const double held = static_cast<double>(s->info.frames) / s->info.samplerate;
        const double promised = cut->second > 0 ? held * cut->first / cut->second : 0;
        s->warnings.push_back(truncated(
            s->name, cut->second > 0 ? seconds(promised) : std::to_string(cut->first) + " bytes",
            held));
    }
    // libsndfile scales integer PCM to [-1, 1); floats are passed through as they are.
    sf_command(f, SFC_SET_NORM_FLOAT, nullptr, SF_TRUE);
    return AudioDecoder(std::move(s));
}

int AudioDecoder::sampleRate() const {
    return state_->info.samplerate;
}
int AudioDecoder::channels() const {
    return state_->info.channels;
}
const std::string& AudioDecoder::name() const {
    return state_->name;
}
std::int64_t AudioDecoder::nonFiniteSamples() const {
    return state_->nonFinite;
}
const std::vector<std::string>& AudioDecoder::warnings() const {
    return state_->warnings;
}

// A FLAC file cut short keeps its header's length, and its decoder stops where the data does:
// the end came before the frames the header declares. (An Ogg file states no length: its
// length is where its last page ends, and a cut one cannot be told from a short one.)
void AudioDecoder::noteEarlyEnd() {
    auto& s = *state_;
    const auto declared = frames();
    if (!declared || s.framesRead >= *declared || !s.warnings.empty()) return;
    const double rate = s.info.samplerate;
    // libsndfile's reason, as "Error : flac decoder lost sync.": the words alone.
    std::string why = sf_strerror(s.file.get());
    if (why.starts_with("Error : ")) why.erase(0, 8);
    while (!why.empty() && why.back() == '.') why.pop_back();
    if (why == "No Error") why.clear();
    s.warnings.push_back(truncated(s.name, seconds(static_cast<double>(*declared) / rate),
                                   static_cast<double>(s.framesRead) / rate, why));
}

std::optional<std::int64_t> AudioDecoder::frames() const {
    const bool seekable = state_->info.seekable && state_->name != "<stdin>";
    if (!seekable || state_->info.frames <= 0 || state_->info.frames == SF_COUNT_MAX)
        return std::nullopt;
    return state_->info.frames;
}

std::size_t AudioDecoder::read(std::span<float> out) {
    auto& s = *state_;
    const auto channels = static_cast<std::size_t>(s.info.channels);
    const std::size_t want = std::min(out.size(), kBlockFrames);
    const bool pcm16 = !s.shorts.empty();
    const auto got =
        pcm16 ? sf_readf_short(s.file.get(), s.shorts.data(), static_cast<sf_count_t>(want))
              : sf_readf_float(s.file.get(), s.interleaved.data(), static_cast<sf_count_t>(want));
    if (got < 0) throw InputError(s.name + ": read error (" + sf_strerror(s.file.get()) + ")");
    s.framesRead += got;
    if (got == 0 && want > 0) noteEarlyEnd();
    const auto n = static_cast<std::size_t>(got);
    if (pcm16 && channels == 1) {  // always finite and within [-1, 1)
        shortsToFloats(s.shorts.data(), out.first(n));
        return n;
    }
    if (pcm16) shortsToFloats(s.shorts.data(), std::span<float>(s.interleaved).first(n * channels));
    if (channels == 1) {
        s.nonFinite += copyMono(s.interleaved.data(), out.first(n), s.channel >= 0);
        return n;
    }
    for (std::size_t i = 0; i < n; ++i) {
        const float* frame = &s.interleaved[i * channels];
        float v = 0;
        if (s.channel >= 0) {
            v = frame[s.channel];
        } else {
            for (std::size_t c = 0; c < channels; ++c)
                if (static_cast<int>(c) != s.skipChannel) v += frame[c];
            v /= static_cast<float>(s.skipChannel >= 0 ? channels - 1 : channels);
        }
        if (!std::isfinite(v)) {
            ++s.nonFinite;
            v = 0;
        }
        out[i] = std::clamp(v, -1.0f, 1.0f);
    }
    return n;
}

MonoAudio readAudioFile(const std::filesystem::path& file, const DecodeOptions& options) {
    auto decoder = AudioDecoder::open(file, options);
    MonoAudio audio;
    audio.sampleRate = decoder.sampleRate();
    if (auto n = decoder.frames()) audio.samples.reserve(static_cast<std::size_t>(*n));
    std::vector<float> block(kBlockFrames);
    while (const auto n = decoder.read(block))
        audio.samples.insert(audio.samples.end(), block.begin(), block.begin() + n);
    audio.warnings = decoder.warnings();
    return audio;
}

namespace {
template <typename Sample>
void writeWav(const std::filesystem::path& file, std::span<const Sample> samples, int rate) {
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
    std::unique_ptr<SNDFILE, SndfileCloser> f(sf_open(file.c_str(), SFM_WRITE, &info));
    if (!f) throw InputError(file.string() + ": cannot write (" + sf_strerror(nullptr) + ")");
    sf_count_t written = 0;
    if constexpr (std::is_same_v<Sample, float>)
        written = sf_write_float(f.get(), samples.data(), static_cast<sf_count_t>(samples.size()));
    else
        written = sf_write_short(f.get(), samples.data(), static_cast<sf_count_t>(samples.size()));
    if (written != static_cast<sf_count_t>(samples.size()))
        throw InputError(file.string() + ": write failed (" + sf_strerror(f.get()) + ")");
}
}  // namespace

void writeWavFile(const std::filesystem::path& file, std::span<const std::int16_t> samples,
                  int sampleRate) {
    writeWav(file, samples, sampleRate);
}

void writeWavFile(const std::filesystem::path& file, std::span<const float> samples,
                  int sampleRate) {
    writeWav(file, samples, sampleRate);
}

}  // namespace lipsyncd::dsp
