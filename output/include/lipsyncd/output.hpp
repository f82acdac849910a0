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
//                     Pca9685Sink (I2C), MaestroSink (USB serial), KernelPwmSink (sysfs).
//   Linkage           a four-bar linkage between servo horn and jaw, solved so the jaw's hinge
//                     angle is the commanded value.
//   GpioLine, HidDevice, I2cDevice  the hardware seams: real (libgpiod, hidapi, i2c-dev) and
//                     fakes for tests.
#pragma once

#include <array>
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

enum class Backend { Servo, Switch, Hid, Virtual, Pca9685, Maestro, Pwm };
// Backends that take servo pulses (pulse_min_us/pulse_max_us, frequency, linkage).
bool takesServoPulses(Backend backend);

// A four-bar linkage (mm, degrees; x right, y up, angles counter-clockwise from +x): the servo
// horn turns about `servo`, the pushrod joins the horn's hole to the jaw arm's hole, the jaw
// arm turns about `hinge`. With a linkage the actuator's value is the jaw's opening at the
// hinge in degrees (0: closed), so the jaw opens linearly in the commanded value.
struct LinkageRow {
    double hingeDeg, hornDeg;
};
struct Linkage {
    std::array<double, 2> servo{0, 0}, hinge{0, 0};
    double horn = 0, rod = 0, arm = 0;  // horn radius, pushrod length, jaw arm radius
    double armClosedDeg = 0;            // the jaw arm's direction with the mouth closed
    bool opensClockwise = false;        // which way the jaw arm turns as the mouth opens
    double hornAtPulseMinDeg = 0, hornAtPulseMaxDeg = 180;  // the servo's travel
    std::vector<LinkageRow> table;  // solved at load, from min to max (equal steps)
};
// Solves the linkage for hinge openings min .. max (`steps` equal steps). Throws InputError
// (no file) saying why when the pushrod cannot reach, the servo's travel is too short, or
// the motion folds back (two jaw angles for one horn angle).
std::vector<LinkageRow> solveLinkage(const Linkage& linkage, double min, double max,
                                     std::size_t steps = 64);

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
    // Servo boards: the channel on the board (PCA9685 0..15, Maestro 0..23, PWM chip channel).
    unsigned channel = 0;
    // PCA9685: /dev/i2c-<bus>, 7-bit address, the board's oscillator (trim to the measured one).
    unsigned i2cBus = 1, i2cAddress = 0x40;
    double oscillatorHz = 25e6;
    // Maestro: serial port; Pololu-protocol device number (-1: compact protocol); baud (TTL
    // serial only); seconds to reach the slew speed (0: no acceleration limit on the board).
    std::string port;
    int maestroDevice = -1;
    unsigned baud = 115200;
    double rampSeconds = 0;
    // Kernel PWM: /sys/class/pwm/pwmchip<pwmChip>, channel `channel`.
    unsigned pwmChip = 0;
    std::optional<Linkage> linkage;  // servo pulses only
};

// The pulse width for a servo-type actuator's value: linear from min..max to
// pulse_min_us..pulse_max_us, or through its linkage's table; never outside the pulses (a
// value out of range is clamped, a non-finite one is rest). No allocation.
double servoPulseUs(const ActuatorConfig& actuator, double value);

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
    void set(std::size_t servo, double value, bool active);         // lock-free (atomics)
    void setPulse(std::size_t servo, double pulseUs, bool active);  // (through a linkage)
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
    const Puppet* puppet_;
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
// Servo boards: PCA9685 (I2C), Pololu Maestro (USB serial), kernel PWM (sysfs). Jitter-free
// pulses from hardware (notes/hardware.md). A board that cannot be opened, or vanishes, is
// logged with the puppet's file and line and looked for again every second, while every
// other output goes on.

using Log = std::function<void(const std::string&)>;

// What the board sinks share: their channels (actuators), the reopen schedule, the messages.
class ServoBoardSink : public CommandSink {
  public:
    void write(double time, std::span<const ActuatorCommand> commands) final;
    bool connected() const { return connected_; }
    static constexpr double kReopenSeconds = 1.0;

  protected:
    struct Channel {
        std::size_t actuator;  // index into the commands
        const ActuatorConfig* config;
    };
    // `board`: how messages name it ("PCA9685 on /dev/i2c-1 at 0x40").
    ServoBoardSink(const Puppet& puppet, std::function<bool(const ActuatorConfig&)> mine,
                   std::string board, Log log);
    // Each throws std::runtime_error saying why it failed; send() returns false when gone.
    virtual void open() = 0;
    virtual bool send(std::span<const ActuatorCommand> commands) = 0;
    virtual void close() = 0;

    std::vector<Channel> channels_;

  private:
    void connect(double time);  // open(), or log why not and try again later

    std::string where_;  // "FILE:LINE: PCA9685 on ..."
    Log log_;
    bool connected_ = false;
    double lastTry_ = -1e9;
    std::string lastWhy_;
};

