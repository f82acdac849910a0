// What the servo-board sinks share: which actuators are theirs, and what happens when a board
// cannot be opened or vanishes (a USB cable pulled, an I2C bus error): the reason is logged
// once with the puppet's file and line, the board is looked for again every second, and
// every other output goes on, as for the HID boards.
#include <algorithm>
#include <lipsyncd/output.hpp>
#include <set>

namespace lipsyncd::output {

ServoBoardSink::ServoBoardSink(const Puppet& puppet,
                               std::function<bool(const ActuatorConfig&)> mine, std::string board,
                               Log log)
    : log_(std::move(log)) {
    for (std::size_t i = 0; i < puppet.actuators.size(); ++i)
        if (mine(puppet.actuators[i])) channels_.push_back({i, &puppet.actuators[i]});
    const std::size_t line = channels_.empty() ? 0 : channels_.front().config->line;
    where_ = InputError(puppet.source.string(), line, board).what();
}

void ServoBoardSink::connect(double time) {
    lastTry_ = time;
    try {
        open();
        connected_ = true;
        if (!lastWhy_.empty() && log_) log_(where_ + ": connected");
        lastWhy_.clear();
    } catch (const std::runtime_error& e) {
        close();
        if (e.what() != lastWhy_ && log_)
            log_(where_ + ": " + e.what() + "; trying again every second, the other outputs go on");
        lastWhy_ = e.what();
    }
}

void ServoBoardSink::write(double time, std::span<const ActuatorCommand> commands) {
    if (!connected_) {
        if (time - lastTry_ < kReopenSeconds && time >= lastTry_) return;
        connect(time);
        if (!connected_) return;
    }
    if (send(commands)) return;
    close();
    connected_ = false;
    lastTry_ = time;
    lastWhy_ = "gone";
    if (log_)
        log_(where_ +
             ": gone (write failed); looking for it every second, the other outputs go on");
}

void addServoBoardSinks(PuppetDriver& driver, const Puppet& puppet, Log log,
                        const std::filesystem::path& pwmRoot) {
    std::set<std::pair<unsigned, unsigned>> pca;
    std::set<std::string> maestro;
    std::set<unsigned> pwm;
    for (const auto& a : puppet.actuators) {
        if (a.backend == Backend::Pca9685 && pca.insert({a.i2cBus, a.i2cAddress}).second)
            driver.addSink(
                std::make_unique<Pca9685Sink>(puppet, a.i2cBus, a.i2cAddress, I2cOpener{}, log));
        if (a.backend == Backend::Maestro && maestro.insert(a.port).second)
            driver.addSink(std::make_unique<MaestroSink>(puppet, a.port, log));
        if (a.backend == Backend::Pwm && pwm.insert(a.pwmChip).second)
            driver.addSink(std::make_unique<KernelPwmSink>(puppet, a.pwmChip, pwmRoot, log));
    }
}

}  // namespace lipsyncd::output
