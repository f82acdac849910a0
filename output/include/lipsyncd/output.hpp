// output: pose weights in, actuator commands out, safely.
//
//   Puppet            a puppet file (config/puppets/*.toml): actuators, their backends and
//                     addresses, mapping from poses, limits, slew, rest, idle; HID boards.
//   ActuatorChannel   one actuator's pipeline: mapping (neutral + trim + Σ gain·weight,
//                     inversion), then the safety layer (non-finite input holds, clamp to
//                     min/max, deadband, slew limit) and idle relax. Nothing leaves it outside
//                     the actuator's limits or faster than its slew.
//   SwitchLogic       on/off from a value: threshold, hysteresis, minimum on and off times.
//   PuppetDriver      all channels of a puppet, stepped by the caller's clock; rest on stop,
//                     fault, signal or stalled input; hands every command to the sinks.
//   CommandSink       where commands go: GpioServoSink / GpioSwitchSink (libgpiod 1.6),
//                     HidSink (hidapi), RecorderSink (CSV / JSON lines), TerminalSink (bars).
//   GpioLine, HidDevice  the hardware seams: real (libgpiod, hidapi) and fakes for tests.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <lipsyncd/core.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace lipsyncd::output {

// ---------------------------------------------------------------------------------------------
// The puppet file.

enum class Backend { Servo, Switch, Hid, Virtual };

struct ActuatorConfig {
    std::string name;
    Backend backend = Backend::Virtual;
    std::size_t line = 0;  // file line of [[actuator]], for messages
    // Address: GPIO chip and line offset (servo, switch); HID device name and channel (hid).
    std::string chip;
    unsigned gpioLine = 0;
    std::string hidDevice;
    unsigned hidChannel = 0;
    // Mapping: value = neutral + trim + Σ gain[pose] · weight[pose]; inverted: min + max − value.
    double neutral = 0, trim = 0;
    std::vector<std::pair<std::string, double>> gains;
    bool invert = false;
    // Safety.
    double min = 0, max = 1;
    double deadband = 0;   // changes smaller than this are not sent (a buzzing jaw)
    double slew = 5;       // units per second
    double rest = 0;       // where it goes on stop, fault, signal or stall
    double idleAfter = 2;  // a servo at rest this long gets no more pulses (0: never relax)
    // Servo pulses: min ↦ pulseMinUs, max ↦ pulseMaxUs.
    double pulseMinUs = 1000, pulseMaxUs = 2000, frequencyHz = 50;
    // Switch: on above threshold + hysteresis/2, off below threshold − hysteresis/2.
    double threshold = 0.5, hysteresis = 0.1, minOnSeconds = 0.05, minOffSeconds = 0.05;
};

enum class HidEncoding { U8, U16LE };

struct HidDeviceConfig {
    std::string name;
    std::size_t line = 0;
    std::uint16_t vid = 0, pid = 0;
    std::string serial, path;  // optional: pick one board among several, or open by path
    std::uint8_t reportId = 0;
    std::size_t reportSize = 16;  // bytes after the report id
    HidEncoding encoding = HidEncoding::U8;
    double rateHz = 50;        // reports per second
    double reopenSeconds = 1;  // how often to look for an unplugged board
};

struct Puppet {
    std::string name, description;
    std::filesystem::path source;
    double stallTimeout = 0.5;  // seconds without input before the mouth goes to rest
    double leadSeconds = 0;     // the mouth is driven this much ahead of the sound (servo lag)
    std::vector<ActuatorConfig> actuators;
    std::vector<HidDeviceConfig> hidDevices;

    static Puppet load(const std::filesystem::path& file);  // strict; InputError with the line
    static Puppet named(
        const std::string& nameOrPath);  // "terminal" → config/puppets/terminal.toml
    // Resolves gains against a track's pose names; InputError for a pose the track lacks.
    void checkPoses(std::span<const std::string> poses) const;
    // The resolved mapping, for `lipsync check`.
    void describe(std::ostream& out) const;
};

// ---------------------------------------------------------------------------------------------
// One actuator.

struct ActuatorCommand {
    double value = 0;    // within [min, max], always
    bool active = true;  // false: a servo relaxed (no pulses) / a switch's state in `on`
    bool on = false;     // switches only
};

class SwitchLogic {
  public:
    explicit SwitchLogic(const ActuatorConfig& config);
    bool update(double time, double value);  // the switch state after this value
    bool on() const { return on_; }

