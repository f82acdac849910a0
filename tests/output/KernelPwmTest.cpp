// The kernel PWM backend against a fake sysfs tree: a small "kernel" thread makes pwmN/ when
// the channel is exported and removes it when unexported. Period, enable and duty cycle are
// checked as the shipped pwm-jaw puppet moves, relaxes and stops.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <thread>

#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

long long readValue(const std::filesystem::path& file) {
    long long v = -1;
    std::ifstream(file) >> v;  // sysfs takes one value; the rest of a longer old one is junk
    return v;
}

class FakePwmTree {
  public:
    explicit FakePwmTree(int channels) {
        root_ =
            std::filesystem::temp_directory_path() / ("lipsyncd_pwm_" + std::to_string(::getpid()));
        std::filesystem::remove_all(root_);
        std::filesystem::create_directories(chip());
        std::ofstream(chip() / "npwm") << channels << "\n";
        std::ofstream(chip() / "export");
        std::ofstream(chip() / "unexport");
        kernel_ = std::thread([this] {
            while (running_) {
                serve("export", true);
                serve("unexport", false);
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
        });
    }
    ~FakePwmTree() {
        running_ = false;
        kernel_.join();
        std::filesystem::remove_all(root_);
    }
    const std::filesystem::path& root() const { return root_; }
    std::filesystem::path chip() const { return root_ / "pwmchip0"; }
    std::filesystem::path channel(int n) const { return chip() / ("pwm" + std::to_string(n)); }
    std::vector<std::string> requests() {  // "export 0", "unexport 0" as the kernel saw them
        std::lock_guard lock(mutex_);
        return requests_;
    }

  private:
    void serve(const std::string& file, bool exporting) {
        const long long n = readValue(chip() / file);
        if (n < 0) return;
        std::ofstream(chip() / file, std::ios::trunc);
        {
            std::lock_guard lock(mutex_);
            requests_.push_back(file + " " + std::to_string(n));
        }
        if (exporting) {
            std::filesystem::create_directories(channel(int(n)));
            for (const char* attr : {"period", "duty_cycle", "enable"})
                std::ofstream(channel(int(n)) / attr) << "0\n";
        } else {
            std::filesystem::remove_all(channel(int(n)));
        }
    }

    std::filesystem::path root_;
    std::mutex mutex_;
    std::vector<std::string> requests_;
    std::atomic<bool> running_{true};
    std::thread kernel_;
};

TEST(KernelPwm, TheShippedJawIsExportedFollowedWithinItsPulsesRestedThenHandedBack) {
    FakePwmTree tree(2);
    const auto puppet = output::Puppet::named("pwm-jaw");
    const auto& jaw = puppet.actuators[0];
    const auto pwm0 = tree.channel(0);
    {
        output::PuppetDriver driver(puppet, std::vector<std::string>{"jaw", "wide", "pbm"});
        driver.addSink(std::make_unique<output::KernelPwmSink>(puppet, 0, tree.root()));
        long long highest = 0;
        for (int i = 0; i < 200; ++i) {
            const float w[3] = {float(0.5 + 0.6 * std::sin(i * 0.07)), 0.0f, 0.0f};
            driver.update(0.01 * i, w);
            const long long duty = readValue(pwm0 / "duty_cycle");
            ASSERT_EQ(duty, std::llround(1000 * output::servoPulseUs(jaw, driver.last()[0].value)));
            ASSERT_GE(duty, 1'100'000);
            ASSERT_LE(duty, 1'900'000);
            highest = std::max(highest, duty);
        }
        EXPECT_EQ(readValue(pwm0 / "period"), 20'000'000);  // 50 Hz
        EXPECT_EQ(readValue(pwm0 / "enable"), 1);
        EXPECT_GT(highest, 1'700'000);
        driver.rest(2.0);
        EXPECT_EQ(readValue(pwm0 / "duty_cycle"), 1'100'000);  // rest: closed
    }
    // Stopped after the rest pose: disabled and unexported, as the channel was found.
    for (int i = 0; i < 200 && std::filesystem::exists(pwm0); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(std::filesystem::exists(pwm0));
    EXPECT_EQ(tree.requests(), (std::vector<std::string>{"export 0", "unexport 0"}));
}

output::Puppet pwmPuppet(int channel) {
    return output::Puppet::load(writePuppet("pwm", R"(name = "p"
[[actuator]]
name = "jaw"
backend = "pwm"
chip = 0
channel = )" + std::to_string(channel) + R"(
gains = { open = 1.0 }
min = 0.0
max = 1.0
)"));
}

TEST(KernelPwm, ARelaxedServoGetsNoPulses) {
    FakePwmTree tree(2);
    std::filesystem::create_directories(tree.channel(1));  // exported already (by a script)
    for (const char* attr : {"period", "duty_cycle", "enable"})
        std::ofstream(tree.channel(1) / attr) << "0\n";
    const auto puppet = pwmPuppet(1);
    {
        output::KernelPwmSink sink(puppet, 0, tree.root());
        const output::ActuatorCommand moving[1] = {{0.5, true, false}};
        const output::ActuatorCommand relaxed[1] = {{0.0, false, false}};
        sink.write(0, moving);
        EXPECT_EQ(readValue(tree.channel(1) / "duty_cycle"), 1'500'000);
        sink.write(0.01, relaxed);
        EXPECT_EQ(readValue(tree.channel(1) / "duty_cycle"), 0);
    }
    EXPECT_EQ(readValue(tree.channel(1) / "enable"), 0);
    EXPECT_TRUE(tree.requests().empty());  // not ours to export or unexport
}

TEST(KernelPwm, AMissingChipOrChannelIsNamedWithThePuppetLine) {
    FakePwmTree tree(2);
    for (const auto& [root, channel, why] :
         {std::tuple<std::filesystem::path, int, std::string>{tree.root() / "nowhere", 0,
                                                              "no such PWM chip"},
          {tree.root(), 5, "channel 5: the chip has 2 channels"}}) {
        const auto puppet = pwmPuppet(channel);
        std::vector<std::string> log;
        output::KernelPwmSink sink(puppet, 0, root,
                                   [&](const std::string& m) { log.push_back(m); });
        const output::ActuatorCommand c[1] = {{0.5, true, false}};
        sink.write(0, c);
        EXPECT_FALSE(sink.connected());
        ASSERT_EQ(log.size(), 1u);
        EXPECT_NE(log[0].find(puppet.source.string() + ":2: PWM chip"), std::string::npos)
            << log[0];
        EXPECT_NE(log[0].find(why), std::string::npos) << log[0];
    }
}

TEST(DeviceListing, ChipsPortsAndBusesAreListedWithWhatToCallThem) {
    FakePwmTree tree(2);
    EXPECT_EQ(output::listPwmChips(tree.root()),
              std::vector<std::string>{"pwmchip0: 2 channels (chip = 0)"});
    const auto dev = tree.root() / "dev";  // a fake /dev
    std::filesystem::create_directories(dev / "serial" / "by-id");
    std::ofstream(dev / "ttyACM0");
    std::ofstream(dev / "ttyACM1");
    std::ofstream(dev / "i2c-1");
    const std::string maestro =
        "usb-Pololu_Corporation_Pololu_Micro_Maestro_6-Servo_Controller_0012";
    std::filesystem::create_symlink("../../ttyACM0",
                                    dev / "serial" / "by-id" / (maestro + "-if00"));
    std::filesystem::create_symlink("../../ttyACM1",
                                    dev / "serial" / "by-id" / (maestro + "-if02"));
    const auto ports = output::listSerialPorts(dev);
    ASSERT_EQ(ports.size(), 4u);
    EXPECT_NE(ports[0].find("-if00 -> " + (dev / "ttyACM0").string()), std::string::npos)
        << ports[0];
    EXPECT_NE(ports[0].find("Maestro command port"), std::string::npos) << ports[0];
    EXPECT_NE(ports[1].find("Maestro TTL port"), std::string::npos) << ports[1];
    EXPECT_EQ(ports[2], (dev / "ttyACM0").string());
    const auto buses = output::listI2cBuses(dev);
    ASSERT_EQ(buses.size(), 1u);  // a plain file: nothing answers on it
    EXPECT_NE(buses[0].find((dev / "i2c-1").string()), std::string::npos) << buses[0];
}

}  // namespace
}  // namespace lipsyncd::test
