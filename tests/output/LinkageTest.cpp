// Linkages and the servo boards' puppet keys: the solved table closes the linkage and opens
// the jaw linearly (checked by running the linkage forwards, independently of the solver); an
// unreachable linkage and every mistake in a board's keys are refused with the line.
#include <gtest/gtest.h>

#include <cmath>

#include "OutputTestSupport.hpp"

namespace lipsyncd::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Forwards: from the horn's angle, where the jaw arm must be for the rod to fit (the
// intersection of the rod's circle about the horn's hole with the arm's circle about the
// hinge), the one nearest `near` degrees of opening.
double jawOpening(const output::Linkage& l, double hornDeg, double near) {
    const double hx = l.servo[0] + l.horn * std::cos(hornDeg * kPi / 180);
    const double hy = l.servo[1] + l.horn * std::sin(hornDeg * kPi / 180);
    double best = 1e9;
    for (int i = 0; i <= 360000; ++i) {  // a brute-force scan, 0.001° steps over ±180°
        const double open = -180 + i * 0.001;
        const double a = (l.armClosedDeg + (l.opensClockwise ? -open : open)) * kPi / 180;
        const double px = l.hinge[0] + l.arm * std::cos(a), py = l.hinge[1] + l.arm * std::sin(a);
        if (std::abs(std::hypot(px - hx, py - hy) - l.rod) < 0.002 &&
            std::abs(open - near) < std::abs(best - near))
            best = open;
    }
    return best;
}

TEST(Linkage, TheShippedJawOpensLinearlyInTheCommandedValue) {
    const auto puppet = output::Puppet::named("maestro-jaw");
    const auto& jaw = puppet.actuators[0];
    ASSERT_TRUE(jaw.linkage);
    const auto& l = *jaw.linkage;
    for (double value = jaw.min; value <= jaw.max; value += 2.5) {
        // The pulse the backend sends, back to the horn angle, forwards to the jaw.
        const double share =
            (output::servoPulseUs(jaw, value) - jaw.pulseMinUs) / (jaw.pulseMaxUs - jaw.pulseMinUs);
        const double horn =
            l.hornAtPulseMinDeg + share * (l.hornAtPulseMaxDeg - l.hornAtPulseMinDeg);
        EXPECT_NEAR(jawOpening(l, horn, value), value, 0.05) << "at " << value << "°";
    }
    // Not a straight line in the servo: equal jaw steps take unequal pulse steps.
    const double first = output::servoPulseUs(jaw, 5) - output::servoPulseUs(jaw, 0);
    const double last = output::servoPulseUs(jaw, 25) - output::servoPulseUs(jaw, 20);
    EXPECT_GT(std::abs(last - first), 5.0);
}

output::Linkage parallelLinkage() {
    output::Linkage l;
    l.servo = {0, 0};
    l.hinge = {30, 40};
    l.horn = 15;
    l.rod = 53;
    l.arm = 20;
    l.armClosedDeg = -12.5;
    l.hornAtPulseMinDeg = -45;
    l.hornAtPulseMaxDeg = 45;
    return l;
}

TEST(Linkage, PulsesNeverLeaveTheServosLimitsWhateverTheValue) {
    for (const char* name : {"maestro-jaw", "pwm-jaw"}) {
        const auto puppet = output::Puppet::named(name);
        const auto& jaw = puppet.actuators[0];
        const double lo =
            std::min(output::servoPulseUs(jaw, jaw.min), output::servoPulseUs(jaw, jaw.max));
        const double hi =
            std::max(output::servoPulseUs(jaw, jaw.min), output::servoPulseUs(jaw, jaw.max));
        for (const double v : {-1e9, jaw.min - 1, jaw.max + 1, 1e300, HUGE_VAL, -HUGE_VAL}) {
            EXPECT_GE(output::servoPulseUs(jaw, v), lo) << name << " " << v;
            EXPECT_LE(output::servoPulseUs(jaw, v), hi) << name << " " << v;
        }
        EXPECT_EQ(output::servoPulseUs(jaw, NAN), output::servoPulseUs(jaw, jaw.rest)) << name;
    }
}

