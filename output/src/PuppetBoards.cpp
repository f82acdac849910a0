// Puppet-file keys of the servo boards, read as strictly as the rest of the file: a bus,
// address, port or channel out of range stops loading with the file and line.
#include "PuppetBoards.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>

namespace lipsyncd::output {

namespace {
unsigned integer(const TomlTable& t, const std::string& key, std::int64_t fallback, std::int64_t lo,
                 std::int64_t hi, const std::string& what) {
    const auto v = t.optInteger(key).value_or(fallback);
    if (v < lo || v > hi) t.fail(key, what);
    return static_cast<unsigned>(v);
}

double positive(const TomlTable& t, const std::string& key) {
    const double v = t.getNumber(key);
    if (!(v > 0 && v < 1e4)) t.fail(key, "must be a length in mm, more than 0");
    return v;
}

std::array<double, 2> point(const TomlTable& t, const std::string& key) {
    const auto v = t.optNumberArray(key);
    if (!v) t.fail(key, "missing: the pivot's position [x, y] in mm");
    if (v->size() != 2) t.fail(key, "must be [x, y] in mm");
    return {(*v)[0], (*v)[1]};
}

void readPca9685(const TomlTable& t, ActuatorConfig& a) {
    if (!t.has("bus")) t.fail("bus", "missing: the I2C bus number (1 is /dev/i2c-1)");
    a.i2cBus = integer(t, "bus", 1, 0, 255, "must be 0 .. 255 (/dev/i2c-N)");
    a.i2cAddress =
        integer(t, "address", 0x40, 0x40, 0x7f, "must be 0x40 .. 0x7F (a PCA9685's addresses)");
    a.channel = integer(t, "channel", 0, 0, 15, "must be 0 .. 15");
    const double osc = t.optNumber("oscillator").value_or(25e6);
    if (!(osc >= 20e6 && osc <= 30e6))
        t.fail("oscillator", "must be 20e6 .. 30e6 Hz (the internal clock is 25 MHz ± 10 %)");
    a.oscillatorHz = osc;
}

void readMaestro(const TomlTable& t, ActuatorConfig& a) {
    a.port = t.getString("port");
    if (a.port.empty()) t.fail("port", "empty: a serial port such as /dev/ttyACM0");
    a.channel = integer(t, "channel", 0, 0, 23, "must be 0 .. 23");
    if (t.has("frequency"))
        t.fail("frequency",
               "a Maestro's pulse period is set on the board (Maestro Control Center)");
    if (t.has("device"))
        a.maestroDevice = static_cast<int>(integer(
            t, "device", 12, 0, 127, "must be 0 .. 127 (the board's Pololu-protocol number)"));
    const auto baud = t.optInteger("baud").value_or(115200);
    static const std::set<std::int64_t> kBauds{9600, 19200, 38400, 57600, 115200, 230400};
    if (!kBauds.contains(baud))
        t.fail("baud", "must be 9600, 19200, 38400, 57600, 115200 or 230400");
    a.baud = static_cast<unsigned>(baud);
    a.rampSeconds = t.optNumber("ramp").value_or(0);
    if (!(a.rampSeconds >= 0 && a.rampSeconds <= 10)) t.fail("ramp", "must be 0 .. 10 s");
}

void readPwm(const TomlTable& t, ActuatorConfig& a) {
    if (!t.has("chip")) t.fail("chip", "missing: the PWM chip number (0 is pwmchip0)");
    a.pwmChip = integer(t, "chip", 0, 0, 1023, "must be 0 .. 1023 (/sys/class/pwm/pwmchipN)");
    a.channel = integer(t, "channel", 0, 0, 1023, "must be 0 .. 1023");
}

std::string where(const ActuatorConfig& a) {
    if (a.backend == Backend::Pca9685) {
        std::ostringstream s;
        s << "PCA9685 on I2C bus " << a.i2cBus << " at 0x" << std::hex << a.i2cAddress;
        return s.str();
    }
    if (a.backend == Backend::Maestro)
        return "Maestro on " + a.port +
               (a.maestroDevice >= 0 ? " device " + std::to_string(a.maestroDevice) : "");
    return "PWM chip " + std::to_string(a.pwmChip);
}
}  // namespace

std::optional<Backend> boardBackend(const std::string& name) {
    if (name == "pca9685") return Backend::Pca9685;
    if (name == "maestro") return Backend::Maestro;
    if (name == "pwm") return Backend::Pwm;
    return std::nullopt;
}

void readBoardAddress(const TomlTable& t, ActuatorConfig& a) {
    if (a.backend == Backend::Pca9685) readPca9685(t, a);
    if (a.backend == Backend::Maestro) readMaestro(t, a);
    if (a.backend == Backend::Pwm) readPwm(t, a);
}

void readLinkage(const TomlTable& t, ActuatorConfig& a) {
    const auto table = t.optTable("linkage");
    if (!table) return;
    if (!takesServoPulses(a.backend))
        t.fail("linkage", "only servos (servo, pca9685, maestro, pwm) take a linkage");
    Linkage l;
    l.servo = point(*table, "servo");
    l.hinge = point(*table, "hinge");
    l.horn = positive(*table, "horn");
    l.rod = positive(*table, "rod");
    l.arm = positive(*table, "arm");
    l.armClosedDeg = table->getNumber("arm_closed");
    const auto opens = table->getString("opens");
    if (opens != "clockwise" && opens != "counterclockwise")
        table->fail("opens", "must be \"clockwise\" or \"counterclockwise\"");
    l.opensClockwise = opens == "clockwise";
    const auto travel = table->optNumberArray("horn_travel").value_or(std::vector<double>{0, 180});
    if (travel.size() != 2 || travel[0] == travel[1] || std::abs(travel[1] - travel[0]) > 360)
        table->fail("horn_travel",
                    "must be [at pulse_min_us, at pulse_max_us] in degrees, at most 360 apart");
    l.hornAtPulseMinDeg = travel[0];
    l.hornAtPulseMaxDeg = travel[1];
    if (a.min < 0) t.fail("min", "with a linkage, min and max are jaw openings (degrees, >= 0)");
    table->finish();
    try {
        l.table = solveLinkage(l, a.min, a.max);
    } catch (const InputError& e) {
        t.fail("linkage", e.what());
    }
    a.linkage = std::move(l);
}

void checkBoardChannels(const Puppet& p) {
    std::map<std::string, const ActuatorConfig*> used;     // board + channel → first user
    std::map<std::string, const ActuatorConfig*> boardHz;  // board → first actuator
    for (const auto& a : p.actuators) {
        if (a.backend != Backend::Pca9685 && a.backend != Backend::Maestro &&
            a.backend != Backend::Pwm)
            continue;
        const auto board = where(a);
        const auto [first, fresh] =
            used.emplace(board + " channel " + std::to_string(a.channel), &a);
        if (!fresh)
            throw InputError(p.source.string(), a.line,
                             board + " channel " + std::to_string(a.channel) +
                                 " is used by two actuators ('" + first->second->name + "' and '" +
                                 a.name + "')");
        // A PCA9685 has one prescaler: its channels share a frequency and an oscillator.
        if (a.backend != Backend::Pca9685) continue;
        const double prescale = std::round(a.oscillatorHz / (4096 * a.frequencyHz)) - 1;
        if (prescale < 3 || prescale > 255)
            throw InputError(p.source.string(), a.line,
                             "actuator '" + a.name + "': a PCA9685 runs at " +
                                 std::to_string(int(a.oscillatorHz / (4096 * 256))) + " .. " +
                                 std::to_string(int(a.oscillatorHz / (4096 * 4))) + " Hz");
        const auto [other, none] = boardHz.emplace(board, &a);
        if (!none && (other->second->frequencyHz != a.frequencyHz ||
                      other->second->oscillatorHz != a.oscillatorHz))
            throw InputError(p.source.string(), a.line,
                             board +
                                 ": every channel of one board runs at one frequency and "
                                 "oscillator (see actuator '" +
                                 other->second->name + "')");
    }
}

void describeBoardAddress(std::ostream& out, const ActuatorConfig& a) {
    if (a.backend == Backend::Pca9685 || a.backend == Backend::Maestro || a.backend == Backend::Pwm)
        out << " " << where(a) << " channel " << a.channel
            << (a.backend == Backend::Maestro ? "; pulse period set on the board" : "");
}

void describeLinkage(std::ostream& out, const ActuatorConfig& a) {
    if (!a.linkage) return;
    const auto& l = *a.linkage;
    out << "    linkage: horn " << l.horn << " mm, pushrod " << l.rod << " mm, jaw arm " << l.arm
        << " mm; value = jaw opening in degrees\n"
        << "      jaw opening   horn angle   pulse\n";
    const std::size_t rows = std::min<std::size_t>(16, l.table.size() - 1);
    for (std::size_t i = 0; i <= rows; ++i) {
        const auto& r = l.table[(l.table.size() - 1) * i / rows];
        out << "      " << std::setw(9) << std::fixed << std::setprecision(1) << r.hingeDeg << "°"
            << std::setw(11) << r.hornDeg << "°" << std::setw(9) << std::setprecision(0)
            << servoPulseUs(a, r.hingeDeg) << " µs\n";
    }
    out << std::defaultfloat << std::setprecision(6);
}

}  // namespace lipsyncd::output
