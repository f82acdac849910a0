#include <gtest/gtest.h>

#include <fstream>
#include <lipsyncd/core.hpp>

using namespace lipsyncd;

TEST(PhonemeSet, CommonSetHasTwentyOneClassesPlusSilence) {
    const auto& set = PhonemeSet::common();
    EXPECT_EQ(set.size(), 22u);
    EXPECT_EQ(set[set.silence()].name, "sil");
    for (const char* name : {"ah", "aa", "ao", "eh", "er", "ih", "w", "ow", "aw", "oy", "ay",
                             "h",  "r",  "l",  "z",  "sh", "th", "f", "d",  "kg", "bmp"})
        EXPECT_TRUE(set.find(name).has_value()) << name;
    EXPECT_TRUE(set[*set.find("aa")].vowel);
    EXPECT_FALSE(set[*set.find("bmp")].vowel);
    EXPECT_EQ(set[*set.find("bmp")].group, "closed");
}

TEST(PhonemeMap, ArpabetIgnoresCaseAndStressDigits) {
    const auto map = PhonemeMap::named("arpabet");
    EXPECT_EQ(map.map("AH0")->phoneme, "ah");
    EXPECT_EQ(map.map("iy1")->phoneme, "ih");
    EXPECT_EQ(map.map("NG")->phoneme, "d");
    EXPECT_EQ(map.map("m")->phoneme, "bmp");
    EXPECT_FALSE(map.map("m")->approximate);
    EXPECT_TRUE(map.map("IX")->approximate);
    EXPECT_FALSE(map.map("xyz").has_value());
}

TEST(PhonemeMap, EspeakEnglishIsCaseSensitive) {
    const auto map = PhonemeMap::named("espeak-en");
    EXPECT_EQ(map.map("I")->phoneme, "ih");
    EXPECT_EQ(map.map("tS")->phoneme, "sh");
    EXPECT_EQ(map.map("aI")->phoneme, "ay");
    EXPECT_TRUE(map.isIgnored("'"));
    EXPECT_FALSE(map.map("Q").has_value());
}

TEST(PhonemeMap, RejectsTargetsOutsideTheSetNamingLineAndKey) {
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_bad_map.toml";
    std::ofstream(path) << "name = \"bad\"\n[map]\naa = \"aa\"\nzz = \"nonsense\"\n";
    try {
        PhonemeMap::load(path);
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(":4:"), std::string::npos) << what;
        EXPECT_NE(what.find("map.zz"), std::string::npos) << what;
        EXPECT_NE(what.find("nonsense"), std::string::npos) << what;
    }
}

TEST(PhonemeMap, EnglishIpaCoversTheFortyPhonemesLikeArpabet) {
    const auto ipa = PhonemeMap::named("ipa");
    const auto arpabet = PhonemeMap::named("arpabet");
    // The same sounds land in the same classes whichever alphabet names them.
    const std::pair<const char*, const char*> same[] = {
        {"æ", "AE"},  {"ɑ", "AA"},  {"ɔ", "AO"},  {"eɪ", "EY"}, {"ɝ", "ER"},
        {"iː", "IY"}, {"uː", "UW"}, {"oʊ", "OW"}, {"aʊ", "AW"}, {"ɔɪ", "OY"},
        {"aɪ", "AY"}, {"h", "HH"},  {"ɹ", "R"},   {"ʃ", "SH"},  {"tʃ", "CH"},
        {"ð", "DH"},  {"v", "V"},   {"ŋ", "NG"},  {"ɡ", "G"},   {"m", "M"}};
    for (const auto& [i, a] : same) {
        ASSERT_TRUE(ipa.map(i)) << i;
        EXPECT_EQ(ipa.map(i)->phoneme, arpabet.map(a)->phoneme) << i << " vs " << a;
        EXPECT_FALSE(ipa.map(i)->approximate) << i;
    }
    EXPECT_TRUE(ipa.map("ɾ")->approximate);  // a flap is not one of the forty: nearest, warned
    EXPECT_FALSE(ipa.map("ʘ"));              // a click: unknown
}
