// lipsyncd: the service. `lipsyncd --config FILE` (default /etc/lipsyncd/lipsyncd.toml).
#include <malloc.h>
#include <systemd/sd-daemon.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <lipsyncd/daemon.hpp>

int main(int argc, char** argv) {
    // Clip buffers are megabytes, made on the worker and freed when played: a fixed mmap
    // threshold gives every one back to the system when freed (glibc's adaptive threshold
    // would keep them in the arenas), and one arena per thread is plenty.
    mallopt(M_MMAP_THRESHOLD, 256 * 1024);
    mallopt(M_ARENA_MAX, 2);
    CLI::App app{
        "lipsyncd: the lip-sync service. Plays speech and drives a puppet's mouth in sync;\n"
        "controlled over a Unix socket (see `lipsync ctl --help`). Runs under systemd\n"
        "(Type=notify) or in the foreground.",
        "lipsyncd"};
    std::string config = "/etc/lipsyncd/lipsyncd.toml";
    app.add_option("--config,-c", config, "Configuration file")->capture_default_str();
    app.set_version_flag("--version", std::string("lipsyncd ") + LIPSYNCD_VERSION);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    try {
        lipsyncd::daemon::Daemon daemon(config);
        return daemon.run();
    } catch (const std::exception& e) {
        std::cerr << SD_ERR << "lipsyncd: " << e.what() << std::endl;
        sd_notifyf(0, "STATUS=failed: %s", e.what());
        return 1;
    }
}
