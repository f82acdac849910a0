// Turns the committed Viterbi path (one node per frame, in order) into the alignment: phoneme
// segments, word spans with confidences, and the stretches no word explains.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "AlignmentGraph.hpp"

namespace lipsyncd::dsp {

class AlignmentPath {
  public:
    AlignmentPath(std::span<const ScriptWord> script, const AlignmentGraph& graph,
                  const PhonemeSet& set, double hopSeconds, const AlignerConfig& config);
    // One frame of the path: its centre time, its node, and how far (dB) each class's distance
    // lay above the nearest class's in that frame.
    void add(double time, int node, std::span<const float> excessDb);
    Alignment finish(bool complete);

  private:
    struct WordStats {
        double start = 0, end = 0;
        double excessDb = 0;
        int frames = 0;
    };
    struct Run {
        int node = -1;
        double start = 0, end = 0;
    };
    void closeRun();
    float confidence(std::size_t word) const;
    float wordConfidenceFloor(std::vector<float> confidences) const;

    const AlignmentGraph* graph_;
    const PhonemeSet* set_;
    double hop_;
    AlignerConfig config_;
    std::vector<std::string> texts_;
    std::vector<WordStats> words_;
    std::vector<int> segmentWord_;  // per segment: its word, -1 for gaps
    Run run_;
    Alignment out_;
};

}  // namespace lipsyncd::dsp
