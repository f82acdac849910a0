// Puppet files (config/puppets/*.toml), read strictly: unknown keys, wrong types, duplicate
// GPIO lines, min > max, a rest outside the limits: each stops loading with the file and line.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <lipsyncd/output.hpp>
#include <lipsyncd/toml_table.hpp>
#include <ostream>
#include <set>

#include "PuppetBoards.hpp"

namespace lipsyncd::output {

namespace {
Backend backendOf(const TomlTable& t) {
    const auto b = t.getString("backend");
    if (b == "servo") return Backend::Servo;
    if (b == "switch") return Backend::Switch;
    if (b == "hid") return Backend::Hid;
    if (b == "virtual") return Backend::Virtual;
    if (const auto board = boardBackend(b)) return *board;
    t.fail("backend",
           "'" + b + "' is not a backend (servo, switch, hid, virtual, pca9685, maestro, pwm)");
}

double number(const TomlTable& t, const std::string& key, double fallback, double lo, double hi) {
    const double v = t.optNumber(key).value_or(fallback);
    if (!(v >= lo && v <= hi)) {
        std::ostringstream s;
        s << "must be within " << lo << " .. " << hi;
        t.fail(key, s.str());
    }
    return v;
}

void readAddress(const TomlTable& t, ActuatorConfig& a) {
    if (a.backend == Backend::Servo || a.backend == Backend::Switch) {
        a.chip = t.optString("chip").value_or("gpiochip0");
        const auto line = t.optInteger("line");
        if (!line) t.fail("line", "missing: the GPIO line offset on the chip");
        if (*line < 0 || *line > 1023) t.fail("line", "must be 0 .. 1023");
        a.gpioLine = static_cast<unsigned>(*line);
    }
    if (a.backend == Backend::Hid) {
        a.hidDevice = t.getString("device");
        a.hidChannel = static_cast<unsigned>(number(t, "channel", 0, 0, 4095));
    }
    readBoardAddress(t, a);
}

void readBackendSettings(const TomlTable& t, ActuatorConfig& a) {
    if (takesServoPulses(a.backend)) {
        a.pulseMinUs = number(t, "pulse_min_us", 1000, 100, 3000);
        a.pulseMaxUs = number(t, "pulse_max_us", 2000, 100, 3000);
        a.frequencyHz = number(t, "frequency", 50, 10, 400);
        if (1e6 / a.frequencyHz < std::max(a.pulseMinUs, a.pulseMaxUs))
            t.fail("frequency", "the period is shorter than a pulse");
    }
    if (a.backend == Backend::Switch) {
        a.threshold = t.getNumber("threshold");
        a.hysteresis = number(t, "hysteresis", 0.1, 0, 1e9);
        a.minOnSeconds = number(t, "min_on", 0.05, 0, 60);
        a.minOffSeconds = number(t, "min_off", 0.05, 0, 60);
    }
}

// Values a puppet file may hold (NaN and inf would pass every later comparison): finite
// within ±1e6; names plain enough for the command record's CSV and the terminal.
void checkActuatorBounds(const TomlTable& t, const ActuatorConfig& a) {
    constexpr double kLimit = 1e6;
    const auto bounded = [&](const char* key, double v) {
        if (!(std::abs(v) <= kLimit)) t.fail(key, "must be a finite number within -1e6 .. 1e6");
    };
    bounded("neutral", a.neutral);
    bounded("trim", a.trim);
    bounded("min", a.min);
    bounded("max", a.max);
    for (const auto& [pose, gain] : a.gains)
        if (!(std::abs(gain) <= kLimit))
            t.fail("gains", "gain for '" + pose + "' must be a finite number within -1e6 .. 1e6");
    const bool plain =
        !a.name.empty() && a.name.size() <= 64 &&
        std::all_of(a.name.begin(), a.name.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
        });
    if (!plain) t.fail("name", "must be 1 to 64 letters, digits, '_', '-' or '.'");
}

ActuatorConfig readActuator(const TomlTable& t) {
    ActuatorConfig a;
    a.line = t.line();
    a.name = t.getString("name");
    a.backend = backendOf(t);
    readAddress(t, a);
    a.neutral = t.optNumber("neutral").value_or(0);
    a.trim = t.optNumber("trim").value_or(0);
    if (const auto gains = t.optTable("gains"))
        for (const auto& pose : gains->keys()) a.gains.emplace_back(pose, gains->getNumber(pose));
    if (a.gains.empty())
        t.fail("gains", "missing: which poses move this actuator (gains = { open = 1.0 })");
    a.invert = t.optBool("invert").value_or(false);
    a.min = t.getNumber("min");
    a.max = t.getNumber("max");
    checkActuatorBounds(t, a);
    if (!(a.min < a.max)) t.fail("max", "must be greater than min");
    a.rest = t.optNumber("rest").value_or(a.min);
    if (!(a.rest >= a.min && a.rest <= a.max)) t.fail("rest", "must be within min .. max");
    a.deadband = number(t, "deadband", 0, 0, a.max - a.min);
    a.slew = number(t, "slew", 5 * (a.max - a.min), 1e-6, 1e9);
    a.idleAfter = number(t, "idle_after", 2, 0, 3600);
    readBackendSettings(t, a);
    readLinkage(t, a);
    t.finish();
    return a;
}

HidDeviceConfig readHid(const TomlTable& t) {
    HidDeviceConfig h;
    h.line = t.line();
    h.name = t.getString("name");
    h.path = t.optString("path").value_or("");
    h.vid = static_cast<std::uint16_t>(number(t, "vid", 0, 0, 0xffff));
    h.pid = static_cast<std::uint16_t>(number(t, "pid", 0, 0, 0xffff));
    if (h.path.empty() && (h.vid == 0 || h.pid == 0)) t.fail("vid", "give vid and pid (or path)");
    h.serial = t.optString("serial").value_or("");
    h.reportId = static_cast<std::uint8_t>(number(t, "report_id", 0, 0, 255));
    h.reportSize = static_cast<std::size_t>(number(t, "report_size", 16, 1, 1024));
    const auto enc = t.optString("encoding").value_or("u8");
    if (enc == "u8")
        h.encoding = HidEncoding::U8;
    else if (enc == "u16le")
        h.encoding = HidEncoding::U16LE;
    else
        t.fail("encoding", "'" + enc + "' is not u8 or u16le");
    h.rateHz = number(t, "rate", 50, 1, 1000);
    h.reopenSeconds = number(t, "reopen_every", 1, 0.05, 60);
    t.finish();
    return h;
}

void checkDuplicates(const Puppet& p, const TomlTable& root) {
    std::set<std::pair<std::string, unsigned>> gpio;
    std::set<std::string> names;
    for (const auto& a : p.actuators) {
        if (!names.insert(a.name).second)
            throw InputError(p.source.string(), a.line,
                             "actuator '" + a.name + "' is defined twice");
        if ((a.backend == Backend::Servo || a.backend == Backend::Switch) &&
            !gpio.insert({a.chip, a.gpioLine}).second)
            throw InputError(p.source.string(), a.line,
                             "GPIO " + a.chip + " line " + std::to_string(a.gpioLine) +
                                 " is used by two actuators");
        if (a.backend == Backend::Hid) {
            const auto dev =
                std::find_if(p.hidDevices.begin(), p.hidDevices.end(),
                             [&](const HidDeviceConfig& h) { return h.name == a.hidDevice; });
            if (dev == p.hidDevices.end())
                throw InputError(
                    p.source.string(), a.line,
                    "actuator '" + a.name + "': no [[hid]] named '" + a.hidDevice + "'");
            const std::size_t width = dev->encoding == HidEncoding::U8 ? 1 : 2;
            if ((a.hidChannel + 1) * width > dev->reportSize)
                throw InputError(p.source.string(), a.line,
                                 "actuator '" + a.name + "': channel " +
                                     std::to_string(a.hidChannel) + " does not fit a " +
                                     std::to_string(dev->reportSize) + "-byte report");
        }
    }
    (void)root;
    checkBoardChannels(p);
}
}  // namespace

