// A line of the script said live (`line`): the sound from its cue on is kept, and once the line
// is over its words are aligned on it and teach the show's voice, as a played file with its
// words does; the lines after it are heard on that voice.
#include <gtest/gtest.h>

#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "../../daemon/src/LiveMode.hpp"
#include "../../daemon/src/ShowSpeaker.hpp"
#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

const char* const kHelloWords =
    "Hello there! I am a puppet. Watch my mouth move when I talk, and wave back at me.";

// The service, its microphone the bundled example line (5.2 s at real-time pace from `live on`).
void startHearingHello(DaemonProcess& d) {
    d.append("[live]\ndevice = \"file:" + findDataFile("examples/hello.wav").string() + "\"");
    d.start();
}

TEST(LiveLine, ALineWithItsWordsTeachesTheShowsVoiceAndSilenceTeachesNothing) {
    daemon::DaemonConfig config;
    config.hardware = false;
    const daemon::ClipMaker maker(config);
    EspeakSynthesizer synth;
    const auto hello = dsp::readAudioFile(findDataFile("examples/hello.wav"));
    std::vector<std::string> said;
    const auto log = [&](const std::string& s) { said.push_back(s); };

    const auto silent = std::vector<float>(static_cast<std::size_t>(hello.sampleRate) * 2, 0.0f);
    const auto nothing = maker.learnFromLine(silent, hello.sampleRate, kHelloWords, synth, log);
    EXPECT_FALSE(nothing.learnt);
    EXPECT_NE(nothing.detail.find("nothing learnt"), std::string::npos) << nothing.detail;
    EXPECT_EQ(maker.speaker()->heard().lines, 0u);
    for (const auto& s : said)  // the log names the line, not the memory file it was read from
        EXPECT_EQ(s.find("/proc/self/fd"), std::string::npos) << s;

    const auto lesson = maker.learnFromLine(hello.samples, hello.sampleRate, kHelloWords, synth);
    EXPECT_TRUE(lesson.learnt) << lesson.detail;
    EXPECT_NE(lesson.detail.find("of 17 words placed"), std::string::npos) << lesson.detail;
    const auto heard = maker.speaker()->heard();
    EXPECT_EQ(heard.lines, 1u);
    EXPECT_GT(heard.frames, 200u);
    EXPECT_TRUE(heard.networks);

    config.adaptSpeaker = false;
    const daemon::ClipMaker off(config);
    const auto refused = off.learnFromLine(hello.samples, hello.sampleRate, kHelloWords, synth);
    EXPECT_FALSE(refused.learnt);
    EXPECT_NE(refused.detail.find("adapt_speaker"), std::string::npos) << refused.detail;
}

// A script file's line ends in a newline, and sd_notify's STATUS must stay on one line.
TEST(LiveLine, ALineIsShownOnOneLineAndLongOnesCutShort) {
    EXPECT_EQ(daemon::shownLine("Hello\n  there!\r\n"), "'Hello there!'");
    EXPECT_EQ(daemon::shownLine(kHelloWords), "'Hello there! I am a puppet. Watch my mou...'");
}

TEST(LiveLine, LiveModeKeepsALinesSoundUpToItsLimit) {
    daemon::DaemonConfig config;
    config.hardware = false;
    config.captureDevice = "file:" + findDataFile("examples/hello.wav").string();
    auto maker = std::make_shared<const daemon::ClipMaker>(config);
    daemon::LiveMode live(config, maker, 0);
    EXPECT_EQ(live.line(), nullptr);
    EXPECT_FALSE(live.beginLine("Hello there!", 30).has_value());
    ASSERT_NE(live.line(), nullptr);
    const float* room = live.line()->samples.data();  // reserved at the cue
    for (int i = 0; i < 30; ++i) {
        std::this_thread::sleep_for(10ms);
        live.tick();
    }
    ASSERT_NE(live.line(), nullptr);
    EXPECT_EQ(live.line()->samples.data(), room) << "a tick reallocated the line's samples";
    EXPECT_GT(live.line()->seconds(), 0.2);
    EXPECT_LT(live.line()->seconds(), 2.0);
    EXPECT_FALSE(live.line()->full);
    // The next line ends this one; this one is short (0.1 s): the rest of it is not kept.
    const auto over = live.beginLine("I am a puppet.", 0.1);
    ASSERT_TRUE(over.has_value());
    EXPECT_EQ(over->text, "Hello there!");
    EXPECT_EQ(over->rate, 22050);
    EXPECT_GT(over->seconds(), 0.2);
    std::this_thread::sleep_for(300ms);
    live.tick();
    ASSERT_NE(live.line(), nullptr);
    EXPECT_TRUE(live.line()->full);
    EXPECT_NEAR(live.line()->seconds(), 0.1, 1.0 / 22050);
    const auto last = live.endLine();
    ASSERT_TRUE(last.has_value());
    EXPECT_EQ(last->text, "I am a puppet.");
    EXPECT_EQ(live.line(), nullptr);
    EXPECT_FALSE(live.endLine().has_value());
}

