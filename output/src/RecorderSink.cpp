// Every command with its time, for tests, for inspecting a show offline, and for other tools.
#include <iomanip>
#include <lipsyncd/output.hpp>
#include <ostream>

namespace lipsyncd::output {

RecorderSink::RecorderSink(std::ostream& out, const Puppet& puppet, Format format)
    : out_(&out), format_(format) {
    for (const auto& a : puppet.actuators) names_.push_back(a.name);
    if (format_ == Format::Csv) *out_ << "time,actuator,value,active,on\n";
}

void RecorderSink::write(double time, std::span<const ActuatorCommand> commands) {
    auto& out = *out_;
    out << std::fixed;
    for (std::size_t i = 0; i < commands.size(); ++i) {
        const auto& c = commands[i];
        if (format_ == Format::Csv)
            out << std::setprecision(4) << time << ',' << names_[i] << ',' << std::setprecision(5)
                << c.value << ',' << c.active << ',' << c.on << '\n';
        else
            out << "{\"time\":" << std::setprecision(4) << time << ",\"actuator\":\"" << names_[i]
                << "\",\"value\":" << std::setprecision(5) << c.value
                << ",\"active\":" << (c.active ? "true" : "false")
                << ",\"on\":" << (c.on ? "true" : "false") << "}\n";
    }
}

TerminalSink::TerminalSink(std::ostream& out, const Puppet& puppet, double refreshHz)
    : out_(&out), puppet_(&puppet), period_(1.0 / refreshHz) {}

void TerminalSink::write(double time, std::span<const ActuatorCommand> commands) {
    if (time - lastDraw_ < period_ && time >= lastDraw_) return;
    lastDraw_ = time;
    auto& out = *out_;
    constexpr int kWidth = 40;
    if (drawn_) out << "\x1b[" << commands.size() + 1 << 'A';  // back up over the last drawing
    drawn_ = true;
    out << "\r\x1b[K" << std::fixed << std::setprecision(2) << time << " s  " << puppet_->name
        << '\n';
    for (std::size_t i = 0; i < commands.size(); ++i) {
        const auto& a = puppet_->actuators[i];
        const double share = (commands[i].value - a.min) / (a.max - a.min);
        const int filled = static_cast<int>(share * kWidth + 0.5);
        out << "\r\x1b[K" << std::setw(12) << std::left << a.name.substr(0, 12) << std::right
            << " |" << std::string(static_cast<std::size_t>(filled), '#')
            << std::string(static_cast<std::size_t>(kWidth - filled), ' ') << "| " << std::setw(7)
            << std::setprecision(3) << commands[i].value
            << (a.backend == Backend::Switch ? (commands[i].on ? "  ON" : "  off")
                                             : (commands[i].active ? "" : "  relaxed"))
            << '\n';
    }
    out.flush();
}

}  // namespace lipsyncd::output
