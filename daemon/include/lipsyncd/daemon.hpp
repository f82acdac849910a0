// daemon: lipsyncd, the service. It plays what it analyses and drives the mouth from the audio
// device's own clock, so sound and mouth stay together.
//
//   DaemonConfig   lipsyncd.toml: audio device, puppet, curves, templates, runtime, delays,
//                  control socket (strict: unknown keys stop start-up with file and line).
//   AudioSink      where sound goes, and how much of it has been heard: ALSA (the playback
//                  position from snd_pcm_delay), null (a real-time clock, no device), a WAV file.
//   Clip           one request made ready: the audio, and the pose weights computed from it
//                  ahead of time (a file is analysed offline; text comes from espeak-ng).
//   Player         the queue: plays clips one after another through the sink and drives the
//                  puppet at the sink's clock plus the puppet's lead time and the sync offset.
//   ControlServer  a Unix socket speaking JSON lines to many clients at once.
//   ControlCommand the protocol's one command table (names, argument types, limits), shared
//                  by the daemon, `lipsync ctl` and the tests; ControlClient is their client.
//   Daemon         all of it in one poll() loop with sd_notify (READY, STATUS, WATCHDOG,
//                  RELOADING, STOPPING), SIGHUP reload and SIGTERM rest-then-exit.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <lipsyncd/core.hpp>
#include <lipsyncd/lipsync.hpp>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lipsyncd {
class EspeakSynthesizer;
namespace dsp {
struct ScriptWord;
struct FrontEndConfig;
struct TemplateSet;
}
}  // namespace lipsyncd

namespace lipsyncd::daemon {

struct DaemonConfig {
    std::filesystem::path source;
    // [audio]
    std::string device = "default";  // an ALSA device, "null" (no sound), or "file:PATH.wav"
    // [mouth]
    std::string puppet = "terminal";
    // poses, curves, character, phonemes, runtime, output_rate, loudness: the runtime as
    // `lipsync animate` names it (lipsync::Runtime builds both).
    lipsync::RuntimeSpec runtime;
    std::string templates;  // empty: the shipped default (dsp::TemplateSet::named)
    std::string voice = "en-us";
    // Learn the show's voice from the played files with words, for everything after (ShowSpeaker).
    bool adaptSpeaker = true;
    std::filesystem::path speakerFile;  // where the voice outlives a restart (empty: memory only)
    // (The lead that makes up for servo lag belongs to the puppet file: Puppet::leadSeconds.)
    double syncOffsetSeconds = 0;  // the user's correction, + moves the mouth later
    bool hardware = true;          // open the puppet's GPIO/HID outputs
    std::string record;            // also record every actuator command here (CSV)
    bool terminal = false;         // show the actuators as bars on stderr
    // [live]
    std::string captureDevice = "default";  // an ALSA capture device, or "file:PATH.wav" (tests)
    int captureRate = 16000;
    // A line cued with its words (`line`) drives the mouth from its words, decided this far
    // behind the sound (dsp::LineFollower); off: from the audio alone, with the least delay.
    bool followLines = true;
    double followLagSeconds = 0.1;
    // [control]
    std::filesystem::path socket = "/run/lipsyncd/control.sock";
    unsigned socketMode = 0660;
    std::size_t maxClients = 16;  // more get {"ok": false, "error": "too many clients"}
    // [limits]: what one request may cost (memory, the worker's time).
    double maxClipSeconds = 30;
    std::size_t maxTextBytes = 600;
    std::size_t maxQueue = 8;
    // Not in the config file: the front end as `lipsync eval --live` was told to run it (its
    // settings, and the set its --class-bias changed). Null: the defaults and `templates`.
    std::shared_ptr<const dsp::FrontEndConfig> frontEnd;
    std::shared_ptr<const dsp::TemplateSet> templateSet;

    static DaemonConfig load(const std::filesystem::path& file);  // InputError with file:line
};

// ---------------------------------------------------------------------------------------------
// The control protocol: one JSON object per line, {"cmd": NAME, ARG: value, ...}; one reply per
// request, {"ok": true, ...} or {"ok": false, "error": "..."}.

struct ControlArg {
    // Path: a string the client makes absolute; Weights: an object of names to finite numbers
    // within [min, max], at most maxLength of them.
    enum class Type { String, Path, Boolean, Integer, Weights };
    std::string_view name;
    Type type;
    bool required;
    std::size_t maxLength;  // strings: bytes
    long min, max;          // integers
    std::string_view help;
};

struct ControlCommand {
    std::string_view name;
    std::string_view usage;       // "play FILE: queue an audio file"
    std::string_view positional;  // the argument `lipsync ctl NAME WORDS...` fills, or ""
    std::span<const ControlArg> args;
};

std::span<const ControlCommand> controlCommands();
const ControlCommand* findControlCommand(std::string_view name);  // nullptr when unknown
std::string controlCommandNames();                                // "live, play, ..."
// nullopt when `request` fits the table; otherwise why not, naming the command and argument.
std::optional<std::string> checkControlRequest(const nlohmann::json& request);

// A client of the control socket with a deadline on every step (connect, write, each reply):
// a daemon that does not answer is an error, never a hang.
class ControlClient {
  public:
    // InputError naming the socket when nothing listens there.
    ControlClient(const std::filesystem::path& socket, std::chrono::milliseconds timeout);
    ~ControlClient();
    ControlClient(const ControlClient&) = delete;
    ControlClient& operator=(const ControlClient&) = delete;

    nlohmann::json request(const nlohmann::json& request);  // send, then the next reply
    void sendRaw(std::string_view bytes);                   // any bytes (tests send bad ones)
    std::string readLine();  // the next line; std::runtime_error on timeout or a closed socket

