// editor: `lipsync edit`, the curve editor of Xu et al. 2013 (section 2.1, figure 3) as a local web
// application. Animators pick a phone bigram, drag the control points of each pose's curve and
// at once hear and see a sentence that uses the pair; save writes a character file holding only
// the bigrams they changed.
//
//   CharacterDraft  the curves being edited: a character file over its base set, with the
//                   unsaved edits; saves only the character's bigrams, validated as `animate
//                   --character` loads them.
//   MouthDrawing    how each pose moves the 2-D mouth the page draws (config/editor/mouth.toml).
//   EditorApi       the HTTP API as a plain function of a request (token, routes, JSON, 4xx).
//   PuppetStream    the puppet the service drives, moved by the preview: the weights go to
//                   lipsyncd's control socket (`pose` requests) at their frame rate.
//   EditorServer    cpp-httplib around the API and the page, which is built into the binary.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <lipsyncd/core.hpp>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/tts.hpp>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace lipsyncd::editor {

// generated: as the base set has it; character: as the character file on disk has it;
// edited: changed here and not saved yet.
enum class BigramState { generated, character, edited };
std::string_view toString(BigramState state);

class CharacterDraft {
  public:
    // `characterFile` is the only file save() ever writes. When it exists, it is loaded (its own
    // base wins over `baseCurves`); when it does not, editing starts from `baseCurves` (a name
    // or a path). An empty `characterFile`: edit and preview only, no saving.
    CharacterDraft(lipsync::PoseSet poses, const PhonemeSet& phonemes,
                   const std::string& baseCurves, std::filesystem::path characterFile);

    const lipsync::PoseSet& poses() const { return poses_; }
    const PhonemeSet& phonemes() const { return *phonemes_; }
    const lipsync::BigramCurveSet& curves() const { return working_; }
    const std::filesystem::path& characterFile() const { return file_; }
    const std::string& baseName() const { return base_; }

    BigramState state(std::size_t first, std::size_t second) const;
    // Per pose of the pose set, its control polygon ((0, 0)–(1, 0) for a pose that stays at 0).
    std::vector<std::vector<lipsync::ControlPoint>> polygons(std::size_t first,
                                                             std::size_t second) const;
    // Replaces one bigram with curves given as JSON text ({"pose": [[t, v], ...], ...}; poses
    // not listed stay at 0), checked exactly as a character file's bigram is. Points are
    // rounded to 1/1000 (as saved). Throws InputError naming `source`; nothing changes then.
    void replace(std::size_t first, std::size_t second, std::string_view posesJson,
                 const std::string& source);
    std::size_t unsaved() const;
    // Writes the character file: the bigrams it had and the edited ones, nothing else. The new
    // file is loaded back as `lipsync animate --character` loads it before it replaces the old
    // one, so a file that would not load is never written. Returns the number of bigrams in it.
    std::size_t save();

  private:
    bool differs(const lipsync::BigramCurveSet& a, const lipsync::BigramCurveSet& b,
                 std::size_t first, std::size_t second) const;
    std::string characterJson() const;

    lipsync::PoseSet poses_;
    const PhonemeSet* phonemes_;
    std::filesystem::path file_;
    std::string base_, name_, description_;
    lipsync::BigramCurveSet saved_;    // what the character file holds (over its base)
    lipsync::BigramCurveSet working_;  // with the edits
    std::set<std::pair<std::size_t, std::size_t>> inCharacter_;
};

// The 2-D mouth of the preview: a few drawing parameters (jaw, width, round, ...), each the
// neutral value plus the sum over poses of weight × the pose's amount. Data, so a new pose
// moves the drawing once it has a line in the file; poses without one do not move it.
struct MouthDrawing {
    std::vector<std::string> parameters;                             // the drawing's vocabulary
    std::vector<double> neutral;                                     // per parameter
    std::vector<std::pair<std::string, std::vector<double>>> poses;  // pose → per parameter
    // config/editor/mouth.toml (or a path); errors name the file, line and key. Poses that
    // `poseSet` lacks are left out (a pose set may drop one the file draws).
    static MouthDrawing load(const std::filesystem::path& file, const lipsync::PoseSet& poseSet);
};

struct ApiRequest {
    std::string method;  // GET, PUT, POST
    std::string path;    // "/api/bigrams/f/ah"
    std::string token;   // from the X-Lipsync-Token header or the ?token= parameter
    std::string body;
};

struct ApiResponse {
    int status = 200;
    std::string body;  // JSON
    std::string contentType = "application/json";
};

