// USB HID boards over hidapi 0.13 (hidraw). A report is the report id and then each channel's
// value scaled from its actuator's range, as u8 or u16 little-endian, sent at the board's
// rate. hidapi 0.13 has no hotplug: on a failed write the board is closed and looked for again
// every reopen interval, while every other output goes on (notes/hardware.md).
#include <hidapi/hidapi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cwchar>
#include <lipsyncd/output.hpp>

namespace lipsyncd::output {

namespace {
class HidapiDevice : public HidDevice {
  public:
    explicit HidapiDevice(hid_device* device) : device_(device) {}
    ~HidapiDevice() override { hid_close(device_); }
    bool write(std::span<const std::uint8_t> report) override {
        return hid_write(device_, report.data(), report.size()) == static_cast<int>(report.size());
    }

  private:
    hid_device* device_;
};

std::string narrow(const wchar_t* w) {
    std::string s;
    for (; w && *w; ++w) s += *w < 128 ? static_cast<char>(*w) : '?';
    return s;
}

std::string hex4(unsigned v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04x", v & 0xffff);
    return buf;
}
}  // namespace

std::unique_ptr<HidDevice> openHidapiDevice(const HidDeviceConfig& c) {
    if (hid_init() != 0) return nullptr;
    hid_device* d = nullptr;
    if (!c.path.empty()) {
        d = hid_open_path(c.path.c_str());
    } else {
        std::wstring serial(c.serial.begin(), c.serial.end());
        d = hid_open(c.vid, c.pid, c.serial.empty() ? nullptr : serial.c_str());
    }
    return d ? std::make_unique<HidapiDevice>(d) : nullptr;
}

std::vector<std::string> listHidDevices() {
    std::vector<std::string> out;
    if (hid_init() != 0) return out;
    hid_device_info* all = hid_enumerate(0, 0);
    for (auto* d = all; d; d = d->next)
        out.push_back(hex4(d->vendor_id) + ":" + hex4(d->product_id) + "  serial \"" +
                      narrow(d->serial_number) + "\"  path " + (d->path ? d->path : "?") + "  " +
                      narrow(d->manufacturer_string) + " " + narrow(d->product_string));
    hid_free_enumeration(all);
    return out;
}

HidSink::HidSink(const Puppet& puppet, const HidDeviceConfig& device, HidOpener open,
                 std::function<void(const std::string&)> log)
    : config_(device),
      open_(std::move(open)),
      log_(std::move(log)),
      report_(device.reportSize + 1, 0) {
    for (std::size_t i = 0; i < puppet.actuators.size(); ++i)
        if (puppet.actuators[i].backend == Backend::Hid &&
            puppet.actuators[i].hidDevice == device.name)
            channels_.emplace_back(i, &puppet.actuators[i]);
    report_[0] = device.reportId;
    device_ = open_(config_);
    if (!device_ && log_)
        log_("HID board '" + config_.name + "' (" +
             (config_.path.empty() ? hex4(config_.vid) + ":" + hex4(config_.pid) : config_.path) +
             ") not present; looking for it every " + std::to_string(config_.reopenSeconds) + " s");
}

void HidSink::encode(std::span<std::uint8_t> report, std::size_t channel, double value, double min,
                     double max, HidEncoding encoding) {
    const double share = std::clamp((value - min) / (max - min), 0.0, 1.0);
    if (encoding == HidEncoding::U8) {
        report[channel] = static_cast<std::uint8_t>(std::lround(share * 255));
    } else {
        const auto v = static_cast<std::uint16_t>(std::lround(share * 65535));
        report[2 * channel] = static_cast<std::uint8_t>(v & 0xff);
        report[2 * channel + 1] = static_cast<std::uint8_t>(v >> 8);
    }
}

void HidSink::write(double time, std::span<const ActuatorCommand> commands) {
    if (!device_) {
        if (time - lastTry_ < config_.reopenSeconds && time >= lastTry_) return;
        lastTry_ = time;
        device_ = open_(config_);
        if (!device_) return;
        if (log_) log_("HID board '" + config_.name + "' is back");
    }
    // (a microsecond of slack: 0.03 − 0.01 is a hair under 0.02 in floating point)
    if (time - lastSent_ < 1.0 / config_.rateHz - 1e-6 && time >= lastSent_) return;
    lastSent_ = time;
    const auto payload = std::span<std::uint8_t>(report_).subspan(1);
    for (const auto& [index, a] : channels_)
        encode(payload, a->hidChannel, commands[index].value, a->min, a->max, config_.encoding);
    if (!device_->write(report_)) {
        device_.reset();
        lastTry_ = time;
        if (log_)
            log_("HID board '" + config_.name +
                 "' is gone (write failed); the other outputs go on");
    }
}

}  // namespace lipsyncd::output
