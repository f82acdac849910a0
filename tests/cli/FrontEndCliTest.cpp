// The `lipsync` tool as a user meets it: help, version, exit codes (0 ok, 1 runtime error,
// 2 usage error), and errors on stderr that name the file and what is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>

#include "RunLipsync.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

// A spoken example, made once per test run by the tool itself (espeak-ng).
const fs::path& exampleWav() {
    static const fs::path wav = [] {
        const auto dir = scratchDir("cli_example");
        const auto path = dir / "hello.wav";
        const auto r = runLipsync({"say", "Hello puppet, open wide.", "--wav", path.string(),
                                   "--schedule", (dir / "hello.lab").string()});
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return path;
    }();
    return wav;
}

TEST(LipsyncCli, HelpListsEveryCommandAndExitsZero) {
    const auto r = runLipsync({"--help"});
    EXPECT_EQ(r.exitCode, 0);
    for (const char* cmd : {"analyze", "eval", "train", "calibrate", "say", "animate", "curves",
                            "plot", "drive", "check", "devices"})
        EXPECT_NE(r.out.find(cmd), std::string::npos) << cmd;
}

TEST(LipsyncCli, EachCommandHasHelp) {
    for (const char* cmd : {"analyze", "eval", "train", "calibrate", "say", "animate", "curves",
                            "plot", "drive", "check", "devices"}) {
        const auto r = runLipsync({cmd, "--help"});
        EXPECT_EQ(r.exitCode, 0) << cmd;
        EXPECT_NE(r.out.find("Usage"), std::string::npos) << cmd;
    }
}

TEST(LipsyncCli, VersionPrintsTheVersion) {
    const auto r = runLipsync({"--version"});
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find(LIPSYNCD_VERSION), std::string::npos) << r.out;
}

