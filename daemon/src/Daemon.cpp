// lipsyncd's main loop: one thread, one poll() over the control socket, a 100 Hz timer and
// the signals (signalfd). Every tick feeds the audio device, reads its clock and drives the
// puppet at that clock plus the lead time; the watchdog is petted from the same tick, so a
// stalled loop is a missed watchdog and systemd restarts the service.
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <iostream>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/output.hpp>
#include <lipsyncd/tts.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "ControlServer.hpp"

namespace lipsyncd::daemon {

namespace {
using nlohmann::json;

void log(const char* level, const std::string& what) {
    std::cerr << level << "lipsyncd: " << what << std::endl;
}
void info(const std::string& w) {
    log(SD_INFO, w);
}
void warn(const std::string& w) {
    log(SD_WARNING, w);
}
void error(const std::string& w) {
    log(SD_ERR, w);
}

void notify(const std::string& state) {
    sd_notify(0, state.c_str());
}

double monotonicSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// Everything the config decides, rebuilt together on reload.
struct Setup {
    DaemonConfig config;
    std::unique_ptr<ClipMaker> clips;
    std::unique_ptr<output::Puppet> puppet;
    std::unique_ptr<output::PuppetDriver> driver;
    std::unique_ptr<AudioSink> audio;
    std::unique_ptr<std::ofstream> recordFile;
    std::unique_ptr<output::RecorderSink> recorder;

    explicit Setup(const std::filesystem::path& file) : config(DaemonConfig::load(file)) {
        clips = std::make_unique<ClipMaker>(config);
        puppet = std::make_unique<output::Puppet>(output::Puppet::named(config.puppet));
        driver = std::make_unique<output::PuppetDriver>(*puppet, clips->poseNames());
        if (config.hardware)
            output::addHardwareSinks(*driver, *puppet, [](const std::string& m) { warn(m); });
        if (!config.record.empty()) {
            recordFile = std::make_unique<std::ofstream>(config.record);
            if (!*recordFile) throw InputError(config.record + ": cannot write the command record");
            recorder = std::make_unique<output::RecorderSink>(*recordFile, *puppet,
                                                              output::RecorderSink::Format::Csv);
            driver->addSink(*recorder);
        }
        if (config.terminal)
            driver->addSink(std::make_unique<output::TerminalSink>(std::cerr, *puppet));
        audio = openAudioSink(config.device);
    }
};
}  // namespace

struct Daemon::Impl {
    std::filesystem::path configFile;
    std::unique_ptr<Setup> setup;
    std::unique_ptr<ControlServer> control;
    std::unique_ptr<EspeakSynthesizer> synth;  // made on the first say, kept across reloads
    // Live: capture → streaming front end → causal runtime → the mouth, with the least delay.
    std::unique_ptr<CaptureSource> capture;
    std::unique_ptr<ClipMaker::Live> live;
    PoseTrack liveFrames;
    std::vector<float> captureBuffer = std::vector<float>(96000);
    double liveStarted = -1;
    std::deque<Clip> queue;
    std::optional<Clip> current;
    std::size_t written = 0;      // samples of the current clip handed to the device
    std::int64_t playedBase = 0;  // device position when the current clip started
    double start = monotonicSeconds();
    double lastEvent = 0, lastWatchdog = 0;
    std::uint64_t watchdogUsec = 0;
    std::size_t clipsPlayed = 0;
    bool quit = false;

    double now() const { return monotonicSeconds() - start; }

    void status(const std::string& what) {
        notify("STATUS=" + what);
        info(what);
    }

    void startNext() {
        if (current || queue.empty()) return;
        current = std::move(queue.front());
        queue.pop_front();
        setup->audio->open(current->rate);
        written = 0;
        playedBase = setup->audio->played();
        status("playing " + current->name);
    }

    // Seconds of the current clip heard so far, by the device's clock.
    double heard() const {
        return current ? static_cast<double>(setup->audio->played() - playedBase) / current->rate
                       : 0;
    }

