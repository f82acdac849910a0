// Building the setup, and building it again on reload from the parts that did not change.
#include <iostream>
#include <sstream>

#include "Setup.hpp"

namespace lipsyncd::daemon {

namespace {
std::string puppetFileText(const std::string& nameOrPath) {
    std::ifstream in(findNamedDataFile(nameOrPath, "puppets", ".toml"));
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}
}  // namespace

Setup::Setup(DaemonConfig c, Setup* previous, const std::function<void(const std::string&)>& warn)
    : config(std::move(c)) {
    clips =
        std::make_shared<const ClipMaker>(config, previous ? previous->clips.get() : nullptr, warn);
    puppetText = puppetFileText(config.puppet);
    const bool keepDriver = previous && previous->keepsDriverFor(*this);
    const bool keepAudio = previous && previous->config.device == config.device;
    // Whatever can fail happens first, so a failed reload leaves the running setup whole.
    if (!keepAudio) audio = openAudioSink(config.device);
    if (!keepDriver) buildDriver(warn, previous != nullptr);
    if (keepDriver) {
        puppet = std::move(previous->puppet);
        recordFile = std::move(previous->recordFile);
        recorder = std::move(previous->recorder);
        driver = std::move(previous->driver);
    }
    if (keepAudio) audio = std::move(previous->audio);
}

bool Setup::keepsDriverFor(const Setup& next) const {
    const auto& a = config;
    const auto& b = next.config;
    return a.puppet == b.puppet && puppetText == next.puppetText &&
           a.runtime.poses == b.runtime.poses && a.hardware == b.hardware && a.record == b.record &&
           a.terminal == b.terminal && clips->poseNames() == next.clips->poseNames();
}

void Setup::buildDriver(const std::function<void(const std::string&)>& warn, bool appendRecord) {
    puppet = std::make_unique<output::Puppet>(output::Puppet::named(config.puppet));
    driver = std::make_unique<output::PuppetDriver>(*puppet, clips->poseNames());
    if (config.hardware) output::addHardwareSinks(*driver, *puppet, warn);
    if (!config.record.empty()) {
        // A reload appends (a new header line marks where the new puppet starts).
        recordFile = std::make_unique<std::ofstream>(
            config.record, appendRecord ? std::ios::app : std::ios::trunc);
        if (!*recordFile) throw InputError(config.record + ": cannot write the command record");
        recorder = std::make_unique<output::RecorderSink>(*recordFile, *puppet,
                                                          output::RecorderSink::Format::Csv);
        driver->addSink(*recorder);
    }
    if (config.terminal)
        driver->addSink(std::make_unique<output::TerminalSink>(std::cerr, *puppet));
}

}  // namespace lipsyncd::daemon

#include <systemd/sd-daemon.h>

#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

// SIGHUP or `reload`: what plays and what waits go on, unless the new config changes the pose
// set (the prepared weights would drive the wrong actuators): then both are dropped, said so.
void Daemon::Impl::reload() {
    sd_notify(0, "RELOADING=1");
    status("reloading " + configFile.string());
    try {
        auto fresh =
            std::make_unique<Setup>(DaemonConfig::load(configFile), setup.get(), logWarning);
        if (setup->driver) restNow();  // a new puppet: the old one rests first
        if (fresh->clips->poseNames() != setup->clips->poseNames()) {
            logWarning("reload: the pose set changed; dropping what played and was queued");
            queue.clear();
            player.stop(setup->audio ? *setup->audio : *fresh->audio);
        } else if (setup->audio && player.clip()) {  // a new audio device: go on there
            setup->audio->stop();
            player.moveTo(*fresh->audio);
        }
        queue.setCapacity(fresh->config.maxQueue);
        control->setMaxClients(fresh->config.maxClients);
        setup = std::move(fresh);
        setupChanged();
        status(std::string("reloaded; ") +
               (player.clip() ? "playing " + player.clip()->name : "idle"));
    } catch (const std::exception& e) {
        logError("reload failed, keeping the running configuration: " + std::string(e.what()));
    }
    sd_notify(0, "READY=1");
}

}  // namespace lipsyncd::daemon
