// The whole front end: formats, rates and channels give the same schedule; streaming equals one
// block; bad input is refused clearly or read correctly.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "TestSpeech.hpp"

using namespace lipsyncd;

namespace {
const dsp::TemplateSet& templates() {
    static const auto t = dsp::TemplateSet::loadDefault();
    return t;
}

dsp::AnalysisResult analyze(const std::filesystem::path& file, dsp::DecodeOptions decode = {}) {
    return dsp::analyzeFile(file, templates(), PhonemeSet::common(), {}, decode);
}

std::string errorOf(const std::filesystem::path& file) {
    try {
        analyze(file);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

std::filesystem::path writeBytes(const std::string& name, const std::string& bytes) {
    const auto path = std::filesystem::temp_directory_path() / ("lipsyncd_test_" + name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

// Share of 10 ms frames on which two schedules agree.
double agreement(const PhonemeSchedule& a, const PhonemeSchedule& b) {
    return dsp::scoreSchedule(a, b, PhonemeSet::common()).accuracy();
}
}  // namespace

TEST(FrontEnd, SameSpeechInAnyFormatRateOrLayoutGivesTheSameSchedule) {
    const auto& speech = test::testSpeech();
    const auto reference = analyze(
        test::writeAudio("ref.wav", speech.samples, speech.rate, SF_FORMAT_WAV | SF_FORMAT_FLOAT));
    ASSERT_GT(reference.schedule.size(), 10u);
    struct Variant {
        const char* name;
        int rate;
        int format;
        std::vector<float> gains;
        int channel;
    };
    const std::vector<Variant> variants = {
        {"s16_16k.wav", 16000, SF_FORMAT_WAV | SF_FORMAT_PCM_16, {1.0f}, -1},
        {"s24_44k.wav", 44100, SF_FORMAT_WAV | SF_FORMAT_PCM_24, {1.0f}, -1},
        {"f32_48k.wav", 48000, SF_FORMAT_WAV | SF_FORMAT_FLOAT, {1.0f}, -1},
        {"s32_48k.wav", 48000, SF_FORMAT_WAV | SF_FORMAT_PCM_32, {1.0f}, -1},
        {"stereo_mix.wav", 44100, SF_FORMAT_WAV | SF_FORMAT_PCM_16, {0.7f, 0.7f}, -1},
        {"stereo_ch1.wav", 48000, SF_FORMAT_WAV | SF_FORMAT_PCM_16, {0.0f, 1.0f}, 1},
        {"flac_16k.flac", 16000, SF_FORMAT_FLAC | SF_FORMAT_PCM_16, {1.0f}, -1},
    };
    for (const auto& v : variants) {
        const auto audio = test::resampleOffline(speech.samples, speech.rate, v.rate);
        const auto file = test::writeAudio(v.name, audio, v.rate, v.format, v.gains);
        const auto result = analyze(file, {v.channel});
        EXPECT_EQ(result.inputRate, v.rate);
        EXPECT_NEAR(result.durationSeconds, reference.durationSeconds, 0.01) << v.name;
        EXPECT_GT(agreement(result.schedule, reference.schedule), 0.9) << v.name;
    }
}

TEST(FrontEnd, SixteenBitSamplesDecodeAsLibsndfileReadsThemAsFloats) {
    // Every 16-bit value, in a mono file and as the second channel of a stereo one (the first
    // channel counts down), decoded by AudioDecoder and by libsndfile's float reading.
    std::vector<short> mono(65536), stereo(2 * 65536);
    for (int i = 0; i < 65536; ++i) {
        mono[i] = static_cast<short>(i - 32768);
        stereo[2 * i] = static_cast<short>(32767 - i);
        stereo[2 * i + 1] = mono[i];
    }
    auto write = [](const std::string& name, const std::vector<short>& samples, int channels) {
        const auto path = std::filesystem::temp_directory_path() / ("lipsyncd_test_" + name);
        SF_INFO info{};
        info.samplerate = 16000;
        info.channels = channels;
        info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
        SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
        sf_writef_short(f, samples.data(), static_cast<sf_count_t>(samples.size() / channels));
        sf_close(f);
        return path;
    };
    auto libsndfileFloats = [](const std::filesystem::path& path) {
        SF_INFO info{};
        SNDFILE* f = sf_open(path.c_str(), SFM_READ, &info);
        std::vector<float> out(static_cast<std::size_t>(info.frames * info.channels));
        sf_command(f, SFC_SET_NORM_FLOAT, nullptr, SF_TRUE);
        sf_readf_float(f, out.data(), info.frames);
        sf_close(f);
        return out;
    };
    auto bitsOf = [](float v) {
        std::uint32_t b;
        std::memcpy(&b, &v, sizeof b);
        return b;
    };
    const auto monoFile = write("all_s16_mono.wav", mono, 1);
    const auto stereoFile = write("all_s16_stereo.wav", stereo, 2);
    const auto expectMono = libsndfileFloats(monoFile);
    const auto expectStereo = libsndfileFloats(stereoFile);
    const auto gotMono = dsp::readAudioFile(monoFile).samples;
    const auto gotSecond = dsp::readAudioFile(stereoFile, {1}).samples;
    const auto gotMix = dsp::readAudioFile(stereoFile).samples;
    ASSERT_EQ(gotMono.size(), 65536u);
    ASSERT_EQ(gotSecond.size(), 65536u);
    ASSERT_EQ(gotMix.size(), 65536u);
    int differ = 0;
    for (std::size_t i = 0; i < 65536; ++i) {
        const float a = expectStereo[2 * i], b = expectStereo[2 * i + 1];
        float mix = 0;
        mix += a;
        mix += b;
        mix /= 2.0f;
        differ += bitsOf(gotMono[i]) != bitsOf(expectMono[i]);
        differ += bitsOf(gotSecond[i]) != bitsOf(b);
        differ += bitsOf(gotMix[i]) != bitsOf(mix);
    }
    EXPECT_EQ(differ, 0);
}

TEST(FrontEnd, ChannelSelectionIgnoresTheOtherChannel) {
    // Voice on the left, a loud control tone on the right (as show files have it).
    const auto& speech = test::testSpeech();
    const auto file = test::writeAudio("show.wav", speech.samples, speech.rate,
                                       SF_FORMAT_WAV | SF_FORMAT_FLOAT, {1.0f, 1.0f});
    const auto voiceOnly =
        test::writeAudio("voice.wav", speech.samples, speech.rate, SF_FORMAT_WAV | SF_FORMAT_FLOAT);
    EXPECT_EQ(analyze(file, {0}).schedule, analyze(voiceOnly).schedule);
    try {
        analyze(file, {2});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--channel 2 does not exist"), std::string::npos)
            << e.what();
    }
}

TEST(FrontEnd, StreamingInOddChunksGivesTheSameFramesAsOneBlock) {
    const auto& speech = test::testSpeech();
    dsp::AnalysisConfig config;
    auto run = [&](std::size_t chunk) {
        dsp::FrameStream stream(config, speech.rate);
        std::vector<dsp::FrameFeatures> frames;
        const dsp::FrameStream::Sink keep = [&](const dsp::FrameFeatures& f) {
            frames.push_back(f);
        };
        for (std::size_t i = 0; i < speech.samples.size(); i += chunk)
            stream.push(std::span<const float>(speech.samples)
                            .subspan(i, std::min(chunk, speech.samples.size() - i)),
                        keep);
        stream.finish(keep);
        return frames;
    };
    const auto whole = run(speech.samples.size());
    for (std::size_t chunk : {1u, 7u, 160u, 333u, 4097u}) {
        const auto parts = run(chunk);
        ASSERT_EQ(parts.size(), whole.size()) << "chunk " << chunk;
        for (std::size_t i = 0; i < whole.size(); ++i) {
            ASSERT_DOUBLE_EQ(parts[i].time, whole[i].time);
            ASSERT_NEAR(parts[i].energyDb, whole[i].energyDb, 1e-3)
                << "chunk " << chunk << " frame " << i;
            for (std::size_t b = 0; b < whole[i].spectrum.size(); ++b)
                ASSERT_NEAR(parts[i].spectrum[b], whole[i].spectrum[b], 1e-2)
                    << "chunk " << chunk << " frame " << i;
        }
    }
}

TEST(FrontEnd, SegmentsCloseWithinTheReportedLatency) {
    const auto& speech = test::testSpeech();
    dsp::StreamingAnalyzer analyzer(templates(), PhonemeSet::common(), speech.rate);
    double pushedSeconds = 0, worstLag = 0;
    int segments = 0;
    analyzer.onSegment([&](const PhonemeSegment& s) {
        worstLag = std::max(worstLag, pushedSeconds - s.end);
        ++segments;
    });
    const std::size_t block = speech.rate / 100;  // 10 ms
    for (std::size_t i = 0; i < speech.samples.size(); i += block) {
        const auto n = std::min(block, speech.samples.size() - i);
        analyzer.push(std::span<const float>(speech.samples).subspan(i, n));
        pushedSeconds += static_cast<double>(n) / speech.rate;
    }
    EXPECT_GT(segments, 5);
    EXPECT_LE(worstLag, analyzer.latencySeconds() + 0.011);
    EXPECT_LT(analyzer.latencySeconds(), 0.2);
}

namespace {
// A vowel of espeak-ng's cut by `gapSeconds` of digital silence, as a stop's closure cuts one;
// returns the class the front end gives the middle of the gap.
std::string classInAGapOf(double gapSeconds, dsp::FrontEndConfig config = {}) {
    const auto speech = test::speak(test::espeak(), "father", "en-us");
    const auto vowel = std::find_if(speech.labels.begin(), speech.labels.end(),
                                    [](const PhonemeSegment& s) { return s.phoneme == "aa"; });
    EXPECT_NE(vowel, speech.labels.end());
    const double cut = 0.5 * (vowel->start + vowel->end);
    const auto at = static_cast<std::ptrdiff_t>(cut * speech.rate);
    std::vector<float> samples(speech.samples.begin(), speech.samples.begin() + at);
    samples.resize(samples.size() + static_cast<std::size_t>(gapSeconds * speech.rate), 0.0f);
    samples.insert(samples.end(), speech.samples.begin() + at, speech.samples.end());

    dsp::StreamingAnalyzer analyzer(templates(), PhonemeSet::common(), speech.rate, config);
    PhonemeSchedule schedule;
    analyzer.onSegment([&](const PhonemeSegment& s) { schedule.push_back(s); });
    analyzer.push(samples);
    analyzer.finish();
    const double middle = cut + gapSeconds / 2;
    for (const auto& s : schedule)
        if (s.start <= middle && middle < s.end) return s.phoneme;
    return "";
}
}  // namespace

TEST(FrontEnd, AShortSilenceInsideAWordIsAStopsClosureAndALongOneAPause) {
    // 90 ms cut into a vowel, of which the front end hears 60 ms as silence (its window reaches
    // into the gap), is what the closure of a t or k sounds like: the mouth holds a consonant.
    // 300 ms is a pause, and the mouth may rest.
    EXPECT_EQ(classInAGapOf(0.09), "d");
    EXPECT_EQ(classInAGapOf(0.3), "sil");
    dsp::FrontEndConfig off;
    off.segmenter.stopClosureSeconds = 0;
    EXPECT_EQ(classInAGapOf(0.09, off), "sil");
}

TEST(FrontEnd, BadFilesGetClearErrors) {
    EXPECT_NE(errorOf("/nonexistent/x.wav").find("no such file"), std::string::npos);
    EXPECT_NE(errorOf(writeBytes("empty.wav", "")).find("cannot decode"), std::string::npos);
    EXPECT_NE(errorOf(writeBytes("junk.wav", std::string(5000, 'x'))).find("cannot decode"),
              std::string::npos);
    EXPECT_NE(errorOf(writeBytes("trunc.wav", "RIFF\x24\x00\x00\x00WAVEfmt "))
                  .find("lipsyncd_test_trunc.wav"),
              std::string::npos);
    EXPECT_NE(errorOf(std::filesystem::temp_directory_path()).find("is a directory"),
              std::string::npos);
}

TEST(FrontEnd, ZeroLengthAudioGivesAnEmptySchedule) {
    const auto file = test::writeAudio("zero.wav", {}, 16000, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
    const auto result = analyze(file);
    EXPECT_EQ(result.durationSeconds, 0.0);
    EXPECT_LE(result.schedule.size(), 1u);
}

// A file cut short (a copy or a download interrupted) is read as far as it goes, and the user
// is told: its header promised more. WAV and AIFF headers say how much audio follows (libsndfile
// then reads less and says so in its log); a FLAC decoder loses sync where the data stops.
TEST(FrontEnd, TruncatedDataIsReadAsFarAsItGoesAndSaidToBe) {
    const auto& speech = test::testSpeech();
    const double seconds = static_cast<double>(speech.samples.size()) / speech.rate;
    for (const auto& [name, format] : {std::pair("cut.wav", SF_FORMAT_WAV | SF_FORMAT_PCM_16),
                                       std::pair("cut.aiff", SF_FORMAT_AIFF | SF_FORMAT_PCM_16),
                                       std::pair("cut.flac", SF_FORMAT_FLAC | SF_FORMAT_PCM_16)}) {
        SCOPED_TRACE(name);
        const auto file = test::writeAudio(name, speech.samples, speech.rate, format);
        const auto whole = analyze(file);
        EXPECT_TRUE(whole.warnings.empty()) << whole.warnings.front();
        std::filesystem::resize_file(file, std::filesystem::file_size(file) / 2);
        const auto result = analyze(file);
        EXPECT_LT(result.durationSeconds, 0.7 * seconds);
        EXPECT_GT(result.durationSeconds, 0.2 * seconds);
        EXPECT_FALSE(result.schedule.empty());
        ASSERT_EQ(result.warnings.size(), 1u);
        const auto& warning = result.warnings.front();
        EXPECT_NE(warning.find(file.string() + ": truncated"), std::string::npos) << warning;
        char promised[32];
        std::snprintf(promised, sizeof promised, "promises %.2f s", seconds);
        EXPECT_NE(warning.find(promised), std::string::npos) << warning;
    }
}

TEST(FrontEnd, NaNSamplesAreCountedAndReadAsSilence) {
    auto samples = test::testSpeech().samples;
    for (std::size_t i = 1000; i < 3000; ++i) samples[i] = std::nanf("");
    samples[5000] = INFINITY;
    const auto file = test::writeAudio("nan.wav", samples, test::testSpeech().rate,
                                       SF_FORMAT_WAV | SF_FORMAT_FLOAT);
    const auto result = analyze(file);
    EXPECT_EQ(result.nonFiniteSamples, 2001);
    for (const auto& s : result.schedule) {
        EXPECT_TRUE(std::isfinite(s.start) && std::isfinite(s.end));
        EXPECT_TRUE(std::isfinite(s.confidence));
    }
}

TEST(FrontEnd, TenHoursOfSilenceStreamInBoundedMemory) {
    // 10 h at 8 kHz, pushed as a live stream would push it; memory must not grow with length.
    dsp::StreamingAnalyzer analyzer(templates(), PhonemeSet::common(), 8000);
    std::size_t segments = 0;
    analyzer.onSegment([&](const PhonemeSegment&) { ++segments; });
    const std::vector<float> block(8000, 0.0f);
    auto maxRssKb = [] {
        rusage u{};
        getrusage(RUSAGE_SELF, &u);
        return u.ru_maxrss;
    };
    for (int s = 0; s < 60; ++s) analyzer.push(block);  // warm up
    const long before = maxRssKb();
    for (int s = 0; s < 10 * 3600; ++s) analyzer.push(block);
    analyzer.finish();
    EXPECT_LT(maxRssKb() - before, 4096) << "peak memory grew by more than 4 MiB";
    EXPECT_EQ(segments, 1u);  // one long silence
}

TEST(FrontEnd, AShowFileCanLeaveTheVoiceChannelOutOfTheMix) {
    // Voice on channel 0, the audience track (here: the voice at a quarter) on channel 1.
    const auto& s = lipsyncd::test::testSpeech();
    const auto file = lipsyncd::test::writeAudio("show.wav", s.samples, s.rate,
                                                 SF_FORMAT_WAV | SF_FORMAT_FLOAT, {1.0f, 0.25f});
    lipsyncd::dsp::DecodeOptions others;
    others.skipChannel = 0;
    const auto played = lipsyncd::dsp::readAudioFile(file, others);
    ASSERT_EQ(played.samples.size(), s.samples.size());
    for (std::size_t i = 0; i < s.samples.size(); i += 997)
        EXPECT_NEAR(played.samples[i], 0.25f * s.samples[i], 1e-6);
}
