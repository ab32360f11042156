// golden_tool extract IN.pcache FRAME OUT.pcache: copies one frame of a cache
// (with its topology) into a new one-frame cache, the input of the golden
// image tests (scripts/bless-golden.sh).
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "crumple/cache/pcache.hpp"

int main(int argc, char** argv) {
  using namespace crumple;
  if (argc != 5 || std::string(argv[1]) != "extract") {
    std::fprintf(stderr, "usage: golden_tool extract IN.pcache FRAME OUT.pcache\n");
    return 2;
  }
  try {
    const cache::CacheReader reader(argv[2]);
    const int frame = std::atoi(argv[3]);
    for (std::size_t i = 0; i < reader.frameCount(); ++i) {
      if (reader.frameNumber(i) != frame) continue;
      cache::CacheHeader header = reader.header();
      header.frameStart = header.frameEnd = frame;
      cache::CacheWriter writer(argv[4], header);
      writer.append(reader.readFrame(i));
      writer.close();
      return 0;
    }
    std::fprintf(stderr, "golden_tool: frame %d is not in %s\n", frame, argv[2]);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "golden_tool: %s\n", e.what());
    return 1;
  }
}