  private:
    double onAbove_, offBelow_, minOn_, minOff_;
    bool on_ = false;
    double since_ = -1e9;  // time of the last change
};

class ActuatorChannel {
  public:
    // `poseIndex[k]` is the track column of gain k.
    ActuatorChannel(const ActuatorConfig& config, std::vector<std::size_t> poseIndex);
    // Steps to `time` toward the target the weights give (or toward rest); returns the command.
    ActuatorCommand step(double time, std::span<const float> weights);
    ActuatorCommand stepToRest(double time);
    bool atRest() const;
    const ActuatorConfig& config() const { return config_; }
    double value() const { return value_; }

  private:
    ActuatorCommand moveToward(double time, double target);

    ActuatorConfig config_;
    std::vector<std::size_t> poseIndex_;
    double value_;          // the last commanded value
    double lastTarget_;     // the last good (finite) target
    double lastTime_ = -1;  // -1: no step yet
    double restingSince_ = 0;
    std::optional<SwitchLogic> switch_;
};

// ---------------------------------------------------------------------------------------------
// Sinks.

class CommandSink {
  public:
    virtual ~CommandSink() = default;
    // One call per step with every actuator's command, in puppet order.
    virtual void write(double time, std::span<const ActuatorCommand> commands) = 0;
};

// Every command with its time: CSV (time,actuator,value,active) or JSON lines.
class RecorderSink : public CommandSink {
  public:
    enum class Format { Csv, JsonLines };
    RecorderSink(std::ostream& out, const Puppet& puppet, Format format);
    void write(double time, std::span<const ActuatorCommand> commands) override;

  private:
    std::ostream* out_;
    std::vector<std::string> names_;
    Format format_;
};

// A live bar per actuator, redrawn in place (for the demo and tuning without hardware).
class TerminalSink : public CommandSink {
  public:
    TerminalSink(std::ostream& out, const Puppet& puppet, double refreshHz = 25);
    void write(double time, std::span<const ActuatorCommand> commands) override;

  private:
    std::ostream* out_;
    const Puppet* puppet_;
    double period_, lastDraw_ = -1e9;
    bool drawn_ = false;
};

// A GPIO output line (libgpiod 1.6 for real; a fake in tests).
class GpioLine {
  public:
    virtual ~GpioLine() = default;
    virtual void set(bool high) = 0;
};
// Opens `line` of `chip` (a name such as "gpiochip0", a path, or a label) as an output, low.
// InputError naming the chip and line when either is missing or busy.
std::unique_ptr<GpioLine> openGpioLine(const std::string& chip, unsigned line,
                                       const std::string& consumer);
// The GPIO chips present, with their lines: "gpiochip0 [label] 54 lines" and one line each.
std::vector<std::string> listGpioChips();

// Software PWM for servos: one thread for all servos of a puppet, absolute-deadline sleeps on
// CLOCK_MONOTONIC, SCHED_FIFO where permitted. Commands set pulse widths; relaxed servos get none.
class ServoPwm {
  public:
    struct Servo {
        std::unique_ptr<GpioLine> line;
        double pulseMinUs, pulseMaxUs, min, max;
    };
    // `sleepUntil` is the clock (absolute deadline sleeps); tests pass a fake one.
    using Clock = std::function<std::int64_t()>;                    // now, ns
    using SleepUntil = std::function<void(std::int64_t deadline)>;  // ns
    ServoPwm(std::vector<Servo> servos, double frequencyHz, Clock clock = {},
             SleepUntil sleep = {});
    ~ServoPwm();
    ServoPwm(const ServoPwm&) = delete;
    ServoPwm& operator=(const ServoPwm&) = delete;
    void set(std::size_t servo, double value, bool active);  // lock-free (atomics)
    void runPeriods(int periods);  // for tests and benchmarks: run the loop inline
    void start();                  // the real-time thread
    bool realtime() const { return realtime_; }
    static double pulseUs(double value, double min, double max, double pulseMinUs,
                          double pulseMaxUs);

  private:
    void period(std::int64_t start);

    std::vector<Servo> servos_;
    std::vector<std::atomic<std::int64_t>> pulseNs_;  // 0: relaxed
    std::int64_t periodNs_;
    Clock clock_;
    SleepUntil sleep_;
    std::atomic<bool> running_{false};
    std::thread thread_;
    bool realtime_ = false;
};

