// Known words over a corpus: `lipsync eval --align` (each NAME.wav aligned on NAME.txt beside
// it, per speaker and voice) and scripts/label-with-aligner.sh (the aligner as the labeller).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>

#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

// espeak-ng's speech of `text` as DIR/NAME.wav with its exact labels (NAME.lab) and, unless
// `words` is empty, the words file NAME.txt.
void speak(const fs::path& dir, const std::string& name, const std::string& text,
           const std::string& voice, const std::string& words) {
    fs::create_directories(dir);
    const auto r =
        runLipsync({"say", text, "--voice", voice, "--wav", (dir / (name + ".wav")).string(),
                    "--schedule", (dir / (name + ".lab")).string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    if (!words.empty()) std::ofstream(dir / (name + ".txt")) << words << '\n';
}

TEST(AlignCli, EvalAlignScoresTheAlignedWordsPerSpeakerAndVoice) {
    const auto dir = scratchDir("cli_eval_align");
    const std::string en = "Seven puppets sang a song about the moon.";
    const std::string ru = "Она завела прядь волос за ухо.";
    speak(dir / "anna", "line", en, "en-us+f3", en);
    speak(dir / "anna", "unscripted", en, "en-us+f3", "");  // no words file: skipped
    speak(dir / "ivan", "line", ru, "ru", ru);
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--align", "--voice", "ivan=ru",
                               "--json", "-", "--no-per-file"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("no words file unscripted.txt"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("aligned on the words"), std::string::npos) << r.out;
    const auto json = nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1));
    EXPECT_EQ(json["files"].size(), 2u);
    for (const auto* speaker : {"anna", "ivan"}) {
        const auto& s = json["speakers"][speaker];
        EXPECT_GT(s["group_accuracy"].get<double>(), 0.7) << speaker;
        EXPECT_GT(s["jaw"]["audio"]["r"].get<double>(), 0.6) << speaker;
        // espeak-ng's own timings: its boundaries come back within issue 11's 15 ms median.
        const auto& b = s["boundaries"];
        EXPECT_GT(b["count"].get<int>(), 10) << speaker;
        EXPECT_LE(b["median_ms"].get<double>(), 15.0) << speaker;
        EXPECT_LT(b["missed"].get<int>(), b["count"].get<int>() / 4) << speaker;
    }
    EXPECT_NE(r.out.find("within 20 ms"), std::string::npos) << r.out;
    // Russian words read by the English voice are spelled, not said: far worse, or refused.
    const auto wrong = runLipsync(
        {"eval", "--corpus", (dir / "ivan").string(), "--align", "--json", "-", "--no-per-file"});
    if (wrong.exitCode == 0) {
        const auto j = nlohmann::json::parse(wrong.out.substr(wrong.out.find("\n{") + 1));
        EXPECT_LT(j["group_accuracy"].get<double>(),
                  json["speakers"]["ivan"]["group_accuracy"].get<double>());
    }
}

// A speaker whose words the voice cannot read: the first file says why and which option helps,
// the others are counted once at the end, not told one by one.
TEST(AlignCli, EvalTellsWordsItCannotUseOnceForEachSpeaker) {
    const auto dir = scratchDir("cli_eval_unused_words");
    const std::string ru = "Она завела прядь волос за ухо.";
    for (const auto* name : {"one", "two", "three"}) speak(dir / "ivan", name, ru, "ru", ru);
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--align", "--no-per-file"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto first = r.err.find("words not used");
    ASSERT_NE(first, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("words not used", first + 1), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--voice ivan=LANG"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("ivan: the words of 3 files not used"), std::string::npos) << r.err;
    // Given the speaker's language, nothing to tell.
    const auto right =
        runLipsync({"eval", "--corpus", dir.string(), "--align", "--voice", "ivan=ru"});
    ASSERT_EQ(right.exitCode, 0) << right.err;
    EXPECT_EQ(right.err.find("not used"), std::string::npos) << right.err;
}

// `--follow-lag`: each file followed as lipsyncd follows a live line with its words; the
// report says so and names the lag, and the option means nothing without --align.
TEST(AlignCli, EvalFollowLagScoresLinesAsTheServiceFollowsThem) {
    const auto dir = scratchDir("cli_eval_follow");
    const std::string en = "Seven puppets sang a song about the moon.";
    speak(dir / "anna", "line", en, "en-us+f3", en);
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--align", "--follow-lag", "0.1",
                               "--json", "-", "--no-per-file"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("(followed on the words, lag 100 ms)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("r 0."), std::string::npos) << r.out;
    const auto json = nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1));
    EXPECT_GT(json["speakers"]["anna"]["group_accuracy"].get<double>(), 0.8);
    const auto alone = runLipsync({"eval", "--corpus", dir.string(), "--follow-lag", "0.1"});
    EXPECT_EQ(alone.exitCode, 2);
    EXPECT_NE(alone.err.find("--follow-lag requires --align"), std::string::npos) << alone.err;
    // Following prices a pause its own way (--follow-silence-cost): the whole-file aligner's
    // cost would be dropped without a word, so it is refused there.
    const auto wholeFileCost = runLipsync({"eval", "--corpus", dir.string(), "--align",
                                           "--follow-lag", "0.1", "--silence-in-speech-cost", "1"});
    EXPECT_EQ(wholeFileCost.exitCode, 2);
    EXPECT_NE(wholeFileCost.err.find("--silence-in-speech-cost"), std::string::npos)
        << wholeFileCost.err;
    const auto own = runLipsync({"eval", "--corpus", dir.string(), "--align", "--follow-lag", "0.1",
                                 "--follow-silence-cost", "1", "--no-per-file"});
    EXPECT_EQ(own.exitCode, 0) << own.err;
}