// The service, as a performer uses it: live on, a cue with the line's words, the line said,
// the next cue. The voice learns the line; a line without live input is refused, saying why.
TEST(LiveLine, TheServiceLearnsTheShowsVoiceFromALineSaidLive) {
    DaemonProcess d("", "null");
    startHearingHello(d);
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto early = c.request({{"cmd", "line"}, {"text", kHelloWords}});
    EXPECT_FALSE(early["ok"]);
    EXPECT_NE(early.value("error", "").find("live on"), std::string::npos) << early.dump();
    ASSERT_TRUE(c.request({{"cmd", "live"}, {"on", true}})["ok"]);
    const auto blank = c.request({{"cmd", "line"}, {"text", "  "}});
    EXPECT_FALSE(blank["ok"]) << blank.dump();
    // The cue as a cue system sends it: `lipsync ctl line --text-file LINE.txt`.
    std::ofstream(d.dir / "line1.txt") << kHelloWords << "\n";
    const auto cueRun = runLipsync({"ctl", "--socket", d.socket().string(), "line", "--text-file",
                                    (d.dir / "line1.txt").string()});
    ASSERT_EQ(cueRun.exitCode, 0) << cueRun.err;
    const auto cue = json::parse(cueRun.out);
    EXPECT_EQ(cue["line"], std::string(kHelloWords) + "\n");
    EXPECT_TRUE(cue["learning"].is_null());
    std::this_thread::sleep_for(5500ms);  // the line, 5.2 s
    const auto status = c.request({{"cmd", "status"}});
    ASSERT_TRUE(status["live_line"].is_object()) << status.dump();
    // The worker read the words at the cue: the mouth follows them (follow_lines).
    EXPECT_TRUE(status["live_line"]["following"]) << status.dump();
    EXPECT_EQ(status["live_line"]["text"], cue["line"]);
    EXPECT_GT(status["live_line"]["seconds"].get<double>(), 5.0);
    // Room for max_clip_seconds (30) of the capture's 22,050 samples a second, reserved at the cue.
    EXPECT_EQ(status["memory"]["live_line_bytes"], 30 * 22050 * sizeof(float));
    const auto overRun = runLipsync({"ctl", "--socket", d.socket().string(), "line"});
    ASSERT_EQ(overRun.exitCode, 0) << overRun.err;
    const auto over = json::parse(overRun.out);
    EXPECT_EQ(over["learning"], cue["line"]);
    json speaker;
    for (int i = 0; i < 300; ++i) {
        speaker = c.request({{"cmd", "speaker"}})["speaker"];
        if (speaker.value("lines", 0) > 0) break;
        std::this_thread::sleep_for(100ms);
    }
    EXPECT_EQ(speaker.value("lines", 0), 1) << speaker.dump() << d.log();
    EXPECT_TRUE(speaker.value("networks_trained", false)) << speaker.dump();
    EXPECT_TRUE(c.request({{"cmd", "live"}, {"on", false}})["ok"]);
    EXPECT_EQ(d.stop(), 0);
    EXPECT_NE(d.log().find("live line 'Hello there! I am a puppet. Watch my mou...': the show's "
                           "voice learnt from 1 line(s)"),
              std::string::npos)
        << d.log();
    EXPECT_NE(d.log().find("Watch my mou...': the mouth follows its 17 words"), std::string::npos)
        << d.log();
}

// A pedal or a show controller sends only "next": the lines come from the script loaded.
TEST(LiveLine, CuesTakeTheScriptsLinesInTurn) {
    DaemonProcess d("", "null");
    startHearingHello(d);
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto ctl = [&](std::vector<std::string> args) {
        args.insert(args.begin(), {"ctl", "--socket", d.socket().string()});
        return runLipsync(args);
    };
    ASSERT_TRUE(c.request({{"cmd", "live"}, {"on", true}})["ok"]);
    const auto none = ctl({"line", "--next"});
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_NE(none.err.find("no script"), std::string::npos) << none.err;
    std::ofstream(d.dir / "scene.txt") << "Hello there!\n\n  \nI am a puppet.\r\n";
    const auto loaded = ctl({"script", "--text-file", (d.dir / "scene.txt").string()});
    ASSERT_EQ(loaded.exitCode, 0) << loaded.err;
    EXPECT_EQ(json::parse(loaded.out)["script"]["lines"], 2) << loaded.out;
    const auto first = json::parse(ctl({"line", "--next"}).out);
    EXPECT_EQ(first["line"], "Hello there!");
    EXPECT_EQ(first["script_line"], 1);
    const auto status = c.request({{"cmd", "status"}});
    EXPECT_EQ(status["script"]["next"], 2) << status.dump();
    // A CRLF file's CR is gone.
    EXPECT_EQ(status["script"]["next_text"], "I am a puppet.") << status.dump();
    const auto second = json::parse(ctl({"line", "--next"}).out);
    EXPECT_EQ(second["learning"], "Hello there!");
    EXPECT_EQ(second["script_line"], 2);
    const auto past = ctl({"line", "--next"});
    EXPECT_EQ(past.exitCode, 1);
    EXPECT_NE(past.err.find("all 2 lines of the script are said"), std::string::npos) << past.err;
    const auto both = c.request({{"cmd", "line"}, {"next", true}, {"text", "Hi"}});
    EXPECT_FALSE(both["ok"]) << both.dump();
    EXPECT_EQ(ctl({"say", "Hi", "--next"}).exitCode, 2);
    EXPECT_TRUE(
        c.request({{"cmd", "script"}, {"text", "\n \n"}}).value("error", "").find("no line") !=
        std::string::npos);
    EXPECT_EQ(d.stop(), 0);
}