class GpioServoSink : public CommandSink {
  public:
    GpioServoSink(const Puppet& puppet,
                  std::function<std::unique_ptr<GpioLine>(const ActuatorConfig&)> open = {});
    void write(double time, std::span<const ActuatorCommand> commands) override;
    ServoPwm& pwm() { return *pwm_; }

  private:
    std::vector<std::size_t> actuator_;  // servo k is actuator actuator_[k]
    std::unique_ptr<ServoPwm> pwm_;
};

class GpioSwitchSink : public CommandSink {
  public:
    GpioSwitchSink(const Puppet& puppet,
                   std::function<std::unique_ptr<GpioLine>(const ActuatorConfig&)> open = {});
    void write(double time, std::span<const ActuatorCommand> commands) override;

  private:
    std::vector<std::pair<std::size_t, std::unique_ptr<GpioLine>>> lines_;
    std::vector<int> state_;
};

// A USB HID board (hidapi for real; a fake in tests).
class HidDevice {
  public:
    virtual ~HidDevice() = default;
    virtual bool write(std::span<const std::uint8_t> report) = 0;  // false: gone
};
using HidOpener = std::function<std::unique_ptr<HidDevice>(const HidDeviceConfig&)>;
// hidapi: by path, else VID:PID (and serial). nullptr when not present.
std::unique_ptr<HidDevice> openHidapiDevice(const HidDeviceConfig& config);
std::vector<std::string> listHidDevices();  // "VID:PID serial path product" lines

// One sink per HID board: channels in report order, encoded, sent at the board's rate; an
// unplugged board is reopened every reopenSeconds while the others go on.
class HidSink : public CommandSink {
  public:
    HidSink(const Puppet& puppet, const HidDeviceConfig& device, HidOpener open = openHidapiDevice,
            std::function<void(const std::string&)> log = {});
    void write(double time, std::span<const ActuatorCommand> commands) override;
    bool connected() const { return device_ != nullptr; }
    static void encode(std::span<std::uint8_t> report, std::size_t channel, double value,
                       double min, double max, HidEncoding encoding);

  private:
    HidDeviceConfig config_;
    std::vector<std::pair<std::size_t, const ActuatorConfig*>> channels_;  // (actuator, config)
    HidOpener open_;
    std::function<void(const std::string&)> log_;
    std::unique_ptr<HidDevice> device_;
    std::vector<std::uint8_t> report_;
    double lastSent_ = -1e9, lastTry_ = -1e9;
};

// ---------------------------------------------------------------------------------------------
// The puppet.

// Opens every hardware output the puppet names (servo, switch, HID) and adds it to `driver`.
// GPIO errors are InputErrors naming chip and line; an absent HID board is waited for.
class PuppetDriver;
void addHardwareSinks(PuppetDriver& driver, const Puppet& puppet,
                      std::function<void(const std::string&)> log);

class PuppetDriver {
  public:
    // `poses`: the weight columns update() receives (resolved against the puppet's gains).
    PuppetDriver(const Puppet& puppet, std::span<const std::string> poses);
    void addSink(std::unique_ptr<CommandSink> sink);
    void addSink(CommandSink& sink);  // not owned

    // New weights at `time` (seconds, the caller's clock).
    void update(double time, std::span<const float> weights);
    // No new weights: moves on toward the last target, or to rest once input has stalled
    // longer than the puppet's stall timeout. Returns true while still resting toward rest.
    void tick(double time);
    // Stop, fault or signal: steps toward rest (slew-limited) at `stepHz` until there, calling
    // `sleepUntilTime` between steps (none: as fast as possible). Returns the time it got there.
    double rest(double time, double stepHz = 100,
                const std::function<void(double)>& sleepUntilTime = {});
    bool atRest() const;
    std::span<const ActuatorCommand> last() const { return last_; }
    const Puppet& puppet() const { return *puppet_; }

  private:
    void send(double time);

    const Puppet* puppet_;
    std::vector<ActuatorChannel> channels_;
    std::vector<ActuatorCommand> last_;
    std::vector<std::unique_ptr<CommandSink>> owned_;
    std::vector<CommandSink*> sinks_;
    std::vector<float> lastWeights_;
    double lastInput_ = 0;
    bool resting_ = false;
};

}  // namespace lipsyncd::output