// `--live`: the files through lipsyncd's live path, scored as the runtime took them; cued with
// their words (--align), the phonemes come from following them and score better.
TEST(AlignCli, EvalLiveScoresTheServicesLivePath) {
    const auto dir = scratchDir("cli_eval_live");
    const std::string en = "Seven puppets sang a song about the moon.";
    speak(dir / "anna", "line", en, "en-us+f3", en);
    const auto audio = runLipsync({"eval", "--corpus", dir.string(), "--live", "--json", "-"});
    ASSERT_EQ(audio.exitCode, 0) << audio.err;
    EXPECT_NE(audio.out.find("from audio live"), std::string::npos) << audio.out;
    const auto followed = runLipsync(
        {"eval", "--corpus", dir.string(), "--live", "--align", "--json", "-", "--no-per-file"});
    ASSERT_EQ(followed.exitCode, 0) << followed.err;
    EXPECT_NE(followed.out.find("(followed on the words, lag 100 ms, live path)"),
              std::string::npos)
        << followed.out;
    const auto score = [](const std::string& out) {
        return nlohmann::json::parse(out.substr(out.find("\n{") + 1))["speakers"]["anna"];
    };
    const auto a = score(audio.out), f = score(followed.out);
    // The schedule the runtime took covers the line as the offline analysis's does.
    EXPECT_GT(a["group_accuracy"].get<double>(), 0.6);
    EXPECT_GT(f["group_accuracy"].get<double>(), a["group_accuracy"].get<double>() + 0.05);
    EXPECT_GT(f["jaw"]["audio"]["r"].get<double>(), 0.7);
}

// The front end's options reach the live path (they were once left at lipsyncd's defaults):
// a class favoured by 12 dB takes the line's frames live as it does offline. Live input cannot
// wait for the whole file, so --offline decoding is refused; the live path aligns as lipsyncd
// does, so an aligner option is refused rather than lost.
TEST(AlignCli, EvalLiveTakesTheFrontEndsOptions) {
    const auto dir = scratchDir("cli_eval_live_options");
    const std::string en = "Seven puppets sang a song about the moon.";
    speak(dir / "anna", "line", en, "en-us+f3", en);
    const auto groups = [&](std::vector<std::string> extra) {
        std::vector<std::string> args{"eval", "--corpus", dir.string(), "--live", "--json", "-"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = runLipsync(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1));
        return j["speakers"]["anna"]["group_accuracy"].get<double>();
    };
    const double asShipped = groups({}), bilabials = groups({"--class-bias", "bmp=-12"});
    EXPECT_GT(asShipped, 0.6);
    EXPECT_LT(bilabials, asShipped - 0.2);
    // The lag the classes were decided at is part of the figure (issue 10: its lag stated).
    const auto lagged =
        runLipsync({"eval", "--corpus", dir.string(), "--live", "--lag", "0.1", "--json", "-"});
    ASSERT_EQ(lagged.exitCode, 0) << lagged.err;
    EXPECT_NE(lagged.out.find("(from audio, decoder lag 100 ms, live path)"), std::string::npos)
        << lagged.out;
    EXPECT_EQ(nlohmann::json::parse(lagged.out.substr(lagged.out.find("\n{") + 1))["decoder"],
              "decoder lag 100 ms");
    const auto offline = runLipsync({"eval", "--corpus", dir.string(), "--live", "--offline"});
    EXPECT_EQ(offline.exitCode, 1);
    EXPECT_NE(offline.err.find("--live with --offline"), std::string::npos) << offline.err;
    const auto aligner =
        runLipsync({"eval", "--corpus", dir.string(), "--live", "--min-word-confidence", "0.5"});
    EXPECT_EQ(aligner.exitCode, 2);
    EXPECT_NE(aligner.err.find("--live excludes --min-word-confidence"), std::string::npos)
        << aligner.err;
}

TEST(AlignCli, EvalAlignWithoutAnyWordsFileSaysSo) {
    const auto dir = scratchDir("cli_eval_align_none");
    speak(dir, "line", "Open wide.", "en-us", "");
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--align"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("NAME.txt"), std::string::npos) << r.err;
}