  private:
    void waitFor(short events, const char* what) const;
    int fd_ = -1;
    std::chrono::milliseconds timeout_;
    std::string buffer_;
    std::filesystem::path socket_;
};

// ---------------------------------------------------------------------------------------------

class AudioSink {
  public:
    virtual ~AudioSink() = default;
    virtual void open(int rate) = 0;  // mono float at `rate`
    // Takes what fits now without blocking; returns how many samples it took.
    virtual std::size_t write(std::span<const float> samples) = 0;
    // Samples heard so far (written minus what is still in the device's buffer).
    virtual std::int64_t played() = 0;
    virtual void stop() = 0;  // drop what is queued
};
// "null", "file:PATH.wav" or an ALSA device name; InputError naming the device if it cannot open.
std::unique_ptr<AudioSink> openAudioSink(const std::string& device);

// Live sound in: samples as they arrive, never blocking. ALSA capture, or a WAV file delivered
// at real-time pace (what tests and latency measurements use).
class CaptureSource {
  public:
    virtual ~CaptureSource() = default;
    virtual int rate() const = 0;
    virtual std::size_t read(std::span<float> out) = 0;  // what has arrived (0 when nothing)
};
std::unique_ptr<CaptureSource> openCaptureSource(const std::string& device, int rate);

struct Clip {
    std::string name;
    std::vector<std::int16_t> samples;  // mono, 16-bit: half a float's memory (max_queue)
    int rate = 0;
    PoseTrack weights;
};

class ShowSpeaker;

// The pieces a request needs to become a Clip, loaded from the config at start and on reload.
class ClipMaker {
  public:
    // `previous`: the maker a reload replaces; its show voice goes on if the templates and the
    // speaker file are the same. `log`: what became of the speaker file.
    explicit ClipMaker(const DaemonConfig& config, const ClipMaker* previous = nullptr,
                       const std::function<void(const std::string&)>& log = {});
    ~ClipMaker();
    // A file's mouth: with its words (`knownText`, else a FILE.txt beside it) by forced
    // alignment (lipsync align), else by recognition; `log` says which was used.
    Clip fromFile(const std::filesystem::path& file, int channel, EspeakSynthesizer& synth,
                  const std::optional<std::string>& knownText = std::nullopt,
                  const std::function<void(const std::string&)>& log = {}) const;
    // espeak-ng allows one synthesiser per process, for the process's life: the daemon owns it.
    // Speech longer than `maxSeconds` (0: no limit) is an InputError, found without ever
    // holding more than that much of it.
    Clip fromText(EspeakSynthesizer& synth, const std::string& text, const std::string& voice,
                  double maxSeconds = 0) const;
    const std::vector<std::string>& poseNames() const;
    // A line said live (`line`): its sound aligned on its words, and the frames the alignment
    // placed taught to the show's voice, as a played file with words teaches it.
    struct LineLesson {
        bool learnt = false;
        std::string detail;  // how many words were placed, or why nothing was learnt
    };
    // A line's words as live input follows them (Live::follow): read by espeak-ng in the
    // config's voice. InputError when they cannot be (no word it reads, another phoneme set).
    std::vector<dsp::ScriptWord> readLine(const std::string& text, EspeakSynthesizer& synth) const;
    LineLesson learnFromLine(std::span<const float> samples, int rate, const std::string& text,
                             EspeakSynthesizer& synth,
                             const std::function<void(const std::string&)>& log = {}) const;
    // The voice learnt from the show's lines with words (null: adapt_speaker = false). Files
    // without words and live input use it too.
    ShowSpeaker* speaker() const;
    // The live path: front end and runtime in their streaming forms (causal: least delay).
    class Live;
    std::unique_ptr<Live> startLive(int rate) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

class ClipMaker::Live {
  public:
    virtual ~Live() = default;
    // Feeds captured samples; appends the weight frames that became final to `out`.
    virtual void push(std::span<const float> samples, PoseTrack& out) = 0;
    // The front end's reported bound (a followed line's, while one is followed).
    virtual double latencySeconds() const = 0;
    // A line with known words (`line`): its cue (the frames from here on wait for its words),
    // its words once read (true: the mouth follows them from the cue on, [live] follow_lag
    // behind; false: the line was over first), and its end (back to the audio alone). Frames
    // that become final meanwhile go to `out`.
    virtual void cue(PoseTrack& out) = 0;
    virtual bool follow(std::span<const dsp::ScriptWord> words, PoseTrack& out) = 0;
    virtual void endLine(PoseTrack& out) = 0;
    virtual bool following() const = 0;
    // Each phoneme as the runtime takes it (`lipsync eval --live` scores them); before pushing.
    virtual void watch(std::function<void(const PhonemeSegment&)> sink) = 0;
    // The input is over (a file, never a microphone): the phonemes still open are taken too.
    virtual void finish(PoseTrack& out) = 0;
};

class Daemon {
  public:
    explicit Daemon(std::filesystem::path configFile);
    ~Daemon();
    // Runs until SIGTERM/SIGINT (or a "quit" request in tests): returns the exit code.
    int run();
    // One JSON request, one JSON reply (the socket's protocol; public for tests).
    nlohmann::json handle(const nlohmann::json& request);
    // The socket's protocol without the socket (fuzzing, tests): one request line in, the
    // reply line out, through the same checks a connection's lines go through.
    std::string answer(const std::string& line);
    // One pass of the loop's work without its timer: a tick, and failures reported.
    void tickOnce();

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace lipsyncd::daemon
