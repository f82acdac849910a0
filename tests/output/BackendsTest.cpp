// The backends behind their seams: servo pulses on a fake line and clock, a HID board that
// vanishes and comes back, the real libgpiod and hidapi paths up to the missing device.
#include <gtest/gtest.h>

#include <sstream>

#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

TEST(ServoPwm, PulseWidthsFollowTheValuesAndRelaxedServosGetNone) {
    std::int64_t now = 0;
    std::vector<FakeGpioLine*> lines;
    std::vector<output::ServoPwm::Servo> servos;
    for (int i = 0; i < 2; ++i) {
        auto line = std::make_unique<FakeGpioLine>(&now);
        lines.push_back(line.get());
        servos.push_back({std::move(line), 1000, 2000, 0.0, 1.0});
    }
    output::ServoPwm pwm(
        std::move(servos), 50, [&] { return now; }, [&](std::int64_t t) { now = t; });
    pwm.set(0, 0.25, true);  // 1250 µs
    pwm.set(1, 0.9, false);  // relaxed
    pwm.runPeriods(3);
    const auto& e = lines[0]->edges;
    ASSERT_EQ(e.size(), 6u);
    for (int p = 0; p < 3; ++p) {
        EXPECT_TRUE(e[2 * p].second);
        EXPECT_FALSE(e[2 * p + 1].second);
        EXPECT_EQ(e[2 * p + 1].first - e[2 * p].first, 1'250'000);  // the pulse
        EXPECT_EQ(e[2 * p].first, e[0].first + p * 20'000'000LL);   // every 20 ms
    }
    EXPECT_TRUE(lines[1]->edges.empty());
    EXPECT_DOUBLE_EQ(output::ServoPwm::pulseUs(5, 0, 1, 1000, 2000), 2000);  // clamped
}

output::Puppet hidPuppet() {
    return output::Puppet::load(writePuppet("hid", R"(name = "hid"
[[hid]]
name = "board"
vid = 0x16c0
pid = 0x0486
report_id = 7
report_size = 4
encoding = "u16le"
rate = 50
reopen_every = 0.5
[[actuator]]
name = "jaw"
backend = "hid"
device = "board"
channel = 1
gains = { open = 1.0 }
min = 0.0
max = 2.0
slew = 1000
[[actuator]]
name = "led"
backend = "virtual"
gains = { open = 1.0 }
min = 0.0
max = 1.0
slew = 1000
)"));
}

TEST(HidSink, ReportsCarryTheEncodedChannelsAtTheBoardRate) {
    const auto puppet = hidPuppet();
    FakeHidBoard board;
    output::HidSink sink(puppet, puppet.hidDevices[0], [&](const output::HidDeviceConfig&) {
        return std::make_unique<FakeHidDevice>(board);
    });
    const output::ActuatorCommand c[2] = {{1.0, true, false}, {0.5, true, false}};
    for (int i = 0; i < 100; ++i) sink.write(0.01 * i, c);  // 1 s at 100 Hz → 50 reports
    EXPECT_EQ(board.reports.size(), 50u);
    ASSERT_EQ(board.reports[0].size(), 5u);  // report id + 4 bytes
    EXPECT_EQ(board.reports[0][0], 7);
    EXPECT_EQ(board.reports[0][3], 0x00);  // channel 1, u16le, 1.0 of 0..2 → 32768 (0x8000)
    EXPECT_EQ(board.reports[0][4], 0x80);
    EXPECT_EQ(board.reports[0][1], 0x00);  // channel 0 unused
}

TEST(HidSink, ABoardThatVanishesIsReopenedWhileOtherOutputsGoOn) {
    const auto puppet = hidPuppet();
    FakeHidBoard board;
    int opens = 0;
    std::vector<std::string> log;
    output::PuppetDriver driver(puppet, std::vector<std::string>{"open"});
    driver.addSink(std::make_unique<output::HidSink>(
        puppet, puppet.hidDevices[0],
        [&](const output::HidDeviceConfig&) -> std::unique_ptr<output::HidDevice> {
            ++opens;
            return board.present ? std::make_unique<FakeHidDevice>(board) : nullptr;
        },
        [&](const std::string& m) { log.push_back(m); }));
    std::ostringstream recorded;
    output::RecorderSink recorder(recorded, puppet, output::RecorderSink::Format::Csv);
    driver.addSink(recorder);
    const float w[1] = {0.5f};
    for (int i = 0; i < 300; ++i) {
        board.present = i < 100 || i >= 200;  // unplugged from 1 s to 2 s
        driver.update(0.01 * i, w);
    }
    const auto text = recorded.str();
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'),
              1 + 2 * 300);  // the recorder never missed a step
    EXPECT_GE(opens, 3);     // first open, retries while gone, the reopen
    ASSERT_GE(log.size(), 2u);
    EXPECT_NE(log.front().find("gone"), std::string::npos);
    EXPECT_NE(log.back().find("back"), std::string::npos);
    const std::size_t before = 50, after = board.reports.size() - before;
    EXPECT_GT(after, 40u);  // reports resumed within the reopen interval
}

