// lipsyncd's main loop: one thread, one poll() over the control socket, a 100 Hz timer and
// the signals (signalfd). Every tick feeds the audio device, reads its clock once and drives
// the puppet at that clock plus the lead time; the watchdog is petted from the same tick, so a
// stalled loop is a missed watchdog and systemd restarts the service. Clips are made ready on
// the queue's worker thread: nothing a request asks for runs inside the tick.
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <thread>

#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

namespace {
void log(const char* level, const std::string& what) {
    std::cerr << level << "lipsyncd: " << what << std::endl;
}
double monotonicSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}
}  // namespace

void logInfo(const std::string& w) {
    log(SD_INFO, w);
}
void logWarning(const std::string& w) {
    log(SD_WARNING, w);
}
void logError(const std::string& w) {
    log(SD_ERR, w);
}

Daemon::Impl::Impl(std::filesystem::path file)
    : configFile(std::move(file)), start(monotonicSeconds()) {
    setup = std::make_unique<Setup>(DaemonConfig::load(configFile), nullptr, logWarning);
    queue.setCapacity(setup->config.maxQueue);
    setupChanged();
    control = std::make_unique<ControlServer>(setup->config.socket, setup->config.socketMode,
                                              setup->config.maxClients, logInfo);
    sd_watchdog_enabled(0, &watchdogUsec);
}

double Daemon::Impl::now() const {
    return monotonicSeconds() - start;
}

void Daemon::Impl::status(const std::string& what) {
    sd_notify(0, ("STATUS=" + what).c_str());
    logInfo(what);
}

void Daemon::Impl::tick() {
    const double t = now();
    auto& driver = *setup->driver;
    if (!player.clip())
        if (auto clip = queue.tryTakeReady()) {
            player.start(std::move(*clip), *setup->audio);
            heldPose.release();  // the clip has the mouth now
            status("playing " + player.clip()->name);
        }
    const auto& config = setup->config;
    // The mouth leads the sound by the puppet's lead time; the user's offset moves it later.
    const auto clipFrame =
        player.tick(*setup->audio, setup->puppet->leadSeconds - config.syncOffsetSeconds,
                    config.runtime.config.outputRate);
    if (live) {  // live input has the mouth while it is on
        const auto liveFrame = live->tick();
        liveFrame.empty() ? driver.tick(t) : driver.update(t, liveFrame);
    } else if (!clipFrame.empty()) {
        driver.update(t, clipFrame);
    } else if (const auto pose = heldPose.at(t); !pose.empty()) {
        driver.update(t, pose);  // a client's pose (`pose`), through the same limits and slew
    } else {
        driver.tick(t);  // idle: the mouth rests once input has stalled
    }
    if (player.finished()) {
        player.take();
        ++clipsPlayed;
        if (queue.empty()) status("idle");
    }
    if (control->subscribers() > 0 && t - lastEvent >= 0.04) {
        lastEvent = t;
        control->broadcast(frameEvent(t));
    }
    if (watchdogUsec > 0 && t - lastWatchdog >= watchdogUsec / 2e6) {
        lastWatchdog = t;
        sd_notify(0, "WATCHDOG=1");
    }
}

void Daemon::Impl::timedTick(std::uint64_t expirations) {
    const double before = threadCpuSeconds();
    tick();
    loop.tick(threadCpuSeconds() - before, expirations > 1 ? expirations - 1 : 0);
}

void Daemon::Impl::reportFailures() {
    if (const auto behind = loop.warning(now())) logWarning(*behind);
    for (const auto& f : queue.takeFailures()) {
        logWarning("cannot play " + f);
        control->broadcast(json{{"event", "failed"}, {"error", f}});
    }
    reportLines();
    followLine();
}

void Daemon::Impl::restNow() {
    setup->driver->rest(now(), 100, [this](double t) {
        std::this_thread::sleep_for(std::chrono::duration<double>(std::max(0.0, t - now())));
    });
}

Daemon::Daemon(std::filesystem::path configFile)
    : impl_(std::make_unique<Impl>(std::move(configFile))) {}

Daemon::~Daemon() = default;

json Daemon::handle(const json& request) {
    return impl_->handle(request);
}

std::string Daemon::answer(const std::string& line) {
    bool subscribed = false;
    return ControlServer::serialise(
        ControlServer::reply(line, subscribed, [this](const json& r) { return impl_->handle(r); }));
}

void Daemon::tickOnce() {
    impl_->tick();
    impl_->reportFailures();
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

    sd_notify(0, "READY=1");
    d.status("ready: puppet '" + d.setup->puppet->name + "', audio '" + d.setup->config.device +
             "', control " + d.control->path().string());
    int exitSignal = 0;
    int exitCode = 0;
    // Whatever ends the loop (a signal, or an error nobody expected), the mouth goes to rest
    // before the process exits.
    try {
        std::vector<pollfd> fds;
        while (!exitSignal) {
            fds.assign({{sigfd, POLLIN, 0}, {timer, POLLIN, 0}});
            d.control->addPollFds(fds);
            if (::poll(fds.data(), fds.size(), 1000) < 0 && errno != EINTR) break;
            const double turnStarted = threadCpuSeconds();
            signalfd_siginfo si{};
            while (::read(sigfd, &si, sizeof si) == sizeof si) {
                if (si.ssi_signo == SIGHUP)
                    d.reload();
                else
                    exitSignal = static_cast<int>(si.ssi_signo);
            }
            std::uint64_t expirations = 0;
            if (::read(timer, &expirations, sizeof expirations) == sizeof expirations)
                d.timedTick(expirations);
            d.control->service([&](const json& r) { return d.handle(r); });
            d.reportFailures();
            d.loop.turn(threadCpuSeconds() - turnStarted);
        }
    } catch (const std::exception& e) {
        logError(std::string("stopping on an error: ") + e.what());
        exitCode = 1;
    }
    sd_notify(0, "STOPPING=1");
    d.status(std::string("stopping (") + (exitSignal ? strsignal(exitSignal) : "error") +
             "): mouth to rest");
    d.player.stop(*d.setup->audio);
    d.restNow();
    logInfo("at rest; bye");
    ::close(timer);
    ::close(sigfd);
    return exitCode;
}

}  // namespace lipsyncd::daemon