TEST(AlignCli, TheLabellingScriptKeepsOnlyConfidentLabels) {
    const auto in = scratchDir("cli_label_in"), out = scratchDir("cli_label_out");
    const std::string line = "Seven puppets sang a song about the moon.";
    speak(in / "anna", "right", line, "en-us+f3", line);
    speak(in / "anna", "wrong", "Moon.", "en-us+f3",
          line + " And then another song about the sun.");
    speak(in / "anna", "unscripted", line, "en-us+f3", "");
    ::setenv("LIPSYNC", LIPSYNCD_LIPSYNC_BIN, 1);
    const auto r =
        runProgram("/bin/bash", {LIPSYNCD_SOURCE_DIR "/scripts/label-with-aligner.sh", in.string(),
                                 out.string(), "--min-word-confidence", "0.1"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("anna: 1 files labelled (1 skipped"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(out / "anna" / "right.wav"));
    EXPECT_FALSE(fs::exists(out / "anna" / "wrong.lab"));
    EXPECT_FALSE(fs::exists(out / "anna" / "unscripted.lab"));
    // The labels are the aligned schedule: close to espeak-ng's own timings.
    const auto aligned = readScheduleFile(out / "anna" / "right.lab");
    const auto truth = readScheduleFile(in / "anna" / "right.lab");
    EXPECT_GT(dsp::scoreSchedule(aligned, truth, PhonemeSet::common()).groupAccuracy(), 0.75);
    const auto usage =
        runProgram("/bin/bash", {LIPSYNCD_SOURCE_DIR "/scripts/label-with-aligner.sh"});
    EXPECT_EQ(usage.exitCode, 2);
}

// `align --speaker FILE`: a show's lines aligned one run at a time carry the voice in a file,
// as lipsyncd's speaker_file does; a broken file is an error naming it.
TEST(AlignCli, ASpeakerFileCarriesTheVoiceFromRunToRun) {
    const auto dir = scratchDir("cli_align_speaker");
    const std::string first = "The old lighthouse keeper waved at every ship.";
    const std::string second = "Nobody knew why the clock stopped at midnight.";
    speak(dir, "first", first, "en-us+klatt3", "");
    speak(dir, "second", second, "en-us+klatt3", "");
    const auto voice = dir / "voice.json";
    const auto align = [&](const std::string& name, const std::string& text, bool carried) {
        std::vector<std::string> args = {"align", (dir / (name + ".wav")).string(), "--text", text,
                                         "-s",    (dir / (name + ".tsv")).string(), "-q"};
        if (carried) args.insert(args.end(), {"--speaker", voice.string()});
        return runLipsync(args);
    };
    ASSERT_EQ(align("second", second, false).exitCode, 0);
    const auto cold = slurp(dir / "second.tsv");
    ASSERT_EQ(align("first", first, true).exitCode, 0);
    ASSERT_TRUE(fs::exists(voice));
    const auto r = align("second", second, true);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(slurp(dir / "second.tsv"), cold) << "the second line ignored the first's voice";

    std::ofstream(voice) << "{\"format\": \"lipsyncd-speaker\", \"version\": 1}\n";
    const auto broken = align("second", second, true);
    EXPECT_EQ(broken.exitCode, 1);
    EXPECT_NE(broken.err.find(voice.string()), std::string::npos) << broken.err;
}

// `eval --adapt-speaker` without --align: the service's adapt_speaker for files played without
// words. The first file is analysed on the shipped templates (nothing learnt yet), the later
// ones on the voice the earlier files' words taught.
TEST(AlignCli, EvalAdaptSpeakerAnalysesEachFileOnTheVoiceTheEarlierOnesTaught) {
    const auto dir = scratchDir("cli_eval_adapt");
    const std::vector<std::string> lines = {"The old lighthouse keeper waved at every ship.",
                                            "Nobody knew why the clock stopped at midnight.",
                                            "Bring me the red umbrella before the storm."};
    for (std::size_t i = 0; i < lines.size(); ++i)
        speak(dir / "anna", "line" + std::to_string(i), lines[i], "en-us+klatt3", lines[i]);
    auto files = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {"eval", "--corpus", dir.string(), "--json", "-"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = runLipsync(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1))["files"];
    };
    const auto plain = files({});
    const auto adapted = files({"--adapt-speaker"});
    ASSERT_EQ(plain.size(), 3u);
    ASSERT_EQ(adapted.size(), 3u);
    EXPECT_EQ(adapted[0]["accuracy"], plain[0]["accuracy"]);
    EXPECT_TRUE(adapted[1]["accuracy"] != plain[1]["accuracy"] ||
                adapted[2]["accuracy"] != plain[2]["accuracy"])
        << "the later files were analysed on the shipped templates";
}

}  // namespace
}  // namespace lipsyncd::test
