// The worker prepares only the front request: one clip ready ahead of the one that plays, so a
// full queue of long clips costs their requests' few bytes, not their audio.
#include "ClipQueue.hpp"

#include <malloc.h>
#include <pthread.h>

#include <csignal>
#include <functional>
#include <lipsyncd/tts.hpp>
#include <utility>

#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

namespace {
// The worker takes no signals (it inherits the mask it starts with): SIGTERM and SIGHUP go to
// the main loop's signalfd, never kill the process from under it.
std::thread startWithoutSignals(std::function<void()> body) {
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    std::thread t(std::move(body));
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    return t;
}
}  // namespace

ClipQueue::ClipQueue(std::size_t capacity)
    : capacity_(capacity), worker_(startWithoutSignals([this] { work(); })) {}

ClipQueue::~ClipQueue() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    worker_.join();
}

bool ClipQueue::push(ClipRequest request) {
    {
        std::lock_guard lock(mutex_);
        if (jobs_.size() >= capacity_) return false;
        jobs_.push_back({std::move(request), std::nullopt, false});
    }
    wake_.notify_all();
    return true;
}

std::optional<Clip> ClipQueue::tryTakeReady() {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock || jobs_.empty() || !jobs_.front().clip) return std::nullopt;
    auto clip = std::move(jobs_.front().clip);
    jobs_.pop_front();
    lock.unlock();
    wake_.notify_all();  // the next one can be made now
    return clip;
}

void ClipQueue::clear() {
    std::lock_guard lock(mutex_);
    jobs_.clear();
    ++generation_;
}

void ClipQueue::setCapacity(std::size_t capacity) {
    std::lock_guard lock(mutex_);
    capacity_ = capacity;
}

std::size_t ClipQueue::capacity() const {
    std::lock_guard lock(mutex_);
    return capacity_;
}

std::vector<std::string> ClipQueue::names() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& j : jobs_) out.push_back(j.request.name);
    return out;
}

bool ClipQueue::empty() const {
    std::lock_guard lock(mutex_);
    return jobs_.empty();
}

std::size_t bytesOf(const Clip& clip) {
    const auto& w = clip.weights;
    std::size_t names = clip.name.capacity();
    for (const auto& p : w.poses) names += sizeof p + p.capacity();
    return sizeof clip + names + clip.samples.capacity() * sizeof(std::int16_t) +
           w.values.capacity() * sizeof(float) + w.times.capacity() * sizeof(double);
}

std::size_t ClipQueue::bytesHeld() const {
    std::lock_guard lock(mutex_);
    std::size_t bytes = 0;
    for (const auto& j : jobs_) {
        const auto& r = j.request;
        bytes += sizeof j + r.name.capacity() + r.file.native().capacity() + r.text.capacity() +
                 r.voice.capacity() + (r.knownText ? r.knownText->capacity() : 0);
        if (j.clip) bytes += bytesOf(*j.clip);
    }
    for (const auto& l : lines_)
        bytes += sizeof l + l.line.text.capacity() + l.line.samples.capacity() * sizeof(float);
    return bytes;
}

std::vector<std::string> ClipQueue::takeFailures() {
    std::lock_guard lock(mutex_);
    return std::exchange(failures_, {});
}

bool ClipQueue::learn(LineRequest request) {
    bool kept = true;
    {
        std::lock_guard lock(mutex_);
        if (lines_.size() >= kMaxWaitingLines) {
            lines_.pop_front();
            kept = false;
        }
        lines_.push_back(std::move(request));
    }
    wake_.notify_all();
    return kept;
}

std::vector<LineOutcome> ClipQueue::takeLineOutcomes() {
    std::lock_guard lock(mutex_);
    return std::exchange(lineOutcomes_, {});
}

bool ClipQueue::clipToMake() const {
    return !jobs_.empty() && !jobs_.front().clip && !jobs_.front().preparing;
}

void ClipQueue::learnNextLine(std::unique_lock<std::mutex>& lock,
                              std::unique_ptr<EspeakSynthesizer>& synth) {
    auto request = std::move(lines_.front());
    lines_.pop_front();
    lock.unlock();
    LineOutcome outcome{request.line.text, {}};
    try {
        if (!synth) synth = std::make_unique<EspeakSynthesizer>();  // one a process (espeak-ng)
        const auto& l = request.line;
        outcome.lesson = request.maker->learnFromLine(l.samples, l.rate, l.text, *synth, logInfo);
    } catch (const std::exception& e) {
        outcome.lesson = {false, e.what()};
    }
    request = {};  // its samples go before the lock is taken again
    ::malloc_trim(0);
    lock.lock();
    lineOutcomes_.push_back(std::move(outcome));
}

void ClipQueue::read(WordsRequest request) {
    {
        std::lock_guard lock(mutex_);
        toRead_ = std::move(request);
    }
    wake_.notify_all();
}

std::optional<WordsRead> ClipQueue::takeWordsRead() {
    std::unique_lock lock(mutex_, std::try_to_lock);  // the loop never waits for the worker
    if (!lock) return std::nullopt;
    return std::exchange(wordsRead_, std::nullopt);
}

void ClipQueue::readWords(std::unique_lock<std::mutex>& lock,
                          std::unique_ptr<EspeakSynthesizer>& synth) {
    auto request = std::move(*toRead_);
    toRead_.reset();
    lock.unlock();
    WordsRead read{request.cue, {}, {}};
    try {
        if (!synth) synth = std::make_unique<EspeakSynthesizer>();  // one a process (espeak-ng)
        read.words = request.maker->readLine(request.text, *synth);
    } catch (const std::exception& e) {
        read.error = e.what();
    }
    lock.lock();
    wordsRead_ = std::move(read);
}

void ClipQueue::work() {
    std::unique_ptr<EspeakSynthesizer> synth;  // this thread's, for the process's life
    std::unique_lock lock(mutex_);
    for (;;) {
        wake_.wait(lock, [&] { return stopping_ || toRead_ || !lines_.empty() || clipToMake(); });
        if (stopping_) return;
        if (toRead_) {
            readWords(lock, synth);
            continue;
        }
        if (!lines_.empty()) {
            learnNextLine(lock, synth);
            continue;
        }
        jobs_.front().preparing = true;
        const auto request = jobs_.front().request;
        const auto generation = generation_;
        lock.unlock();
        std::optional<Clip> clip;
        std::string failure;
        try {
            clip = prepareClip(request, synth);
        } catch (const std::exception& e) {
            failure = request.name + ": " + e.what();
        }
        ::malloc_trim(0);  // the decoder's and analysis's buffers back to the system
        lock.lock();
        // clear() in the meantime: the front is another request now, or nothing.
        if (generation != generation_ || jobs_.empty()) continue;
        if (clip) {
            jobs_.front().clip = std::move(clip);
            jobs_.front().preparing = false;
        } else {
            failures_.push_back(std::move(failure));
            jobs_.pop_front();
        }
    }
}

}  // namespace lipsyncd::daemon
