// lipsync ctl: the client of lipsyncd's control socket (JSON lines). Requests are built from the
// daemon's command table and checked against it before they are sent; every wait has a deadline.
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "Commands.hpp"
#include "NameValue.hpp"

namespace lipsyncd::cli {

namespace {
using daemon::ControlArg;

struct CtlOptions {
    std::string socket = "/run/lipsyncd/control.sock";
    std::vector<std::string> args;
    int channel = -1;
    std::string voice, textFile;
    bool wait = false, next = false;
    // The reply indented, a field a line (for a person), or on one line (for scripts); neither
    // given: indented when standard output is a terminal.
    bool pretty = false, oneLine = false;
    double timeout = 5;
};

std::string usage() {
    std::string u = "commands:";
    for (const auto& c : daemon::controlCommands()) u += "\n  " + std::string(c.usage);
    return u + "\n  raw JSON: send a request as it is";
}

// One command-line word as the argument's JSON value.
nlohmann::json valueOf(const ControlArg& arg, const std::string& word) {
    switch (arg.type) {
        case ControlArg::Type::Boolean:
            if (word == "on" || word == "true") return true;
            if (word == "off" || word == "false") return false;
            break;
        case ControlArg::Type::Integer:
            try {
                return std::stol(word);
            } catch (const std::exception&) {
            }
            break;
        case ControlArg::Type::Path:
            return std::filesystem::absolute(word).string();
        case ControlArg::Type::String:
            return word;
        case ControlArg::Type::Weights:
            break;  // several words: weightsOf
    }
    throw CLI::ValidationError("ctl", "'" + word + "' is not " + std::string(arg.help));
}

// NAME=VALUE words as a weights object: `lipsync ctl pose jaw=0.5 open=0.2`.
nlohmann::json weightsOf(const ControlArg& arg, std::span<const std::string> words) {
    nlohmann::json weights = nlohmann::json::object();
    for (const auto& word : words) {
        const auto pair = parseNameValue(word);
        if (!pair)
            throw CLI::ValidationError(
                "ctl", "'" + word + "' is not NAME=VALUE: " + std::string(arg.help));
        weights[pair->first] = pair->second;
    }
    return weights;
}

nlohmann::json requestFrom(const CtlOptions& o) {
    const auto& a = o.args;
    if (a.front() == "raw") {
        if (a.size() != 2) throw CLI::ValidationError("ctl", "usage: lipsync ctl raw '{...}'");
        auto r = nlohmann::json::parse(a[1], nullptr, false);
        if (r.is_discarded()) throw CLI::ValidationError("ctl", "raw: not JSON: " + a[1]);
        return r;
    }
    const auto* command = daemon::findControlCommand(a.front());
    if (!command)
        throw CLI::ValidationError("ctl", "unknown command '" + a.front() + "'\n" + usage());
    nlohmann::json r = {{"cmd", a.front()}};
    if (!command->positional.empty() && a.size() > 1) {
        const auto& arg =
            *std::find_if(command->args.begin(), command->args.end(),
                          [&](const ControlArg& x) { return x.name == command->positional; });
        if (arg.type == ControlArg::Type::String) {  // words join into one text
            std::string text;
            for (std::size_t i = 1; i < a.size(); ++i) text += (i > 1 ? " " : "") + a[i];
            r[arg.name] = text;
        } else if (arg.type == ControlArg::Type::Weights) {
            r[arg.name] = weightsOf(arg, std::span<const std::string>(a).subspan(1));
        } else if (a.size() == 2) {
            r[arg.name] = valueOf(arg, a[1]);
        } else {
            throw CLI::ValidationError("ctl", "usage: lipsync ctl " + std::string(command->usage));
        }
    } else if (a.size() > 1) {
        throw CLI::ValidationError("ctl", "usage: lipsync ctl " + std::string(command->usage));
    }
    if (o.channel >= 0 && command->name == "play") r["channel"] = o.channel;
    if (!o.voice.empty() && command->name == "say") r["voice"] = o.voice;
    if (o.next) {
        if (command->name != "line") throw CLI::ValidationError("--next", "is for line");
        r["next"] = true;
    }
    if (!o.textFile.empty()) {
        if (command->name != "play" && command->name != "line" && command->name != "script")
            throw CLI::ValidationError("--text-file", "is for play, line and script");
        std::ifstream in(o.textFile);
        if (!in) throw InputError(o.textFile + ": cannot read");
        std::ostringstream words;
        words << in.rdbuf();
        r["text"] = words.str();
    }
    if (const auto bad = daemon::checkControlRequest(r)) throw CLI::ValidationError("ctl", *bad);
    return r;
}

void runCtl(const CtlOptions& o) {
    const auto request = requestFrom(o);
    daemon::ControlClient c(o.socket,
                            std::chrono::milliseconds(static_cast<long>(o.timeout * 1000)));
    const auto reply = c.request(request);
    const bool pretty = o.pretty || (!o.oneLine && ::isatty(STDOUT_FILENO) == 1);
    std::cout << reply.dump(pretty ? 2 : -1) << std::endl;
    if (!reply.value("ok", false))
        throw std::runtime_error("lipsyncd: " +
                                 reply.value("error", std::string("request refused")));
    if (request["cmd"] == "subscribe")
        for (;;) std::cout << c.readLine() << std::endl;  // until interrupted or the daemon goes
    // --wait: until nothing plays or is queued.
    while (o.wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        const auto s = c.request({{"cmd", "status"}});
        if (s["playing"].is_null() && s["queue"].empty()) break;
    }
}
}  // namespace

void addCtlCommand(CLI::App& app) {
    auto o = std::make_shared<CtlOptions>();
    auto* cmd = app.add_subcommand(
        "ctl", "Talk to a running lipsyncd: " + daemon::controlCommandNames() + ", raw JSON");
    cmd->footer(usage());
    cmd->add_option("--socket", o->socket, "lipsyncd's control socket")->capture_default_str();
    cmd->add_option("--channel", o->channel, "play: analyse only this channel of the file");
    cmd->add_option("--voice", o->voice, "say: espeak-ng voice");
    cmd->add_option("--text-file", o->textFile,
                    "play: the words spoken in the file, aligned instead of recognised "
                    "(default: FILE.txt beside the file, when there is one); line: the words "
                    "the performer says next; script: the show's lines, one a line");
    cmd->add_option("--timeout", o->timeout, "Seconds to wait for the daemon at each step")
        ->capture_default_str()
        ->check(CLI::Range(0.05, 3600.0));
    cmd->add_flag("--wait", o->wait, "Return when nothing plays or is queued any more");
    auto* pretty = cmd->add_flag("--pretty", o->pretty,
                                 "Print the reply indented, a field a line (the default on a "
                                 "terminal)");
    cmd->add_flag("--one-line", o->oneLine,
                  "Print the reply on one line (the default into a pipe or a file, for scripts)")
        ->excludes(pretty);
    cmd->add_flag("--next", o->next, "line: cue the script's next line (loaded with `script`)");
    cmd->add_option("request", o->args, "The request and its arguments")->required();
    cmd->callback([o] { runCtl(*o); });
}

}  // namespace lipsyncd::cli
