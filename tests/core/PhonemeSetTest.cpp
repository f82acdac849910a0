#include <gtest/gtest.h>

#include <filesystem>
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

// French espeak-ng reads "camping" or "wapiti" with its English voice: those phonemes come
// under English names, which the French map takes from espeak-en.toml (its `fallback`), while
// a name French uses for its own sound keeps the French class ("a" is the open /a/, aa).
TEST(PhonemeMap, AFallbackMapFillsOnlyTheNamesTheMapLacks) {
    const auto fr = PhonemeMap::named("espeak-fr");
    EXPECT_EQ(fr.map("a")->phoneme, "aa");
    EXPECT_EQ(PhonemeMap::named("espeak-en").map("a")->phoneme, "ah");
    EXPECT_EQ(fr.map("aI")->phoneme, "ay");  // English only
    EXPECT_EQ(fr.map("T")->phoneme, "th");
    EXPECT_TRUE(fr.isIgnored("(en)"));
    EXPECT_EQ(PhonemeMap::named("espeak-ru").map("oU")->phoneme, "ow");  // a Latin-script word
}

// Every espeak-ng map shipped (hand-written or made by scripts/make-phoneme-maps.py) and the IPA
// table the generated ones come from load, and map onto classes of their phoneme set.
TEST(PhonemeMap, EveryShippedEspeakMapLoads) {
    std::size_t maps = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dataDirectory() / "phonemes")) {
        const auto stem = entry.path().stem().string();
        if (stem.rfind("espeak-", 0) != 0 && stem != "ipa-multilingual") continue;
        EXPECT_NO_THROW(PhonemeMap::load(entry.path())) << entry.path();
        ++maps;
    }
    EXPECT_GE(maps, 51u);  // 12 by hand, 38 generated, the IPA table
    EXPECT_EQ(PhonemeMap::named("espeak-pl").map("S")->phoneme, "sh");
    EXPECT_EQ(PhonemeMap::named("ipa-multilingual").map("ʏ")->phoneme, "w");
}

// espeak-ng switches language inside a line ("(de)" before a German word in a Croatian one,
// "(id)" in a Malay one): every map passes over such a mark, listed or not, as it does stress.
TEST(PhonemeMap, ALanguageSwitchIsAMarkInEveryMap) {
    for (const std::string name : {"espeak-hr", "espeak-de", "espeak-fr", "arpabet"}) {
        const auto map = PhonemeMap::named(name);
        EXPECT_TRUE(map.isIgnored("(de)")) << name;
        EXPECT_TRUE(map.isIgnored("(pt-pt)")) << name;
        EXPECT_FALSE(map.isIgnored("()")) << name;
        EXPECT_FALSE(map.isIgnored("(")) << name;
    }
    EXPECT_FALSE(PhonemeMap::named("espeak-de").isIgnored("a"));
}

TEST(PhonemeMap, AFallbackCycleOrAnotherSetIsAnErrorNamingTheFile) {
    const auto dir = std::filesystem::temp_directory_path();
    const auto a = dir / "lipsyncd_cycle_a.toml", b = dir / "lipsyncd_cycle_b.toml";
    std::ofstream(a) << "fallback = \"" << b.string() << "\"\n[map]\naa = \"aa\"\n";
    std::ofstream(b) << "fallback = \"" << a.string() << "\"\n[map]\nbb = \"bmp\"\n";
    try {
        PhonemeMap::load(a);
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("cycle"), std::string::npos) << e.what();
    }
    const auto c = dir / "lipsyncd_other_set.toml";
    std::ofstream(c) << "phoneme_set = \"mandarin\"\nfallback = \"espeak-en\"\n[map]\n"
                        "aa = \"aa\"\n";
    try {
        PhonemeMap::load(c);
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(c.string()), std::string::npos) << what;
        EXPECT_NE(what.find("espeak-en"), std::string::npos) << what;
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
