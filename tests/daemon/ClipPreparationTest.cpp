// Requests are bounded before they are queued, prepared on the worker while the mouth goes on,
// and a reload keeps what plays and what waits.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

std::string errorOf(const json& reply) {
    return reply.value("error", std::string());
}

TEST(ClipPreparation, AFifoIsRefusedAndTheLoopGoesOn) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto fifo = d.dir / "pipe.wav";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto reply = c.request({{"cmd", "play"}, {"file", fifo.string()}});
    EXPECT_EQ(reply["ok"], false);
    EXPECT_NE(errorOf(reply).find("not a regular file"), std::string::npos) << reply;
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);
    EXPECT_EQ(d.stop(), 0);
}

TEST(ClipPreparation, ClipsAndTextBeyondTheConfiguredLimitsAreRefused) {
    DaemonProcess d;
    d.append("[limits]\nmax_clip_seconds = 0.5\nmax_text_bytes = 100\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto longFile =
        c.request({{"cmd", "play"}, {"file", findDataFile("examples/hello.wav").string()}});
    EXPECT_EQ(longFile["ok"], false);
    EXPECT_NE(errorOf(longFile).find("max_clip_seconds"), std::string::npos) << longFile;
    const auto longText = c.request({{"cmd", "say"}, {"text", std::string(101, 'a')}});
    EXPECT_EQ(longText["ok"], false);
    EXPECT_NE(errorOf(longText).find("max_text_bytes"), std::string::npos) << longText;
    // Speech longer than the clip limit fails on the worker, said to subscribers; never plays.
    Client watcher(d.socket());
    ASSERT_TRUE(watcher.request({{"cmd", "subscribe"}})["ok"]);
    ASSERT_TRUE(
        c.request({{"cmd", "say"}, {"text", "This takes longer than half a second."}})["ok"]);
    bool failed = false;
    for (int i = 0; i < 200 && !failed; ++i) {
        const auto line = json::parse(watcher.readLine(), nullptr, false);
        failed = line.value("event", "") == "failed";
        EXPECT_TRUE(line.value("weights", json::object()).empty()) << "it played: " << line;
    }
    EXPECT_TRUE(failed) << "no failed event";
    EXPECT_EQ(d.stop(), 0);
}

TEST(ClipPreparation, TheQueueIsBounded) {
    DaemonProcess d;
    d.append("[limits]\nmax_queue = 2\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    int accepted = 0;
    json refused;
    for (int i = 0; i < 5; ++i) {
        const auto reply =
            c.request({{"cmd", "say"}, {"text", "Number " + std::to_string(i) + "."}});
        if (reply["ok"].get<bool>())
            ++accepted;
        else
            refused = reply;
    }
    // Two wait, one may already play: never all five. Which ones are refused depends on when
    // the first line, prepared on the worker, starts to play and leaves the queue (on a loaded
    // machine the fifth found room after the third and fourth were refused).
    EXPECT_LE(accepted, 3);
    ASSERT_FALSE(refused.is_null()) << "all five accepted";
    EXPECT_NE(errorOf(refused).find("queue full"), std::string::npos) << refused;
    EXPECT_EQ(d.stop(), 0);
}

// The longest gap between two recorded commands of one actuator.
double longestGap(const std::vector<std::pair<double, double>>& stream) {
    double gap = 0;
    for (std::size_t i = 1; i < stream.size(); ++i)
        gap = std::max(gap, stream[i].first - stream[i - 1].first);
    return gap;
}

TEST(ClipPreparation, PreparingALongTextNeverStallsTheMouth) {
    DaemonProcess d;
    d.append("[limits]\nmax_text_bytes = 16384\nmax_clip_seconds = 3600\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    ASSERT_TRUE(c.request({{"cmd", "say"}, {"text", "Open wide, open wide, open wide."}})["ok"]);
    std::this_thread::sleep_for(700ms);  // it plays
    std::string text;
    while (text.size() < 16000) text += "The quick brown fox jumps over the lazy dog. ";
    c.sendLine(json{{"cmd", "say"}, {"text", text}}.dump());
    std::this_thread::sleep_for(1500ms);
    EXPECT_TRUE(json::parse(c.readLine())["ok"]);
    // Nothing long ran on the loop while the worker prepared the text (about a second of
    // espeak-ng's CPU): its busiest turn took well under a millisecond (CPU time, which a busy
    // machine does not stretch).
    const auto loop = c.request({{"cmd", "status"}})["loop"];
    EXPECT_LT(loop["busiest_cpu_ms"].get<double>(), 50) << loop;
    EXPECT_EQ(d.stop(), 0);
    const auto jaw = d.recorded("jaw");
    ASSERT_GT(jaw.size(), 50u);
    // The recorder gets a command every 10 ms tick: a loop that waited for the worker would
    // show as a gap of a second or more (a generous bound: on a busy machine the loop itself
    // may wait a while for a core).
    EXPECT_LT(longestGap(jaw), 1.0) << "the loop stalled while a clip was prepared";
}

TEST(ClipPreparation, ReloadKeepsWhatPlaysAndWhatWaitsAndAppendsTheRecord) {
    DaemonProcess d;
    NotifySocket notify(d.dir / "notify");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    ASSERT_TRUE(
        c.request({{"cmd", "say"}, {"text", "Hello, this is the first of two lines."}})["ok"]);
    ASSERT_TRUE(c.request({{"cmd", "say"}, {"text", "And this is the second."}})["ok"]);
    std::this_thread::sleep_for(800ms);
    const auto before = c.request({{"cmd", "status"}});
    ASSERT_FALSE(before["playing"].is_null()) << before;
    ::kill(d.pid, SIGHUP);
    ASSERT_TRUE(notify.waitFor("RELOADING=1"));
    std::this_thread::sleep_for(300ms);
    const auto after = c.request({{"cmd", "status"}});
    EXPECT_EQ(after["playing"], before["playing"]) << after;
    EXPECT_GT(after["position"].get<double>(), before["position"].get<double>()) << after;
    EXPECT_EQ(after["queue"], before["queue"]) << after;
    waitUntilIdle(c);
    EXPECT_EQ(c.request({{"cmd", "status"}})["played"], 2);
    // The reload runs on the loop (about 25 ms of CPU, two ticks): its busiest turn.
    const auto loop = c.request({{"cmd", "status"}})["loop"];
    EXPECT_LT(loop["busiest_cpu_ms"].get<double>(), 250) << loop;
    EXPECT_EQ(d.stop(), 0);
    const auto jaw = d.recorded("jaw");
    ASSERT_FALSE(jaw.empty());
    EXPECT_LT(jaw.front().first, 0.5) << "the record lost what came before the reload";
    EXPECT_LT(longestGap(jaw), 1.0) << "the mouth stopped across the reload";
}

}  // namespace
}  // namespace lipsyncd::test

namespace lipsyncd::test {
namespace {

// A show file's words beside it (FILE.txt) are aligned, not recognised, and the log says so;
// play's own text wins over the file beside it.
TEST(ClipPreparation, KnownWordsBesideAPlayedFileAreAligned) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto wav = d.dir / "line.wav";
    std::filesystem::copy_file(findDataFile("examples/hello.wav"), wav);
    std::ofstream(d.dir / "line.txt")
        << "Hello there! I am a puppet. Watch my mouth move when I talk, and wave back at me.\n";
    ASSERT_TRUE(c.request({{"cmd", "play"}, {"file", wav.string()}})["ok"]);
    waitUntilIdle(c);
    EXPECT_NE(d.log().find("words from " + (d.dir / "line.txt").string() + " aligned"),
              std::string::npos)
        << d.log();
    const auto reply =
        c.request({{"cmd", "play"}, {"file", wav.string()}, {"text", "Hello there!"}});
    ASSERT_TRUE(reply["ok"]) << reply;
    waitUntilIdle(c);
    EXPECT_NE(d.log().find("words from the request"), std::string::npos) << d.log();
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test

namespace lipsyncd::test {
namespace {

json speakerOf(Client& c) {
    return c.request({{"cmd", "status"}})["speaker"];
}

// Plays a request until it has been prepared (it plays), then stops it: what a clip teaches is
// learnt when it is made, before it is heard.
void prepare(Client& c, const json& request) {
    ASSERT_TRUE(c.request(request)["ok"]);
    const auto playing = [](const json& s) { return !s["playing"].is_null(); };
    ASSERT_TRUE(playing(statusWhen(c, playing, 20s))) << "the request never played";
    ASSERT_TRUE(c.request({{"cmd", "stop"}})["ok"]);
}

// A line with its words, prepared (and so learnt) then stopped.
void prepareLine(const DaemonProcess& d, Client& c) {
    const auto wav = d.dir / "line.wav";
    if (!std::filesystem::exists(wav))
        std::filesystem::copy_file(findDataFile("examples/hello.wav"), wav);
    prepare(c, {{"cmd", "play"},
                {"file", wav.string()},
                {"text", "Hello there! I am a puppet. Watch my mouth move when I talk."}});
}

// The show's voice (adapt_speaker, on by default): a played file with its words teaches it, a
// file without words does not; a reload with the same templates goes on with it, `speaker
// reset` forgets it.
TEST(ClipPreparation, LinesPlayedWithTheirWordsTeachTheShowsVoice) {
    DaemonProcess d;
    NotifySocket notify(d.dir / "notify");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    EXPECT_EQ(speakerOf(c),
              (json{{"adapting", true}, {"lines", 0}, {"frames", 0}, {"networks_trained", false}}));
    const auto wav = d.dir / "line.wav";
    std::filesystem::copy_file(findDataFile("examples/hello.wav"), wav);
    prepare(c, {{"cmd", "play"}, {"file", wav.string()}});  // no words
    EXPECT_EQ(speakerOf(c)["lines"], 0);
    prepareLine(d, c);
    const auto taught = speakerOf(c);
    EXPECT_EQ(taught["lines"], 1) << taught;
    EXPECT_GT(taught["frames"].get<int>(), 100) << taught;
    EXPECT_EQ(taught["networks_trained"], true) << taught;
    EXPECT_NE(d.log().find("the show's voice learnt from 1 line(s)"), std::string::npos) << d.log();
    ::kill(d.pid, SIGHUP);
    ASSERT_TRUE(notify.waitFor("RELOADING=1"));
    std::this_thread::sleep_for(300ms);
    EXPECT_EQ(speakerOf(c), taught) << "a reload forgot the voice";
    const auto reset = c.request({{"cmd", "speaker"}, {"action", "reset"}});
    ASSERT_TRUE(reset["ok"]) << reset;
    EXPECT_EQ(reset["speaker"]["frames"], 0) << reset;
    EXPECT_EQ(reset["speaker"]["networks_trained"], false) << reset;
    const auto bad = c.request({{"cmd", "speaker"}, {"action", "forget"}});
    EXPECT_EQ(bad["ok"], false);
    EXPECT_NE(errorOf(bad).find("show or reset"), std::string::npos) << bad;
    EXPECT_EQ(d.stop(), 0);
}

// speaker_file: the voice outlives a restart; a reset removes it; a broken file is said and the
// service starts with an empty voice.
TEST(ClipPreparation, TheShowsVoiceOutlivesARestartInItsFile) {
    const auto voice = scratchDir("daemon_voice") / "voice.json";
    std::filesystem::remove(voice);
    const std::string key = "speaker_file = \"" + voice.string() + "\"\n";
    json taught;
    {
        DaemonProcess d(key);
        d.start();
        Client c(d.socket());
        ASSERT_TRUE(c.connected());
        prepareLine(d, c);
        taught = speakerOf(c);
        ASSERT_GT(taught["frames"].get<int>(), 100) << taught;
        EXPECT_TRUE(std::filesystem::exists(voice));
        EXPECT_EQ(d.stop(), 0);
    }
    {  // the networks the line trained further are kept too
        std::ifstream in(voice);
        const auto file = json::parse(in);
        EXPECT_TRUE(file.contains("class_network") && file.contains("jaw_network"));
    }
    {
        DaemonProcess d(key);
        d.start();
        Client c(d.socket());
        ASSERT_TRUE(c.connected());
        EXPECT_EQ(speakerOf(c)["frames"], taught["frames"]);
        EXPECT_NE(d.log().find("the show's voice from " + voice.string()), std::string::npos)
            << d.log();
        ASSERT_TRUE(c.request({{"cmd", "speaker"}, {"action", "reset"}})["ok"]);
        EXPECT_FALSE(std::filesystem::exists(voice));
        EXPECT_EQ(d.stop(), 0);
    }
    std::ofstream(voice) << "{\"format\": \"lipsyncd-speaker\", \"version\": 1}\n";
    DaemonProcess d(key);
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    EXPECT_EQ(speakerOf(c)["frames"], 0);
    EXPECT_NE(d.log().find(voice.string()), std::string::npos) << d.log();
    EXPECT_NE(d.log().find("starts again"), std::string::npos) << d.log();
    EXPECT_EQ(d.stop(), 0);
}

// A speaker file that cannot be written is said; the voice is still learnt and used.
TEST(ClipPreparation, AVoiceFileThatCannotBeWrittenIsSaidAndTheVoiceStillLearnt) {
    DaemonProcess d("speaker_file = \"/nonexistent/lipsyncd/voice.json\"\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    prepareLine(d, c);
    EXPECT_GT(speakerOf(c)["frames"].get<int>(), 100);
    EXPECT_NE(d.log().find("not kept for a restart: /nonexistent/lipsyncd/voice.json"),
              std::string::npos)
        << d.log();
    EXPECT_EQ(d.stop(), 0);
}

TEST(ClipPreparation, WithAdaptSpeakerOffNothingIsLearnt) {
    DaemonProcess d("adapt_speaker = false\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    EXPECT_EQ(speakerOf(c), (json{{"adapting", false}}));
    const auto reply = c.request({{"cmd", "speaker"}});
    EXPECT_EQ(reply["ok"], false);
    EXPECT_NE(errorOf(reply).find("adapt_speaker"), std::string::npos) << reply;
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
