// What a full queue of the longest clips holds: one clip made ready ahead, whatever the
// queue's length and whatever the files' sample rate (issue 12: memory under 24 MB). Bytes
// the queue holds are counted exactly (status "memory"), so the bound is deterministic; the
// process's RSS is measured by scripts/measure-daemon.sh memory.
#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/dsp.hpp>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

TEST(QueueMemory, AFullQueueOfTheLongestClipsHoldsOneClipReadyAhead) {
    const auto dir = scratchDir("queue_memory");
    // The longest clip the config allows (max_clip_seconds), at twice the rate played: it is
    // resampled to 48 kHz, so it holds no more than a 48 kHz clip.
    const double seconds = 30;
    const int rate = 96000;
    std::vector<float> tone(static_cast<std::size_t>(seconds * rate));
    for (std::size_t i = 0; i < tone.size(); ++i)
        tone[i] =
            0.3f * static_cast<float>(std::sin(2 * M_PI * 220 * static_cast<double>(i) / rate));
    dsp::writeWavFile(dir / "long.wav", tone, rate);
    tone = {};

    std::ofstream(dir / "lipsyncd.toml")
        << "[audio]\ndevice = \"null\"\n[mouth]\npuppet = \"terminal\"\nhardware = false\n"
        << "[control]\nsocket = \"" << (dir / "control.sock").string() << "\"\n"
        << "[limits]\nmax_clip_seconds = 30\nmax_queue = 8\n";
    // In process, the loop never ticked: nothing starts playing, the queue stays full.
    daemon::Daemon d(dir / "lipsyncd.toml");
    for (int i = 0; i < 8; ++i)
        ASSERT_TRUE(d.handle({{"cmd", "play"}, {"file", (dir / "long.wav").string()}})["ok"]);
    EXPECT_FALSE(d.handle({{"cmd", "play"}, {"file", (dir / "long.wav").string()}})["ok"]);

    const std::size_t oneClipAudio = static_cast<std::size_t>(seconds * 48000) * 2;
    // Its weights: 100 frames a second of the pose set (10 poses) and their times.
    const std::size_t oneClipWeights = static_cast<std::size_t>(seconds * 100 + 2) * (10 * 4 + 8);
    const std::size_t perRequest = 4096;  // a request's path and name
    json status;
    for (int i = 0; i < 600; ++i) {  // the front clip is prepared on the worker
        status = d.handle({{"cmd", "status"}});
        if (status["memory"]["queue_bytes"].get<std::size_t>() > oneClipAudio) break;
        std::this_thread::sleep_for(100ms);
    }
    ASSERT_GT(status["memory"]["queue_bytes"].get<std::size_t>(), oneClipAudio)
        << "the front clip was never made ready: " << status;
    std::this_thread::sleep_for(1s);  // a worker that went on preparing would show now
    const auto held = d.handle({{"cmd", "status"}})["memory"]["queue_bytes"].get<std::size_t>();
    // One clip (with 1 % for the resampler's edges), never two.
    EXPECT_LE(held, (oneClipAudio + oneClipWeights) * 101 / 100 + 8 * perRequest)
        << "more than one clip is held ready, or a clip holds spare capacity";
    EXPECT_TRUE(status["playing"].is_null());
}

}  // namespace
}  // namespace lipsyncd::test