Puppet Puppet::load(const std::filesystem::path& file) {
    const auto root = TomlTable::parseFile(file);
    Puppet p;
    p.source = file;
    p.name = root.getString("name");
    p.description = root.optString("description").value_or("");
    p.stallTimeout = number(root, "stall_timeout", 0.5, 0.01, 3600);
    p.leadSeconds = number(root, "lead", 0, 0, 1);
    for (const auto& h : root.tableArray("hid")) p.hidDevices.push_back(readHid(h));
    for (const auto& t : root.tableArray("actuator")) p.actuators.push_back(readActuator(t));
    root.finish();
    if (p.actuators.empty()) throw InputError(file.string(), 0, "no [[actuator]] defined");
    checkDuplicates(p, root);
    return p;
}

Puppet Puppet::named(const std::string& nameOrPath) {
    return load(findNamedDataFile(nameOrPath, "puppets", ".toml"));
}

void Puppet::checkPoses(std::span<const std::string> poses) const {
    for (const auto& a : actuators)
        for (const auto& [pose, gain] : a.gains)
            if (std::find(poses.begin(), poses.end(), pose) == poses.end())
                throw InputError(source.string(), a.line,
                                 "actuator '" + a.name + "': pose '" + pose +
                                     "' is not among the weights' poses");
}