TEST(Linkage, AnUnreachableRangeIsRefusedSayingWhy) {
    auto l = parallelLinkage();
    EXPECT_NO_THROW(output::solveLinkage(l, 0, 25));
    const auto whyNot = [](const output::Linkage& x, double max) {
        try {
            output::solveLinkage(x, 0, max);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("solved");
    };
    EXPECT_NE(whyNot(l, 120).find("cannot reach"), std::string::npos);  // past a dead point
    l.rod = 20;                                                         // cannot span the pivots
    EXPECT_NE(whyNot(l, 25).find("pushrod cannot join"), std::string::npos) << whyNot(l, 25);
    l = parallelLinkage();
    l.hornAtPulseMinDeg = 0;  // a servo that turns only 0 .. 45°
    EXPECT_NE(whyNot(l, 25).find("outside the servo's travel"), std::string::npos) << whyNot(l, 25);
}

std::string errorOf(const std::string& body) {
    try {
        output::Puppet::load(writePuppet("boards", "name = \"x\"\n" + body));
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

const std::string kPca =
    "[[actuator]]\nname = \"jaw\"\nbackend = \"pca9685\"\nbus = 1\ngains = { open = 1 }\n"
    "min = 0\nmax = 1\n";

TEST(BoardPuppets, MistakesNameTheLine) {
    EXPECT_EQ(errorOf(kPca), "no error");
    EXPECT_NE(errorOf(kPca + "adress = 0x41\n").find(":9: unknown key"), std::string::npos);
    EXPECT_NE(errorOf(kPca + "address = 0x20\n").find(":9: key 'actuator[0].address'"),
              std::string::npos)
        << errorOf(kPca + "address = 0x20\n");
    EXPECT_NE(errorOf(kPca + "channel = 16\n").find("must be 0 .. 15"), std::string::npos);
    EXPECT_NE(errorOf(kPca + "frequency = 10\n").find("a PCA9685 runs at"), std::string::npos);
    EXPECT_NE(errorOf("[[actuator]]\nname = \"jaw\"\nbackend = \"pca9685\"\ngains = { open = 1 }\n"
                      "min = 0\nmax = 1\n")
                  .find("missing: the I2C bus"),
              std::string::npos);
    const std::string lip =
        "[[actuator]]\nname = \"lip\"\nbackend = \"pca9685\"\nbus = 1\ngains = { w = 1 }\n"
        "min = 0\nmax = 1\n";
    EXPECT_NE(errorOf(kPca + lip).find(":9: PCA9685 on I2C bus 1 at 0x40 channel 0 is used by two"),
              std::string::npos)
        << errorOf(kPca + lip);
    EXPECT_NE(errorOf(kPca + lip + "channel = 1\nfrequency = 60\n").find("one frequency"),
              std::string::npos);
    EXPECT_EQ(errorOf(kPca + lip + "channel = 1\n"), "no error");

    const std::string maestro =
        "[[actuator]]\nname = \"jaw\"\nbackend = \"maestro\"\nport = \"/dev/ttyACM0\"\n"
        "gains = { open = 1 }\nmin = 0\nmax = 1\n";
    EXPECT_EQ(errorOf(maestro), "no error");
    EXPECT_NE(errorOf(maestro + "frequency = 50\n").find("Maestro Control Center"),
              std::string::npos);
    EXPECT_NE(errorOf(maestro + "channel = 24\n").find("0 .. 23"), std::string::npos);
    EXPECT_NE(errorOf(maestro + "device = 200\n").find("0 .. 127"), std::string::npos);
    EXPECT_NE(errorOf(maestro + "baud = 1234\n").find("baud"), std::string::npos);
    EXPECT_NE(errorOf("[[actuator]]\nname = \"jaw\"\nbackend = \"maestro\"\ngains = { open = 1 }\n"
                      "min = 0\nmax = 1\n")
                  .find("port"),
              std::string::npos);
    EXPECT_NE(errorOf("[[actuator]]\nname = \"jaw\"\nbackend = \"pwm\"\nchip = \"gpiochip0\"\n"
                      "gains = { open = 1 }\nmin = 0\nmax = 1\n")
                  .find(":5:"),
              std::string::npos);
}

const std::string kLinkage = R"([actuator.linkage]
servo = [0.0, 0.0]
horn = 15.0
rod = 53.0
hinge = [30.0, 40.0]
arm = 20.0
arm_closed = -12.5
opens = "counterclockwise"
horn_travel = [-45.0, 45.0]
)";

TEST(BoardPuppets, ALinkageIsSolvedAtLoadAndAnUnreachableOneRefusedWithItsLine) {
    const std::string servo =
        "[[actuator]]\nname = \"jaw\"\nbackend = \"servo\"\nline = 18\ngains = { open = 25 }\n"
        "min = 0\nmax = ";
    EXPECT_EQ(errorOf(servo + "25\n" + kLinkage), "no error");  // GPIO servos take one too
    const auto unreachable = errorOf(servo + "90\n" + kLinkage);
    EXPECT_NE(unreachable.find(":9: key 'actuator[0].linkage': cannot reach 0° .. 90°"),
              std::string::npos)
        << unreachable;
    auto typo = kLinkage;
    typo.replace(typo.find("opens = \"counterclockwise\""), 26, "opens = \"anticlockwise\"");
    EXPECT_NE(errorOf(servo + "25\n" + typo).find("clockwise"), std::string::npos);
    EXPECT_NE(errorOf(servo + "25\n" + kLinkage + "extra = 1\n").find("unknown key"),
              std::string::npos);
    EXPECT_NE(errorOf("[[actuator]]\nname = \"v\"\nbackend = \"virtual\"\ngains = { open = 1 }\n"
                      "min = 0\nmax = 25\n" +
                      kLinkage)
                  .find("only servos"),
              std::string::npos);
}

TEST(BoardPuppets, TheShippedBoardPuppetsLoad) {
    for (const char* name : {"pca9685-jaw-lips", "maestro-jaw", "pwm-jaw"}) {
        const auto p = output::Puppet::named(name);
        EXPECT_FALSE(p.actuators.empty()) << name;
    }
}

TEST(BoardPuppets, MaestroLimitsComeFromTheSlew) {
    output::ActuatorConfig a;
    a.min = 0;
    a.max = 0.9;
    a.pulseMinUs = 1100;
    a.pulseMaxUs = 1900;
    a.slew = 6;  // 6 / 0.9 · 800 µs = 5333 µs/s = 213.3 quarter-µs per 10 ms
    EXPECT_EQ(output::MaestroSink::speed(a), 213u);
    EXPECT_EQ(output::MaestroSink::acceleration(a), 0u);
    a.rampSeconds = 0.2;  // 213 · 0.08 / 0.2 = 85.2 → 86 per 80 ms
    EXPECT_EQ(output::MaestroSink::acceleration(a), 86u);
}

}  // namespace
}  // namespace lipsyncd::test
