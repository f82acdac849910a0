// Everything the config decides: the clip maker, the puppet and its driver and sinks, the
// audio device. Built at start; on reload built again, keeping what has not changed (the
// audio device, the driver with its actuators' state, the command record), so a reload
// neither interrupts the sound nor jumps the mouth nor truncates the record.
#pragma once

#include <fstream>
#include <functional>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/output.hpp>
#include <memory>

namespace lipsyncd::daemon {

struct Setup {
    DaemonConfig config;
    std::string puppetText;  // the puppet file as read: an edited file is a new puppet
    std::shared_ptr<const ClipMaker> clips;
    std::unique_ptr<output::Puppet> puppet;
    std::unique_ptr<std::ofstream> recordFile;
    std::unique_ptr<output::RecorderSink> recorder;
    std::unique_ptr<output::PuppetDriver> driver;
    std::unique_ptr<AudioSink> audio;

    // `previous`: the running setup, whose unchanged parts move into this one (it is left
    // without them: the caller drops it).
    Setup(DaemonConfig config, Setup* previous,
          const std::function<void(const std::string&)>& warn);
    // Whether the mouth can go on into `next` without a stop: the same puppet, poses, sinks.
    bool keepsDriverFor(const Setup& next) const;

  private:
    void buildDriver(const std::function<void(const std::string&)>& warn, bool appendRecord);
};

}  // namespace lipsyncd::daemon