void Puppet::describe(std::ostream& out) const {
    static const char* kBackend[] = {"servo",   "switch",  "hid", "virtual",
                                     "pca9685", "maestro", "pwm"};
    out << "puppet '" << name << "' (" << source.string() << "): " << actuators.size()
        << " actuator(s), rest after " << stallTimeout << " s without input\n";
    for (const auto& a : actuators) {
        out << "  " << a.name << " [" << kBackend[static_cast<int>(a.backend)];
        if (a.backend == Backend::Servo || a.backend == Backend::Switch)
            out << " " << a.chip << " line " << a.gpioLine;
        if (a.backend == Backend::Hid) out << " " << a.hidDevice << " channel " << a.hidChannel;
        describeBoardAddress(out, a);
        out << "]\n    value = " << a.neutral + a.trim;
        for (const auto& [pose, gain] : a.gains)
            out << (gain < 0 ? " - " : " + ") << std::abs(gain) << "·" << pose;
        out << (a.invert ? ", inverted" : "") << "; limits " << a.min << " .. " << a.max
            << ", rest " << a.rest << ", slew " << a.slew << "/s, deadband " << a.deadband;
        if (takesServoPulses(a.backend))
            out << "\n    pulses " << a.pulseMinUs << " .. " << a.pulseMaxUs << " µs at "
                << a.frequencyHz << " Hz, relax after " << a.idleAfter << " s at rest";
        if (a.backend == Backend::Switch)
            out << "\n    on above " << a.threshold + a.hysteresis / 2 << ", off below "
                << a.threshold - a.hysteresis / 2 << ", at least " << a.minOnSeconds << " s on / "
                << a.minOffSeconds << " s off";
        out << '\n';
        describeLinkage(out, a);
    }
    for (const auto& h : hidDevices)
        out << "  hid '" << h.name << "': " << (h.path.empty() ? "" : h.path + " ") << std::hex
            << std::setfill('0') << std::setw(4) << h.vid << ':' << std::setw(4) << h.pid
            << std::dec << std::setfill(' ') << ", report id " << int(h.reportId) << ", "
            << h.reportSize << " bytes, " << (h.encoding == HidEncoding::U8 ? "u8" : "u16le")
            << ", " << h.rateHz << " Hz\n";
}

}  // namespace lipsyncd::output