TEST(LiveLine, CtlTakesATextFileForPlayLineAndScriptOnly) {
    const auto words = scratchDir("ctl_text_file") / "words.txt";
    std::ofstream(words) << "Hello there!\n";
    const auto r = runLipsync(
        {"ctl", "--socket", "/nonexistent/sock", "say", "Hi", "--text-file", words.string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("is for play, line and script"), std::string::npos) << r.err;
}

// Without adapt_speaker a line's words still drive the mouth (follow_lines); without either,
// a line would serve nothing and is refused, saying why.
TEST(LiveLine, WithoutAdaptSpeakerALineIsFollowedOnlyAndWithoutEitherRefused) {
    DaemonProcess d("adapt_speaker = false\n", "null");
    d.append("[live]\ndevice = \"file:" + findDataFile("examples/hello.wav").string() +
             "\"\nfollow_lines = false");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    ASSERT_TRUE(c.request({{"cmd", "live"}, {"on", true}})["ok"]);
    const auto r = c.request({{"cmd", "line"}, {"text", kHelloWords}});
    EXPECT_FALSE(r["ok"]);
    EXPECT_NE(r.value("error", "").find("adapt_speaker and follow_lines"), std::string::npos)
        << r.dump();
    EXPECT_EQ(d.stop(), 0);

    DaemonProcess f("adapt_speaker = false\n", "null");
    startHearingHello(f);
    Client cf(f.socket());
    ASSERT_TRUE(cf.connected());
    ASSERT_TRUE(cf.request({{"cmd", "live"}, {"on", true}})["ok"]);
    Client watcher(f.socket());
    ASSERT_TRUE(watcher.request({{"cmd", "subscribe"}})["ok"]);
    const auto followed = cf.request({{"cmd", "line"}, {"text", kHelloWords}});
    EXPECT_TRUE(followed["ok"]) << followed.dump();
    // Subscribers hear when the mouth starts following the words.
    json event = json::object();
    for (int i = 0; i < 500 && event.value("event", "") != "following"; ++i) {
        event = json::parse(watcher.readLine(), nullptr, false);
        if (!event.is_object()) event = json::object();
    }
    EXPECT_EQ(event.value("words", 0), 17) << event.dump();
    EXPECT_EQ(event.value("text", ""), kHelloWords) << event.dump();
    const auto following = [](const json& s) {
        const auto line = s.value("live_line", json::object());
        return line.is_object() && line.value("following", false);
    };
    const auto line = statusWhen(cf, following, 5s)["live_line"];
    ASSERT_TRUE(line.is_object()) << line.dump();
    EXPECT_TRUE(line.value("following", false)) << line.dump();
    // Nothing is kept to learn from.
    EXPECT_EQ(cf.request({{"cmd", "status"}})["memory"]["live_line_bytes"], 0);
    // Words espeak-ng cannot read: the line is taken, the mouth follows the audio alone, and
    // subscribers and the log say why.
    EXPECT_TRUE(cf.request({{"cmd", "line"}, {"text", "?!"}})["ok"]);
    event = json::object();
    for (int i = 0; i < 500 && event.value("event", "") != "following"; ++i) {
        event = json::parse(watcher.readLine(), nullptr, false);
        if (!event.is_object()) event = json::object();
    }
    EXPECT_NE(event.value("error", "").find("found no words it can read"), std::string::npos)
        << event.dump();
    EXPECT_FALSE(cf.request({{"cmd", "status"}})["live_line"].value("following", true));
    EXPECT_TRUE(cf.request({{"cmd", "line"}})["learning"].is_null());
    EXPECT_EQ(f.stop(), 0);
    EXPECT_NE(f.log().find("live line '?!': the mouth follows the audio alone: espeak-ng"),
              std::string::npos)
        << f.log();
}

}  // namespace
}  // namespace lipsyncd::test
