// The PCA9685 backend against a register-level fake behind the I2C seam: the prescaler set
// while asleep, the restart sequence, LEDn_OFF counts that follow the jaw within its pulse
// limits, full-off when relaxed and on stop; a board that does not answer or vanishes.
#include <gtest/gtest.h>

#include <sstream>

#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

output::Puppet pcaPuppet(const std::string& address = "0x40") {
    return output::Puppet::load(writePuppet("pca", R"(name = "pca"
[[actuator]]
name = "jaw"
backend = "pca9685"
bus = 1
address = )" + address + R"(
channel = 3
frequency = 50
pulse_min_us = 1100
pulse_max_us = 1900
gains = { open = 1.0 }
min = 0.0
max = 0.9
slew = 6.0
idle_after = 0.5
)" + kVirtualActuator));
}

output::I2cOpener opener(FakePca9685& chip, int* opens = nullptr) {
    return [&chip, opens](unsigned bus, unsigned address) -> std::unique_ptr<output::I2cDevice> {
        EXPECT_EQ(bus, 1u);
        EXPECT_EQ(address, 0x40u);
        if (opens) ++*opens;
        return std::make_unique<FakeI2cDevice>(chip);
    };
}

TEST(Pca9685, ThePrescalerIsSetAsleepAndTheBoardWokenAndRestarted) {
    const auto puppet = pcaPuppet();
    FakePca9685 chip;
    chip.reg[FakePca9685::kMode1] = 0x21;  // awake, auto-increment: left running by a program
    chip.reg[8 + 4 * 5] = 0x33;            // channel 5 still pulsing
    chip.reg[9 + 4 * 5] = 0x01;
    output::Pca9685Sink sink(puppet, 1, 0x40, opener(chip));
    const output::ActuatorCommand c[2] = {{0.45, true, false}, {0, true, false}};
    sink.write(0, c);
    ASSERT_TRUE(sink.connected());
    // 25 MHz / (4096 · 50 Hz) = 122.07 → PRE_SCALE 121 (datasheet 7.3.5), kept: written asleep.
    EXPECT_EQ(chip.reg[FakePca9685::kPreScale], 121);
    EXPECT_EQ(chip.prescaleWritesLost, 0);
    ASSERT_GE(chip.mode1Writes.size(), 3u);
    EXPECT_TRUE(chip.mode1Writes[0] & FakePca9685::kSleep);    // first: to sleep
    EXPECT_FALSE(chip.mode1Writes[1] & FakePca9685::kSleep);   // then awake
    EXPECT_TRUE(chip.mode1Writes[2] & FakePca9685::kRestart);  // channels were running: restart
    EXPECT_FALSE(chip.sleeping());
    EXPECT_FALSE(chip.reg[FakePca9685::kMode1] & FakePca9685::kRestart);  // restart done
    EXPECT_TRUE(chip.reg[FakePca9685::kMode1] & FakePca9685::kAutoIncrement);
    EXPECT_TRUE(chip.fullOff(5));  // what the other program left is switched off
    // 1500 µs with a tick of 122 / 25 MHz = 4.88 µs → 307 counts, ON at 0.
    EXPECT_EQ(output::Pca9685Sink::counts(1500, 25e6, 121), 307);
    EXPECT_EQ(chip.off(3), 307);
    EXPECT_FALSE(chip.fullOff(3));
    EXPECT_EQ(chip.reg[6 + 4 * 3], 0);
}

TEST(Pca9685, CountsFollowTheJawWithinItsPulsesOnlyChangesAreWrittenRestThenFullOff) {
    const auto puppet = pcaPuppet();
    FakePca9685 chip;
    std::vector<int> counts;
    {
        output::PuppetDriver driver(puppet, std::vector<std::string>{"open"});
        driver.addSink(std::make_unique<output::Pca9685Sink>(puppet, 1, 0x40, opener(chip)));
        struct Watch : output::CommandSink {
            FakePca9685* chip;
            std::vector<int>* counts;
            void write(double, std::span<const output::ActuatorCommand>) override {
                counts->push_back(chip->fullOff(3) ? -1 : chip->off(3));
            }
        } watch;
        watch.chip = &chip;
        watch.counts = &counts;
        driver.addSink(watch);
        for (int i = 0; i < 200; ++i) {
            const float w[1] = {i < 100 ? (i % 40 < 20 ? 2.0f : -1.0f) : 0.6f};
            driver.update(0.01 * i, w);
        }
        const std::size_t writesHolding = chip.writes;
        const float w[1] = {0.6f};
        for (int i = 200; i < 210; ++i) driver.update(0.01 * i, w);  // held still
        EXPECT_EQ(chip.writes, writesHolding);  // nothing changed, nothing sent
        driver.rest(2.1);
        EXPECT_EQ(chip.off(3), output::Pca9685Sink::counts(1100, 25e6, 121));  // rest: 1100 µs
        EXPECT_FALSE(chip.fullOff(3));
    }
    const int lo = output::Pca9685Sink::counts(1100, 25e6, 121);
    const int hi = output::Pca9685Sink::counts(1900, 25e6, 121);
    // Slew 6/s over 0.9 ↦ 800 µs: at most 53.3 µs (11 counts) per 10 ms step.
    for (std::size_t i = 0; i < counts.size(); ++i) {
        ASSERT_GE(counts[i], lo) << i;
        ASSERT_LE(counts[i], hi) << i;
        if (i > 0) {
            ASSERT_LE(std::abs(counts[i] - counts[i - 1]), 11) << i;
        }
    }
    EXPECT_EQ(*std::max_element(counts.begin(), counts.end()), hi);       // it did open fully
    for (int ch = 0; ch < 16; ++ch) EXPECT_TRUE(chip.fullOff(ch)) << ch;  // stopped: all off
}

TEST(Pca9685, ARelaxedServoGetsFullOff) {
    const auto puppet = pcaPuppet();
    FakePca9685 chip;
    output::Pca9685Sink sink(puppet, 1, 0x40, opener(chip));
    const output::ActuatorCommand moving[2] = {{0.3, true, false}, {0, true, false}};
    const output::ActuatorCommand relaxed[2] = {{0.0, false, false}, {0, true, false}};
    sink.write(0, moving);
    EXPECT_FALSE(chip.fullOff(3));
    sink.write(0.01, relaxed);
    EXPECT_TRUE(chip.fullOff(3));
}

TEST(Pca9685, ABoardThatDoesNotAnswerIsNamedWithThePuppetLineAndTheOthersGoOn) {
    const auto puppet = pcaPuppet();
    FakePca9685 chip;
    chip.present = false;  // nothing at 0x40 (a wrong address, a loose wire)
    int opens = 0;
    std::vector<std::string> log;
    output::PuppetDriver driver(puppet, std::vector<std::string>{"open"});
    driver.addSink(std::make_unique<output::Pca9685Sink>(
        puppet, 1, 0x40, opener(chip, &opens), [&](const std::string& m) { log.push_back(m); }));
    std::ostringstream recorded;
    output::RecorderSink recorder(recorded, puppet, output::RecorderSink::Format::Csv);
    driver.addSink(recorder);
    const float w[1] = {0.5f};
    for (int i = 0; i < 300; ++i) {
        chip.present = i >= 150;  // answers from 1.5 s
        driver.update(0.01 * i, w);
    }
    const auto text = recorded.str();
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 2 * 300);  // never missed a step
    ASSERT_GE(log.size(), 2u);
    EXPECT_NE(log[0].find(puppet.source.string() + ":2:"), std::string::npos) << log[0];
    EXPECT_NE(log[0].find("no device answers at 0x40"), std::string::npos) << log[0];
    EXPECT_EQ(log.size(), 2u);  // the same reason is not repeated every second
    EXPECT_NE(log[1].find("connected"), std::string::npos) << log[1];
    EXPECT_GE(opens, 2);
    EXPECT_LE(opens, 3);  // once a second, not every step
    EXPECT_FALSE(chip.fullOff(3));
}

