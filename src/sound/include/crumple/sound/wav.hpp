#pragma once
// The soundtrack's file and clock (docs/ARCHITECTURE.md "The command line"):
// sample i sounds at time i / rate after the shot's first frame, and a
// soundtrack lasts exactly frame_count / fps. WAV files through libsndfile:
// 24-bit PCM or 32-bit float, 48 kHz by default, 44.1 kHz selectable.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace crumple::sound {

enum class SampleFormat : std::uint8_t { Pcm24, Float32 };

// The rates a soundtrack may have (Hz).
inline constexpr int kDefaultSampleRate = 48000;
bool supportedSampleRate(int rate);  // 48000 or 44100

// The clock of a shot's soundtrack: `frameCount` frames at `fps` from the
// first frame (t = 0 here), sampled at `sampleRate`.
class Timeline {
 public:
  // Throws std::invalid_argument for a rate other than 48000 / 44100, a
  // non-positive or non-finite fps, or a negative frame count.
  Timeline(int sampleRate, double fps, int frameCount);

  int sampleRate() const { return rate_; }
  double fps() const { return fps_; }
  int frameCount() const { return frames_; }
  // round(frameCount * rate / fps): exact when rate / fps is a whole number
  // (24, 25, 30, 48, 50, 60 fps at either rate), else within half a sample.
  std::int64_t sampleCount() const;
  double duration() const { return frames_ / fps_; }  // s
  // The sample nearest time t (s after the first frame), not clamped.
  std::int64_t sampleAt(double t) const;
  // The time of sample i (s after the first frame).
  double timeOf(std::int64_t sample) const;
  // The first sample of frame f (0 = the first frame): sampleAt(f / fps).
  std::int64_t frameStart(int frame) const { return sampleAt(frame / fps_); }

 private:
  int rate_;
  double fps_;
  int frames_;
};

// Planar audio: channels[c][i] is sample i of channel c, nominally in
// [-1, 1]. One channel (mono) or two (stereo: left, right).
struct Audio {
  int sampleRate = kDefaultSampleRate;
  std::vector<std::vector<float>> channels;
  std::size_t sampleCount() const { return channels.empty() ? 0 : channels.front().size(); }
};

// Writes `audio` as a WAV file (libsndfile). Pcm24 clips to [-1, 1]; the
// caller is told how many samples were clipped (return value), so a level
// problem is never silent. Throws std::invalid_argument for no channels,
// more than two, channels of different lengths, a non-finite sample or an
// unsupported rate; std::runtime_error naming the path when the file cannot
// be written.
std::int64_t writeWav(const std::filesystem::path& path, const Audio& audio, SampleFormat format);

// Reads a WAV (or any file libsndfile reads) of one or two channels as
// floats, at the rate it was stored at. Throws std::runtime_error naming the
// path when it cannot be read or has more than two channels.
Audio readWav(const std::filesystem::path& path);

}  // namespace crumple::sound
