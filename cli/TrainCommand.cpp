// lipsync train: spectral templates from labelled audio (cluster means per class).
#include <iomanip>
#include <iostream>
#include <lipsyncd/dsp.hpp>
#include <optional>

#include "Commands.hpp"
#include "Corpus.hpp"
#include "NumberOption.hpp"
#include "Output.hpp"

namespace lipsyncd::cli {

namespace {
struct TrainOptions {
    std::vector<std::string> corpora;
    std::string output;
    std::string labels = "auto";
    dsp::TrainingOptions training;
    std::string description;
    std::vector<std::string> extraFeatures{"log_error", "level"};
    bool normaliseChannel = false;
    std::string keepTemplates;  // train only the networks, into this set
    int fineTuneEpochs = 0;     // with keepTemplates: train its networks further (0: anew)
    float fineTuneRate = 1e-4f;
};

// The mean spectrum of the training speech (valid frames within 30 dB of their file's peak):
// where the channel normalisation's running mean starts (dsp::SpectrumNormaliser).
std::vector<float> speechSpectrumMean(const TrainOptions& o) {
    auto analysis = o.training.analysis;
    analysis.spectrumMean.clear();
    const auto bins = static_cast<std::size_t>(analysis.spectrumBins);
    std::vector<double> sum(bins, 0.0);
    std::size_t frames = 0;
    for (const auto& dir : o.corpora)
        for (const auto& item : listCorpus(dir, nullptr)) {
            const auto features = dsp::analyzeFrames(item.audio, analysis);
            float peak = -120;
            for (const auto& f : features) peak = std::max(peak, f.energyDb);
            for (const auto& f : features)
                if (f.valid && f.energyDb >= peak - 30) {
                    for (std::size_t b = 0; b < bins; ++b) sum[b] += f.spectrum[b];
                    ++frames;
                }
        }
    if (frames == 0) throw InputError("training: no speech frames for the channel mean");
    std::vector<float> mean(bins);
    for (std::size_t b = 0; b < bins; ++b) mean[b] = static_cast<float>(sum[b] / frames);
    return mean;
}

void runTrain(TrainOptions o) {
    std::optional<dsp::TemplateSet> kept;
    if (o.fineTuneEpochs > 0 && o.keepTemplates.empty())
        throw InputError(
            "--fine-tune-epochs trains a set's networks further: give the set with "
            "--keep-templates");
    if (!o.keepTemplates.empty()) {
        kept = dsp::TemplateSet::named(o.keepTemplates);
        if (o.fineTuneEpochs > 0) {  // the frames the set's own networks learn from are kept
            if (!kept->jawNetwork && !kept->classNetwork)
                throw InputError("--fine-tune-epochs: " + o.keepTemplates + " has no network");
            o.training = dsp::fineTuningOptions(*kept);
        } else {
            o.training.analysis = kept->analysis;  // the network hears frames as the set does
            o.training.clustersPerClass = 1;       // the clusters are thrown away ...
            o.training.minFramesPerCluster = 1;    // ... and need no minimum
            if (o.training.jawHiddenUnits == 0 && o.training.classHiddenUnits == 0)
                throw InputError(
                    "--keep-templates trains only the networks: --jaw-hidden 0 without "
                    "--class-hidden leaves nothing to train");
        }
    }
    if (o.normaliseChannel) o.training.analysis.spectrumMean = speechSpectrumMean(o);
    const auto& set = PhonemeSet::common();
    dsp::TemplateTrainer trainer(o.training, set);
    std::size_t files = 0;
    double seconds = 0;
    for (const auto& dir : o.corpora) {
        std::vector<std::string> skipped;
        const auto items = listCorpus(dir, &skipped);
        for (const auto& s : skipped) std::cerr << "lipsync train: skipped " << s << '\n';
        for (const auto& item : items) {
            const auto labels = readLabels(item.labels, o.labels);
            std::vector<std::string> warnings;
            const auto frames = dsp::analyzeFrames(item.audio, o.training.analysis, {}, &warnings);
            printWarnings("train", warnings);
            trainer.addUtterance(frames, labels);
            seconds += frames.size() * o.training.analysis.hopSeconds;
            if (++files % 50 == 0)
                std::cerr << "lipsync train: " << files << " files, " << std::fixed
                          << std::setprecision(0) << seconds << " s of audio\n";
        }
    }
    if (kept && o.fineTuneEpochs > 0) {
        if (trainer.networkFrames() == 0)
            throw InputError("--fine-tune-epochs: no labelled speech to train on");
        auto tuned = trainer.fineTuneNetworks(std::move(*kept), o.fineTuneEpochs, o.fineTuneRate);
        if (!o.description.empty()) tuned.description = o.description;
        tuned.save(o.output);
        std::cerr << "lipsync train: " << files << " files (" << std::fixed << std::setprecision(0)
                  << seconds << " s, " << trainer.networkFrames() << " frames): " << o.keepTemplates
                  << "'s networks trained further into " << o.output << '\n';
        return;
    }
    auto templates = trainer.build(o.description.empty() ? "trained by 'lipsync train' from " +
                                                               std::to_string(files) + " files"
                                                         : o.description);
    if (kept) {  // each network asked for replaces the set's own; the others stay
        if (o.training.jawHiddenUnits > 0 && !templates.jawNetwork)
            throw InputError("--keep-templates: too little labelled speech for the jaw network");
        if (o.training.classHiddenUnits > 0 && !templates.classNetwork)
            throw InputError("--keep-templates: too little labelled speech for the class network");
        if (o.training.jawHiddenUnits > 0) kept->jawNetwork = std::move(templates.jawNetwork);
        if (o.training.classHiddenUnits > 0) {
            kept->classNetwork = std::move(templates.classNetwork);
            // The bias corrected the old network's priors; a new network needs its own fit.
            if (!kept->classBiasDb.empty())
                std::cerr << "lipsync train: dropped the set's class_bias_db (fitted for its old "
                             "class network; scripts/fit-class-bias.py fits one)\n";
            kept->classBiasDb.clear();
        }
        if (!o.description.empty()) kept->description = o.description;
        templates = std::move(*kept);
    }
    templates.save(o.output);
    std::cerr << "lipsync train: " << files << " files (" << std::fixed << std::setprecision(0)
              << seconds << " s) -> " << templates.classes.size() << " classes in " << o.output
              << '\n';
    for (const auto& c : set.classes())
        if (trainer.frames(c.name) < o.training.minFramesPerCluster && c.name != "sil")
            std::cerr << "lipsync train: note: class '" << c.name << "' has only "
                      << trainer.frames(c.name) << " frames: no template\n";
}
}  // namespace

void addTrainCommand(CLI::App& app) {
    auto o = std::make_shared<TrainOptions>();
    auto* cmd = app.add_subcommand(
        "train", "Train spectral templates from labelled audio (NAME.wav + NAME.lab folders)");
    cmd->add_option("corpus", o->corpora,
                    "Folders of NAME.wav + NAME.lab (a segment labelled with confidence 0, a "
                    "fourth column, is not learnt)")
        ->required()
        ->check(CLI::ExistingDirectory);
    cmd->add_option("-o,--output", o->output, "Template file to write (JSON)")->required();
    cmd->add_option("--labels", o->labels,
                    "Label alphabet: auto, common, arpabet, or a map name/file")
        ->capture_default_str();
    addNumberOption(*cmd, "--clusters", o->training.clustersPerClass, "Cluster means per class", 1,
                    64);
    cmd->add_flag("--full-covariance", o->training.fullCovariance,
                  "Match under the pooled within-class covariance of all features (a Mahalanobis "
                  "distance, stored as the set's 'whitening') instead of per-feature weights");
    addNumberOption(*cmd, "--jaw-hidden", o->training.jawHiddenUnits,
                    "Hidden units of the jaw network trained beside the templates (the jaw heard "
                    "from each frame); 0: none, the jaw comes from the class distances",
                    0, 256);
    addNumberOption(*cmd, "--jaw-epochs", o->training.jawEpochs,
                    "Passes of the jaw network's training", 1, 100);
    addNumberOption(*cmd, "--jaw-slopes", o->training.jawSlopeFrames,
                    "The jaw network also hears each feature's slope over the frame and this "
                    "many frames before it (a live frame waits for none); 0: the frame alone",
                    0, dsp::kMaxSlopeFrames);
    addNumberOption(*cmd, "--class-hidden", o->training.classHiddenUnits,
                    "Hidden units of the class network trained beside the templates (scaled "
                    "class likelihoods added to the template distances); 0: none",
                    0, 256);
    addNumberOption(*cmd, "--class-epochs", o->training.classEpochs,
                    "Passes of the class network's training", 1, 100);
    addNumberOption(*cmd, "--class-slopes", o->training.classSlopeFrames,
                    "The class network also hears each feature's slope over the frame and this "
                    "many frames before it (a live frame waits for none); 0: the frame alone",
                    0, dsp::kMaxSlopeFrames);
    addNumberOption(*cmd, "--order", o->training.analysis.order, "LPC order", 2, dsp::kMaxOrder);
    addNumberOption(*cmd, "--bins", o->training.analysis.spectrumBins, "Spectrum points 0..rate/2",
                    4, 512);
    cmd->add_option("--extra-features", o->extraFeatures,
                    "Features after the spectrum: log_error, level (comma list, or 'none')")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_flag("--normalise-channel", o->normaliseChannel,
                  "Subtract a running mean spectrum (channel and speaker normalisation), starting "
                  "from the training speech's mean, which the set stores");
    addNumberOption(*cmd, "--mean-prior", o->training.analysis.meanPriorSeconds,
                    "With --normalise-channel: seconds of speech the training mean counts for "
                    "before a voice's own mean takes over",
                    0.1, 600.0);
    cmd->add_option("--keep-templates", o->keepTemplates,
                    "Train only the networks (the jaw network, and the class network with "
                    "--class-hidden; --jaw-hidden 0 keeps the set's jaw network): write this "
                    "template set (name or file) with them, its analysis, templates and weights "
                    "unchanged")
        ->excludes("--normalise-channel");
    addNumberOption(*cmd, "--fine-tune-epochs", o->fineTuneEpochs,
                    "With --keep-templates: train the set's own networks further on this speech "
                    "(one speaker's, say) for this many passes, from their weights, instead of "
                    "new networks (0); the class bias stays",
                    0, 100);
    addNumberOption(*cmd, "--fine-tune-rate", o->fineTuneRate,
                    "Step size of that training (Adam's; networks are trained anew at 0.001)",
                    1e-6f, 1e-2f);
    cmd->add_option("--seed", o->training.seed,
                    "Seed of the k-means++ seeding and of the networks' starting weights and "
                    "batch order: the same speech and seed give the same set; other seeds show "
                    "how much of a difference between two recipes is the draw")
        ->capture_default_str();
    cmd->add_option("--description", o->description, "Description stored in the file");
    cmd->callback([o] {
        auto& a = o->training.analysis;
        a.errorFeature = a.levelFeature = false;
        for (const auto& f : o->extraFeatures) {
            if (f == "log_error")
                a.errorFeature = true;
            else if (f == "level")
                a.levelFeature = true;
            else if (f != "none")
                throw CLI::ValidationError(
                    "--extra-features",
                    "unknown feature '" + f + "' (known: log_error, level, none)");
        }
        runTrain(*o);
    });
}

}  // namespace lipsyncd::cli
