// Synthetic frames with their labels, as the network tests make them, and the share of them a
// template set's classifier decides right.
#pragma once

#include <lipsyncd/dsp.hpp>
#include <vector>

namespace lipsyncd::test {

struct LabelledFrames {
    std::vector<dsp::FrameFeatures> frames;
    PhonemeSchedule labels;
};

// `segments` of 0.2 s, "aa" and "ih" in turn, 20 valid frames each at −20 dB, the spectrum of
// frame i of a segment from spectrum(aa, i).
template <class Spectrum>
LabelledFrames aaAndIhInTurn(int segments, Spectrum spectrum) {
    LabelledFrames u;
    double t = 0;
    for (int segment = 0; segment < segments; ++segment) {
        const bool aa = segment % 2 == 0;
        u.labels.push_back({t, t + 0.2, aa ? "aa" : "ih", 1});
        for (int i = 0; i < 20; ++i, t += 0.01) {
            dsp::FrameFeatures f;
            f.valid = true;
            f.energyDb = -20;
            f.time = t + 0.005;
            f.spectrum = spectrum(aa, i);
            u.frames.push_back(std::move(f));
        }
    }
    return u;
}

// The share of `u`'s frames whose class `t` (classifying them in order, as the front end does)
// decides as the labels say.
inline double shareDecidedRight(const dsp::TemplateSet& t, const LabelledFrames& u,
                                const dsp::ClassifierConfig& config = {}) {
    const auto& set = PhonemeSet::common();
    dsp::FrameClassifier classifier(t, set, config);
    int right = 0;
    for (const auto& f : u.frames) {
        const auto label = classifier.classify(f);
        for (const auto& s : u.labels)
            if (f.time >= s.start && f.time < s.end) right += set[label.phoneme].name == s.phoneme;
    }
    return static_cast<double>(right) / static_cast<double>(u.frames.size());
}

}  // namespace lipsyncd::test