TEST(RealDevices, AMissingGpioChipIsNamed) {
    try {
        output::openGpioLine("gpiochip9", 4, "test");
        FAIL() << "opened a chip that does not exist";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("gpiochip9"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(output::listGpioChips().empty());  // none on this machine (no /dev/gpiochip*)
}

TEST(RealDevices, AnAbsentHidBoardIsNotAnError) {
    output::HidDeviceConfig c;
    c.vid = 0x16c0;
    c.pid = 0x0486;
    EXPECT_EQ(output::openHidapiDevice(c), nullptr);
    c.path = "/dev/hidraw99";
    EXPECT_EQ(output::openHidapiDevice(c), nullptr);
}

TEST(PuppetFiles, TheShippedExamplesLoad) {
    for (const char* name :
         {"jaw-servo", "jaw-and-lips", "pneumatic-jaw", "led-mouth", "hid-board", "terminal"}) {
        const auto p = output::Puppet::load(findDataFile(std::string("puppets/") + name + ".toml"));
        EXPECT_FALSE(p.actuators.empty()) << name;
    }
}

TEST(PuppetFiles, MistakesNameTheLine) {
    auto errorOf = [](const std::string& body) {
        try {
            output::Puppet::load(writePuppet("bad", "name = \"x\"\n" + body));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string jaw =
        "[[actuator]]\nname = \"jaw\"\nbackend = \"servo\"\nline = 18\ngains = { open = 1 }\n";
    EXPECT_NE(errorOf(jaw + "min = 0\nmax = 1\nslwe = 3\n").find(":9: unknown key"),
              std::string::npos);  // unknown key
    EXPECT_NE(errorOf(jaw + "min = \"0\"\nmax = 1\n").find(":7:"),
              std::string::npos);  // wrong type
    EXPECT_NE(errorOf(jaw + "min = 0.8\nmax = 0.2\n").find("greater than min"),
              std::string::npos);  // min > max
    EXPECT_NE(errorOf(jaw + "min = 0\nmax = 1\n" +
                      "[[actuator]]\nname = \"lip\"\nbackend = \"servo\"\nline = 18\n"
                      "gains = { w = 1 }\nmin = 0\nmax = 1\n")
                  .find(":9: GPIO gpiochip0 line 18 is used by two actuators"),
              std::string::npos);
    EXPECT_NE(errorOf(jaw + "min = 0\nmax = 1\nrest = 2\n").find("rest"), std::string::npos);
    EXPECT_NE(errorOf("[[actuator]]\nname = \"j\"\nbackend = \"hid\"\ndevice = \"nope\"\ngains = { "
                      "open = 1 }\nmin = 0\nmax = 1\n")
                  .find("no [[hid]] named 'nope'"),
              std::string::npos);
    EXPECT_NE(errorOf(jaw + "min = 0\nmax = 1\nbackend2 = 1\n").find("backend2"),
              std::string::npos);
}

TEST(PuppetFiles, PosesTheWeightsLackAreNamed) {
    const auto p = output::Puppet::load(findDataFile("puppets/jaw-servo.toml"));
    try {
        p.checkPoses(std::vector<std::string>{"open"});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("pose 'jaw'"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace lipsyncd::test
