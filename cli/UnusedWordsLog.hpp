// Files whose words a run over a corpus could not use (espeak-ng read none of them, say), per
// speaker. The first file of a speaker is told in full, with a hint when one option would help;
// the others are counted and told once at the end. A speaker whose every line fails the same way
// (Russian words read by the default English voice: each of 620 files) then does not bury the
// run's other messages under one message a file.
#pragma once

#include <cstddef>
#include <map>
#include <ostream>
#include <string>

namespace lipsyncd::cli {

class UnusedWordsLog {
  public:
    // `where`: how a message about this file begins; `why`: what was not done and the reason;
    // `hint`: said after the first message of a speaker only (may be empty).
    void add(std::ostream& out, const std::string& speaker, const std::string& where,
             const std::string& why, const std::string& hint) {
        if (count_[speaker]++ > 0) return;
        out << where << why << (hint.empty() ? "" : " (" + hint + ")") << '\n';
    }

    // One line for each speaker with more than the one file told.
    void summarise(std::ostream& out, const std::string& program) const {
        for (const auto& [speaker, files] : count_)
            if (files > 1)
                out << program << ": " << speaker << ": the words of " << files
                    << " files not used (the first told above); audio-only analysis there\n";
    }

  private:
    std::map<std::string, std::size_t> count_;
};

}  // namespace lipsyncd::cli
