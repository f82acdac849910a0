// Where the sound goes, and the clock the mouth follows: how many samples have been heard.
// ALSA reports it as written minus snd_pcm_delay (what is still queued before the speaker);
// the null and file sinks have no device, so a monotonic clock stands in for the speaker.
#include <alsa/asoundlib.h>
#include <sndfile.h>

#include <algorithm>
#include <chrono>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::daemon {

namespace {
class ClockSink : public AudioSink {
  public:
    void open(int rate) override {
        rate_ = rate;
        written_ = 0;
        start_ = std::chrono::steady_clock::now();
    }
    std::size_t write(std::span<const float> samples) override {
        // Take no more than half a second ahead of the clock, as a device buffer would.
        const auto room = static_cast<std::int64_t>(elapsed() * rate_ + rate_ / 2) - written_;
        const auto n = static_cast<std::size_t>(
            std::clamp<std::int64_t>(room, 0, static_cast<std::int64_t>(samples.size())));
        consume(samples.first(n));
        written_ += static_cast<std::int64_t>(n);
        return n;
    }
    std::int64_t played() override {
        return std::min(written_, static_cast<std::int64_t>(elapsed() * rate_));
    }
    void stop() override { written_ = played(); }

  protected:
    virtual void consume(std::span<const float>) {}

  private:
    double elapsed() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    int rate_ = 48000;
    std::int64_t written_ = 0;
    std::chrono::steady_clock::time_point start_;
};

// A WAV file receives every sample played (tests compare it with the source).
class FileSink : public ClockSink {
  public:
    explicit FileSink(std::string path) : path_(std::move(path)) {}
    ~FileSink() override { close(); }
    void open(int rate) override {
        close();
        SF_INFO info{};
        info.samplerate = rate;
        info.channels = 1;
        info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
        file_ = sf_open(path_.c_str(), SFM_WRITE, &info);
        if (!file_)
            throw InputError("audio file '" + path_ + "': cannot write (" + sf_strerror(nullptr) +
                             ")");
        ClockSink::open(rate);
    }

  private:
    void consume(std::span<const float> s) override {
        if (file_) sf_write_float(file_, s.data(), static_cast<sf_count_t>(s.size()));
    }
    void close() {
        if (file_) sf_close(file_);
        file_ = nullptr;
    }
    std::string path_;
    SNDFILE* file_ = nullptr;
};

class AlsaSink : public AudioSink {
  public:
    explicit AlsaSink(std::string device) : device_(std::move(device)) {
        // Open once at start so a missing device is an error now, not at the first request.
        if (snd_pcm_open(&pcm_, device_.c_str(), SND_PCM_STREAM_PLAYBACK, SND_PCM_NONBLOCK) < 0)
            throw InputError("audio device '" + device_ +
                             "': cannot open for playback (no sound card? use device = \"null\")");
    }
    ~AlsaSink() override {
        if (pcm_) snd_pcm_close(pcm_);
    }
    void open(int rate) override {
        snd_pcm_drop(pcm_);
        const int err =
            snd_pcm_set_params(pcm_, SND_PCM_FORMAT_FLOAT_LE, SND_PCM_ACCESS_RW_INTERLEAVED, 1,
                               static_cast<unsigned>(rate), 1, 100'000);  // 100 ms buffer
        if (err < 0) throw InputError("audio device '" + device_ + "': " + snd_strerror(err));
        written_ = 0;
    }
    std::size_t write(std::span<const float> samples) override {
        if (samples.empty()) return 0;
        snd_pcm_sframes_t n = snd_pcm_writei(pcm_, samples.data(), samples.size());
        if (n == -EAGAIN) return 0;
        if (n < 0) {  // an underrun or a suspend: recover and try again on the next tick
            snd_pcm_recover(pcm_, static_cast<int>(n), 1);
            return 0;
        }
        written_ += n;
        return static_cast<std::size_t>(n);
    }
    std::int64_t played() override {
        snd_pcm_sframes_t delay = 0;
        if (snd_pcm_delay(pcm_, &delay) < 0) delay = 0;
        return std::max<std::int64_t>(0, written_ - delay);
    }
    void stop() override {
        snd_pcm_drop(pcm_);
        snd_pcm_prepare(pcm_);
        written_ = 0;
    }

  private:
    std::string device_;
    snd_pcm_t* pcm_ = nullptr;
    std::int64_t written_ = 0;
};
}  // namespace

std::unique_ptr<AudioSink> openAudioSink(const std::string& device) {
    if (device == "null") return std::make_unique<ClockSink>();
    if (device.rfind("file:", 0) == 0) return std::make_unique<FileSink>(device.substr(5));
    return std::make_unique<AlsaSink>(device);
}

}  // namespace lipsyncd::daemon

namespace lipsyncd::daemon {

namespace {
class AlsaCapture : public CaptureSource {
  public:
    AlsaCapture(const std::string& device, int rate) : rate_(rate) {
        if (snd_pcm_open(&pcm_, device.c_str(), SND_PCM_STREAM_CAPTURE, SND_PCM_NONBLOCK) < 0)
            throw InputError("capture device '" + device +
                             "': cannot open (no sound card or microphone?)");
        const int err =
            snd_pcm_set_params(pcm_, SND_PCM_FORMAT_FLOAT_LE, SND_PCM_ACCESS_RW_INTERLEAVED, 1,
                               static_cast<unsigned>(rate), 1, 40'000);
        if (err < 0) {
            snd_pcm_close(pcm_);
            throw InputError("capture device '" + device + "': " + snd_strerror(err));
        }
        snd_pcm_start(pcm_);
    }
    ~AlsaCapture() override { snd_pcm_close(pcm_); }
    int rate() const override { return rate_; }
    std::size_t read(std::span<float> out) override {
        const auto n = snd_pcm_readi(pcm_, out.data(), out.size());
        if (n == -EAGAIN) return 0;
        if (n < 0) {
            snd_pcm_recover(pcm_, static_cast<int>(n), 1);
            return 0;
        }
        return static_cast<std::size_t>(n);
    }

  private:
    snd_pcm_t* pcm_ = nullptr;
    int rate_;
};

// A WAV file that arrives at real-time pace from the moment it is opened, then silence.
class FileCapture : public CaptureSource {
  public:
    FileCapture(const std::string& path, int) {
        const auto audio = dsp::readAudioFile(path);
        samples_ = audio.samples;
        rate_ = audio.sampleRate;
        start_ = std::chrono::steady_clock::now();
    }
    int rate() const override { return rate_; }
    std::size_t read(std::span<float> out) override {
        const auto due = static_cast<std::size_t>(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() *
            rate_);
        const std::size_t n = std::min(out.size(), due > given_ ? due - given_ : 0);
        for (std::size_t i = 0; i < n; ++i)
            out[i] = given_ + i < samples_.size() ? samples_[given_ + i] : 0.0f;
        given_ += n;
        return n;
    }

  private:
    std::vector<float> samples_;
    int rate_ = 16000;
    std::size_t given_ = 0;
    std::chrono::steady_clock::time_point start_;
};
}  // namespace

std::unique_ptr<CaptureSource> openCaptureSource(const std::string& device, int rate) {
    if (device.rfind("file:", 0) == 0) return std::make_unique<FileCapture>(device.substr(5), rate);
    return std::make_unique<AlsaCapture>(device, rate);
}

}  // namespace lipsyncd::daemon
