// The queue of requests waiting to play, and the worker thread that makes them ready (decode,
// analysis, speech synthesis). The real-time loop only ever try-locks it: a clip that is not
// ready yet, or a worker that holds the lock, costs the loop nothing but a later start.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "LiveMode.hpp"

namespace lipsyncd::daemon {

// One play or say request, checked and bounded, not yet prepared.
struct ClipRequest {
    std::string name;            // as status shows it
    std::filesystem::path file;  // play: a regular audio file (empty for say)
    int channel = -1;            // play: the voice channel, -1: the mix
    std::string text, voice;     // say
    // The words spoken in `file`, when known (a script beside the file, or play's text
    // argument): preparation passes them on to alignment instead of recognition.
    std::optional<std::string> knownText;
    double maxSeconds = 30;                  // the config's limit on a clip's length
    std::shared_ptr<const ClipMaker> maker;  // the config's pieces when it was asked for
};

// A line said live, over, waiting to teach the show's voice (`line`).
struct LineRequest {
    LiveLine line;
    std::shared_ptr<const ClipMaker> maker;  // the config's pieces when the line was over
};
struct LineOutcome {
    std::string text;
    ClipMaker::LineLesson lesson;
};

// A line's words to read for live input to follow (`line` with follow_lines): the cue's number.
struct WordsRequest {
    std::uint64_t cue = 0;
    std::string text;
    std::shared_ptr<const ClipMaker> maker;
};
struct WordsRead {
    std::uint64_t cue = 0;
    std::vector<dsp::ScriptWord> words;
    std::string error;  // why they could not be read (words empty)
};

class ClipQueue {
  public:
    explicit ClipQueue(std::size_t capacity);
    ~ClipQueue();  // stops the worker (after the clip it is making)
    ClipQueue(const ClipQueue&) = delete;
    ClipQueue& operator=(const ClipQueue&) = delete;

    // False when the queue is full.
    bool push(ClipRequest request);
    // The front clip when it is ready and the lock is free: never waits (the real-time loop).
    std::optional<Clip> tryTakeReady();
    void clear();  // drops every waiting request; a clip being made is dropped when done
    void setCapacity(std::size_t capacity);
    std::size_t capacity() const;
    std::vector<std::string> names() const;  // what waits, in order
    bool empty() const;
    // Bytes the waiting requests and the clip made ready ahead hold (the queue's memory: one
    // prepared clip at most, however long the queue).
    std::size_t bytesHeld() const;
    // Requests whose preparation failed since the last call: "NAME: why".
    std::vector<std::string> takeFailures();

    // A line said live, to align on its words and learn from: the worker takes it before the
    // next clip (a line takes about a tenth of a second). At most kMaxWaitingLines wait; one
    // more drops the oldest (false).
    static constexpr std::size_t kMaxWaitingLines = 4;
    bool learn(LineRequest request);
    std::vector<LineOutcome> takeLineOutcomes();  // what the lines taught since the last call

    // A line's words, read before anything else waiting (the line is being said): only the
    // newest cue's matter, so one still waiting is replaced, and one read is kept till taken.
    void read(WordsRequest request);
    std::optional<WordsRead> takeWordsRead();

  private:
    struct Job {
        ClipRequest request;
        std::optional<Clip> clip;
        bool preparing = false;
    };
    void work();
    bool clipToMake() const;  // the front request waits for the worker (mutex_ held)
    void learnNextLine(std::unique_lock<std::mutex>& lock,
                       std::unique_ptr<EspeakSynthesizer>& synth);
    void readWords(std::unique_lock<std::mutex>& lock, std::unique_ptr<EspeakSynthesizer>& synth);

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Job> jobs_;
    std::vector<std::string> failures_;
    std::deque<LineRequest> lines_;
    std::vector<LineOutcome> lineOutcomes_;
    std::optional<WordsRequest> toRead_;
    std::optional<WordsRead> wordsRead_;
    std::size_t capacity_;
    std::uint64_t generation_ = 0;  // bumped by clear(): a result from before is dropped
    bool stopping_ = false;
    std::thread worker_;  // last: started when everything above exists
};

// Bytes a clip's audio and weights hold.
std::size_t bytesOf(const Clip& clip);

// Request-time checks (cheap: a stat and an audio header). InputError saying what is wrong.
double checkAudioFile(const std::filesystem::path& file, double maxSeconds);  // its duration
// `command` names the request in the message.
void checkText(const std::string& text, std::size_t maxBytes, const std::string& command);

// Decodes and analyses a file, or synthesises text (`synth` is made on first use and kept:
// espeak-ng allows one per process). InputError naming the file or text when it cannot.
Clip prepareClip(const ClipRequest& request, std::unique_ptr<EspeakSynthesizer>& synth);

}  // namespace lipsyncd::daemon
