#include <lipsyncd/toml_table.hpp>

#include <gtest/gtest.h>

#include <functional>

using namespace lipsyncd;

namespace {
std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST(TomlTable, ReadsTypedValues) {
    auto t = TomlTable::parseString("a = 1\nb = 2.5\nc = \"x\"\nd = true\ne = [1, 2]\n", "t.toml");
    EXPECT_EQ(t.getNumber("a"), 1);
    EXPECT_EQ(t.getNumber("b"), 2.5);
    EXPECT_EQ(t.getString("c"), "x");
    EXPECT_EQ(t.optBool("d"), true);
    EXPECT_EQ(t.optNumberArray("e")->size(), 2u);
    EXPECT_NO_THROW(t.finish());
}

TEST(TomlTable, UnknownKeysAreErrorsWithTheirLine) {
    auto t = TomlTable::parseString("a = 1\n\n[sub]\nx = 1\ntypo = 2\n", "p.toml");
    t.getNumber("a");
    auto sub = t.optTable("sub");
    sub->getNumber("x");
    EXPECT_NO_THROW(t.finish());
    const auto e = errorOf([&] { sub->finish(); });
    EXPECT_NE(e.find("p.toml:5:"), std::string::npos) << e;
    EXPECT_NE(e.find("sub.typo"), std::string::npos) << e;
}

TEST(TomlTable, WrongTypesAndMissingKeysNameTheKey) {
    auto t = TomlTable::parseString("gain = \"high\"\n", "p.toml");
    const auto e = errorOf([&] { t.getNumber("gain"); });
    EXPECT_NE(e.find("p.toml:1:"), std::string::npos) << e;
    EXPECT_NE(e.find("expected a number"), std::string::npos) << e;
    EXPECT_NE(errorOf([&] { t.getString("name"); }).find("missing key 'name'"), std::string::npos);
}

TEST(TomlTable, SyntaxErrorsGiveLine) {
    const auto e = errorOf([] { TomlTable::parseString("a = 1\nb = = 2\n", "s.toml"); });
    EXPECT_NE(e.find("s.toml:2:"), std::string::npos) << e;
}