TEST(Pca9685, ABoardThatVanishesIsSetUpAgainWhenItIsBack) {
    const auto puppet = pcaPuppet();
    FakePca9685 chip;
    std::vector<std::string> log;
    output::Pca9685Sink sink(puppet, 1, 0x40, opener(chip),
                             [&](const std::string& m) { log.push_back(m); });
    for (int i = 0; i < 300; ++i) {
        chip.present = i < 100 || i >= 200;
        if (i == 150) chip = FakePca9685{};  // power-cycled while away: asleep, prescale lost
        const output::ActuatorCommand c[2] = {{0.1 + 0.001 * i, true, false}, {0, true, false}};
        sink.write(0.01 * i, c);
    }
    ASSERT_EQ(log.size(), 2u);
    EXPECT_NE(log[0].find("gone"), std::string::npos);
    EXPECT_NE(log[1].find("connected"), std::string::npos);
    EXPECT_EQ(chip.reg[FakePca9685::kPreScale], 121);
    EXPECT_FALSE(chip.sleeping());
    EXPECT_EQ(chip.off(3),
              output::Pca9685Sink::counts(1100 + 800 * (0.1 + 0.299) / 0.9, 25e6, 121));
}

TEST(Pca9685, AMissingBusIsNamedWithThePuppetLineAndTheOthersGoOn) {
    auto text = R"(name = "pca"
[[actuator]]
name = "jaw"
backend = "pca9685"
bus = 99
gains = { open = 1.0 }
min = 0.0
max = 1.0
)" + kVirtualActuator;
    const auto puppet = output::Puppet::load(writePuppet("pca99", text));
    std::vector<std::string> log;
    output::PuppetDriver driver(puppet, std::vector<std::string>{"open"});
    output::addServoBoardSinks(driver, puppet, [&](const std::string& m) { log.push_back(m); });
    std::ostringstream recorded;
    output::RecorderSink recorder(recorded, puppet, output::RecorderSink::Format::Csv);
    driver.addSink(recorder);
    const float w[1] = {0.5f};
    for (int i = 0; i < 50; ++i) driver.update(0.01 * i, w);
    const auto rows = recorded.str();
    EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 1 + 2 * 50);
    ASSERT_EQ(log.size(), 1u);
    EXPECT_NE(log[0].find(puppet.source.string() + ":2: PCA9685 on /dev/i2c-99 at 0x40: no I2C "
                                                   "bus /dev/i2c-99"),
              std::string::npos)
        << log[0];
}

