// Fuzz target: bytes as a pose-weights CSV, driven through the terminal puppet. Whatever the
// file holds, no actuator command leaves its limits (the project's first safety rule).
#include <cstdint>
#include <lipsyncd/core.hpp>
#include <lipsyncd/output.hpp>
#include <sstream>

using namespace lipsyncd;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const auto puppet = output::Puppet::named("terminal");
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    try {
        const auto track = readPoseTrackCsv(in, "fuzz.csv");
        for (const double t : track.times)
            if (!(t >= 0 && t <= 86400)) __builtin_trap();
        output::PuppetDriver driver(puppet, track.poses);
        for (std::size_t f = 0; f < track.frames() && f < 2000; ++f) {
            driver.update(track.times[f], track.frame(f));
            const auto commands = driver.last();
            for (std::size_t i = 0; i < commands.size(); ++i) {
                const auto& a = puppet.actuators[i];
                if (!(commands[i].value >= a.min && commands[i].value <= a.max)) __builtin_trap();
            }
        }
    } catch (const InputError&) {
    }
    return 0;
}
