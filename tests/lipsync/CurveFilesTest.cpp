// Curve sets, character files and pose sets as data: the shipped ones load and are reproducible;
// malformed ones are refused with the bigram, pose or line at fault.
#include "RuntimeTestSupport.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

fs::path writeTemp(const std::string& name, const std::string& text) {
    const auto path = fs::temp_directory_path() / ("lipsyncd_" + std::to_string(::getpid()) + "_" + name);
    std::ofstream(path) << text;
    return path;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string errorLoading(const std::string& json) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto path = writeTemp("curves.json", json);
    try {
        lipsync::BigramCurveSet::load(path, poses);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

const std::string kHead = R"({"format": "lipsyncd-curves", "version": 1, "name": "bad", "pose_set": "facefx", "bigrams": )";

TEST(CurveFiles, TheShippedSetCoversEveryPair) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::BigramCurveSet::named("english", poses);
    EXPECT_EQ(set.classes(), 22u);
    // Lips close fully for bmp; silence pairs bring the mouth to rest.
    const auto* close = set.curve(cls("aa"), cls("bmp"), *poses.find("pbm"));
    ASSERT_NE(close, nullptr);
    EXPECT_NEAR(close->at(0.75), 1.0, 0.01);
    EXPECT_EQ(set.curve(cls("sil"), cls("sil"), *poses.find("open")), nullptr);
}

TEST(CurveFiles, RegeneratingTheShippedSetGivesTheCommittedFile) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::generateCurveSet(findDataFile("curves/english-rules.toml"), poses);
    const auto out = fs::temp_directory_path() / ("lipsyncd_english_" + std::to_string(::getpid()) + ".json");
    set.save(out, poses, PhonemeSet::common());
    EXPECT_EQ(slurp(out), slurp(findDataFile("curves/english.json")))
        << "config/curves/english.json is stale: run scripts/make-curves.sh";
}

TEST(CurveFiles, ErrorsNameTheBigramAndPose) {
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"jaw": [[0,0],[1,0]]}}})").find("bigrams.aa-bmp.jaw: unknown pose"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0,0],[0.6,0.2],[0.5,0.1],[1,0]]}}})")
                  .find("bigrams.aa-bmp.open[2]: times must increase"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0,0],[0.5,1.5],[1,0]]}}})")
                  .find("bigrams.aa-bmp.open[1]: value must be in [0, 1]"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-zz": {}}})").find("bigrams.aa-zz: not a pair"), std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {}}})").find("missing pair 'sil-sil'"), std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0.1,0],[1,0]]}}})").find("from time 0 to time 1"),
              std::string::npos);
    EXPECT_NE(errorLoading(R"({"format": "lipsyncd-curves", "version": 2, "name": "x"})").find("version"),
              std::string::npos);
    EXPECT_NE(errorLoading("{").find("not valid JSON"), std::string::npos);
}

TEST(CurveFiles, ACharacterReplacesSingleBigramsOnly) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto base = lipsync::BigramCurveSet::named("english", poses);
    const auto path = writeTemp("crab.json", R"({"format": "lipsyncd-character", "version": 1, "name": "crab",
        "base": "english", "pose_set": "facefx",
        "bigrams": {"aa-bmp": {"w": [[0,0],[0.5,1],[1,0]]}}})");
    const auto crab = lipsync::BigramCurveSet::load(path, poses);
    EXPECT_EQ(crab.name(), "crab");
    const auto w = *poses.find("w"), pbm = *poses.find("pbm");
    ASSERT_NE(crab.curve(cls("aa"), cls("bmp"), w), nullptr);
    EXPECT_EQ(crab.curve(cls("aa"), cls("bmp"), pbm), nullptr);  // the override replaces the bigram
    // Every other bigram is the base's.
    const auto* mine = crab.curve(cls("ow"), cls("bmp"), pbm);
    const auto* theirs = base.curve(cls("ow"), cls("bmp"), pbm);
    ASSERT_TRUE(mine && theirs);
    EXPECT_TRUE(std::equal(mine->polygon().begin(), mine->polygon().end(), theirs->polygon().begin(),
                           theirs->polygon().end()));
}

TEST(PoseSetFiles, MistakesNameTheLine) {
    auto errorOf = [](const std::string& toml) {
        try {
            lipsync::PoseSet::load(writeTemp("poses.toml", toml));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\nspeed = 3\n").find(":4:"), std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\n[[pose]]\nname = \"open\"\n").find("defined twice"),
              std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\n[[constraint]]\nposes = [\"open\", \"jaw\"]\nthreshold = 0.5\n")
                  .find("unknown pose 'jaw'"),
              std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\nspeed_limit = -1\n").find("greater than 0"),
              std::string::npos);
}

}  // namespace
}  // namespace lipsyncd::test
