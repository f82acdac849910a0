// The show's voice in the clip maker: lines played with their words teach it, and live input
// started afterwards follows it (lipsyncd's adapt_speaker).
#include <gtest/gtest.h>

#include <array>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

namespace lipsyncd::test {
namespace {

// The pose weights live input gives for a file's sound, pushed in 10 ms blocks.
PoseTrack liveWeights(const daemon::ClipMaker& maker, const std::filesystem::path& file) {
    auto decoder = dsp::AudioDecoder::open(file);
    auto live = maker.startLive(decoder.sampleRate());
    PoseTrack out;
    out.poses = maker.poseNames();
    std::vector<float> block(static_cast<std::size_t>(decoder.sampleRate() / 100));
    while (const auto n = decoder.read(block)) live->push(std::span(block).first(n), out);
    return out;
}

TEST(ShowVoice, LiveInputFollowsTheVoiceTheLinesBeforeTaught) {
    daemon::DaemonConfig config;
    config.hardware = false;
    const auto line = findDataFile("examples/hello.wav");
    const daemon::ClipMaker fresh(config), taught(config);
    EspeakSynthesizer synth;
    taught.fromFile(line, -1, synth,
                    "Hello there! I am a puppet. Watch my mouth move when I talk, and wave back "
                    "at me.");
    const auto before = liveWeights(fresh, line), after = liveWeights(taught, line);
    ASSERT_GT(before.frames(), 100u);
    EXPECT_NE(before.values, after.values) << "live input did not use the voice the line taught";
    // Without adapt_speaker nothing is carried: the same weights as a fresh start.
    config.adaptSpeaker = false;
    const daemon::ClipMaker off(config);
    off.fromFile(line, -1, synth, "Hello there! I am a puppet.");
    EXPECT_EQ(liveWeights(off, line).values, before.values);
}

}  // namespace
}  // namespace lipsyncd::test