    // New live weights since the last tick: the mouth takes the newest (the slew limit smooths).
    bool tickLive(double t) {
        if (!live) return false;
        const auto n = capture->read(captureBuffer);
        live->push(std::span<const float>(captureBuffer).first(n), liveFrames);
        if (liveFrames.frames() > 0) {
            setup->driver->update(t, liveFrames.frame(liveFrames.frames() - 1));
            liveFrames.times.clear();  // keep memory flat: only the newest frame matters
            liveFrames.values.clear();
        } else {
            setup->driver->tick(t);
        }
        return true;
    }

    json setLive(bool on) {
        if (!on) {
            live.reset();
            capture.reset();
            status("live off");
            return {{"ok", true}, {"live", false}};
        }
        if (!live) {
            capture = openCaptureSource(setup->config.captureDevice, setup->config.captureRate);
            live = setup->clips->startLive(capture->rate());
            liveFrames = PoseTrack{};
            liveStarted = now();
            status("live from " + setup->config.captureDevice);
        }
        return {{"ok", true},
                {"live", true},
                {"started", liveStarted},
                {"front_end_latency", live->latencySeconds()}};
    }

    void tick() {
        const double t = now();
        startNext();
        const bool following = tickLive(t);
        if (current) {
            written +=
                setup->audio->write(std::span<const float>(current->samples).subspan(written));
            // The mouth leads the sound by the puppet's lead time; the user's offset moves it.
            const double at = heard() + setup->config.leadSeconds - setup->config.syncOffsetSeconds;
            const auto& w = current->weights;
            if (w.frames() > 0) {
                const auto f =
                    static_cast<std::size_t>(std::clamp(std::round(at * setup->config.outputRateHz),
                                                        0.0, static_cast<double>(w.frames() - 1)));
                if (!following) setup->driver->update(t, w.frame(f));
            }
            if (written >= current->samples.size() &&
                heard() >= static_cast<double>(current->samples.size()) / current->rate) {
                ++clipsPlayed;
                current.reset();
                if (queue.empty()) status("idle");
            }
        } else if (!following) {
            setup->driver->tick(t);  // idle: the mouth rests once input has stalled
        }
        if (control && control->clients() > 0 && t - lastEvent >= 0.04) {
            lastEvent = t;
            control->broadcast(event(t));
        }
        if (watchdogUsec > 0 && t - lastWatchdog >= watchdogUsec / 2e6) {
            lastWatchdog = t;
            notify("WATCHDOG=1");
        }
    }

    json event(double t) const {
        json weights = json::object(), actuators = json::object();
        const auto commands = setup->driver->last();
        for (std::size_t i = 0; i < commands.size(); ++i)
            actuators[setup->puppet->actuators[i].name] = commands[i].value;
        if (current && current->weights.frames() > 0) {
            const auto f = std::min(current->weights.frames() - 1,
                                    static_cast<std::size_t>(heard() * setup->config.outputRateHz));
            for (std::size_t p = 0; p < current->weights.poses.size(); ++p)
                weights[current->weights.poses[p]] = current->weights.frame(f)[p];
        }
        return {{"event", "frame"}, {"time", t}, {"weights", weights}, {"actuators", actuators}};
    }

    json statusReply() const {
        json q = json::array();
        for (const auto& c : queue) q.push_back(c.name);
        return {{"ok", true},
                {"playing", current ? json(current->name) : json(nullptr)},
                {"position", heard()},
                {"queue", q},
                {"played", clipsPlayed},
                {"puppet", setup->puppet->name},
                {"at_rest", setup->driver->atRest()},
                {"live", live != nullptr},
                {"live_started", liveStarted}};
    }

    // Moves the mouth to rest in real time (slew-limited steps, really waited for).
    void restNow() {
        setup->driver->rest(now(), 100, [this](double t) {
            std::this_thread::sleep_for(std::chrono::duration<double>(std::max(0.0, t - now())));
        });
    }

    void reload() {
        notify("RELOADING=1");
        status("reloading " + configFile.string());
        try {
            auto fresh = std::make_unique<Setup>(configFile);
            restNow();
            queue.clear();
            current.reset();
            live.reset();
            capture.reset();
            setup = std::move(fresh);
            status("reloaded; idle");
        } catch (const std::exception& e) {
            error("reload failed, keeping the running configuration: " + std::string(e.what()));
        }
        notify("READY=1");
    }

