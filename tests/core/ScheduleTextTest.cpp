#include <lipsyncd/core.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>

using namespace lipsyncd;

namespace {
PhonemeSchedule parse(const std::string& text, ScheduleReadOptions options = {},
                      std::vector<std::string>* warnings = nullptr) {
    std::istringstream in(text);
    return readSchedule(in, "test.tsv", options, warnings);
}

std::string errorOf(const std::string& text, ScheduleReadOptions options = {}) {
    try {
        parse(text, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST(ScheduleText, ReadsTsvWithOptionalConfidenceAndComments) {
    const auto s = parse("# a comment\n0\t0.1\tsil\n0.1\t0.25\taa\t0.5\n\n0.25 0.3 bmp\n");
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s[1].phoneme, "aa");
    EXPECT_FLOAT_EQ(s[1].confidence, 0.5f);
    EXPECT_DOUBLE_EQ(s[2].end, 0.3);
}

TEST(ScheduleText, RoundTripsThroughWriter) {
    const PhonemeSchedule in = {{0, 0.1, "sil", 1}, {0.1, 0.25, "aa", 0.75f}, {0.25, 0.4, "f", 1}};
    std::ostringstream out;
    writeSchedule(out, in);
    EXPECT_EQ(parse(out.str()), in);
}

// An aligned file's last silence can be a sliver (0.9978 to 0.998 s): written in ms it would
// end where it starts, a line the reader refuses (lipsync train failed on such a label file).
TEST(ScheduleText, ASliverThatRoundsToNoLengthIsLeftOutSoTheFileReadsBack) {
    const PhonemeSchedule in = {
        {0, 0.8384, "kg", 1}, {0.8384, 0.9978, "sh", 1}, {0.9978, 0.998, "sil", 1}};
    std::ostringstream out;
    writeSchedule(out, in);
    const auto back = parse(out.str());
    ASSERT_EQ(back.size(), 2u);
    EXPECT_DOUBLE_EQ(back[0].end, 0.838);
    EXPECT_DOUBLE_EQ(back[1].start, 0.838);
    EXPECT_DOUBLE_EQ(back[1].end, 0.998);
    std::ostringstream json;
    writeScheduleJson(json, in);
    EXPECT_EQ(nlohmann::json::parse(json.str()).size(), 2u);
}

TEST(ScheduleText, MapsArpabetLabelsAndFillsGapsWithSilence) {
    const auto map = PhonemeMap::named("arpabet");
    ScheduleReadOptions o;
    o.map = &map;
    const auto s = parse("0.2 0.3 HH\n0.3 0.45 AH0\n0.5 0.6 M\n", o);
    ASSERT_EQ(s.size(), 5u);
    EXPECT_EQ(s[0].phoneme, "sil");
    EXPECT_DOUBLE_EQ(s[0].end, 0.2);
    EXPECT_EQ(s[1].phoneme, "h");
    EXPECT_EQ(s[2].phoneme, "ah");
    EXPECT_EQ(s[3].phoneme, "sil");
    EXPECT_EQ(s[4].phoneme, "bmp");
}

TEST(ScheduleText, MergesNeighboursOfOneClass) {
    const auto map = PhonemeMap::named("arpabet");
    ScheduleReadOptions o;
    o.map = &map;
    const auto s = parse("0 0.1 S\n0.1 0.2 Z\n", o);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].phoneme, "z");
    EXPECT_DOUBLE_EQ(s[0].end, 0.2);
}

TEST(ScheduleText, ErrorsNameTheLine) {
    EXPECT_NE(errorOf("0 0.1 sil\n0.1 x aa\n").find("test.tsv:2:"), std::string::npos);
    EXPECT_NE(errorOf("0 0.1 sil\n0.05 0.2 aa\n").find("overlaps"), std::string::npos);
    EXPECT_NE(errorOf("0.2 0.1 aa\n").find("before it starts"), std::string::npos);
    EXPECT_NE(errorOf("-1 0.1 aa\n").find("negative"), std::string::npos);
    EXPECT_NE(errorOf("0 0.1\n").find("found 2 fields"), std::string::npos);
    EXPECT_NE(errorOf("0 0.1 aa 1.5\n").find("confidence"), std::string::npos);
    EXPECT_NE(errorOf("0 nan aa\n").find("not a number"), std::string::npos);
}

TEST(ScheduleText, GapsCanBeErrors) {
    ScheduleReadOptions o;
    o.fillGapsWithSilence = false;
    EXPECT_NE(errorOf("0 0.1 aa\n0.2 0.3 aa\n", o).find("gap"), std::string::npos);
}

TEST(ScheduleText, UnknownPhonemesWarnOrFail) {
    std::vector<std::string> warnings;
    const auto s = parse("0 0.1 zork\n", {}, &warnings);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].phoneme, "sil");
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("'zork'"), std::string::npos);
    ScheduleReadOptions strict;
    strict.unknownIsError = true;
    EXPECT_NE(errorOf("0 0.1 zork\n", strict).find("'zork'"), std::string::npos);
}

TEST(ScheduleText, TimesBeyondADayAreRefusedWithTheLine) {
    EXPECT_NE(errorOf("0 0.1 sil\n0.1 1e7 aa\n").find("test.tsv:2:"), std::string::npos);
    EXPECT_NE(errorOf("0 1e300 aa\n").find("86400"), std::string::npos);
    EXPECT_NE(errorOf("0 0.1 aa 1e300\n").find("test.tsv:1:"), std::string::npos);
}
