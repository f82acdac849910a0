// GPIO over libgpiod 1.6 (Debian 12): servo pulses in software and on/off switches. The lines
// are opened once, as outputs, low; a missing chip or line is an InputError naming both.
#include <gpiod.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <lipsyncd/output.hpp>

namespace lipsyncd::output {

namespace {
class LibgpiodLine : public GpioLine {
  public:
    LibgpiodLine(gpiod_chip* chip, gpiod_line* line) : chip_(chip), line_(line) {}
    ~LibgpiodLine() override {
        gpiod_line_set_value(line_, 0);
        gpiod_line_release(line_);
        gpiod_chip_close(chip_);
    }
    void set(bool high) override { gpiod_line_set_value(line_, high ? 1 : 0); }

  private:
    gpiod_chip* chip_;
    gpiod_line* line_;
};
}  // namespace

std::unique_ptr<GpioLine> openGpioLine(const std::string& chipName, unsigned offset,
                                       const std::string& consumer) {
    gpiod_chip* chip = gpiod_chip_open_lookup(chipName.c_str());
    if (!chip)
        throw InputError("GPIO chip '" + chipName + "': cannot open (" + std::strerror(errno) +
                         "); `lipsync devices` lists the chips present");
    gpiod_line* line = gpiod_chip_get_line(chip, offset);
    if (!line) {
        const std::string why = std::strerror(errno);
        const unsigned lines = gpiod_chip_num_lines(chip);
        gpiod_chip_close(chip);
        throw InputError("GPIO chip '" + chipName + "' line " + std::to_string(offset) + ": " +
                         why + " (the chip has " + std::to_string(lines) + " lines)");
    }
    if (gpiod_line_request_output(line, consumer.c_str(), 0) != 0) {
        const std::string why = std::strerror(errno);
        gpiod_chip_close(chip);
        throw InputError("GPIO chip '" + chipName + "' line " + std::to_string(offset) +
                         ": cannot claim it (" + why + "; another program may hold it)");
    }
    return std::make_unique<LibgpiodLine>(chip, line);
}

std::vector<std::string> listGpioChips() {
    std::vector<std::string> out;
    gpiod_chip_iter* iter = gpiod_chip_iter_new();
    if (!iter) return out;
    for (gpiod_chip* chip = gpiod_chip_iter_next(iter); chip; chip = gpiod_chip_iter_next(iter)) {
        out.push_back(std::string(gpiod_chip_name(chip)) + " [" + gpiod_chip_label(chip) + "] " +
                      std::to_string(gpiod_chip_num_lines(chip)) + " lines");
        for (unsigned i = 0; i < gpiod_chip_num_lines(chip); ++i) {
            gpiod_line* line = gpiod_chip_get_line(chip, i);
            if (!line) continue;
            const char* name = gpiod_line_name(line);
            const char* user = gpiod_line_consumer(line);
            out.push_back("    line " + std::to_string(i) + ": " + (name ? name : "unnamed") +
                          (gpiod_line_is_used(line)
                               ? std::string(" (used by ") + (user ? user : "kernel") + ")"
                               : ""));
        }
    }
    gpiod_chip_iter_free(iter);
    return out;
}

namespace {
std::function<std::unique_ptr<GpioLine>(const ActuatorConfig&)> realOpener(const Puppet& puppet) {
    return [name = puppet.name](const ActuatorConfig& a) {
        return openGpioLine(a.chip, a.gpioLine, "lipsyncd:" + name + ":" + a.name);
    };
}
}  // namespace

GpioServoSink::GpioServoSink(const Puppet& puppet,
                             std::function<std::unique_ptr<GpioLine>(const ActuatorConfig&)> open)
    : puppet_(&puppet) {
    if (!open) open = realOpener(puppet);
    std::vector<ServoPwm::Servo> servos;
    double frequency = 50;
    for (std::size_t i = 0; i < puppet.actuators.size(); ++i) {
        const auto& a = puppet.actuators[i];
        if (a.backend != Backend::Servo) continue;
        servos.push_back({open(a), a.pulseMinUs, a.pulseMaxUs, a.min, a.max});
        actuator_.push_back(i);
        frequency = a.frequencyHz;  // one loop: servos of a puppet share a frequency
    }
    pwm_ = std::make_unique<ServoPwm>(std::move(servos), frequency);
    pwm_->start();
}

void GpioServoSink::write(double, std::span<const ActuatorCommand> commands) {
    for (std::size_t k = 0; k < actuator_.size(); ++k)
        pwm_->setPulse(k,
                       servoPulseUs(puppet_->actuators[actuator_[k]], commands[actuator_[k]].value),
                       commands[actuator_[k]].active);  // (through the linkage, if any)
}

GpioSwitchSink::GpioSwitchSink(
    const Puppet& puppet, std::function<std::unique_ptr<GpioLine>(const ActuatorConfig&)> open) {
    if (!open) open = realOpener(puppet);
    for (std::size_t i = 0; i < puppet.actuators.size(); ++i)
        if (puppet.actuators[i].backend == Backend::Switch)
            lines_.emplace_back(i, open(puppet.actuators[i]));
    state_.assign(lines_.size(), -1);
}

void GpioSwitchSink::write(double, std::span<const ActuatorCommand> commands) {
    for (std::size_t k = 0; k < lines_.size(); ++k) {
        const int on = commands[lines_[k].first].on ? 1 : 0;
        if (on != state_[k]) lines_[k].second->set(on != 0);  // only edges reach the hardware
        state_[k] = on;
    }
}

}  // namespace lipsyncd::output

namespace lipsyncd::output {

void addHardwareSinks(PuppetDriver& driver, const Puppet& puppet,
                      std::function<void(const std::string&)> log) {
    const auto uses = [&](Backend b) {
        return std::any_of(puppet.actuators.begin(), puppet.actuators.end(),
                           [&](const ActuatorConfig& a) { return a.backend == b; });
    };
    if (uses(Backend::Servo)) driver.addSink(std::make_unique<GpioServoSink>(puppet));
    if (uses(Backend::Switch)) driver.addSink(std::make_unique<GpioSwitchSink>(puppet));
    for (const auto& h : puppet.hidDevices)
        driver.addSink(std::make_unique<HidSink>(puppet, h, openHidapiDevice, log));
    addServoBoardSinks(driver, puppet, log);
}

}  // namespace lipsyncd::output
