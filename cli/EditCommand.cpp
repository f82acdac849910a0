// lipsync edit: the curve editor, a local web application (Xu et al. 2013, section 2.1, figure 3).
// A process of its own, so the service (lipsyncd) never needs the network.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <iostream>
#include <lipsyncd/editor.hpp>
#include <thread>

#include "Commands.hpp"
#include "NumberOption.hpp"

namespace lipsyncd::cli {

namespace {
struct EditOptions {
    std::string curves = "english";
    std::string character;
    std::string poses = "facefx";
    std::string phonemes = "common";
    std::string voice = "en-us";
    std::string socket, puppet;
    editor::ServerOptions server;
    bool noOpen = false;
};

bool isLoopback(const std::string& host) {
    return host == "127.0.0.1" || host == "::1" || host == "localhost" || host.starts_with("127.");
}

// Best effort: a desktop opens the page; a headless machine just has the printed address.
void openInBrowser(const std::string& url) {
    const char* argv[] = {"xdg-open", url.c_str(), nullptr};
    pid_t pid = 0;
    if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, const_cast<char**>(argv), environ) != 0)
        return;
    std::thread([pid] { ::waitpid(pid, nullptr, 0); }).detach();
}

void runEdit(const EditOptions& o) {
    // SIGINT and SIGTERM stop the server from a thread of their own (sigwait), not a handler;
    // blocked before any thread starts (espeak-ng and the server start their own).
    sigset_t stopSignals;
    sigemptyset(&stopSignals);
    sigaddset(&stopSignals, SIGINT);
    sigaddset(&stopSignals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);

    if (!o.character.empty() &&
        !std::filesystem::is_directory(std::filesystem::absolute(o.character).parent_path()))
        throw InputError(o.character + ": no such folder to save the character in");
    const auto& phonemes = PhonemeSet::named(o.phonemes);
    auto poses = lipsync::PoseSet::named(o.poses);
    auto mouth = editor::MouthDrawing::load(findDataFile("editor/mouth.toml"), poses);
    editor::CharacterDraft draft(std::move(poses), phonemes, o.curves, o.character);
    if (!o.puppet.empty() && o.socket.empty())
        throw CLI::ValidationError("--puppet", "names the puppet lipsyncd drives: give --socket");
    std::optional<editor::PuppetStream> puppet;
    if (!o.socket.empty()) puppet.emplace(o.socket, o.puppet);
    EspeakSynthesizer speech;
    editor::PreviewSettings preview;
    preview.voice = o.voice;
    preview.puppet = puppet ? &*puppet : nullptr;
    editor::EditorApi api(std::move(draft), std::move(mouth), editor::randomToken(), speech,
                          preview);

    editor::EditorServer server(api, o.server);
    if (!isLoopback(o.server.bind))
        std::cerr << "lipsync edit: warning: listening on " << o.server.bind
                  << ", not only this machine: anyone with the address can edit and save\n";
    std::cout << "lipsync edit: " << server.url() << '\n'
              << "lipsync edit: "
              << (o.character.empty() ? "no --character: saving is off" : "saves to " + o.character)
              << (puppet ? "; the preview moves '" + puppet->puppet() + "' (lipsyncd, " + o.socket +
                               ")"
                         : std::string())
              << "; Ctrl-C stops" << std::endl;
    if (!o.noOpen) openInBrowser(server.url());
    std::thread watcher([&] {
        int sig = 0;
        sigwait(&stopSignals, &sig);
        server.stop();
    });
    server.run();
    pthread_kill(watcher.native_handle(), SIGTERM);  // run() may also end on its own
    watcher.join();
}
}  // namespace

void addEditCommand(CLI::App& app) {
    auto o = std::make_shared<EditOptions>();
    auto* cmd = app.add_subcommand(
        "edit",
        "Edit bigram curves in a browser: drag control points, hear and see a sentence or a "
        "recording with its words (and, with --socket, the puppet lipsyncd drives)");
    cmd->add_option("--curves", o->curves, "Base curve set (config/curves/NAME.json, or a file)")
        ->capture_default_str();
    cmd->add_option("--character", o->character,
                    "Character file to edit and save (created on the first save; only the "
                    "changed bigrams are written)");
    cmd->add_option("--poses", o->poses, "Pose set (config/poses/NAME.toml, or a file)")
        ->capture_default_str();
    cmd->add_option("--phonemes", o->phonemes, "Phoneme set: common, mandarin, or a file")
        ->capture_default_str();
    cmd->add_option("--voice", o->voice,
                    "espeak-ng voice for the preview (and for reading a recording's words)")
        ->capture_default_str();
    cmd->add_option("--socket", o->socket,
                    "lipsyncd's control socket: the preview moves the puppet it drives too");
    cmd->add_option("--puppet", o->puppet,
                    "With --socket: the puppet lipsyncd must be driving (refused otherwise)");
    addNumberOption(*cmd, "--port", o->server.port, "TCP port (0: any free one)", 0, 65535);
    cmd->add_option("--bind", o->server.bind,
                    "Address to listen on (this machine only unless you change it)")
        ->capture_default_str();
    cmd->add_flag("--no-open", o->noOpen, "Only print the address; do not open a browser");
    cmd->callback([o] { runEdit(*o); });
}

}  // namespace lipsyncd::cli
