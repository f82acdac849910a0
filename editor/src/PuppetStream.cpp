// The preview on the real puppet: lipsyncd owns the puppet (its limits, slew and rest), the
// editor only sends it weights, one `pose` request a frame, through the daemon's own client.
// The service holds a pose briefly: a stream that stops (page paused, editor gone) lets the
// mouth go to rest by itself.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::editor {

namespace {
using nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr std::chrono::milliseconds kTimeout{1000};

json poseRequest(const PoseTrack& track, std::size_t frame) {
    json weights = json::object();
    const auto values = track.frame(frame);
    for (std::size_t p = 0; p < track.poses.size(); ++p) {
        const float v = values[p];
        weights[track.poses[p]] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    }
    return {{"cmd", "pose"}, {"weights", std::move(weights)}};
}

std::optional<std::string> refusal(const json& reply) {
    if (reply.value("ok", false)) return std::nullopt;
    return reply.value("error", std::string("refused"));
}
}  // namespace

PuppetStream::PuppetStream(std::filesystem::path socket, const std::string& puppet)
    : socket_(std::move(socket)) {
    daemon::ControlClient client(socket_, kTimeout);
    const auto status = client.request({{"cmd", "status"}});
    if (!status.value("ok", false) || !status.contains("puppet") || !status["puppet"].is_string())
        throw InputError(socket_.string() +
                         ": not lipsyncd's control socket (status: " + status.dump() + ")");
    puppet_ = status["puppet"].get<std::string>();
    // The servo's lag, from the puppet file: the daemon drives a clip's mouth this far ahead of
    // its sound, and the stream does the same for the page's sound.
    if (status.contains("latency") && status["latency"].value("lead", 0.0) > 0)
        leadSeconds_ = status["latency"]["lead"].get<double>();
    if (!puppet.empty() && puppet != puppet_)
        throw InputError(socket_.string() + ": lipsyncd drives the puppet '" + puppet_ +
                         "', not '" + puppet + "' (--puppet)");
}

PuppetStream::~PuppetStream() {
    stop();
}

void PuppetStream::stop() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

std::string PuppetStream::lastError() const {
    std::lock_guard lock(mutex_);
    return error_;
}

std::optional<std::string> PuppetStream::play(PoseTrack track, double fromSeconds) {
    stop();
    const auto start = Clock::now();  // the page's audio is at `fromSeconds` now
    {
        std::lock_guard lock(mutex_);
        stopping_ = false;
        error_.clear();
    }
    sent_ = 0;
    const auto first =
        static_cast<std::size_t>(std::lower_bound(track.times.begin(), track.times.end(),
                                                  fromSeconds + leadSeconds_ - 1e-9) -
                                 track.times.begin());
    if (first >= track.frames()) return std::nullopt;  // played to its end already
    try {
        daemon::ControlClient client(socket_, kTimeout);
        if (auto refused = refusal(client.request(poseRequest(track, first)))) return refused;
    } catch (const std::exception& e) {
        return std::string(e.what());
    }
    ++sent_;
    thread_ = std::thread([this, t = std::move(track), first, start, fromSeconds]() mutable {
        stream(std::move(t), first + 1, start, fromSeconds);
    });
    return std::nullopt;
}

// Frame f goes out the puppet's lead before the page's audio reaches its time: the clock
// was at `from` at `start`, when the page started playing (play() has sent the frame due then).
void PuppetStream::stream(PoseTrack track, std::size_t next,
                          std::chrono::steady_clock::time_point start, double from) {
    try {
        daemon::ControlClient client(socket_, kTimeout);
        for (std::size_t f = next; f < track.frames(); ++f) {
            const auto due =
                start + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(track.times[f] - leadSeconds_ - from));
            std::unique_lock lock(mutex_);
            if (wake_.wait_until(lock, due, [this] { return stopping_; })) return;
            lock.unlock();
            if (auto refused = refusal(client.request(poseRequest(track, f)))) {
                std::lock_guard again(mutex_);
                error_ = *refused;
                return;
            }
            ++sent_;
        }
    } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        error_ = e.what();
    }
}

}  // namespace lipsyncd::editor
