// A PCA9685 16-channel PWM board over I2C (NXP PCA9685 datasheet, rev. 4). The board makes the
// pulses itself from its 25 MHz oscillator, 12 bits per period (about 4.9 µs steps at 50 Hz),
// so they do not jitter with the Linux scheduler; a channel is written only when its count
// changes (5 bytes with auto-increment).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <lipsyncd/output.hpp>
#include <stdexcept>
#include <thread>

namespace lipsyncd::output {

namespace {
// Registers and MODE1 bits (datasheet 7.3).
constexpr std::uint8_t kMode1 = 0x00, kMode2 = 0x01, kLed0OnL = 0x06, kAllLedOnL = 0xfa,
                       kPreScale = 0xfe;
constexpr std::uint8_t kRestart = 0x80, kAutoIncrement = 0x20, kSleep = 0x10;
constexpr std::uint8_t kOutDrv = 0x04;  // MODE2: totem-pole outputs, as servo signal lines want
constexpr int kFullOff = 0x1000;        // bit 4 of LEDn_OFF_H
// The oscillator needs 500 µs after SLEEP is cleared before RESTART may be set (7.3.1.1).
constexpr auto kOscillatorStart = std::chrono::microseconds(500);

std::string hex(unsigned v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", v);
    return buf;
}

std::string boardName(unsigned bus, unsigned address) {
    return "PCA9685 on /dev/i2c-" + std::to_string(bus) + " at " + hex(address);
}
}  // namespace

std::uint8_t Pca9685Sink::prescale(double oscillatorHz, double frequencyHz) {
    // prescale = round(osc / (4096 · f)) − 1 (7.3.5), within the chip's 3 .. 255.
    return static_cast<std::uint8_t>(
        std::clamp(std::lround(oscillatorHz / (4096 * frequencyHz)) - 1, 3L, 255L));
}

std::uint16_t Pca9685Sink::counts(double pulseUs, double oscillatorHz, std::uint8_t prescale) {
    const double tickUs = 1e6 * (prescale + 1) / oscillatorHz;
    return static_cast<std::uint16_t>(std::clamp(std::lround(pulseUs / tickUs), 0L, 4095L));
}

Pca9685Sink::Pca9685Sink(const Puppet& puppet, unsigned bus, unsigned address, I2cOpener open,
                         Log log)
    : ServoBoardSink(
          puppet,
          [bus, address](const ActuatorConfig& a) {
              return a.backend == Backend::Pca9685 && a.i2cBus == bus && a.i2cAddress == address;
          },
          boardName(bus, address), std::move(log)),
      bus_(bus),
      address_(address),
      opener_(open ? std::move(open) : [](unsigned b, unsigned a) { return openI2cDevice(b, a); }),
      sent_(channels_.size(), -1) {
    if (!channels_.empty())  // (the puppet checks that a board's channels agree)
        prescale_ =
            prescale(channels_.front().config->oscillatorHz, channels_.front().config->frequencyHz);
}

Pca9685Sink::~Pca9685Sink() {
    // Stop comes after the rest pose: now every channel full-off, the servos unpowered.
    if (device_) {
        const std::uint8_t allOff[] = {kAllLedOnL, 0, 0, 0, kFullOff >> 8};
        device_->write(allOff);
    }
}

void Pca9685Sink::open() {
    device_ = opener_(bus_, address_);
    std::uint8_t mode1 = 0;
    if (!device_->read(kMode1, {&mode1, 1}))
        throw std::runtime_error("no device answers at " + hex(address_) +
                                 " (wrong address? a PCA9685 is at 0x40 unless its A0-A5 pads are "
                                 "bridged; `lipsync devices` shows what answers)");
    // PRE_SCALE can be written only while the oscillator sleeps (7.3.1.1, 7.3.5).
    const std::uint8_t awake =
        static_cast<std::uint8_t>((mode1 & ~(kRestart | kSleep)) | kAutoIncrement);
    const std::uint8_t sleep[] = {kMode1, static_cast<std::uint8_t>(awake | kSleep)};
    const std::uint8_t scale[] = {kPreScale, prescale_};
    const std::uint8_t mode2[] = {kMode2, kOutDrv};
    const std::uint8_t allOff[] = {kAllLedOnL, 0, 0, 0, kFullOff >> 8};
    const std::uint8_t wake[] = {kMode1, awake};
    std::uint8_t readBack = 0;
    if (!device_->write(sleep) || !device_->write(scale) || !device_->write(mode2) ||
        !device_->write(allOff) || !device_->read(kPreScale, {&readBack, 1}))
        throw std::runtime_error("bus error while setting the board up");
    if (readBack != prescale_)
        throw std::runtime_error("the device at " + hex(address_) +
                                 " is not a PCA9685 (PRE_SCALE does not keep its value)");
    if (!device_->write(wake)) throw std::runtime_error("bus error while waking the board");
    std::this_thread::sleep_for(kOscillatorStart);
    // RESTART reads 1 when channels were running before the sleep: writing 1 resumes them.
    if (!device_->read(kMode1, {&mode1, 1}))
        throw std::runtime_error("bus error while waking the board");
    const std::uint8_t restart[] = {kMode1, static_cast<std::uint8_t>(awake | kRestart)};
    if ((mode1 & kRestart) && !device_->write(restart))
        throw std::runtime_error("bus error while restarting the board");
    std::fill(sent_.begin(), sent_.end(), -1);
}

bool Pca9685Sink::send(std::span<const ActuatorCommand> commands) {
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        const auto& [index, config] = channels_[k];
        const auto& c = commands[index];
        const int off =
            c.active ? counts(servoPulseUs(*config, c.value), config->oscillatorHz, prescale_)
                     : kFullOff;
        if (off == sent_[k]) continue;
        // ON at count 0, OFF after the pulse: LEDn_ON_L, ON_H, OFF_L, OFF_H (7.3.3).
        const std::uint8_t led[] = {static_cast<std::uint8_t>(kLed0OnL + 4 * config->channel), 0, 0,
                                    static_cast<std::uint8_t>(off & 0xff),
                                    static_cast<std::uint8_t>(off >> 8)};
        if (!device_->write(led)) return false;
        sent_[k] = off;
    }
    return true;
}

void Pca9685Sink::close() {
    device_.reset();
}

}  // namespace lipsyncd::output
