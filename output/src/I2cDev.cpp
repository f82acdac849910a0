// I2C through the kernel's i2c-dev interface (/dev/i2c-N; Linux i2c-dev): plain write() for
// register writes, I2C_RDWR for a register read (write the register, repeated start, read).
// Open errors say what a builder must do: enable the bus, join group i2c, free the address.
#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <lipsyncd/output.hpp>
#include <stdexcept>

#include "DeviceFiles.hpp"

namespace lipsyncd::output {

namespace {
class I2cDevDevice : public I2cDevice {
  public:
    I2cDevDevice(int fd, unsigned address) : fd_(fd), address_(address) {}
    ~I2cDevDevice() override { ::close(fd_); }
    I2cDevDevice(const I2cDevDevice&) = delete;
    I2cDevDevice& operator=(const I2cDevDevice&) = delete;

    bool write(std::span<const std::uint8_t> bytes) override {
        return ::write(fd_, bytes.data(), bytes.size()) == static_cast<ssize_t>(bytes.size());
    }
    bool read(std::uint8_t reg, std::span<std::uint8_t> out) override {
        return readRegister(fd_, address_, reg, out);
    }
    static bool readRegister(int fd, unsigned address, std::uint8_t reg,
                             std::span<std::uint8_t> out) {
        i2c_msg messages[2] = {
            {static_cast<__u16>(address), 0, 1, &reg},
            {static_cast<__u16>(address), I2C_M_RD, static_cast<__u16>(out.size()), out.data()}};
        i2c_rdwr_ioctl_data transfer{messages, 2};
        return ioctl(fd, I2C_RDWR, &transfer) == 2;
    }

  private:
    int fd_;
    unsigned address_;
};

std::string hex(unsigned v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", v);
    return buf;
}

std::string openError(const std::string& path, int error) {
    if (error == ENOENT)
        return "no I2C bus " + path +
               " (enable I2C, e.g. dtparam=i2c_arm=on on a Raspberry Pi, and load i2c-dev; "
               "`lipsync devices` lists the buses)";
    if (error == EACCES || error == EPERM)
        return path + ": permission denied (add the user to group i2c)";
    return path + ": " + std::strerror(error);
}
}  // namespace

std::unique_ptr<I2cDevice> openI2cDevice(unsigned bus, unsigned address,
                                         const std::filesystem::path& dev) {
    const std::string path = (dev / ("i2c-" + std::to_string(bus))).string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) throw std::runtime_error(openError(path, errno));
    if (ioctl(fd, I2C_SLAVE, static_cast<unsigned long>(address)) != 0) {
        const int error = errno;
        ::close(fd);
        throw std::runtime_error(path + " address " + hex(address) + ": " +
                                 (error == EBUSY    ? "taken by a kernel driver"
                                  : error == ENOTTY ? "not an I2C bus"
                                                    : std::string(std::strerror(error))));
    }
    return std::make_unique<I2cDevDevice>(fd, address);
}

std::vector<std::string> listI2cBuses(const std::filesystem::path& dev) {
    std::vector<std::string> out;
    for (const auto& path : sortedEntries(dev, {"i2c-"})) {
        std::string name;
        std::getline(std::ifstream("/sys/class/i2c-dev/" + path.filename().string() + "/name"),
                     name);
        std::string line = path.string() + (name.empty() ? "" : " [" + name + "]");
        const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) {
            out.push_back(line + ": not scanned (" + openError(path, errno) + ")");
            continue;
        }
        // A PCA9685 answers at 0x40 + its address pads; 0x70 is every PCA9685's all-call.
        std::string answering;
        for (unsigned address = 0x40; address <= 0x7f; ++address) {
            std::uint8_t mode1 = 0;
            if (ioctl(fd, I2C_SLAVE, static_cast<unsigned long>(address)) == 0 &&
                I2cDevDevice::readRegister(fd, address, 0x00, {&mode1, 1}))
                answering += " " + hex(address);
        }
        ::close(fd);
        out.push_back(line + (answering.empty() ? ": nothing answers at 0x40-0x7F"
                                                : ": answering at" + answering +
                                                      " (a PCA9685 is at 0x40 by default)"));
    }
    return out;
}

}  // namespace lipsyncd::output
