// cpp-httplib around the API and the built-in page. The page and its two files are the only
// things served besides the API; a URL never names a file on disk.
#include <httplib.h>
#include <sys/socket.h>

#include <lipsyncd/editor.hpp>

namespace lipsyncd::editor {

struct EditorServer::Impl {
    httplib::Server server;
};

namespace {
// A bigram's curves or a sentence: far less; a recording's preview: its bytes in base64 (the
// API's own limit, PreviewSettings::maxUploadBytes, answers with the figures below this).
constexpr std::size_t kMaxBody = 16u << 20;

void serveApi(EditorApi& api, const httplib::Request& req, httplib::Response& res) {
    ApiRequest r{req.method, req.path, req.get_header_value("X-Lipsync-Token"), req.body};
    if (r.token.empty()) r.token = req.get_param_value("token");
    const auto out = api.handle(r);
    res.status = out.status;
    res.set_content(out.body, out.contentType.c_str());
}

void serveAsset(const httplib::Request& req, httplib::Response& res) {
    const auto* asset = findAsset(req.path);
    if (!asset) {
        res.status = 404;
        res.set_content("not found", "text/plain");
        return;
    }
    res.set_content(std::string(asset->body), std::string(asset->contentType).c_str());
}
}  // namespace

EditorServer::EditorServer(EditorApi& api, const ServerOptions& options)
    : impl_(std::make_unique<Impl>()), host_(options.bind), token_(api.token()) {
    auto& s = impl_->server;
    // The token travels in the URL of the page: keep it out of Referer headers and caches.
    s.set_default_headers({{"Cache-Control", "no-store"},
                           {"Referrer-Policy", "no-referrer"},
                           {"X-Content-Type-Options", "nosniff"},
                           {"Content-Security-Policy",
                            "default-src 'self'; media-src 'self' data:; img-src 'self' data:"}});
    s.set_payload_max_length(kMaxBody);
    s.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request& req,
                                                                httplib::Response& res) {
        // The server's own refusal of a body over kMaxBody comes without one; the API's
        // answers keep theirs.
        if (res.status != 413 || !res.body.empty())
            return httplib::Server::HandlerResponse::Unhandled;
        // cpp-httplib takes only 8 KiB of a body it thinks is a form (curl's default type).
        const bool form =
            req.get_header_value("Content-Type") == "application/x-www-form-urlencoded";
        res.set_content(form ? R"({"error": "send the JSON with Content-Type: application/json"})"
                             : R"({"error": "request larger than )" +
                                   std::to_string(kMaxBody >> 20) +
                                   R"( MiB: preview a shorter recording"})",
                        "application/json");
        return httplib::Server::HandlerResponse::Handled;
    }));
    // cpp-httplib's default adds SO_REUSEPORT, which lets a second editor share the port and
    // take half the requests: only SO_REUSEADDR, so a busy port is an error.
    s.set_socket_options([](int sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    const auto toApi = [&api](const httplib::Request& req, httplib::Response& res) {
        serveApi(api, req, res);
    };
    s.Get("/api/.*", toApi);
    s.Put("/api/.*", toApi);
    s.Post("/api/.*", toApi);
    s.Delete("/api/.*", toApi);
    s.Get("/[a-z.]*", serveAsset);
    if (options.port == 0)
        port_ = s.bind_to_any_port(host_);
    else
        port_ = s.bind_to_port(host_, options.port) ? options.port : -1;
    if (port_ <= 0)
        throw InputError("cannot listen on " + host_ + ":" + std::to_string(options.port) +
                         " (in use, or not an address of this machine): try another --port");
}

EditorServer::~EditorServer() = default;

std::string EditorServer::url() const {
    const bool v6 = host_.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + host_ + "]" : host_) + ":" + std::to_string(port_) +
           "/?token=" + token_;
}

void EditorServer::run() {
    impl_->server.listen_after_bind();
}
void EditorServer::stop() {
    impl_->server.stop();
}

}  // namespace lipsyncd::editor