TEST(Pca9685, RealI2cErrorsSayWhatToDo) {
    EXPECT_THROW(
        {
            try {
                output::openI2cDevice(99, 0x40);
            } catch (const std::runtime_error& e) {
                EXPECT_NE(std::string(e.what()).find("no I2C bus /dev/i2c-99"), std::string::npos)
                    << e.what();
                throw;
            }
        },
        std::runtime_error);
    // A file that is not an I2C bus.
    const auto dir =
        std::filesystem::temp_directory_path() / ("lipsyncd_i2c_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "i2c-1") << "";
    try {
        output::openI2cDevice(1, 0x40, dir);
        FAIL() << "a plain file opened as an I2C bus";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("not an I2C bus"), std::string::npos) << e.what();
    }
    std::filesystem::remove_all(dir);
}

TEST(Pca9685DeathTest, ABusTheUserMayNotOpenSaysWhichGroup) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("lipsyncd_i2cperm_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "i2c-1") << "";
    std::filesystem::permissions(dir / "i2c-1", std::filesystem::perms::none);
    EXPECT_EXIT(
        {
            dropPrivileges();
            try {
                output::openI2cDevice(1, 0x40, dir);
            } catch (const std::runtime_error& e) {
                std::fprintf(stderr, "%s\n", e.what());
                std::_Exit(0);
            }
            std::_Exit(1);
        },
        ::testing::ExitedWithCode(0), "permission denied \\(add the user to group i2c\\)");
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lipsyncd::test