    json handle(const json& r) {
        const std::string cmd = r.value("cmd", "");
        try {
            if (cmd == "play") {
                if (!r.contains("file") || !r["file"].is_string())
                    return {{"ok", false}, {"error", "play needs \"file\""}};
                queue.push_back(
                    setup->clips->fromFile(r["file"].get<std::string>(), r.value("channel", -1)));
                return {{"ok", true},
                        {"queued", queue.back().name},
                        {"duration",
                         static_cast<double>(queue.back().samples.size()) / queue.back().rate}};
            }
            if (cmd == "say") {
                if (!r.contains("text") || !r["text"].is_string())
                    return {{"ok", false}, {"error", "say needs \"text\""}};
                if (!synth) synth = std::make_unique<EspeakSynthesizer>();
                queue.push_back(setup->clips->fromText(*synth, r["text"].get<std::string>(),
                                                       r.value("voice", std::string())));
                return {{"ok", true}, {"queued", queue.back().name}};
            }
            if (cmd == "stop") {
                queue.clear();
                if (current) setup->audio->stop();
                current.reset();
                status("stopped; idle");
                return {{"ok", true}};
            }
            if (cmd == "status" || cmd == "queue") return statusReply();
            if (cmd == "reload") {
                reload();
                return {{"ok", true}, {"config", configFile.string()}};
            }
            if (cmd == "live") return setLive(r.value("on", true));
            if (cmd == "quit" && std::getenv("LIPSYNCD_TEST_QUIT")) {
                quit = true;
                return {{"ok", true}};
            }
            return {{"ok", false},
                    {"error", "unknown cmd '" + cmd +
                                  "' (play, say, stop, queue, status, live, reload, subscribe)"}};
        } catch (const std::exception& e) {
            return {{"ok", false}, {"error", e.what()}};
        }
    }
};

Daemon::Daemon(std::filesystem::path configFile) : impl_(std::make_unique<Impl>()) {
    impl_->configFile = std::move(configFile);
    impl_->setup = std::make_unique<Setup>(impl_->configFile);
    impl_->control = std::make_unique<ControlServer>(impl_->setup->config.socket,
                                                     impl_->setup->config.socketMode);
    sd_watchdog_enabled(0, &impl_->watchdogUsec);
}

Daemon::~Daemon() = default;

json Daemon::handle(const json& request) {
    return impl_->handle(request);
}

int Daemon::run() {
    auto& d = *impl_;
    sigset_t signals;
    sigemptyset(&signals);
    for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
    sigprocmask(SIG_BLOCK, &signals, nullptr);
    const int sigfd = signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
    const int timer = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
    const itimerspec every10ms{{0, 10'000'000}, {0, 10'000'000}};
    timerfd_settime(timer, 0, &every10ms, nullptr);

    notify("READY=1");
    d.status("ready: puppet '" + d.setup->puppet->name + "', audio '" + d.setup->config.device +
             "', control " + d.control->path().string());
    int exitSignal = 0;
    while (!exitSignal && !d.quit) {
        std::vector<pollfd> fds{{sigfd, POLLIN, 0}, {timer, POLLIN, 0}};
        d.control->addPollFds(fds);
        if (::poll(fds.data(), fds.size(), 1000) < 0 && errno != EINTR) break;
        signalfd_siginfo si{};
        while (::read(sigfd, &si, sizeof si) == sizeof si) {
            if (si.ssi_signo == SIGHUP)
                d.reload();
            else
                exitSignal = static_cast<int>(si.ssi_signo);
        }
        std::uint64_t expirations = 0;
        if (::read(timer, &expirations, sizeof expirations) == sizeof expirations) d.tick();
        d.control->service([&](const json& r) { return d.handle(r); });
    }
    notify("STOPPING=1");
    d.status(std::string("stopping (") + (exitSignal ? strsignal(exitSignal) : "asked") +
             "): mouth to rest");
    if (d.current) d.setup->audio->stop();
    d.restNow();
    info("at rest; bye");
    ::close(timer);
    ::close(sigfd);
    return 0;
}

}  // namespace lipsyncd::daemon
