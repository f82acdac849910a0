// The puppet-file parts of the servo boards (PCA9685, Maestro, kernel PWM) and of linkages,
// kept apart from Puppet.cpp: one reader per backend, called from the actuator reader.
#pragma once

#include <iosfwd>
#include <lipsyncd/output.hpp>
#include <lipsyncd/toml_table.hpp>
#include <optional>

namespace lipsyncd::output {

std::optional<Backend> boardBackend(const std::string& name);  // "pca9685", "maestro", "pwm"
void readBoardAddress(const TomlTable& t, ActuatorConfig& a);
// Reads [actuator.linkage] and solves it (after min/max and the pulses are known).
void readLinkage(const TomlTable& t, ActuatorConfig& a);
// Two actuators on one board channel, boards that disagree on their frequency.
void checkBoardChannels(const Puppet& p);
void describeBoardAddress(std::ostream& out, const ActuatorConfig& a);
void describeLinkage(std::ostream& out, const ActuatorConfig& a);

}  // namespace lipsyncd::output