// The puppet that the running lipsyncd drives, moved by the preview: a thread sends the
// weights of a preview to the control socket as `pose` requests, one per frame at the frames'
// rate, from the moment the page starts playing the audio, each the puppet's lead early (as the
// service drives a clip's mouth ahead of its sound). The service applies them through
// the puppet's limits and slew and holds each briefly; when the stream stops, the mouth rests.
class PuppetStream {
  public:
    // Asks the service its status: InputError naming the socket when nothing answers there,
    // or when it drives another puppet than `puppet` (empty: any).
    PuppetStream(std::filesystem::path socket, const std::string& puppet);
    ~PuppetStream();
    PuppetStream(const PuppetStream&) = delete;
    PuppetStream& operator=(const PuppetStream&) = delete;

    // Sends the frame at `fromSeconds` now and returns the service's refusal of it (a clip
    // plays, a pose it does not know), if any; then streams the rest from a thread. Replaces
    // what was streaming.
    std::optional<std::string> play(PoseTrack track, double fromSeconds);
    void stop();
    const std::string& puppet() const { return puppet_; }
    double leadSeconds() const { return leadSeconds_; }  // the puppet's, as the service says
    std::size_t framesSent() const { return sent_; }     // by the last play()
    std::string lastError() const;  // why the last stream stopped early ("" when it did not)

  private:
    void stream(PoseTrack track, std::size_t next, std::chrono::steady_clock::time_point start,
                double from);
    std::filesystem::path socket_;
    std::string puppet_;
    double leadSeconds_ = 0;
    std::atomic<std::size_t> sent_ = 0;
    mutable std::mutex mutex_;  // guards error_ and stopping_
    std::condition_variable wake_;
    std::string error_;
    bool stopping_ = false;
    std::thread thread_;
};

struct PreviewSettings {
    std::string voice = "en-us";
    lipsync::RuntimeConfig runtime;
    std::filesystem::path templates;  // empty: the shipped default (recordings only)
    // A recording's upload: at most this many bytes (after base64) and seconds.
    std::size_t maxUploadBytes = 8u << 20;
    double maxRecordingSeconds = 60;
    PuppetStream* puppet = nullptr;  // --socket: the preview moves the puppet too
};

// The API of README "lipsync edit": every call needs the token; errors are 4xx with
// {"error": "..."} naming what is wrong. Calls are served one at a time.
class EditorApi {
  public:
    // `speech` is the process's one synthesiser (espeak-ng cannot start twice in a process).
    EditorApi(CharacterDraft draft, MouthDrawing mouth, std::string token,
              EspeakSynthesizer& speech, PreviewSettings preview = {});
    ApiResponse handle(const ApiRequest& request);
    const std::string& token() const { return token_; }

  private:
    ApiResponse route(const ApiRequest& request);
    ApiResponse listBigrams() const;
    ApiResponse bigram(std::size_t first, std::size_t second) const;
    ApiResponse putBigram(std::size_t first, std::size_t second, const ApiRequest& request);
    ApiResponse preview(const ApiRequest& request);
    ApiResponse previewRecording(const nlohmann::json& body, const std::string& voice,
                                 const lipsync::RuntimeConfig& runtime);
    ApiResponse perform(const ApiRequest& request);
    ApiResponse save();

    CharacterDraft draft_;
    MouthDrawing mouth_;
    std::string token_;
    EspeakSynthesizer* speech_;
    PreviewSettings settings_;
    std::optional<dsp::TemplateSet> templates_;  // loaded by the first recording's preview
    PoseTrack lastPreview_;                      // what /api/perform plays on the puppet
    std::mutex mutex_;
};

// 128 random bits from the system's entropy source, as 32 hex digits.
std::string randomToken();

// The page (index.html, editor.js, editor.css), built into the binary: nullptr for any other
// name, so no request ever names a file.
struct Asset {
    std::string_view contentType, body;
};
const Asset* findAsset(std::string_view urlPath);

struct ServerOptions {
    std::string bind = "127.0.0.1";
    int port = 8080;  // 0: any free port
};

// Serves the page and the API until stop(). Binding fails with a clear error (port in use).
class EditorServer {
  public:
    EditorServer(EditorApi& api, const ServerOptions& options);
    ~EditorServer();
    EditorServer(const EditorServer&) = delete;
    EditorServer& operator=(const EditorServer&) = delete;

    int port() const { return port_; }
    // The page's address with the token, as printed and opened.
    std::string url() const;
    void run();   // blocks until stop()
    void stop();  // from any thread or a signal-watching thread

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::string host_, token_;
    int port_ = 0;
};

}  // namespace lipsyncd::editor
