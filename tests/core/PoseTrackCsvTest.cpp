#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/core.hpp>
#include <sstream>

using namespace lipsyncd;

namespace {
std::string errorOf(const std::string& text) {
    std::istringstream in(text);
    try {
        readPoseTrackCsv(in, "w.csv");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST(PoseTrackCsv, RoundTrips) {
    PoseTrack t;
    t.poses = {"open", "pbm"};
    const float a[] = {0.5f, 0.0f}, b[] = {0.25f, 1.0f};
    t.append(0.0, a);
    t.append(0.01, b);
    std::stringstream s;
    writePoseTrackCsv(s, t);
    const auto back = readPoseTrackCsv(s, "w.csv");
    EXPECT_EQ(back.poses, t.poses);
    EXPECT_EQ(back.times, t.times);
    EXPECT_EQ(back.values, t.values);
    EXPECT_EQ(back.pose("pbm"), 1u);
}

TEST(PoseTrackCsv, RefusesNonFiniteAndOutOfRangeValuesAndTimesWithTheLine) {
    EXPECT_NE(errorOf("time,open\n0,nan\n").find("w.csv:2:"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0,0\n0.01,inf\n").find("w.csv:3:"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0,-inf\n").find("'open'"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0,1e300\n").find("w.csv:2:"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0,0\n1e300,0\n").find("w.csv:3:"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0,0\n1e7,0\n").find("86400"), std::string::npos);
}

TEST(PoseTrackCsv, ErrorsNameLineAndColumn) {
    EXPECT_NE(errorOf("").find("empty"), std::string::npos);
    EXPECT_NE(errorOf("t,open\n").find("header must start"), std::string::npos);
    EXPECT_NE(errorOf("time,open,open\n").find("twice"), std::string::npos);
    const auto e = errorOf("time,open\n0,0.5\n0.01,abc\n");
    EXPECT_NE(e.find("w.csv:3:"), std::string::npos) << e;
    EXPECT_NE(e.find("'open'"), std::string::npos) << e;
    EXPECT_NE(errorOf("time,open\n0,1,2\n").find("expected 2 columns"), std::string::npos);
    EXPECT_NE(errorOf("time,open\n0.1,1\n0.1,1\n").find("does not increase"), std::string::npos);
}
