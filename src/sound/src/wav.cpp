#include "crumple/sound/wav.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace crumple::sound {

namespace {

struct SndfileCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};
using SndfilePtr = std::unique_ptr<SNDFILE, SndfileCloser>;

}  // namespace

bool supportedSampleRate(int rate) { return rate == 48000 || rate == 44100; }

Timeline::Timeline(int sampleRate, double fps, int frameCount)
    : rate_(sampleRate), fps_(fps), frames_(frameCount) {
  if (!supportedSampleRate(sampleRate))
    throw std::invalid_argument("sound: sample rate " + std::to_string(sampleRate) +
                                " Hz is not supported (48000 or 44100)");
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw std::invalid_argument("sound: fps must be finite and > 0");
  if (frameCount < 0) throw std::invalid_argument("sound: negative frame count");
}

std::int64_t Timeline::sampleCount() const {
  return std::llround(static_cast<double>(frames_) * rate_ / fps_);
}

std::int64_t Timeline::sampleAt(double t) const {
  return std::llround(t * static_cast<double>(rate_));
}

double Timeline::timeOf(std::int64_t sample) const {
  return static_cast<double>(sample) / static_cast<double>(rate_);
}

std::int64_t writeWav(const std::filesystem::path& path, const Audio& audio, SampleFormat format) {
  const std::size_t channels = audio.channels.size();
  if (channels == 0 || channels > 2)
    throw std::invalid_argument("writeWav: need one or two channels, got " +
                                std::to_string(channels));
  if (!supportedSampleRate(audio.sampleRate))
    throw std::invalid_argument("writeWav: sample rate " + std::to_string(audio.sampleRate) +
                                " Hz is not supported (48000 or 44100)");
  const std::size_t n = audio.channels.front().size();
  for (const auto& c : audio.channels) {
    if (c.size() != n) throw std::invalid_argument("writeWav: channels of different lengths");
    if (!std::all_of(c.begin(), c.end(), [](float x) { return std::isfinite(x); }))
      throw std::invalid_argument("writeWav: a non-finite sample");
  }
  SF_INFO info{};
  info.samplerate = audio.sampleRate;
  info.channels = static_cast<int>(channels);
  info.format =
      SF_FORMAT_WAV | (format == SampleFormat::Pcm24 ? SF_FORMAT_PCM_24 : SF_FORMAT_FLOAT);
  SndfilePtr file(sf_open(path.c_str(), SFM_WRITE, &info));
  if (!file)
    throw std::runtime_error(path.string() +
                             ": cannot write the soundtrack: " + sf_strerror(nullptr));
  // PCM: libsndfile scales floats in [-1, 1] to the full range; clip first
  // (it would wrap otherwise) and count what was clipped.
  std::int64_t clipped = 0;
  std::vector<float> interleaved(n * channels);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < channels; ++c) {
      float x = audio.channels[c][i];
      if (format == SampleFormat::Pcm24 && std::abs(x) > 1.0f) {
        x = std::clamp(x, -1.0f, 1.0f);
        ++clipped;
      }
      interleaved[i * channels + c] = x;
    }
  if (format == SampleFormat::Pcm24) sf_command(file.get(), SFC_SET_CLIPPING, nullptr, SF_TRUE);
  const sf_count_t written =
      sf_writef_float(file.get(), interleaved.data(), static_cast<sf_count_t>(n));
  if (written != static_cast<sf_count_t>(n))
    throw std::runtime_error(path.string() +
                             ": writing the soundtrack failed: " + sf_strerror(file.get()));
  if (sf_close(file.release()) != 0)
    throw std::runtime_error(path.string() + ": closing the soundtrack failed");
  return clipped;
}

Audio readWav(const std::filesystem::path& path) {
  SF_INFO info{};
  SndfilePtr file(sf_open(path.c_str(), SFM_READ, &info));
  if (!file)
    throw std::runtime_error(path.string() + ": cannot read the sound: " + sf_strerror(nullptr));
  if (info.channels < 1 || info.channels > 2)
    throw std::runtime_error(path.string() + ": " + std::to_string(info.channels) +
                             " channels (one or two are read)");
  const auto channels = static_cast<std::size_t>(info.channels);
  const auto n = static_cast<std::size_t>(info.frames);
  std::vector<float> interleaved(n * channels);
  if (sf_readf_float(file.get(), interleaved.data(), info.frames) != info.frames)
    throw std::runtime_error(path.string() + ": the sound is truncated");
  Audio audio;
  audio.sampleRate = info.samplerate;
  audio.channels.assign(channels, std::vector<float>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < channels; ++c) audio.channels[c][i] = interleaved[i * channels + c];
  return audio;
}

}  // namespace crumple::sound