TEST(LipsyncCli, UsageErrorsExitTwo) {
    EXPECT_EQ(runLipsync({}).exitCode, 2);
    EXPECT_EQ(runLipsync({"frobnicate"}).exitCode, 2);
    EXPECT_EQ(runLipsync({"analyze", "x.wav", "--bogus"}).exitCode, 2);
    const auto r = runLipsync({"analyze", "x.wav", "-s", "-", "--format", "xml"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("--format"), std::string::npos) << r.err;
}

TEST(LipsyncCli, MissingInputNamesTheFileAndExitsOne) {
    const auto r = runLipsync({"analyze", "/nonexistent/speech.wav", "-s", "-"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("/nonexistent/speech.wav"), std::string::npos) << r.err;
}

TEST(LipsyncCli, NonAudioBytesNameTheFile) {
    const auto path = scratchDir("cli_bad") / "notes.wav";
    std::ofstream(path) << "these are not the samples you are looking for\n";
    const auto r = runLipsync({"analyze", path.string(), "-s", "-"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(path.string()), std::string::npos) << r.err;
}

// A cut-short file is analysed as far as it goes, with a warning naming it: analyze, align and
// train.
TEST(LipsyncCli, ATruncatedFileIsAnalysedWithAWarning) {
    const auto dir = scratchDir("cli_truncated");
    const auto cut = dir / "cut.wav";
    fs::copy_file(exampleWav(), cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, fs::file_size(cut) / 2);
    const auto analyzed = runLipsync({"analyze", cut.string(), "-s", "-", "-q"});
    EXPECT_EQ(analyzed.exitCode, 0) << analyzed.err;
    EXPECT_FALSE(analyzed.out.empty());
    EXPECT_NE(analyzed.err.find("warning: " + cut.string() + ": truncated"), std::string::npos)
        << analyzed.err;
    const auto aligned =
        runLipsync({"align", cut.string(), "--text", "Hello puppet", "-s", "-", "-q"});
    EXPECT_EQ(aligned.exitCode, 0) << aligned.err;
    EXPECT_NE(aligned.err.find(cut.string() + ": truncated"), std::string::npos) << aligned.err;
    const auto labels = fs::path(exampleWav()).replace_extension(".lab");
    fs::copy_file(labels, dir / "cut.lab", fs::copy_options::overwrite_existing);
    for (const std::string whole : {"whole1", "whole2", "whole3", "whole4"}) {  // enough frames
        fs::copy_file(exampleWav(), dir / (whole + ".wav"), fs::copy_options::overwrite_existing);
        fs::copy_file(labels, dir / (whole + ".lab"), fs::copy_options::overwrite_existing);
    }
    const auto trained = runLipsync({"train", dir.string(), "--clusters", "1", "--jaw-hidden", "0",
                                     "--class-hidden", "0", "-o", (dir / "set.json").string()});
    EXPECT_EQ(trained.exitCode, 0) << trained.err;
    EXPECT_NE(trained.err.find("warning: " + cut.string() + ": truncated"), std::string::npos)
        << trained.err;
    EXPECT_EQ(trained.err.find("whole1.wav: truncated"), std::string::npos) << trained.err;
}

TEST(LipsyncCli, AnalyzeWritesAScheduleThatReadsBack) {
    const auto out = scratchDir("cli_analyze") / "hello.tsv";
    const auto frames = out.parent_path() / "frames.csv";
    const auto r = runLipsync(
        {"analyze", exampleWav().string(), "-s", out.string(), "--frames", frames.string(), "-q"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto schedule = readScheduleFile(out);
    ASSERT_GT(schedule.size(), 5u);
    EXPECT_EQ(schedule.front().start, 0.0);
    std::ifstream csv(frames);
    std::string header;
    std::getline(csv, header);
    EXPECT_NE(header.find("runner_up"), std::string::npos) << header;
}

// --class-bias CLASS=DB moves a class's distance (over the set's class_bias_db): enough dB on
// the bilabials and the schedule has none. A malformed one is named.
TEST(LipsyncCli, AnalyzeTakesAClassBiasAndNamesABadOne) {
    const auto dir = scratchDir("cli_class_bias");
    const auto countBilabials = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {"analyze", exampleWav().string(), "-s",
                                         (dir / "s.tsv").string(), "-q"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = runLipsync(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        const auto schedule = readScheduleFile(dir / "s.tsv");
        return std::count_if(schedule.begin(), schedule.end(),
                             [](const auto& p) { return p.phoneme == "bmp"; });
    };
    EXPECT_GT(countBilabials({}), 0);  // "puppet"
    EXPECT_EQ(countBilabials({"--class-bias", "bmp=19"}), 0);
    EXPECT_GT(countBilabials({"--class-bias", "bmp=19", "--class-bias", "bmp=0"}), 0);
    for (const auto& [bad, says] : std::vector<std::pair<std::string, std::string>>{
             {"bmp", "--class-bias: 'bmp' is not CLASS=DB"},
             {"bmp=x", "--class-bias: 'bmp=x' is not CLASS=DB"},
             {"xx=1", "class_bias_db.xx: 'xx' is not a phoneme class"},
             {"bmp=30", "class_bias_db.bmp: must be a finite dB within ±20"}}) {
        const auto r = runLipsync({"analyze", exampleWav().string(), "-s", (dir / "s.tsv").string(),
                                   "--class-bias", bad});
        EXPECT_EQ(r.exitCode, 1) << bad;
        EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    }
}

// --features: every frame's feature vector, as the templates and the jaw network see it, with
// the class decided and the heard jaw (what a training experiment starts from).
TEST(LipsyncCli, AnalyzeWritesEachFramesFeatures) {
    const auto out = scratchDir("cli_features") / "features.csv";
    const auto r = runLipsync(
        {"analyze", exampleWav().string(), "-s", "/dev/null", "--features", out.string(), "-q"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream csv(out);
    std::string line;
    std::getline(csv, line);
    const auto features = dsp::TemplateSet::loadDefault().analysis.featureCount();
    EXPECT_EQ(line.rfind("time,class,silent,jaw,f0,", 0), 0u) << line;
    EXPECT_NE(line.find(",f" + std::to_string(features - 1)), std::string::npos) << line;
    std::size_t rows = 0, open = 0;
    while (std::getline(csv, line)) {
        ++rows;
        EXPECT_EQ(std::count(line.begin(), line.end(), ','), 3 + features) << line;
        const auto jaw =
            std::stod(line.substr(line.find(',', line.find(',', line.find(',') + 1) + 1) + 1));
        EXPECT_GE(jaw, 0.0);
        EXPECT_LE(jaw, 1.0);
        open += jaw > 0.5;
    }
    EXPECT_GT(rows, 100u);  // 10 ms frames of a second and more of speech
    EXPECT_GT(open, 5u) << "'open wide' opens the heard jaw";
}

TEST(LipsyncCli, AnalyzeReadsRawPcmFromStdin) {
    const auto raw = scratchDir("cli_raw") / "hello.f32";
    {
        const auto audio = dsp::readAudioFile(exampleWav());
        std::ofstream(raw, std::ios::binary)
            .write(reinterpret_cast<const char*>(audio.samples.data()),
                   static_cast<std::streamsize>(audio.samples.size() * sizeof(float)));
    }
    const auto viaPipe = runLipsync({"analyze", "-", "--raw", "22050:f32:1", "-s", "-", "-q"}, raw);
    const auto viaFile = runLipsync({"analyze", exampleWav().string(), "-s", "-", "-q"});
    ASSERT_EQ(viaPipe.exitCode, 0) << viaPipe.err;
    EXPECT_EQ(viaPipe.out, viaFile.out);
}

// --schedules keeps what was scored, file by file: the audio-only schedule is analyze's, the
// aligned one align's.
TEST(LipsyncCli, EvalWritesEachFilesScheduleAsScored) {
    const auto corpus = scratchDir("cli_eval_schedules");
    const auto speaker = corpus / "puppeteer";
    fs::create_directories(speaker);
    fs::copy_file(exampleWav(), speaker / "hello.wav", fs::copy_options::overwrite_existing);
    fs::copy_file(fs::path(exampleWav()).replace_extension(".lab"), speaker / "hello.lab",
                  fs::copy_options::overwrite_existing);
    std::ofstream(speaker / "hello.txt") << "Hello puppet, open wide.\n";
    const auto out = corpus / "out";
    const auto written = (out / "puppeteer" / "hello.tsv").string();
    const auto audioOnly =
        runLipsync({"eval", "--corpus", corpus.string(), "--schedules", out.string()});
    ASSERT_EQ(audioOnly.exitCode, 0) << audioOnly.err;
    const auto analyzed =
        runLipsync({"analyze", (speaker / "hello.wav").string(), "-s", "-", "-q"});
    EXPECT_EQ(slurp(written), analyzed.out);
    const auto aligned =
        runLipsync({"eval", "--corpus", corpus.string(), "--align", "--schedules", out.string()});
    ASSERT_EQ(aligned.exitCode, 0) << aligned.err;
    const auto byAlign = runLipsync({"align", (speaker / "hello.wav").string(), "--text-file",
                                     (speaker / "hello.txt").string(), "-s", "-", "-q"});
    EXPECT_EQ(slurp(written), byAlign.out);
    EXPECT_NE(slurp(written), analyzed.out);
    const auto blocked = corpus / "blocked";
    std::ofstream(blocked) << "a file where a folder should be\n";
    const auto refused =
        runLipsync({"eval", "--corpus", corpus.string(), "--schedules", blocked.string()});
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_NE(refused.err.find(blocked.string()), std::string::npos) << refused.err;
}

// A file whose words cannot be aligned at all (none the voice can read) is named and scored
// from the audio alone, as the service plays such a file; the files after it are still aligned.
TEST(LipsyncCli, EvalScoresAFileWithUnreadableWordsFromTheAudioAndGoesOn) {
    const auto corpus = scratchDir("cli_eval_unreadable");
    const auto speaker = corpus / "puppeteer";
    fs::create_directories(speaker);
    for (const std::string name : {"a", "b"}) {
        fs::copy_file(exampleWav(), speaker / (name + ".wav"),
                      fs::copy_options::overwrite_existing);
        fs::copy_file(fs::path(exampleWav()).replace_extension(".lab"), speaker / (name + ".lab"),
                      fs::copy_options::overwrite_existing);
    }
    std::ofstream(speaker / "a.txt") << "日本語\n";
    std::ofstream(speaker / "b.txt") << "Hello puppet, open wide.\n";
    const auto out = corpus / "out";
    const auto r =
        runLipsync({"eval", "--corpus", corpus.string(), "--align", "--schedules", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("puppeteer/a: words not used:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("audio-only analysis"), std::string::npos) << r.err;
    const auto analyzed = runLipsync({"analyze", (speaker / "a.wav").string(), "-s", "-", "-q"});
    EXPECT_EQ(slurp(out / "puppeteer" / "a.tsv"), analyzed.out);
    EXPECT_NE(slurp(out / "puppeteer" / "b.tsv"), analyzed.out) << "b was not aligned";
}

TEST(LipsyncCli, EvalFailsBelowTheFloorAndPassesAboveIt) {
    const auto dir = exampleWav().parent_path();
    EXPECT_EQ(runLipsync({"eval", "--corpus", dir.string(), "--min-accuracy", "0.05"}).exitCode, 0);
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--min-accuracy", "0.999"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("below the floor"), std::string::npos) << r.err;
}

// The per-class table says how often each class is heard against how often it is labelled:
// a class biased out of reach is heard 0 times as often.
TEST(LipsyncCli, EvalSaysHowOftenEachClassIsHeard) {
    const auto dir = exampleWav().parent_path();
    const auto heardBilabials = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {"eval", "--corpus", dir.string(), "--no-jaw"};
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = runLipsync(args);
        EXPECT_EQ(r.exitCode, 0) << r.err;
        EXPECT_NE(r.out.find("heard (frames decided as it / its frames)"), std::string::npos);
        const auto row = r.out.find("\n  bmp ");
        if (row == std::string::npos) return -1.0;
        const auto x = r.out.find('x', row);
        return std::stod(r.out.substr(r.out.rfind(' ', x) + 1, x - r.out.rfind(' ', x) - 1));
    };
    EXPECT_GT(heardBilabials({}), 0.3);
    EXPECT_EQ(heardBilabials({"--class-bias", "bmp=19"}), 0.0);
}

// One subfolder per speaker: the jaw is scored per speaker, three ways, through the puppet.
TEST(LipsyncCli, EvalScoresThePuppetsJawPerSpeaker) {
    const auto dir = scratchDir("cli_eval_speakers");
    for (const auto* speaker : {"alice", "bob"}) {
        std::filesystem::create_directories(dir / speaker);
        std::filesystem::copy_file(exampleWav(), dir / speaker / "hello.wav");
        auto lab = exampleWav();
        std::filesystem::copy_file(lab.replace_extension(".lab"), dir / speaker / "hello.lab");
    }
    const auto r = runLipsync({"eval", "--corpus", dir.string(), "--json", "-", "--no-per-file",
                               "--puppet", "jaw-servo"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto json = nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1));
    for (const auto* speaker : {"alice", "bob"}) {
        const auto& jaw = json["speakers"][speaker]["jaw"];
        EXPECT_GT(jaw["labels"]["r"].get<double>(), 0.8) << speaker;
        EXPECT_GT(jaw["audio"]["r"].get<double>(), jaw["envelope"]["r"].get<double>() - 0.3);
        EXPECT_GE(jaw["labels"]["closures_caught"].get<double>(), 0.9);
        EXPECT_LE(jaw["labels"]["false_closures"].get<double>(), 0.05);
        // Per class, the mean jaw: from the labels the open vowel opens, the bilabial shuts.
        const auto& byClass = json["speakers"][speaker]["jaw_by_class"];
        ASSERT_TRUE(byClass.contains("bmp") && byClass.contains("ah")) << byClass.dump();
        EXPECT_GT(byClass["ah"]["labels"].get<double>(), 0.4) << speaker;
        EXPECT_LT(byClass["bmp"]["labels"].get<double>(), 0.2) << speaker;
        EXPECT_GT(byClass["ah"]["frames"].get<int>(), 0);
    }
    EXPECT_NE(r.out.find("jaw through 'jaw-servo'"), std::string::npos) << r.out;
    EXPECT_NE(json["jaw_by_class"].dump(), "null");
    const auto floor = runLipsync({"eval", "--corpus", dir.string(), "--min-exact-jaw-r", "0.999"});
    EXPECT_EQ(floor.exitCode, 1);
    EXPECT_NE(floor.err.find("jaw r from the labels"), std::string::npos) << floor.err;
    // The jaw from audio has a floor on its closures and a ceiling on its false closures too.
    const auto audio = json["speakers"]["alice"]["jaw"]["audio"];
    const double caught = audio["closures_caught"].get<double>();
    const double falseClosed = audio["false_closures"].get<double>();
    const auto within = runLipsync({"eval", "--corpus", dir.string(), "--min-closures",
                                    std::to_string(caught - 0.01), "--max-false-closures",
                                    std::to_string(falseClosed + 0.01)});
    EXPECT_EQ(within.exitCode, 0) << within.err;
    const auto tooOpen = runLipsync({"eval", "--corpus", dir.string(), "--min-closures",
                                     std::to_string(std::min(1.0, caught + 0.01))});
    if (caught < 0.995) {
        EXPECT_EQ(tooOpen.exitCode, 1);
        EXPECT_NE(tooOpen.err.find("closures caught from audio"), std::string::npos);
    }
    ASSERT_GT(falseClosed, 0.0) << "the example's audio jaw no longer shuts by mistake: "
                                   "pick a file where it does, so the ceiling is tested";
    const auto tooShut = runLipsync({"eval", "--corpus", dir.string(), "--max-false-closures",
                                     std::to_string(falseClosed / 2)});
    EXPECT_EQ(tooShut.exitCode, 1);
    EXPECT_NE(tooShut.err.find("false closures from audio"), std::string::npos) << tooShut.err;
    const auto bad = runLipsync({"eval", "--corpus", dir.string(), "--jaw-actuator", "tail"});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("no actuator named 'tail'"), std::string::npos) << bad.err;
}

// The worst speaker's frames between the visual groups: the table names that speaker, and the
// JSON holds every speaker's, summing to its frames with its group accuracy on the diagonal.
TEST(LipsyncCli, EvalShowsWhereTheWorstSpeakersGroupsGo) {
    const auto dir = scratchDir("cli_eval_groups");
    for (const auto* speaker : {"alice", "bob"}) {
        fs::create_directories(dir / speaker);
        fs::copy_file(exampleWav(), dir / speaker / "hello.wav",
                      fs::copy_options::overwrite_existing);
    }
    auto lab = exampleWav();
    fs::copy_file(lab.replace_extension(".lab"), dir / "alice" / "hello.lab",
                  fs::copy_options::overwrite_existing);
    // bob's labels say the whole line is one open vowel: most of his frames are heard elsewhere.
    std::ofstream(dir / "bob" / "hello.lab") << "0.000\t5.216\tah\n";
    const auto r =
        runLipsync({"eval", "--corpus", dir.string(), "--json", "-", "--no-per-file", "--no-jaw"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("visual groups of the worst speaker, bob"), std::string::npos) << r.out;
    const auto json = nlohmann::json::parse(r.out.substr(r.out.find("\n{") + 1));
    for (const auto* name : {"alice", "bob"}) {
        const auto& speaker = json["speakers"][name];
        std::size_t frames = 0, same = 0;
        for (const auto& [labelled, row] : speaker["group_confusion"].items())
            for (const auto& [heard, n] : row.items()) {
                frames += n.get<std::size_t>();
                if (heard == labelled) same += n.get<std::size_t>();
            }
        EXPECT_EQ(frames, speaker["frames"].get<std::size_t>()) << name;
        EXPECT_NEAR(static_cast<double>(same) / frames, speaker["group_accuracy"].get<double>(),
                    1e-9)
            << name;
        EXPECT_TRUE(speaker["confusion"].contains("ah")) << name;
    }
    EXPECT_EQ(json["speakers"]["bob"]["group_confusion"].size(), 1u) << "bob's labels: open only";
}

TEST(LipsyncCli, EvalOnAFolderWithoutLabelsSaysSo) {
    const auto r = runLipsync({"eval", "--corpus", scratchDir("cli_empty").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("cli_empty"), std::string::npos) << r.err;
}

TEST(LipsyncCli, CalibrateBuildsLoadableTemplatesAndNamesStrayFiles) {
    const auto dir = scratchDir("cli_calibrate");
    // Sustained-ish sounds from espeak-ng stand in for a speaker's recordings.
    for (const auto& [cls, text] :
         {std::pair{"aa", "ahhhhhh"}, {"ow", "ohhhhhh"}, {"sh", "shhhhhh"}})
        ASSERT_EQ(runLipsync({"say", text, "--wav", (dir / (std::string(cls) + ".wav")).string()})
                      .exitCode,
                  0);
    std::ofstream(dir / "hum.wav") << "x";
    const auto out = dir.parent_path() / "calibrated.json";
    const auto r = runLipsync({"calibrate", dir.string(), "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("hum.wav"), std::string::npos) << r.err;
    const auto set = dsp::TemplateSet::load(out);
    EXPECT_EQ(set.classes.size(), PhonemeSet::common().size());
}

// Read speech with its words (NAME.wav + NAME.txt): the templates of the classes the aligner
// places move toward the speaker's frames, the rest stay as the base set has them; a recording
// whose words do not fit is named and left out. A larger --prior moves them less.
TEST(LipsyncCli, CalibrateFromReadSpeechMovesTheClassesItHeard) {
    const auto dir = scratchDir("cli_calibrate_read");
    const std::pair<const char*, const char*> lines[] = {
        {"s1", "Hello puppet, open wide and sing to me."},
        {"s2", "Bob bought a big bag of beans by the bay."},
        {"s3", "Why do you sit so still when the show is on?"}};
    for (const auto& [name, text] : lines) {
        ASSERT_EQ(runLipsync({"say", text, "--wav", (dir / (std::string(name) + ".wav")).string()})
                      .exitCode,
                  0);
        std::ofstream(dir / (std::string(name) + ".txt")) << text << '\n';
    }
    // Far more words than its audio holds: the aligner cannot place them all.
    fs::copy_file(dir / "s1.wav", dir / "s4.wav", fs::copy_options::overwrite_existing);
    std::ofstream(dir / "s4.txt") << "Twenty seven thousand and forty two unexpected "
                                     "mathematicians politely disagreed about everything.\n";
    // Words the voice cannot read: that file is named and skipped, the others serve.
    fs::copy_file(dir / "s2.wav", dir / "s5.wav", fs::copy_options::overwrite_existing);
    std::ofstream(dir / "s5.txt") << "Она завела прядь волос за ухо.\n";
    const auto out = dir.parent_path() / "calibrated-read.json";
    const auto r = runLipsync({"calibrate", dir.string(), "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("skipped " + (dir / "s4.wav").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("skipped " + (dir / "s5.wav").string()), std::string::npos) << r.err;
    const auto own = dsp::TemplateSet::load(out);
    const auto base = dsp::TemplateSet::loadDefault();
    ASSERT_EQ(own.classes.size(), base.classes.size());
    auto spectraOf = [](const dsp::TemplateSet& set, const std::string& phoneme) {
        for (const auto& c : set.classes)
            if (c.phoneme == phoneme) return c.spectra;
        return std::vector<std::vector<float>>{};
    };
    EXPECT_NE(spectraOf(own, "bmp"), spectraOf(base, "bmp")) << "b, m, p were heard: moved";
    EXPECT_NE(spectraOf(own, "ih"), spectraOf(base, "ih"));
    EXPECT_EQ(spectraOf(own, "oy"), spectraOf(base, "oy")) << "no oy in these lines: kept";
    // How far the templates moved, summed over every value.
    auto moved = [&](const dsp::TemplateSet& set) {
        double sum = 0;
        for (std::size_t c = 0; c < set.classes.size(); ++c)
            for (std::size_t t = 0; t < set.classes[c].spectra.size(); ++t)
                for (std::size_t k = 0; k < set.classes[c].spectra[t].size(); ++k)
                    sum += std::abs(set.classes[c].spectra[t][k] - base.classes[c].spectra[t][k]);
        return sum;
    };
    const auto firm = dir.parent_path() / "calibrated-read-firm.json";
    ASSERT_EQ(
        runLipsync({"calibrate", dir.string(), "-o", firm.string(), "--prior", "200"}).exitCode, 0);
    EXPECT_LT(moved(dsp::TemplateSet::load(firm)), 0.5 * moved(own));
    // The networks are trained further on the voice's aligned frames, from the base's weights
    // (its input standardisation and class priors kept); with no pass they stay the base's.
    ASSERT_TRUE(own.jawNetwork && base.jawNetwork && own.classNetwork && base.classNetwork);
    EXPECT_NE(own.jawNetwork->outputWeights, base.jawNetwork->outputWeights);
    EXPECT_NE(own.classNetwork->outputWeights, base.classNetwork->outputWeights);
    EXPECT_EQ(own.classNetwork->inputMean, base.classNetwork->inputMean);
    EXPECT_EQ(own.classNetwork->logPrior, base.classNetwork->logPrior);
    EXPECT_NE(r.err.find("networks: 4 pass(es) over"), std::string::npos) << r.err;
    const auto kept = dir.parent_path() / "calibrated-read-networks-kept.json";
    ASSERT_EQ(runLipsync({"calibrate", dir.string(), "-o", kept.string(), "--network-epochs", "0"})
                  .exitCode,
              0);
    const auto same = dsp::TemplateSet::load(kept);
    EXPECT_EQ(same.jawNetwork->outputWeights, base.jawNetwork->outputWeights);
    EXPECT_EQ(same.classNetwork->outputWeights, base.classNetwork->outputWeights);
    EXPECT_EQ(same.classNetwork->hiddenWeights, base.classNetwork->hiddenWeights);
}

// Read speech none of which the voice can read: a clear error that says which option helps.
TEST(LipsyncCli, CalibrateOnWordsTheVoiceCannotReadSaysWhichVoiceReadThem) {
    const auto dir = scratchDir("cli_calibrate_unreadable");
    const std::string ru = "Она завела прядь волос за ухо.";
    ASSERT_EQ(
        runLipsync({"say", ru, "--voice", "ru", "--wav", (dir / "line.wav").string()}).exitCode, 0);
    std::ofstream(dir / "line.txt") << ru << '\n';
    const auto out = dir / "calibrated.json";
    const auto r = runLipsync({"calibrate", dir.string(), "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("skipped " + (dir / "line.wav").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("none of its recordings with words could be aligned"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("--voice"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(runLipsync({"calibrate", dir.string(), "-o", out.string(), "--voice", "ru"}).exitCode,
              0);
}

// A copy of a WAV file whose header claims `factor` times its sample rate: played slower, its
// formants lie lower by that factor, as a speaker with a longer vocal tract's do.
void copyAtRate(const fs::path& from, const fs::path& to, double factor) {
    std::ifstream in(from, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
        return v;
    };
    auto put32 = [&](std::size_t at, std::uint32_t v) {
        for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<char>((v >> (8 * k)) & 0xff);
    };
    for (std::size_t at = 12; at + 8 <= bytes.size(); at += 8 + u32(at + 4) + (u32(at + 4) & 1)) {
        if (bytes.compare(at, 4, "fmt ") != 0) continue;
        const auto rate = static_cast<std::uint32_t>(std::lround(u32(at + 12) * factor));
        const auto blockAlign = static_cast<unsigned char>(bytes[at + 20]);
        put32(at + 12, rate);
        put32(at + 16, rate * blockAlign);
        break;
    }
    std::ofstream(to, std::ios::binary) << bytes;
}

double warpOf(const fs::path& templates) {
    return dsp::TemplateSet::load(templates).analysis.warp;
}

// With read speech, calibrate chooses the speaker's vocal-tract-length warp: none for the voice
// the templates know, below 1 for the same lines with every formant 12 % lower.
TEST(LipsyncCli, CalibrateChoosesAWarpForAVoiceWithLowerFormants) {
    const auto plain = scratchDir("cli_calibrate_warp_plain");
    const auto low = scratchDir("cli_calibrate_warp_low");
    const char* lines[] = {"Hello puppet, open wide and sing to me.",
                           "Bob bought a big bag of beans by the bay.",
                           "Why do you sit so still when the show is on?",
                           "Father asked the man to carry the heavy boxes."};
    for (int i = 0; i < 4; ++i) {
        const auto name = "s" + std::to_string(i);
        ASSERT_EQ(
            runLipsync({"say", lines[i], "--wav", (plain / (name + ".wav")).string()}).exitCode, 0);
        copyAtRate(plain / (name + ".wav"), low / (name + ".wav"), 0.88);
        for (const auto& dir : {plain, low}) std::ofstream(dir / (name + ".txt")) << lines[i];
    }
    const auto plainOut = plain.parent_path() / "calibrated-plain.json";
    const auto lowOut = low.parent_path() / "calibrated-low.json";
    const auto r = runLipsync({"calibrate", plain.string(), "-o", plainOut.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warp 0.85: the audio alone hears"), std::string::npos) << r.err;
    EXPECT_EQ(warpOf(plainOut), 1.0);
    const auto l = runLipsync({"calibrate", low.string(), "-o", lowOut.string()});
    ASSERT_EQ(l.exitCode, 0) << l.err;
    EXPECT_LE(warpOf(lowOut), 0.9) << l.err;
}

// --warp fixes the warp instead; a value out of range is named.
TEST(LipsyncCli, CalibrateTakesAFixedWarpAndRejectsABadOne) {
    const auto dir = scratchDir("cli_calibrate_fixed_warp");
    ASSERT_EQ(runLipsync({"say", "ahhhhhh", "--wav", (dir / "aa.wav").string()}).exitCode, 0);
    const auto out = dir.parent_path() / "calibrated-fixed.json";
    const auto r = runLipsync({"calibrate", dir.string(), "-o", out.string(), "--warp", "0.9"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_DOUBLE_EQ(warpOf(out), 0.9);
    const auto bad = runLipsync({"calibrate", dir.string(), "-o", out.string(), "--warp", "2"});
    EXPECT_NE(bad.exitCode, 0);
    EXPECT_NE(bad.err.find("--warp"), std::string::npos) << bad.err;
}

// train --keep-templates: only the networks asked for are trained, on the labelled speech given;
// the set's analysis, templates, weights and other network are written back as they were. Too
// little speech for a network is an error, not a set without one.
TEST(LipsyncCli, TrainKeepTemplatesReplacesOnlyTheNetworksAskedFor) {
    const auto dir = scratchDir("cli_train_jaw");
    const char* lines[] = {"Hello puppet, open wide and sing to me.",
                           "Bob bought a big bag of beans by the bay.",
                           "Why do you sit so still when the show is on?",
                           "A large black cat sat on the warm mat at home.",
                           "Father saw the old car far down the long road.",
                           "We will meet again when the moon is high."};
    for (int i = 0; i < 6; ++i)
        for (const char* voice : {"en-us", "en-gb+f2", "en-us+m3"}) {
            const auto name = dir / ("s" + std::to_string(i) + "-" + voice);
            ASSERT_EQ(runLipsync({"say", lines[i], "--voice", voice, "--wav",
                                  name.string() + ".wav", "--schedule", name.string() + ".lab"})
                          .exitCode,
                      0);
        }
    const auto out = dir.parent_path() / "with-jaw.json";
    auto r = runLipsync({"train", dir.string(), "--keep-templates", "default", "--jaw-hidden", "8",
                         "--class-hidden", "0", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto set = dsp::TemplateSet::load(out);
    const auto base = dsp::TemplateSet::loadDefault();
    ASSERT_TRUE(set.jawNetwork.has_value());
    EXPECT_EQ(set.jawNetwork->hiddenUnits(), 8u);
    ASSERT_TRUE(set.classNetwork && base.classNetwork);  // not asked for: the base's stays
    EXPECT_EQ(set.classNetwork->hiddenUnits(), base.classNetwork->hiddenUnits());
    EXPECT_EQ(set.classNetwork->classes, base.classNetwork->classes);
    ASSERT_EQ(set.classes.size(), base.classes.size());
    for (std::size_t c = 0; c < set.classes.size(); ++c)
        for (std::size_t k = 0; k < set.classes[c].spectra.size(); ++k)
            for (std::size_t b = 0; b < set.classes[c].spectra[k].size(); ++b)
                ASSERT_NEAR(set.classes[c].spectra[k][b], base.classes[c].spectra[k][b], 1e-3);
    EXPECT_EQ(set.analysis.featureCount(), base.analysis.featureCount());

    // Now the class network alone, into that set: its jaw network stays.
    const auto both = dir.parent_path() / "with-both.json";
    r = runLipsync({"train", dir.string(), "--keep-templates", out.string(), "--jaw-hidden", "0",
                    "--class-hidden", "8", "-o", both.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto second = dsp::TemplateSet::load(both);
    ASSERT_TRUE(second.classNetwork && second.jawNetwork);
    EXPECT_EQ(second.classNetwork->hiddenUnits(), 8u);
    EXPECT_EQ(second.jawNetwork->hiddenUnits(), 8u);
    // --class-slopes: the class network hears each feature's slope too, and the set analyses.
    const auto sloped = dir.parent_path() / "with-slopes.json";
    r = runLipsync({"train", dir.string(), "--keep-templates", out.string(), "--jaw-hidden", "0",
                    "--class-hidden", "8", "--class-slopes", "2", "-o", sloped.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto third = dsp::TemplateSet::load(sloped);
    ASSERT_TRUE(third.classNetwork.has_value());
    EXPECT_EQ(third.classNetwork->slopeFrames, 2);
    EXPECT_EQ(third.classNetwork->inputMean.size(),
              2 * static_cast<std::size_t>(third.analysis.featureCount()));
    r = runLipsync({"analyze", (dir / "s0-en-us.wav").string(), "--templates", sloped.string(),
                    "-s", (dir.parent_path() / "sloped.tsv").string()});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    // --jaw-slopes: the jaw network's, apart from the class network's.
    const auto jawSloped = dir.parent_path() / "with-jaw-slopes.json";
    r = runLipsync({"train", dir.string(), "--keep-templates", sloped.string(), "--jaw-hidden", "8",
                    "--jaw-slopes", "3", "--class-hidden", "0", "-o", jawSloped.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto fourth = dsp::TemplateSet::load(jawSloped);
    ASSERT_TRUE(fourth.jawNetwork && fourth.classNetwork);
    EXPECT_EQ(fourth.jawNetwork->slopeFrames, 3);
    EXPECT_EQ(fourth.classNetwork->slopeFrames, 2);
    r = runLipsync({"analyze", (dir / "s0-en-us.wav").string(), "--templates", jawSloped.string(),
                    "-s", (dir.parent_path() / "jaw-sloped.tsv").string()});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    r = runLipsync({"train", dir.string(), "--keep-templates", "default", "--jaw-hidden", "0",
                    "--class-hidden", "0", "-o", both.string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("nothing to train"), std::string::npos) << r.err;

    fs::create_directories(dir / "one");
    fs::copy_file(dir / "s0-en-us.wav", dir / "one/s0.wav", fs::copy_options::overwrite_existing);
    fs::copy_file(dir / "s0-en-us.lab", dir / "one/s0.lab", fs::copy_options::overwrite_existing);
    r = runLipsync(
        {"train", (dir / "one").string(), "--keep-templates", "default", "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("too little labelled speech"), std::string::npos) << r.err;

    // --seed: the same speech and seed give the same network, another seed another draw.
    const auto jawWith = [&](const std::string& seed) {
        const auto file = dir.parent_path() / ("seed-" + seed + ".json");
        const auto t =
            runLipsync({"train", dir.string(), "--keep-templates", "default", "--jaw-hidden", "8",
                        "--class-hidden", "0", "--seed", seed, "-o", file.string()});
        EXPECT_EQ(t.exitCode, 0) << t.err;
        return dsp::TemplateSet::load(file).jawNetwork->hiddenWeights;
    };
    EXPECT_EQ(jawWith("1"), jawWith("1"));
    EXPECT_NE(jawWith("1"), jawWith("2"));
}

// train --keep-templates --fine-tune-epochs: the set's own networks trained further on the speech
// given (their sizes, standardisation, priors and the class bias kept), not new ones; without a
// set to start from it is an error.
TEST(LipsyncCli, TrainFineTuneEpochsTrainsTheSetsOwnNetworksFurther) {
    const auto dir = scratchDir("cli_train_fine_tune");
    const char* lines[] = {"Hello puppet, open wide and sing to me.",
                           "Bob bought a big bag of beans by the bay."};
    for (int i = 0; i < 2; ++i) {
        const auto name = dir / ("s" + std::to_string(i));
        ASSERT_EQ(runLipsync({"say", lines[i], "--voice", "en-us+m3", "--wav",
                              name.string() + ".wav", "--schedule", name.string() + ".lab"})
                      .exitCode,
                  0);
    }
    const auto out = dir.parent_path() / "fine-tuned.json";
    auto r = runLipsync({"train", dir.string(), "--keep-templates", "default", "--fine-tune-epochs",
                         "2", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("networks trained further"), std::string::npos) << r.err;
    const auto tuned = dsp::TemplateSet::load(out);
    const auto base = dsp::TemplateSet::loadDefault();
    ASSERT_TRUE(tuned.classNetwork && tuned.jawNetwork && base.classNetwork && base.jawNetwork);
    EXPECT_EQ(tuned.classNetwork->hiddenUnits(), base.classNetwork->hiddenUnits());
    EXPECT_EQ(tuned.classNetwork->inputMean, base.classNetwork->inputMean);
    EXPECT_EQ(tuned.classNetwork->logPrior, base.classNetwork->logPrior);
    EXPECT_NE(tuned.classNetwork->outputWeights, base.classNetwork->outputWeights);
    EXPECT_NE(tuned.jawNetwork->outputWeights, base.jawNetwork->outputWeights);
    EXPECT_EQ(tuned.classBiasDb, base.classBiasDb);
    ASSERT_EQ(tuned.classes.size(), base.classes.size());
    for (std::size_t c = 0; c < base.classes.size(); ++c)
        EXPECT_EQ(tuned.classes[c].spectra, base.classes[c].spectra);

    r = runLipsync({"train", dir.string(), "--fine-tune-epochs", "2", "-o", out.string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("--keep-templates"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace lipsyncd::test