// One I2C device at one address (i2c-dev for real; a register-level fake in tests).
class I2cDevice {
  public:
    virtual ~I2cDevice() = default;
    // bytes[0] is the register, the rest its data (auto-increment); false: no answer.
    virtual bool write(std::span<const std::uint8_t> bytes) = 0;
    // Reads out.size() bytes from `reg` on (repeated start); false: no answer.
    virtual bool read(std::uint8_t reg, std::span<std::uint8_t> out) = 0;
};
// Throws std::runtime_error saying why (no such bus, permission denied, address taken by a
// kernel driver).
using I2cOpener = std::function<std::unique_ptr<I2cDevice>(unsigned bus, unsigned address)>;
std::unique_ptr<I2cDevice> openI2cDevice(unsigned bus, unsigned address,
                                         const std::filesystem::path& dev = "/dev");
// "/dev/i2c-1" lines, each with the addresses 0x40–0x7F that answer (where readable).
std::vector<std::string> listI2cBuses(const std::filesystem::path& dev = "/dev");

// One PCA9685 board (every actuator naming its bus and address): the prescaler set from the
// frequency (sleep, PRE_SCALE, wake, restart: datasheet 7.3.1.1), then each channel's
// LEDn_OFF count when it changes; a relaxed servo's channel is full-off, and so is every
// channel when the sink closes (after the rest pose).
class Pca9685Sink : public ServoBoardSink {
  public:
    Pca9685Sink(const Puppet& puppet, unsigned bus, unsigned address, I2cOpener open = {},
                Log log = {});
    ~Pca9685Sink() override;
    static std::uint8_t prescale(double oscillatorHz, double frequencyHz);
    // LEDn_OFF count of a pulse: one tick is (prescale + 1) / oscillator.
    static std::uint16_t counts(double pulseUs, double oscillatorHz, std::uint8_t prescale);

  private:
    void open() override;
    bool send(std::span<const ActuatorCommand> commands) override;
    void close() override;

    unsigned bus_, address_;
    I2cOpener opener_;
    std::unique_ptr<I2cDevice> device_;
    std::uint8_t prescale_ = 121;
    std::vector<int> sent_;  // per channel: the last count sent (-1: none, 0x1000: full-off)
};

// A Pololu Maestro on a serial port (its USB command port, or TTL serial with `baud`): Set
// Target in quarter-µs, compact protocol (0x84) or Pololu protocol (0xAA, device) when the
// puppet names a device; Set Speed and Set Acceleration from the slew on every (re)open.
class MaestroSink : public ServoBoardSink {
  public:
    MaestroSink(const Puppet& puppet, const std::string& port, Log log = {});
    ~MaestroSink() override;
    // A command (0x84 Set Target, 0x87 Set Speed, 0x89 Set Acceleration) with a 14-bit value,
    // in the compact protocol (device < 0) or the Pololu protocol; returns the bytes written.
    static std::size_t encode(std::span<std::uint8_t, 6> out, int device, std::uint8_t command,
                              unsigned channel, unsigned value);
    // The board's speed limit (0.25 µs per 10 ms) for the actuator's slew, and its
    // acceleration limit (0.25 µs per 10 ms per 80 ms) for its ramp (0: none).
    static unsigned speed(const ActuatorConfig& actuator);
    static unsigned acceleration(const ActuatorConfig& actuator);
    std::size_t framesDropped() const { return dropped_; }

  private:
    void open() override;
    bool send(std::span<const ActuatorCommand> commands) override;
    void close() override;
    bool writeAll(std::span<const std::uint8_t> bytes);

    std::string port_;
    int fd_ = -1;
    std::vector<unsigned> sent_;       // per channel: last target (quarter-µs), ~0u: none
    std::vector<std::uint8_t> frame_;  // one write's bytes, sized at construction
    std::size_t dropped_ = 0;          // frames the port had no room for
};
// Serial ports: /dev/serial/by-id links (a Pololu Maestro's command port marked) and
// /dev/ttyACM*.
std::vector<std::string> listSerialPorts(const std::filesystem::path& dev = "/dev");

// Kernel PWM through sysfs: <root>/pwmchipN/export, then pwmM/period, duty_cycle, enable
// (ns). `root` is /sys/class/pwm (tests point it at a fake tree). A relaxed servo gets duty 0;
// on close the channels are disabled and unexported again.
class KernelPwmSink : public ServoBoardSink {
  public:
    KernelPwmSink(const Puppet& puppet, unsigned chip,
                  std::filesystem::path root = "/sys/class/pwm", Log log = {});
    ~KernelPwmSink() override;

  private:
    void open() override;
    bool send(std::span<const ActuatorCommand> commands) override;
    void close() override;

    std::filesystem::path chipDir_;
    std::vector<int> dutyFd_;         // per channel, open while connected
    std::vector<std::int64_t> sent_;  // per channel: last duty (ns), -1: none
    std::vector<bool> exported_;      // we exported it: unexport on close
};
// "pwmchip0: 2 channels" lines.
std::vector<std::string> listPwmChips(const std::filesystem::path& root = "/sys/class/pwm");

// Adds one sink per PCA9685 board, Maestro port and PWM chip the puppet names.
class PuppetDriver;
void addServoBoardSinks(PuppetDriver& driver, const Puppet& puppet, Log log,
                        const std::filesystem::path& pwmRoot = "/sys/class/pwm");

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
