// lipsync drive / check / devices: pose weights through a puppet's actuators; a puppet file
// validated and explained; the GPIO chips, HID boards, I2C buses, serial ports and PWM chips
// present.
#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iostream>
#include <lipsyncd/output.hpp>
#include <thread>

#include "Commands.hpp"

namespace lipsyncd::cli {

namespace {
volatile std::sig_atomic_t gStop = 0;  // set by SIGINT/SIGTERM: the one global a signal needs
extern "C" void onStopSignal(int) {
    gStop = 1;
}

struct DriveOptions {
    std::string weights, puppet, record;
    bool realtime = false, terminal = false, noHardware = false;
};

void say(const std::string& what) {
    std::cerr << "lipsync drive: " << what << '\n';
}

void runDrive(const DriveOptions& o) {
    const auto puppet = output::Puppet::named(o.puppet);
    const auto track = readPoseTrackCsvFile(o.weights);
    output::PuppetDriver driver(puppet, track.poses);
    if (!o.noHardware) output::addHardwareSinks(driver, puppet, say);
    std::ofstream recordFile;
    if (!o.record.empty()) {
        const bool json = o.record.ends_with(".jsonl") || o.record.ends_with(".json");
        std::ostream* out = &std::cout;
        if (o.record != "-") {
            recordFile.open(o.record);
            if (!recordFile) throw InputError(o.record + ": cannot write");
            out = &recordFile;
        }
        driver.addSink(std::make_unique<output::RecorderSink>(
            *out, puppet,
            json ? output::RecorderSink::Format::JsonLines : output::RecorderSink::Format::Csv));
    }
    if (o.terminal) driver.addSink(std::make_unique<output::TerminalSink>(std::cerr, puppet));

    std::signal(SIGINT, onStopSignal);
    std::signal(SIGTERM, onStopSignal);
    const auto start = std::chrono::steady_clock::now();
    const auto waitUntil = [&](double t) {
        // The puppet's lead: each frame goes out that much before its time (servo lag).
        if (o.realtime)
            std::this_thread::sleep_until(start +
                                          std::chrono::duration<double>(t - puppet.leadSeconds));
    };
    double t = 0;
    bool stalled = false;
    for (std::size_t f = 0; f < track.frames() && !gStop; ++f) {
        // A gap in the weights longer than the stall timeout: the mouth goes to rest meanwhile.
        for (double gap = t + 0.01; f > 0 && gap < track.times[f] - 0.01 && !gStop; gap += 0.01) {
            waitUntil(gap);
            driver.tick(gap);
            if (!stalled && gap - t > puppet.stallTimeout)
                say("no weights for " + std::to_string(puppet.stallTimeout) + " s: moving to rest");
            stalled = gap - t > puppet.stallTimeout;
        }
        t = track.times[f];
        waitUntil(t);
        driver.update(t, track.frame(f));
        stalled = false;
    }
    if (gStop) say("interrupted: moving to rest");
    const double restedAt = driver.rest(t, 100, waitUntil);
    if (gStop || o.terminal) say("at rest (" + std::to_string(restedAt - t) + " s to get there)");
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}
}  // namespace

// The servo boards' buses and ports, each with the puppet keys that name it.
void listSection(const std::string& title, const std::vector<std::string>& found,
                 const std::string& none) {
    std::cout << title << '\n';
    if (found.empty()) std::cout << "  none (" << none << ")\n";
    for (const auto& f : found) std::cout << "  " << f << '\n';
}

void listServoBoards() {
    listSection("I2C buses (PCA9685: backend = \"pca9685\", bus = N, address = 0x40):",
                output::listI2cBuses(),
                "no /dev/i2c-*: enable I2C and load i2c-dev, e.g. raspi-config");
    listSection("Serial ports (Maestro: backend = \"maestro\", port = \"/dev/serial/by-id/...\"):",
                output::listSerialPorts(), "no USB serial board plugged in");
    listSection("PWM chips (backend = \"pwm\", chip = N, channel = M):", output::listPwmChips(),
                "no /sys/class/pwm/pwmchip*: enable a PWM overlay, e.g. dtoverlay=pwm-2chan");
}

void addDriveCommands(CLI::App& app) {
    auto o = std::make_shared<DriveOptions>();
    auto* drive = app.add_subcommand("drive", "Play pose weights through a puppet's actuators");
    drive->add_option("--weights", o->weights, "Pose weights (CSV; '-' for stdin)")->required();
    drive
        ->add_option("--puppet", o->puppet,
                     "Puppet file (or a name in config/puppets: jaw-servo, terminal, ...)")
        ->required();
    drive->add_flag("--realtime", o->realtime,
                    "Play at the weights' own pace (default: as fast as possible)");
    drive->add_option("--record", o->record,
                      "Record every command (CSV, or JSON lines for .jsonl; '-' for stdout)");
    drive->add_flag("--terminal", o->terminal, "Show a live bar per actuator on stderr");
    drive->add_flag("--no-hardware", o->noHardware,
                    "Do not open GPIO or HID outputs (recorder/terminal only)");
    drive->callback([o] { runDrive(*o); });

    auto puppet = std::make_shared<std::string>();
    auto weights = std::make_shared<std::string>();
    auto* check =
        app.add_subcommand("check", "Validate a puppet file and print the resolved mapping");
    check->add_option("--puppet", *puppet, "Puppet file or name")->required();
    check->add_option("--weights", *weights, "Also check its poses against this weights file");
    check->callback([puppet, weights] {
        const auto p = output::Puppet::named(*puppet);
        if (!weights->empty()) p.checkPoses(readPoseTrackCsvFile(*weights).poses);
        p.describe(std::cout);
    });

    auto* devices =
        app.add_subcommand("devices",
                           "List the GPIO chips, USB HID devices, I2C buses, serial ports and "
                           "PWM chips present");
    devices->callback([] {
        const auto chips = output::listGpioChips();
        std::cout << "GPIO chips (name them in a puppet as chip = \"gpiochipN\", line = OFFSET):\n";
        if (chips.empty())
            std::cout
                << "  none (no /dev/gpiochip*, or no permission: add yourself to group gpio)\n";
        for (const auto& c : chips) std::cout << "  " << c << '\n';
        const auto hid = output::listHidDevices();
        std::cout << "USB HID devices (name them in a [[hid]] table as vid = 0xVVVV, pid = 0xPPPP, "
                     "or path):\n";
        if (hid.empty())
            std::cout << "  none (no /dev/hidraw*, or no permission: see "
                         "systemd/99-lipsyncd-hidraw.rules)\n";
        for (const auto& h : hid) std::cout << "  " << h << '\n';
        listServoBoards();
    });
}

}  // namespace lipsyncd::cli
