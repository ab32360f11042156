// The soundtrack's clock and WAV files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include "crumple/sound/wav.hpp"
#include "scratch.hpp"

using namespace crumple::sound;
namespace fs = std::filesystem;

namespace {

using Scratch = crumple::testing::SoundScratch;

Audio sine(int rate, std::size_t n, double hz, double amplitude, int channels = 1) {
  Audio a;
  a.sampleRate = rate;
  a.channels.assign(static_cast<std::size_t>(channels), std::vector<float>(n));
  for (int c = 0; c < channels; ++c)
    for (std::size_t i = 0; i < n; ++i)
      a.channels[static_cast<std::size_t>(c)][i] = static_cast<float>(
          amplitude * std::sin(2.0 * std::numbers::pi * hz * static_cast<double>(i) / rate + c));
  return a;
}

}  // namespace

// A soundtrack lasts exactly frame_count / fps: 2000 samples per frame at
// 24 fps and 48 kHz, and frame f starts at its sample.
TEST(Timeline, WholeSamplesPerFrameAreExact) {
  const Timeline t(48000, 24.0, 73);
  EXPECT_EQ(t.sampleCount(), 146000);
  EXPECT_DOUBLE_EQ(t.duration(), 73.0 / 24.0);
  for (int f = 0; f <= 73; ++f) EXPECT_EQ(t.frameStart(f), 2000 * f);
  EXPECT_EQ(Timeline(44100, 25.0, 10).sampleCount(), 17640);
  EXPECT_DOUBLE_EQ(t.timeOf(t.sampleAt(1.2345)), std::round(1.2345 * 48000) / 48000);
}

// Rates that do not divide into frames: the length is within half a sample
// of frame_count / fps (44.1 kHz at 24 fps; NTSC 24000/1001 fps).
TEST(Timeline, OtherRatesAreWithinHalfASample) {
  for (const auto& [rate, fps] : {std::pair{44100, 24.0}, std::pair{48000, 24000.0 / 1001.0},
                                  std::pair{44100, 30000.0 / 1001.0}})
    for (const int frames : {1, 7, 73, 1001, 14400}) {
      const Timeline t(rate, fps, frames);
      EXPECT_LE(std::abs(static_cast<double>(t.sampleCount()) / rate - frames / fps),
                0.5 / rate * (1.0 + 1e-9))
          << rate << " Hz, " << fps << " fps, " << frames << " frames";
    }
  EXPECT_THROW(Timeline(22050, 24.0, 10), std::invalid_argument);
  EXPECT_THROW(Timeline(48000, 0.0, 10), std::invalid_argument);
  EXPECT_THROW(Timeline(48000, 24.0, -1), std::invalid_argument);
}

// 32-bit float round-trips exactly, 24-bit PCM within one step of 2^-23;
// stereo keeps its channels apart; the file is as long as the audio.
TEST(Wav, RoundTripsFloatExactlyAndPcm24WithinAStep) {
  const Scratch s;
  const Audio a = sine(48000, 4801, 440.0, 0.8, 2);
  ASSERT_EQ(writeWav(s.dir / "f.wav", a, SampleFormat::Float32), 0);
  ASSERT_EQ(writeWav(s.dir / "p.wav", a, SampleFormat::Pcm24), 0);
  const Audio f = readWav(s.dir / "f.wav");
  const Audio p = readWav(s.dir / "p.wav");
  ASSERT_EQ(f.channels.size(), 2u);
  ASSERT_EQ(p.channels.size(), 2u);
  EXPECT_EQ(f.sampleRate, 48000);
  EXPECT_EQ(f.sampleCount(), 4801u);
  EXPECT_EQ(p.sampleCount(), 4801u);
  double worst = 0.0;
  for (std::size_t c = 0; c < 2; ++c)
    for (std::size_t i = 0; i < a.sampleCount(); ++i) {
      EXPECT_EQ(f.channels[c][i], a.channels[c][i]);
      worst = std::max(worst, static_cast<double>(std::abs(p.channels[c][i] - a.channels[c][i])));
    }
  EXPECT_LE(worst, std::ldexp(1.0, -23) * 1.01);
  EXPECT_GT(worst, 0.0) << "PCM quantises";
  // 44.1 kHz mono.
  const Audio m = sine(44100, 1000, 1000.0, 0.5);
  writeWav(s.dir / "m.wav", m, SampleFormat::Pcm24);
  EXPECT_EQ(readWav(s.dir / "m.wav").sampleRate, 44100);
}

// Samples beyond [-1, 1] are clipped in PCM (never wrapped) and counted;
// float keeps them.
TEST(Wav, Pcm24ClipsAndCountsWhatItClipped) {
  const Scratch s;
  const Audio a = sine(48000, 4800, 100.0, 1.5);
  std::int64_t expected = 0;
  for (float x : a.channels[0]) expected += std::abs(x) > 1.0f ? 1 : 0;
  ASSERT_GT(expected, 0);
  EXPECT_EQ(writeWav(s.dir / "p.wav", a, SampleFormat::Pcm24), expected);
  const Audio p = readWav(s.dir / "p.wav");
  for (std::size_t i = 0; i < a.sampleCount(); ++i) {
    EXPECT_LE(std::abs(p.channels[0][i]), 1.0f);
    if (a.channels[0][i] > 1.0f) {
      EXPECT_GT(p.channels[0][i], 0.999f) << i;
    }
    if (a.channels[0][i] < -1.0f) {
      EXPECT_LT(p.channels[0][i], -0.999f) << i;
    }
  }
  EXPECT_EQ(writeWav(s.dir / "f.wav", a, SampleFormat::Float32), 0);
  const Audio f = readWav(s.dir / "f.wav");
  EXPECT_FLOAT_EQ(*std::max_element(f.channels[0].begin(), f.channels[0].end()),
                  *std::max_element(a.channels[0].begin(), a.channels[0].end()));
}

// Bad audio is refused before a file is made; a path that cannot be written
// or read is named in the error.
TEST(Wav, RefusesBadAudioAndNamesThePath) {
  const Scratch s;
  Audio three = sine(48000, 10, 100.0, 0.1, 3);
  EXPECT_THROW(writeWav(s.dir / "x.wav", three, SampleFormat::Pcm24), std::invalid_argument);
  Audio uneven = sine(48000, 10, 100.0, 0.1, 2);
  uneven.channels[1].pop_back();
  EXPECT_THROW(writeWav(s.dir / "x.wav", uneven, SampleFormat::Pcm24), std::invalid_argument);
  Audio nan = sine(48000, 10, 100.0, 0.1);
  nan.channels[0][3] = std::nanf("");
  EXPECT_THROW(writeWav(s.dir / "x.wav", nan, SampleFormat::Float32), std::invalid_argument);
  Audio rate = sine(22050, 10, 100.0, 0.1);
  EXPECT_THROW(writeWav(s.dir / "x.wav", rate, SampleFormat::Pcm24), std::invalid_argument);
  EXPECT_FALSE(fs::exists(s.dir / "x.wav"));
  const fs::path nowhere = s.dir / "missing" / "x.wav";
  try {
    writeWav(nowhere, sine(48000, 10, 100.0, 0.1), SampleFormat::Pcm24);
    FAIL() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(nowhere.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(readWav(s.dir / "none.wav"), std::runtime_error);
}
