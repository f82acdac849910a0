// The daemon's state and its parts, shared by the files that each do one job with it:
// Daemon.cpp (the loop and signals), Requests.cpp (the control commands), Events.cpp (what
// subscribers and status see), DaemonReload.cpp (SIGHUP).
#pragma once

#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>

#include "ClipQueue.hpp"
#include "ControlServer.hpp"
#include "FrameEvent.hpp"
#include "LiveMode.hpp"
#include "LoopHealth.hpp"
#include "Player.hpp"
#include "PoseHold.hpp"
#include "Setup.hpp"

namespace lipsyncd::daemon {

void logInfo(const std::string& what);
void logWarning(const std::string& what);
void logError(const std::string& what);

struct Daemon::Impl {
    std::filesystem::path configFile;
    std::unique_ptr<Setup> setup;
    std::unique_ptr<ControlServer> control;
    ClipQueue queue{8};
    Player player;
    std::optional<LiveMode> live;
    PoseHold heldPose;               // PoseRequest.cpp
    std::vector<float> poseWeights;  // the request's weights, in the clip maker's pose order
    double start = 0;
    double lastEvent = 0, lastWatchdog = 0;
    std::uint64_t watchdogUsec = 0;
    std::size_t clipsPlayed = 0;
    LoopHealth loop;  // whether the 10 ms loop keeps up (status "loop")

    explicit Impl(std::filesystem::path file);
    double now() const;
    void status(const std::string& what);
    void tick();
    void timedTick(std::uint64_t expirations);  // tick(), its CPU time and the periods missed
    void restNow();  // the mouth to rest in real time (slew-limited steps, really waited for)
    void reload();
    void reportFailures();

    // Requests.cpp
    nlohmann::json handle(const nlohmann::json& request);
    nlohmann::json play(const nlohmann::json& request);
    nlohmann::json say(const nlohmann::json& request);
    nlohmann::json stop();
    nlohmann::json setLive(bool on);
    nlohmann::json line(const nlohmann::json& request);  // LiveLines.cpp
    nlohmann::json loadScript(const nlohmann::json& request);
    nlohmann::json scriptReply() const;
    struct {
        std::vector<std::string> lines;  // the show's script (`script`), for `line` with next
        std::size_t next = 0;            // the line `line` with next cues
    } script;
    // A live line that is over goes to the worker to teach the show's voice; its name, or null.
    nlohmann::json learnLine(std::optional<LiveLine> over);
    void reportLines();  // what the lines taught: logged by the worker, sent to subscribers
    void followLine();   // the words of the line being said, once read: the mouth follows them
    nlohmann::json holdPose(const nlohmann::json& request);  // PoseRequest.cpp

    // Events.cpp
    FrameEventWriter frameWriter;
    std::string_view frameEvent(double t);  // this tick's frame event line (no allocation)
    void setupChanged();                    // a new setup: its pose and actuator names
    nlohmann::json statusReply() const;
    nlohmann::json lineReply() const;     // the live line being heard, or null
    nlohmann::json speakerReply() const;  // what the show's voice has learnt (status, speaker)
    nlohmann::json speaker(const std::string& action);
};

}  // namespace lipsyncd::daemon
